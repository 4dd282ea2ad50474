//! Catching a dependency's panic quietly: a decoder or parser that panics on a
//! damaged file (an index out of bounds in the glTF crate, an `unwrap` in a codec) is
//! turned into an error message, and the panic's own text and backtrace hint never
//! reach the user's terminal.
//!
//! [`catch_quiet`] runs a closure under `catch_unwind` with this thread marked quiet;
//! a panic hook (installed once, on first use, in front of whatever hook the program
//! had) says nothing for a panic on a quiet thread and hands every other panic to the
//! previous hook. Work that a quiet closure spawns on its own threads runs under
//! [`quietly`] so that a panic there (propagated to the caller by a scoped thread) is
//! silent too. The panic's message comes back in the error, and is logged at debug
//! level with its location.
//!
//! The hook is process-wide: a program that sets its own hook *after* the library's
//! first use replaces it, and caught panics are printed again.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// How many [`catch_quiet`] / [`quietly`] calls this thread is inside.
    static QUIET: Cell<u32> = const { Cell::new(0) };
}

static INSTALL: Once = Once::new();

fn install_hook() {
    INSTALL.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if QUIET.with(Cell::get) > 0 {
                log::debug!("caught panic: {info}");
                return;
            }
            previous(info);
        }));
    });
}

/// Restores the thread's quiet depth however the closure ends.
struct Depth;

impl Depth {
    fn enter() -> Depth {
        install_hook();
        QUIET.with(|q| q.set(q.get() + 1));
        Depth
    }
}

impl Drop for Depth {
    fn drop(&mut self) {
        QUIET.with(|q| q.set(q.get().saturating_sub(1)));
    }
}

/// Runs `f`; a panic inside it comes back as `Err(its message)`, printed by no hook.
pub fn catch_quiet<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    let _depth = Depth::enter();
    catch_unwind(AssertUnwindSafe(f)).map_err(|p| panic_message(&*p))
}

/// Runs `f` with this thread marked quiet, without catching: for the body of a
/// thread that a [`catch_quiet`] closure spawns and joins (its panic is propagated
/// to the caller, which catches it).
pub fn quietly<R>(f: impl FnOnce() -> R) -> R {
    let _depth = Depth::enter();
    f()
}

/// The text of a panic payload (`panic!("...")` gives a `&str` or a `String`).
pub fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_caught_panic_comes_back_as_its_message() {
        assert_eq!(catch_quiet(|| 5), Ok(5));
        let r: Result<(), String> = catch_quiet(|| panic!("bad {}", 7));
        assert_eq!(r, Err("bad 7".to_string()));
        // The depth is restored after a panic.
        assert_eq!(QUIET.with(Cell::get), 0);
    }

    #[test]
    fn a_panic_on_a_quiet_scoped_thread_is_caught_by_the_caller() {
        let r = catch_quiet(|| {
            std::thread::scope(|s| {
                s.spawn(|| quietly(|| panic!("worker")));
            })
        });
        assert!(r.is_err());
    }
}
