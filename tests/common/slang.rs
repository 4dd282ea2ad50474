//! One-pass slang presets written by the tests: a GLSL fragment body with the
//! default vertex stage, `Source`, `OriginalHistory1` and `PassFeedback0`.

use std::path::{Path, PathBuf};

/// The `.slang` text of a one-pass shader: `decls` in the push block, `extra`
/// before the stages (pragmas, includes), `body` as the fragment `main`.
pub fn one_pass_shader(decls: &str, body: &str, extra: &str) -> String {
    format!(
        "#version 450\n\
         layout(push_constant) uniform Push {{ vec4 SourceSize; uint FrameCount; {decls} }} params;\n\
         layout(std140, set = 0, binding = 0) uniform UBO {{ mat4 MVP; }} global;\n\
         {extra}\n\
         #pragma stage vertex\n\
         layout(location = 0) in vec4 Position;\nlayout(location = 1) in vec2 TexCoord;\n\
         layout(location = 0) out vec2 vTexCoord;\n\
         void main() {{ gl_Position = global.MVP * Position; vTexCoord = TexCoord; }}\n\
         #pragma stage fragment\n\
         layout(location = 0) in vec2 vTexCoord;\nlayout(location = 0) out vec4 FragColor;\n\
         layout(set = 0, binding = 2) uniform sampler2D Source;\n\
         layout(set = 0, binding = 3) uniform sampler2D OriginalHistory1;\n\
         layout(set = 0, binding = 4) uniform sampler2D PassFeedback0;\n\
         void main() {{ {body} }}\n"
    )
}

/// `dir/NAME.slangp` (nearest filtering) over `dir/NAME.slang` of
/// [`one_pass_shader`]; the preset's path.
pub fn one_pass_preset(dir: &Path, name: &str, decls: &str, body: &str, extra: &str) -> PathBuf {
    std::fs::write(
        dir.join(format!("{name}.slang")),
        one_pass_shader(decls, body, extra),
    )
    .unwrap();
    let p = dir.join(format!("{name}.slangp"));
    std::fs::write(
        &p,
        format!("shaders = 1\nshader0 = {name}.slang\nfilter_linear0 = false\n"),
    )
    .unwrap();
    p
}

/// The body of a preset whose frame n is `(in[n] + in[n-1]) / 2 + out[n-1] / 4`.
pub const TEMPORAL_BODY: &str =
    "FragColor = 0.5 * (texture(Source, vTexCoord) + texture(OriginalHistory1, vTexCoord)) \
     + 0.25 * texture(PassFeedback0, vTexCoord);";

/// The frames `levels` (grey codes) give through [`TEMPORAL_BODY`]: the first
/// frame's history is itself, its feedback 0; each output is then the one the
/// run stored (`got(n)`, 8-bit rounding kept), checked within `tolerance`.
pub fn check_temporal(levels: &[u8], got: impl Fn(usize) -> f64, tolerance: f64) {
    let mut previous_out = 0.0f64;
    for n in 0..levels.len() {
        let cur = f64::from(levels[n]);
        let prev = f64::from(levels[n.saturating_sub(1)]);
        let expected = ((cur + prev) / 2.0 + previous_out / 4.0).min(255.0);
        let g = got(n);
        assert!(
            (g - expected).abs() <= tolerance,
            "frame {n}: {g}, expected {expected:.1}"
        );
        previous_out = g;
    }
}
