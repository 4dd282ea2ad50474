//! The EFFECT script of a lowered preset: one pass per preset pass, its inputs
//! (the slang texture semantics as graph sources), size, format and colour
//! space, sampler modes, and the preset's parameters as effect parameters.

use super::error::SlangError;
use crate::script::ast::VIEWPORT;
use librashader_common::{FilterMode, ImageFormat, WrapMode};
use librashader_preprocess::ShaderParameter;
use librashader_presets::{PassMeta, ScaleFactor, ScaleType, Scaling, TextureMeta};
use std::fmt::Write;
use std::path::Path;

/// One pass of the preset, after translation.
pub struct PassPlan<'a> {
    pub meta: &'a PassMeta,
    /// `#pragma name` of its shader: a second alias.
    pub name: Option<String>,
    /// `#pragma format` of its shader.
    pub format: ImageFormat,
    /// The textures its shader binds: (slang semantic, WGSL name).
    pub textures: Vec<(String, String)>,
    /// The parameters its shader reads: (`#pragma parameter` id, WGSL field).
    pub params: Vec<(String, String)>,
    /// The name of its WGSL file, without `.wgsl`.
    pub shader: String,
}

/// The preset as a whole.
pub struct ScriptInput<'a> {
    pub path: &'a Path,
    pub effect: &'a str,
    pub passes: &'a [PassPlan<'a>],
    pub luts: &'a [TextureMeta],
    pub parameters: &'a [ShaderParameter],
}

/// The script text.
pub fn script(s: &ScriptInput) -> Result<String, SlangError> {
    let mut out = String::new();
    let _ = writeln!(out, "// Lowered by fxgraph from {}", s.path.display());
    let _ = writeln!(out, "EFFECT.{} = {{", s.effect);
    let _ = writeln!(
        out,
        "    DESCRIPTION = \"RetroArch slang preset {}\"",
        s.path.display().to_string().replace(['"', '\\'], "/")
    );
    write_params(&mut out, s.parameters);
    out.push_str("    PASS = {\n");
    for i in 0..s.passes.len() {
        write_pass(&mut out, s, i)?;
    }
    out.push_str("    }\n");
    let _ = writeln!(out, "    OUT = {}", pass_name(s.passes, s.passes.len() - 1));
    out.push_str("}\n");
    Ok(out)
}

fn write_params(out: &mut String, params: &[ShaderParameter]) {
    if params.is_empty() {
        return;
    }
    out.push_str("    PARAM = {\n");
    for p in params {
        let (lo, hi) = (p.minimum.min(p.initial), p.maximum.max(p.initial));
        let description = p.description.replace(['"', '\\'], "'");
        let step = if p.step > 0.0 && p.step.is_finite() {
            format!("  STEP = {}", p.step)
        } else {
            String::new()
        };
        let _ = writeln!(
            out,
            "        {} = FLOAT {{ DEFAULT = {}  RANGE = ({}, {}){step}  DESCRIPTION = \"{}\" }}",
            p.id,
            p.initial,
            lo,
            hi,
            description.trim()
        );
    }
    out.push_str("    }\n");
}

/// The graph name of pass `i`: `pass{i}`.
pub fn pass_name(_passes: &[PassPlan], i: usize) -> String {
    format!("pass{i}")
}

fn write_pass(out: &mut String, s: &ScriptInput, i: usize) -> Result<(), SlangError> {
    let p = &s.passes[i];
    let _ = writeln!(
        out,
        "        {} = SHADER.{} {{",
        pass_name(s.passes, i),
        p.shader
    );
    for (semantic, t) in &p.textures {
        let b = bind(s, i, semantic)?;
        let _ = writeln!(out, "            {t} = {}", b.source);
        let _ = writeln!(out, "            {t}.FILTER = {}", filter(b.filter));
        let _ = writeln!(out, "            {t}.WRAP = {}", wrap(b.wrap));
        let _ = writeln!(out, "            {t}.COLORSPACE = {}", b.colorspace);
        if b.mipmap {
            let _ = writeln!(out, "            {t}.MIPMAP = true");
        }
    }
    for (id, field) in &p.params {
        let _ = writeln!(out, "            {field} = PARAM.{id}");
    }
    if i + 1 < s.passes.len() {
        write_size(out, p, i);
    } else {
        let _ = writeln!(out, "            OUT.RELATIVE_TO = {VIEWPORT}");
    }
    let (format, colorspace) = format_of(p);
    let _ = writeln!(out, "            OUT.FORMAT = {format}");
    let _ = writeln!(out, "            OUT.COLORSPACE = {colorspace}");
    out.push_str("        }\n");
    Ok(())
}

/// Where a texture semantic comes from, and how it is sampled.
struct Binding {
    source: String,
    filter: FilterMode,
    wrap: WrapMode,
    colorspace: &'static str,
    /// Read with a mip chain: the pass's `Source` with `mipmap_input`, an
    /// output of the pass before one that has it (its texture has the chain in
    /// librashader, for every reader), a LUT with `NAME_mipmap`.
    mipmap: bool,
}

fn bind(s: &ScriptInput, i: usize, texture: &str) -> Result<Binding, SlangError> {
    let first = s.passes[0].meta;
    let own = s.passes[i].meta;
    let pass = |k: usize, back: &str| -> Result<Binding, SlangError> {
        if k >= s.passes.len() || (back.is_empty() && k >= i) {
            return Err(SlangError::Unsupported {
                path: s.path.to_path_buf(),
                feature: format!("`{texture}` in pass {i}"),
                why: format!("pass {k} does not run before pass {i}"),
            });
        }
        let meta = s.passes[k].meta;
        let next_mipmaps = s.passes.get(k + 1).is_some_and(|n| n.meta.mipmap_input);
        Ok(Binding {
            source: format!("PASS.{}{back}", pass_name(s.passes, k)),
            filter: meta.filter,
            wrap: meta.wrap_mode,
            colorspace: colorspace_of(&s.passes[k]),
            mipmap: back.is_empty() && next_mipmaps,
        })
    };
    let input = |source: String, meta: &PassMeta| Binding {
        source,
        filter: meta.filter,
        wrap: meta.wrap_mode,
        colorspace: "srgb",
        mipmap: false,
    };
    if texture == "Source" {
        return match i {
            0 => Ok(Binding {
                mipmap: own.mipmap_input,
                ..input("IN".into(), own)
            }),
            _ => pass(i - 1, "").map(|b| Binding {
                filter: own.filter,
                wrap: own.wrap_mode,
                ..b
            }),
        };
    }
    if texture == "Original" || texture == "OriginalHistory0" {
        return Ok(input("IN".into(), first));
    }
    if let Some(n) = number_after(texture, "OriginalHistory") {
        return Ok(input(format!("IN[-{n}]"), first));
    }
    if let Some(k) = number_after(texture, "PassOutput") {
        return pass(k, "");
    }
    if let Some(k) = number_after(texture, "PassFeedback") {
        return pass(k, "[-1]");
    }
    if let Some(k) = alias_index(s.passes, texture) {
        return pass(k, "");
    }
    if let Some(k) = texture
        .strip_suffix("Feedback")
        .and_then(|a| alias_index(s.passes, a))
    {
        return pass(k, "[-1]");
    }
    if let Some(lut) = s.luts.iter().find(|l| l.name.as_str() == texture) {
        return Ok(Binding {
            source: format!("AUX.{texture}"),
            filter: lut.filter_mode,
            wrap: lut.wrap_mode,
            colorspace: "srgb",
            mipmap: lut.mipmap,
        });
    }
    Err(SlangError::Semantic {
        path: s.path.to_path_buf(),
        name: texture.to_string(),
    })
}

fn number_after(name: &str, prefix: &str) -> Option<usize> {
    name.strip_prefix(prefix)?.parse().ok()
}

/// The pass `alias` names: its preset `alias` or its shader's `#pragma name`.
fn alias_index(passes: &[PassPlan], alias: &str) -> Option<usize> {
    passes.iter().position(|p| {
        p.meta.alias.as_ref().is_some_and(|a| a.as_str() == alias)
            || p.name.as_deref() == Some(alias)
    })
}

fn filter(f: FilterMode) -> &'static str {
    match f {
        FilterMode::Linear => "linear",
        FilterMode::Nearest => "nearest",
    }
}

fn wrap(w: WrapMode) -> &'static str {
    match w {
        WrapMode::ClampToEdge => "clamp",
        WrapMode::Repeat => "repeat",
        WrapMode::MirroredRepeat => "mirror",
        WrapMode::ClampToBorder => "border",
    }
}

/// A pass's output size, axis by axis: pixels (`absolute`), or a factor of
/// the pass's `Source` (`source`), the effect's input (`original`) or the
/// viewport (`viewport`: `VIEWPORT`, the run's output size).
fn write_size(out: &mut String, p: &PassPlan, i: usize) {
    let sc = &p.meta.scaling;
    if !sc.valid {
        if i > 0 {
            out.push_str("            OUT.SCALE = 1\n            OUT.RELATIVE_TO = Source\n");
        }
        return;
    }
    let (x, y) = (&sc.x, &sc.y);
    let absolute = |s: &Scaling| matches!(s.scale_type, ScaleType::Absolute);
    let f = |s: &Scaling| match s.factor {
        ScaleFactor::Float(v) => v as f64,
        ScaleFactor::Absolute(v) => v as f64,
    };
    let of = |s: &Scaling| match s.scale_type {
        ScaleType::Input if i > 0 => "Source",
        ScaleType::Viewport => VIEWPORT,
        _ => "IN",
    };
    let line = |out: &mut String, text: String| {
        let _ = writeln!(out, "            {text}");
    };
    match (absolute(x), absolute(y)) {
        (true, true) => line(out, format!("OUT.SIZE = ({}, {})", f(x), f(y))),
        (true, false) => {
            line(out, format!("OUT.WIDTH = {}", f(x)));
            line(out, format!("OUT.SCALE = (1, {})", f(y)));
            line(out, format!("OUT.RELATIVE_TO = {}", of(y)));
        }
        (false, true) => {
            line(out, format!("OUT.HEIGHT = {}", f(y)));
            line(out, format!("OUT.SCALE = ({}, 1)", f(x)));
            line(out, format!("OUT.RELATIVE_TO = {}", of(x)));
        }
        (false, false) => {
            line(out, format!("OUT.SCALE = ({}, {})", f(x), f(y)));
            match (of(x), of(y)) {
                ("IN", "IN") => {}
                (a, b) if a == b => line(out, format!("OUT.RELATIVE_TO = {a}")),
                (a, b) => line(out, format!("OUT.RELATIVE_TO = ({a}, {b})")),
            }
        }
    }
}

/// True when pass `i` needs its `Source` bound to size itself.
pub fn needs_source(meta: &PassMeta, i: usize, last: bool) -> bool {
    if i == 0 || last {
        return false;
    }
    let sc = &meta.scaling;
    !sc.valid
        || matches!(sc.x.scale_type, ScaleType::Input)
        || matches!(sc.y.scale_type, ScaleType::Input)
}

/// The colour space a pass's values are in: sRGB-encoded codes, as RetroArch
/// stores them, except in an sRGB framebuffer (linear values the hardware encodes).
fn colorspace_of(p: &PassPlan) -> &'static str {
    if format_of(p).0 == "rgba8-srgb" {
        "linear"
    } else {
        "srgb"
    }
}

/// `OUT.FORMAT` and `OUT.COLORSPACE` of a pass.
fn format_of(p: &PassPlan) -> (&'static str, &'static str) {
    let format = if p.meta.srgb_framebuffer {
        "rgba8-srgb"
    } else if p.meta.float_framebuffer {
        "rgba16f"
    } else {
        match p.format {
            ImageFormat::R8G8B8A8Srgb => "rgba8-srgb",
            ImageFormat::R16G16B16A16Sfloat => "rgba16f",
            ImageFormat::R32G32B32A32Sfloat => "rgba32f",
            ImageFormat::A2B10G10R10UnormPack32 => "rgb10a2",
            ImageFormat::R8Unorm => "r8",
            ImageFormat::R16Sfloat => "r16f",
            ImageFormat::R32Sfloat => "r32f",
            ImageFormat::R16G16Sfloat => "rg16f",
            ImageFormat::R32G32Sfloat => "rg32f",
            _ => "rgba8",
        }
    };
    let colorspace = if format == "rgba8-srgb" {
        "linear"
    } else {
        "srgb"
    };
    (format, colorspace)
}
