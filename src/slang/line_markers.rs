//! The `#line` markers of librashader's preprocessed stages, corrected, so that a
//! glslang error names the line of the file it lies in.
//!
//! librashader-preprocess 0.12.1 marks a line after each `#pragma`/`#endif` and
//! after each `#include` with the index its line iterator had, and that index
//! starts at 0 for the shader's line 2 (its `#version` line is read first) but for
//! an included file's line 1. The markers it writes are therefore short by:
//! - in the shader file: 1 after a `#pragma` or `#endif`, 2 after an `#include`;
//! - in an included file: 0 after a `#pragma` or `#endif`, 1 after an `#include`.
//!
//! A stack of the files being read tells which kind a marker is: a marker naming
//! the file below the top returns from an include (pop), one naming the top
//! follows a `#pragma` in it, and any other starts an include (push). Stage
//! splitting drops the other stage's lines with their markers, but what it
//! drops is whole regions of the shader file, never half an include, so the
//! stack stays right.

/// `stage` with each `#line N "FILE"` marker corrected; `shader` is the file
/// name (no folder) of the pass's own shader.
pub fn corrected_line_markers(stage: &str, shader: &str) -> String {
    let mut out = String::with_capacity(stage.len());
    let mut reading: Vec<String> = Vec::new();
    for line in stage.split_inclusive('\n') {
        let Some((n, file)) = marker(line) else {
            out.push_str(line);
            continue;
        };
        let depth = reading.len();
        let short_by = if depth >= 2 && reading[depth - 2] == file {
            reading.pop();
            if depth == 2 && file == shader {
                2
            } else {
                1
            }
        } else if reading.last().is_some_and(|top| top == file) {
            u32::from(depth == 1 && file == shader)
        } else {
            reading.push(file.to_string());
            0
        };
        out.push_str(&format!("#line {} \"{file}\"", n + short_by));
        if line.ends_with('\n') {
            out.push('\n');
        }
    }
    out
}

/// `(N, FILE)` of a `#line N "FILE"` line.
fn marker(line: &str) -> Option<(u32, &str)> {
    let rest = line.trim_end().strip_prefix("#line ")?;
    let (n, file) = rest.split_once(' ')?;
    let file = file.strip_prefix('"')?.strip_suffix('"')?;
    Some((n.parse().ok()?, file))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `a.slang`: 1 `#version`, 2 `x`, 3 `#pragma foo`, 4 `#include "inc.h"`,
    /// 5 `z`; `inc.h`: 1 `y`, 2 `#pragma bar`, 3 `w` (librashader's output).
    #[test]
    fn markers_after_pragmas_and_includes_are_moved_to_their_lines() {
        let stage = "#version 450\n#line 2 \"a.slang\"\nx\n#pragma foo\n#line 3 \"a.slang\"\n\
                     #line 1 \"inc.h\"\ny\n#pragma bar\n#line 3 \"inc.h\"\nw\n#line 3 \"a.slang\"\nz\n";
        let got = corrected_line_markers(stage, "a.slang");
        assert_eq!(
            got,
            "#version 450\n#line 2 \"a.slang\"\nx\n#pragma foo\n#line 4 \"a.slang\"\n\
             #line 1 \"inc.h\"\ny\n#pragma bar\n#line 3 \"inc.h\"\nw\n#line 5 \"a.slang\"\nz\n"
        );
    }

    /// `outer.h` includes `inner.h` on its line 1: the return marker is `#line 1`,
    /// like an include's first, and the stack tells them apart.
    #[test]
    fn an_include_returning_into_an_include_is_moved_by_one() {
        let stage =
            "#line 2 \"a.slang\"\n#line 1 \"outer.h\"\n#line 1 \"inner.h\"\n#line 1 \"outer.h\"\n";
        assert_eq!(
            corrected_line_markers(stage, "a.slang"),
            "#line 2 \"a.slang\"\n#line 1 \"outer.h\"\n#line 1 \"inner.h\"\n#line 2 \"outer.h\"\n"
        );
    }
}
