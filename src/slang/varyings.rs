//! Matrix varyings split into column vectors. A slang vertex stage may pass a
//! matrix to its fragment stage (`layout(location = 1) out mat4 profile;`);
//! WGSL forbids matrices between stages, so naga rejects the translated module
//! inside librashader ("matrix varying"). Before glslang sees the stages, each
//! such matrix becomes one `vecR` varying per column at consecutive locations (a
//! `matCxR` takes C locations in GLSL as well, so the other locations stay):
//! - each stage keeps the matrix as a private global of the same name, and a new
//!   `main` runs the stage's own (renamed) `main`: the vertex stage's stores the
//!   columns after it, the fragment stage's rebuilds the matrix before it.
//!
//! Each rewritten declaration stays on its line, and the new `main` goes after
//! the last line, so glslang's line numbers do not move. This is text
//! work on GLSL that glslang has not parsed yet; no crate does it, and it only
//! has to recognise one declaration form.

use super::words::replace_word;

/// One matrix varying: its location, column count, row count and name.
#[derive(Debug, Clone, PartialEq)]
struct MatrixVarying {
    location: u32,
    columns: u32,
    rows: u32,
    name: String,
}

/// The vertex and fragment stage texts with their matrix varyings split into
/// columns (unchanged when there are none).
pub fn split_matrix_varyings(vertex: &str, fragment: &str) -> (String, String) {
    let (vertex, outs) = rewrite_declarations(vertex, "out");
    let (fragment, ins) = rewrite_declarations(fragment, "in");
    (
        with_new_main(vertex, &outs, Order::StoreColumnsAfter),
        with_new_main(fragment, &ins, Order::BuildMatrixBefore),
    )
}

/// `text` with each `layout(location = N) DIRECTION matCxR NAME;` line replaced
/// by its column declarations, and the varyings found.
fn rewrite_declarations(text: &str, direction: &str) -> (String, Vec<MatrixVarying>) {
    let mut found = Vec::new();
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        match parse_declaration(line, direction) {
            Some(m) => {
                out.push_str(&column_declarations(&m, direction));
                if line.ends_with('\n') {
                    out.push('\n');
                }
                found.push(m);
            }
            None => out.push_str(line),
        }
    }
    (out, found)
}

/// A line `layout(location = N) DIRECTION matK[xR] NAME;` (any spacing, an
/// optional interpolation qualifier before the direction is not accepted).
fn parse_declaration(line: &str, direction: &str) -> Option<MatrixVarying> {
    let compact: String = line.split_whitespace().collect::<Vec<_>>().join(" ");
    let rest = compact.strip_prefix("layout")?.trim_start();
    let rest = rest.strip_prefix('(')?;
    let (qualifier, rest) = rest.split_once(')')?;
    let (key, value) = qualifier.split_once('=')?;
    if key.trim() != "location" {
        return None;
    }
    let location: u32 = value.trim().parse().ok()?;
    let mut words = rest.split_whitespace();
    if words.next()? != direction {
        return None;
    }
    let ty = words.next()?.strip_prefix("mat")?;
    let name_part: String = words.collect::<Vec<_>>().join("");
    let name = name_part.strip_suffix(';')?;
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return None;
    }
    let (columns, rows) = match ty.split_once('x') {
        Some((c, r)) => (c.parse().ok()?, r.parse().ok()?),
        None => {
            let n = ty.parse().ok()?;
            (n, n)
        }
    };
    if !(2..=4).contains(&columns) || !(2..=4).contains(&rows) {
        return None;
    }
    Some(MatrixVarying {
        location,
        columns,
        rows,
        name: name.to_string(),
    })
}

fn column_name(m: &MatrixVarying, c: u32) -> String {
    format!("{}_fxcol{c}", m.name)
}

fn matrix_type(m: &MatrixVarying) -> String {
    if m.columns == m.rows {
        format!("mat{}", m.columns)
    } else {
        format!("mat{}x{}", m.columns, m.rows)
    }
}

/// One line: the column varyings, then the private matrix.
fn column_declarations(m: &MatrixVarying, direction: &str) -> String {
    let mut line = String::new();
    for c in 0..m.columns {
        line.push_str(&format!(
            "layout(location = {}) {direction} vec{} {}; ",
            m.location + c,
            m.rows,
            column_name(m, c)
        ));
    }
    line.push_str(&format!("{} {};", matrix_type(m), m.name));
    line
}

/// What the new `main` does around the stage's own.
#[derive(Clone, Copy)]
enum Order {
    /// Vertex stage: each output column from the matrix, after the stage ran.
    StoreColumnsAfter,
    /// Fragment stage: the matrix from its input columns, before the stage runs.
    BuildMatrixBefore,
}

/// The stage text with its `main` renamed and a new `main` after it (unchanged
/// when the stage has no matrix varying).
fn with_new_main(text: String, matrices: &[MatrixVarying], order: Order) -> String {
    if matrices.is_empty() {
        return text;
    }
    // GLSL cannot call `main`: the identifier is the definition alone.
    let renamed = replace_word(&text, "main", "fx_stage_main");
    let mut moves = String::new();
    for m in matrices {
        match order {
            Order::StoreColumnsAfter => {
                for c in 0..m.columns {
                    moves.push_str(&format!(" {} = {}[{c}];", column_name(m, c), m.name));
                }
            }
            Order::BuildMatrixBefore => {
                let columns: Vec<String> = (0..m.columns).map(|c| column_name(m, c)).collect();
                moves.push_str(&format!(
                    " {} = {}({});",
                    m.name,
                    matrix_type(m),
                    columns.join(", ")
                ));
            }
        }
    }
    let body = match order {
        Order::StoreColumnsAfter => format!(" fx_stage_main();{moves}"),
        Order::BuildMatrixBefore => format!("{moves} fx_stage_main();"),
    };
    let sep = if renamed.ends_with('\n') { "" } else { "\n" };
    format!("{renamed}{sep}void main() {{{body} }}\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    const VERTEX: &str = "#version 450\nlayout(location = 0) out vec2 vTexCoord;\nlayout(location = 1) out mat4 profile;\nvoid main()\n{\n  profile = mat4(1.0);\n}\n";
    const FRAGMENT: &str = "#version 450\nlayout(location = 0) in vec2 vTexCoord;\nlayout(location=1)   in  mat3x2 m;\nvoid main() { float x = m[2].y; }\n";

    #[test]
    fn matrix_varyings_become_columns_on_the_same_lines() {
        let (v, f) = split_matrix_varyings(VERTEX, FRAGMENT);
        let vl: Vec<&str> = v.lines().collect();
        assert_eq!(vl[1], "layout(location = 0) out vec2 vTexCoord;");
        assert_eq!(
            vl[2],
            "layout(location = 1) out vec4 profile_fxcol0; layout(location = 2) out vec4 profile_fxcol1; \
             layout(location = 3) out vec4 profile_fxcol2; layout(location = 4) out vec4 profile_fxcol3; mat4 profile;"
        );
        assert_eq!(vl[3], "void fx_stage_main()");
        assert_eq!(
            vl.last().unwrap(),
            &"void main() { fx_stage_main(); profile_fxcol0 = profile[0]; profile_fxcol1 = profile[1]; \
              profile_fxcol2 = profile[2]; profile_fxcol3 = profile[3]; }"
        );
        let fl: Vec<&str> = f.lines().collect();
        assert_eq!(
            fl[2],
            "layout(location = 1) in vec2 m_fxcol0; layout(location = 2) in vec2 m_fxcol1; \
             layout(location = 3) in vec2 m_fxcol2; mat3x2 m;"
        );
        assert_eq!(fl[3], "void fx_stage_main() { float x = m[2].y; }");
        assert_eq!(
            fl[4],
            "void main() { m = mat3x2(m_fxcol0, m_fxcol1, m_fxcol2); fx_stage_main(); }"
        );
        assert_eq!(fl.len(), 5, "one line added, after the stage");
    }

    #[test]
    fn stages_without_matrix_varyings_are_unchanged() {
        let v = "layout(location = 0) out vec2 a;\nvoid main() {}\n";
        let f = "layout(location = 0) in vec2 a;\nmat4 m;\nvoid main() {}\n";
        assert_eq!(split_matrix_varyings(v, f), (v.to_string(), f.to_string()));
    }
}
