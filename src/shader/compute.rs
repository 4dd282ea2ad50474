//! A pass's fragment shader as a compute shader: the engine's compute execution
//! path (docs/architecture.md, "Execution paths").
//!
//! A pass author writes one `@fragment` function (docs/shaders.md). To run the
//! pass as a compute dispatch the engine rewrites that same module, in naga's IR:
//!
//! 1. the fragment entry point becomes an ordinary function (its `@location(0)`
//!    `uv` and `@builtin(position)` `pos` arguments become plain arguments, its
//!    `@location(0)` result a plain result);
//! 2. every implicit-derivative sample (`textureSample`, `textureSampleBias`,
//!    `textureSampleCompare`) samples level 0 explicitly: pass textures have one
//!    mip level (and samplers of inputs without `NAME.MIPMAP` read level 0 only),
//!    so the level an implicit sample computes is always 0 and the result is the
//!    same texel fetch and filter. An implicit sample of a mipmapped input
//!    (`NAME.MIPMAP = true`) needs the derivatives the fragment stage has: such a
//!    shader is [`ComputeUnsupported::FragmentOnly`];
//! 3. a `@compute @workgroup_size(8, 8)` entry point computes, for each invocation
//!    inside the target, the same `pos` (pixel centre, `z = 0`, `w = 1`) and `uv`
//!    (`pos.xy / size`) the rasteriser gives the fragment stage, calls the
//!    function and stores its result to a write-only storage texture (bound at
//!    a binding the pass does not use), sRGB-encoding it first when the target is
//!    an 8-bit texture the fragment path writes through an sRGB view.
//!
//! The rewrite works on the IR rather than on text so that comments, nesting and
//! overloads of the sampling builtins need no parser of our own; naga writes the
//! module back as WGSL (`wgsl-out`). Shaders the compute stage cannot run (screen
//! derivatives `dpdx`/`fwidth`, `discard`, an entry point with other inputs or a
//! struct result) are reported as [`ComputeUnsupported`]: the executor keeps the
//! fragment path for that pass.

use naga::{Binding, BuiltIn, Expression, SampleLevel, ShaderStage, Statement};

/// Workgroup size of the wrapped passes: 8 × 8 invocations, one per pixel.
pub const WRAP_WORKGROUP: (u32, u32) = (8, 8);

/// The name of the generated compute entry point.
pub const COMPUTE_ENTRY: &str = "fxgraph_compute_main";

/// Why a fragment shader cannot run as a compute shader.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ComputeUnsupported {
    #[error("the WGSL does not parse: {0}")]
    Parse(String),
    #[error("no fragment entry point named `{0}`")]
    NoEntry(String),
    #[error("the entry point reads `{0}`, which only the fragment stage has")]
    Input(String),
    #[error("the entry point returns a structure")]
    StructResult,
    #[error("the shader uses {0}, which only the fragment stage has")]
    FragmentOnly(&'static str),
    #[error("the rewritten module is invalid: {0}")]
    Invalid(String),
}

/// How the wrapper stores the pass's result.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StorageTarget {
    /// The WGSL texel format of the storage texture (`rgba16float`, `rgba8unorm`).
    pub format: String,
    /// Encode rgb with the sRGB curve before storing (alpha stays linear).
    pub encode_srgb: bool,
    /// The binding of the storage texture in group 0.
    pub binding: u32,
}

/// What a fragment entry point argument is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Arg {
    Uv,
    Position,
}

/// The WGSL of `wgsl`'s fragment entry point `entry` as the compute entry point
/// [`COMPUTE_ENTRY`], writing `target`.
/// `mipmapped` names the textures read with a mip chain.
pub fn wrap_fragment_as_compute(
    wgsl: &str,
    entry: &str,
    target: &StorageTarget,
    mipmapped: &[String],
) -> Result<String, ComputeUnsupported> {
    let mut module = naga::front::wgsl::parse_str(wgsl)
        .map_err(|e| ComputeUnsupported::Parse(e.message().to_string()))?;
    let args = demote_entry_point(&mut module, entry)?;
    let mips: Vec<_> = module
        .global_variables
        .iter()
        .filter(|(_, g)| g.name.as_ref().is_some_and(|n| mipmapped.contains(n)))
        .map(|(h, _)| h)
        .collect();
    for (_, f) in module.functions.iter_mut() {
        sample_level_zero(f, &mips)?;
    }
    let body = write_wgsl(&module)?;
    Ok(format!("{body}\n{}", compute_entry(&args, target)))
}

/// Move the fragment entry point `entry` into the module's functions (named
/// `fxgraph_fragment_body`), without its stage bindings; returns its arguments.
fn demote_entry_point(
    module: &mut naga::Module,
    entry: &str,
) -> Result<Vec<Arg>, ComputeUnsupported> {
    let at = module
        .entry_points
        .iter()
        .position(|e| e.name == entry && e.stage == ShaderStage::Fragment)
        .ok_or_else(|| ComputeUnsupported::NoEntry(entry.to_string()))?;
    let mut function = module.entry_points.remove(at).function;
    let mut args = Vec::with_capacity(function.arguments.len());
    for a in &mut function.arguments {
        args.push(match &a.binding {
            Some(Binding::Location { location: 0, .. }) => Arg::Uv,
            Some(Binding::BuiltIn(BuiltIn::Position { .. })) => Arg::Position,
            _ => {
                let name = a.name.clone().unwrap_or_else(|| "an argument".into());
                return Err(ComputeUnsupported::Input(name));
            }
        });
        a.binding = None;
    }
    match &mut function.result {
        Some(r) if matches!(r.binding, Some(Binding::Location { location: 0, .. })) => {
            r.binding = None;
        }
        _ => return Err(ComputeUnsupported::StructResult),
    }
    function.name = Some(BODY.to_string());
    module.functions.append(function, naga::Span::UNDEFINED);
    Ok(args)
}

/// The name the fragment function gets in the compute module.
const BODY: &str = "fxgraph_fragment_body";

/// Implicit-level samples become level-0 samples; fragment-only operations
/// (and implicit-level samples of the mipmapped textures `mips`, or of a
/// texture passed as an argument when there are any) are refused.
fn sample_level_zero(
    f: &mut naga::Function,
    mips: &[naga::Handle<naga::GlobalVariable>],
) -> Result<(), ComputeUnsupported> {
    let mipmapped = |e: &Expression| match e {
        Expression::GlobalVariable(g) => mips.contains(g),
        _ => !mips.is_empty(),
    };
    let implicit_of_mips = f.expressions.iter().any(|(_, e)| match e {
        Expression::ImageSample { image, level, .. } => {
            matches!(level, SampleLevel::Auto | SampleLevel::Bias(_))
                && mipmapped(&f.expressions[*image])
        }
        _ => false,
    });
    if implicit_of_mips {
        return Err(ComputeUnsupported::FragmentOnly(
            "an implicit-level sample (textureSample, textureSampleBias) of a mipmapped input",
        ));
    }
    for (_, e) in f.expressions.iter_mut() {
        match e {
            Expression::ImageSample { level, .. } => {
                if matches!(level, SampleLevel::Auto | SampleLevel::Bias(_)) {
                    *level = SampleLevel::Zero;
                }
            }
            Expression::Derivative { .. } => {
                return Err(ComputeUnsupported::FragmentOnly(
                    "screen-space derivatives (dpdx, dpdy, fwidth)",
                ))
            }
            _ => {}
        }
    }
    if block_has_kill(&f.body) {
        return Err(ComputeUnsupported::FragmentOnly("`discard`"));
    }
    Ok(())
}

/// Whether a block (or a block nested in it) discards.
fn block_has_kill(block: &naga::Block) -> bool {
    block.iter().any(|s| match s {
        Statement::Kill => true,
        Statement::Block(b) => block_has_kill(b),
        Statement::If { accept, reject, .. } => block_has_kill(accept) || block_has_kill(reject),
        Statement::Switch { cases, .. } => cases.iter().any(|c| block_has_kill(&c.body)),
        Statement::Loop {
            body, continuing, ..
        } => block_has_kill(body) || block_has_kill(continuing),
        _ => false,
    })
}

/// Validate the rewritten module and write it back as WGSL.
fn write_wgsl(module: &naga::Module) -> Result<String, ComputeUnsupported> {
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(module)
    .map_err(|e| ComputeUnsupported::Invalid(e.as_inner().to_string()))?;
    naga::back::wgsl::write_string(module, &info, naga::back::wgsl::WriterFlags::empty())
        .map_err(|e| ComputeUnsupported::Invalid(e.to_string()))
}

/// The compute entry point: one invocation per target pixel.
fn compute_entry(args: &[Arg], target: &StorageTarget) -> String {
    let (wx, wy) = WRAP_WORKGROUP;
    let call_args: Vec<&str> = args
        .iter()
        .map(|a| match a {
            Arg::Uv => "fxgraph_pos.xy / vec2<f32>(fxgraph_size)",
            Arg::Position => "fxgraph_pos",
        })
        .collect();
    let (encode_fn, stored) = if target.encode_srgb {
        (SRGB_ENCODE, "fxgraph_srgb_encode(fxgraph_color)")
    } else {
        ("", "fxgraph_color")
    };
    format!(
        "@group(0) @binding({binding}) var fxgraph_target: texture_storage_2d<{format}, write>;
{encode_fn}
@compute @workgroup_size({wx}, {wy}, 1)
fn {COMPUTE_ENTRY}(@builtin(global_invocation_id) fxgraph_id: vec3<u32>) {{
    let fxgraph_size = textureDimensions(fxgraph_target);
    if fxgraph_id.x >= fxgraph_size.x || fxgraph_id.y >= fxgraph_size.y {{
        return;
    }}
    let fxgraph_pos = vec4<f32>(vec2<f32>(fxgraph_id.xy) + vec2<f32>(0.5), 0.0, 1.0);
    let fxgraph_color = {BODY}({args});
    textureStore(fxgraph_target, fxgraph_id.xy, {stored});
}}
",
        binding = target.binding,
        format = target.format,
        args = call_args.join(", "),
    )
}

/// The sRGB curve (IEC 61966-2-1) the fragment path's sRGB views apply in
/// hardware; alpha stays linear as it does there. Defines
/// `fxgraph_srgb_encode(c: vec4<f32>) -> vec4<f32>`.
pub const SRGB_ENCODE: &str = "
fn fxgraph_srgb_encode(c: vec4<f32>) -> vec4<f32> {
    let x = clamp(c.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let lo = x * 12.92;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - vec3<f32>(0.055);
    return vec4<f32>(select(hi, lo, x <= vec3<f32>(0.0031308)), c.a);
}
";

#[cfg(test)]
mod tests {
    use super::*;

    fn target() -> StorageTarget {
        StorageTarget {
            format: "rgba16float".into(),
            encode_srgb: false,
            binding: 9,
        }
    }

    fn valid(wgsl: &str) {
        let m = naga::front::wgsl::parse_str(wgsl).unwrap_or_else(|e| panic!("{e}\n{wgsl}"));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&m)
        .unwrap_or_else(|e| panic!("{e:?}\n{wgsl}"));
        let ep = m
            .entry_points
            .iter()
            .find(|e| e.name == COMPUTE_ENTRY)
            .expect("compute entry");
        assert_eq!(ep.stage, ShaderStage::Compute);
        assert_eq!(ep.workgroup_size, [8, 8, 1]);
    }

    const SAMPLING: &str = "
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;
fn helper(t: texture_2d<f32>, s: sampler, uv: vec2<f32>) -> vec4<f32> {
    // a comment with textureSample( in it
    return textureSample(t, s, uv) + textureSampleBias(t, s, uv, 1.0, vec2<i32>(1, 0));
}
@fragment
fn fs_main(@location(0) uv: vec2<f32>, @builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return helper(img, img_sampler, uv) * pos.x;
}
";

    #[test]
    fn implicit_samples_become_level_zero_everywhere() {
        let out = wrap_fragment_as_compute(SAMPLING, "fs_main", &target(), &[]).unwrap();
        valid(&out);
        assert!(!out.contains("@fragment"), "{out}");
        assert!(out.contains("textureSampleLevel"), "{out}");
        assert!(!out.contains("textureSample("), "{out}");
        assert!(!out.contains("textureSampleBias"), "{out}");
        assert!(out.contains(
            "fxgraph_fragment_body(fxgraph_pos.xy / vec2<f32>(fxgraph_size), fxgraph_pos)"
        ));
    }

    #[test]
    fn arguments_in_any_order_or_none() {
        let pos_only = "@fragment fn main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> { return p; }";
        let out = wrap_fragment_as_compute(pos_only, "main", &target(), &[]).unwrap();
        valid(&out);
        assert!(out.contains("fxgraph_fragment_body(fxgraph_pos)"), "{out}");
        let none = "@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }";
        valid(&wrap_fragment_as_compute(none, "main", &target(), &[]).unwrap());
    }

    #[test]
    fn srgb_targets_are_encoded_in_the_shader() {
        let t = StorageTarget {
            format: "rgba8unorm".into(),
            encode_srgb: true,
            binding: 3,
        };
        let out = wrap_fragment_as_compute(SAMPLING, "fs_main", &t, &[]).unwrap();
        valid(&out);
        assert!(out.contains("texture_storage_2d<rgba8unorm, write>"));
        assert!(out.contains("fxgraph_srgb_encode(fxgraph_color)"));
    }

    #[test]
    fn fragment_only_shaders_are_refused() {
        let deriv = "@fragment fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> { return vec4<f32>(fwidth(uv), 0.0, 1.0); }";
        assert!(matches!(
            wrap_fragment_as_compute(deriv, "fs_main", &target(), &[]),
            Err(ComputeUnsupported::FragmentOnly(_))
        ));
        let kill = "@fragment fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> { if uv.x > 0.5 { discard; } return vec4<f32>(1.0); }";
        assert!(matches!(
            wrap_fragment_as_compute(kill, "fs_main", &target(), &[]),
            Err(ComputeUnsupported::FragmentOnly(_))
        ));
        let other_input = "@fragment fn fs_main(@builtin(front_facing) f: bool) -> @location(0) vec4<f32> { return vec4<f32>(1.0); }";
        assert!(matches!(
            wrap_fragment_as_compute(other_input, "fs_main", &target(), &[]),
            Err(ComputeUnsupported::Input(_))
        ));
        assert!(matches!(
            wrap_fragment_as_compute(SAMPLING, "nope", &target(), &[]),
            Err(ComputeUnsupported::NoEntry(_))
        ));
    }

    #[test]
    fn implicit_samples_of_mipmapped_inputs_stay_fragment() {
        let mips = ["img".to_string()];
        // Through a helper taking the texture as an argument: refused.
        assert!(matches!(
            wrap_fragment_as_compute(SAMPLING, "fs_main", &target(), &mips),
            Err(ComputeUnsupported::FragmentOnly(_))
        ));
        let direct = "
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var lut: texture_2d<f32>;
@group(0) @binding(2) var s: sampler;
@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    return textureSample(lut, s, uv) + textureSampleLevel(img, s, uv, 2.0);
}
";
        // An explicit level of the mipmapped input, an implicit one of another.
        valid(&wrap_fragment_as_compute(direct, "fs_main", &target(), &mips).unwrap());
        let lut = ["lut".to_string()];
        assert!(matches!(
            wrap_fragment_as_compute(direct, "fs_main", &target(), &lut),
            Err(ComputeUnsupported::FragmentOnly(_))
        ));
    }
}
