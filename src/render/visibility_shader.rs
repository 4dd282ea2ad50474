//! The WGSL of the visibility buffer (`visibility.rs`): the raster half's
//! module, the tile classification's, and each material variant's resolve module: its geometry module
//! (`material::template`, preprocessed for the variant) with every
//! `textureSample` turned into `fx_vis_sample` (explicit gradients, which a
//! compute shader needs) and the resolve entry point appended. A surface that
//! takes derivatives another way (`dpdx`, `fwidth`, `textureSampleBias`, ...)
//! has none to take in compute: its draws stay in the G-buffer pass.

use super::material::template::{geometry_module, Generated};
use super::material::{MaterialSet, VariantKey, VariantMode};

const RASTER: &str = concat!(
    include_str!("../../shaders/render/visibility.wgsl"),
    include_str!("../../shaders/render/instance.wgsl")
);
const RESOLVE: &str = include_str!("../../shaders/render/visibility_resolve.wgsl");
const CLASSIFY: &str = include_str!("../../shaders/render/visibility_classify.wgsl");

/// Builtins with implicit derivatives other than `textureSample`: a fragment
/// quad's, which a compute invocation does not have.
const DERIVATIVES: [&str; 10] = [
    "dpdx",
    "dpdy",
    "fwidth",
    "dpdxCoarse",
    "dpdyCoarse",
    "dpdxFine",
    "dpdyFine",
    "textureSampleBias",
    "textureSampleCompare",
    "fwidthFine",
];

/// The raster half's module (standalone: it reads group 0's frame and
/// instances only).
pub(crate) fn raster_module() -> &'static str {
    RASTER
}

/// The tile classification's module for `groups` resolve dispatches.
pub(crate) fn classify_module(groups: usize) -> String {
    format!("const FX_VIS_GROUPS: u32 = {groups}u;\n{CLASSIFY}")
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// `text` without `//` comments (line comments only: the generated modules
/// have no block comments that name builtins).
fn code_only(text: &str) -> String {
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every call of `name(` in `text` as a whole identifier renamed `to(`;
/// returns the text and how many were renamed.
fn rename_calls(text: &str, name: &str, to: &str) -> (String, usize) {
    let pattern = format!("{name}(");
    let mut out = String::with_capacity(text.len());
    let mut count = 0;
    let mut rest = text;
    while let Some(i) = rest.find(&pattern) {
        let whole = rest[..i].chars().next_back().is_none_or(|c| !is_ident(c));
        out.push_str(&rest[..i]);
        if whole {
            out.push_str(to);
            out.push('(');
            count += 1;
        } else {
            out.push_str(&pattern);
        }
        rest = &rest[i + pattern.len()..];
    }
    out.push_str(rest);
    (out, count)
}

/// The first derivative builtin `code` calls, if any.
fn derivative_use(code: &str) -> Option<&'static str> {
    DERIVATIVES.into_iter().find(|d| {
        let (_, n) = rename_calls(code, d, d);
        n > 0
    })
}

/// The resolve module of material variant `key`; `Err` with the reason when
/// its surface cannot be resolved in compute (a derivative it takes itself).
pub(crate) fn resolve_module(
    set: &MaterialSet,
    key: VariantKey,
    normal_encoding: u32,
) -> Result<String, String> {
    let Generated { wgsl, .. } =
        geometry_module(set, key, VariantMode::Preprocess, 1, normal_encoding)?;
    let code = code_only(&wgsl);
    if let Some(d) = derivative_use(&code) {
        return Err(format!("its surface shader calls `{d}`"));
    }
    let (code, samples) = rename_calls(&code, "textureSample", "fx_vis_sample");
    let mut text = format!("const FX_VIS_GRADIENTS: bool = {};\n", samples > 0);
    text.push_str(&code);
    text.push('\n');
    text.push_str(RESOLVE);
    text.push_str(crate::shader::compute::SRGB_ENCODE);
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_sample_calls_are_renamed_as_whole_identifiers() {
        let (t, n) = rename_calls(
            "a = textureSample(t, s, uv) + textureSampleLevel(t, s, uv, 0.0) + my_textureSample(x);",
            "textureSample",
            "fx_vis_sample",
        );
        assert_eq!(n, 1);
        assert_eq!(
            t,
            "a = fx_vis_sample(t, s, uv) + textureSampleLevel(t, s, uv, 0.0) + my_textureSample(x);"
        );
    }

    #[test]
    fn derivatives_are_found_in_code_not_comments() {
        assert_eq!(derivative_use(&code_only("// dpdx(x)\nlet a = 1.0;")), None);
        assert_eq!(
            derivative_use(&code_only("let a = fwidth(uv);")),
            Some("fwidth")
        );
        assert_eq!(
            derivative_use("textureSampleCompareLevel(t, s, uv, 0.5)"),
            None
        );
    }
}
