//! The built-in deferred renderer (see issue: scene input with G-buffer auxiliary inputs).
