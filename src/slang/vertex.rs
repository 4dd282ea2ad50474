//! A pass's vertex stage, evaluated per pixel. fxgraph draws every pass with its
//! own full-screen triangle, whose only output is `uv`; a slang vertex stage
//! often computes more (about one shader in five passes extra values to its
//! fragment stage). Both stages become plain functions of one WGSL module, and a
//! new `@fragment` entry point calls the vertex function at the pixel's `uv` (the
//! quad's `Position` and `TexCoord` there) and hands its outputs to the fragment
//! function. A vertex output that is affine in the quad's corners (texture
//! coordinates, constants: what presets compute) interpolates to exactly this
//! value; anything else is approximated by its value at the pixel.
//!
//! A vertex stage that moves the quad (`gl_Position` other than `MVP *
//! Position`: a flip, a zoom) puts the quad's point `q` at another pixel. Then
//! the entry point first evaluates `gl_Position` at three corners, inverts that
//! affine map at the pixel, and evaluates the stage at `q`: what a rasteriser
//! interpolates, for any stage whose position is affine in `Position`.

use super::error::SlangError;
use crate::shader::rename::prefix_module_names;
use naga::{Binding, BuiltIn, Module, TypeInner};
use std::path::Path;

/// The WGSL of a pass: its fragment and vertex modules (already rewritten to
/// share `params`) joined under one `@fragment fn fs_main`.
///
/// `vertex_glsl` is the stage's GLSL text: it tells whether the stage moves the
/// quad.
pub fn combine(
    mut fragment: Module,
    mut vertex: Module,
    vertex_glsl: &str,
    path: &Path,
) -> Result<String, SlangError> {
    let fs = detach(&mut fragment, "fs_stage", path)?;
    let vs = detach(&mut vertex, "stage", path)?;
    let vs_call = |at: &str| vertex_call(&vertex, &vs, at, path);
    let fragment_text = write(&fragment, path)?;
    let vertex_text = write(&vertex, path)?;
    // Struct members are named as the WGSL writer named them: read them back.
    let (vm, fm) = (
        parse_back(&vertex_text, path)?,
        parse_back(&fragment_text, path)?,
    );
    let outputs = vertex_outputs(function_result(&vm, "stage"));
    let fs_args = fragment_args(&outputs, &fs, path)?;
    let color = fragment_color(function_result(&fm, "fs_stage"), path)?;
    let vertex_text = shared_params_removed(
        &prefix_module_names(&vertex_text, "vs_", &["Params", "params"])
            .map_err(|e| unsupported(path, "the vertex stage's WGSL", &e))?,
    );
    let (quad_point, at) = if moves_the_quad(vertex_glsl) {
        let position = vertex_position(function_result(&vm, "stage")).ok_or_else(|| {
            unsupported(
                path,
                "a vertex stage that moves the quad without a position output",
                "the quad's point at a pixel is found from gl_Position",
            )
        })?;
        (quad_point_fn(&vs_call, &position)?, "q")
    } else {
        (String::new(), "uv")
    };
    let v_at = vs_call(at)?;
    // the quad point once per pixel: its corners are three vertex-stage runs
    let q = if at == "q" {
        "let q = fx_quad_point(uv);\n    "
    } else {
        ""
    };
    Ok(format!(
        "{fragment_text}\n// The vertex stage, evaluated per pixel.\n{vertex_text}\n{quad_point}\
         @fragment\nfn fs_main(@location(0) uv: vec2<f32>, @builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {{\n    \
         {q}let v = {v_at};\n    return fs_stage({fs_args}){color};\n}}\n"
    ))
}

/// Whether the stage places the quad other than where `MVP * Position` puts it
/// (the GLSL text without whitespace has one `gl_Position =`, and that is not
/// `MVP * Position` under any block name).
fn moves_the_quad(glsl: &str) -> bool {
    let text: String = glsl.chars().filter(|c| !c.is_whitespace()).collect();
    let stores: Vec<&str> = text
        .match_indices("gl_Position=")
        .map(|(at, m)| &text[at + m.len()..])
        .collect();
    let plain = |rhs: &str| {
        let rhs = rhs.split(';').next().unwrap_or("");
        let rhs = rhs.rsplit_once('.').map_or(rhs, |(_, field)| field);
        rhs == "MVP*Position"
    };
    !(stores.len() == 1 && plain(stores[0]))
}

/// `fn fx_quad_point(uv)`: the quad point `q` (its `Position.xy` and
/// `TexCoord`) that the stage puts at pixel `uv`. `gl_Position` at the corners
/// (0,0), (1,0) and (0,1), in pixel `uv` (the inverse of fxgraph's `MVP`; the
/// translated stage has already turned clip space's y upwards, as WGSL's), gives
/// the affine map `q -> uv`; a degenerate map leaves `q = uv`.
fn quad_point_fn(
    vs_call: &dyn Fn(&str) -> Result<String, SlangError>,
    position: &str,
) -> Result<String, SlangError> {
    let corner = |at: &str| -> Result<String, SlangError> {
        let call = vs_call(at)?;
        Ok(format!("fx_clip_uv({call}.{position})"))
    };
    Ok(format!(
        "fn fx_clip_uv(c: vec4<f32>) -> vec2<f32> {{\n    return vec2<f32>(c.x / c.w + 1.0, 1.0 - c.y / c.w) * 0.5;\n}}\n\
         fn fx_quad_point(uv: vec2<f32>) -> vec2<f32> {{\n    \
         let s0 = {};\n    let a = {} - s0;\n    let b = {} - s0;\n    \
         let det = a.x * b.y - a.y * b.x;\n    \
         if abs(det) < 1e-12 {{\n        return uv;\n    }}\n    \
         let d = uv - s0;\n    \
         return vec2<f32>(d.x * b.y - d.y * b.x, a.x * d.y - a.y * d.x) / det;\n}}\n",
        corner("vec2<f32>(0.0, 0.0)")?,
        corner("vec2<f32>(1.0, 0.0)")?,
        corner("vec2<f32>(0.0, 1.0)")?,
    ))
}

/// The member of the vertex function's result that holds `gl_Position`.
fn vertex_position(result: Option<(&Module, naga::FunctionResult)>) -> Option<String> {
    let (m, r) = result?;
    match &m.types[r.ty].inner {
        TypeInner::Struct { members, .. } => members
            .iter()
            .find(|mem| {
                matches!(
                    mem.binding,
                    Some(Binding::BuiltIn(BuiltIn::Position { .. }))
                )
            })
            .and_then(|mem| mem.name.clone()),
        _ => None,
    }
}

fn parse_back(text: &str, path: &Path) -> Result<Module, SlangError> {
    naga::front::wgsl::parse_str(text)
        .map_err(|e| unsupported(path, "the translated WGSL", &e.emit_to_string(text)))
}

/// The result of function `name` of `m`.
fn function_result<'m>(m: &'m Module, name: &str) -> Option<(&'m Module, naga::FunctionResult)> {
    m.functions
        .iter()
        .find(|(_, f)| f.name.as_deref() == Some(name))
        .and_then(|(_, f)| f.result.clone())
        .map(|r| (m, r))
}

/// An entry point turned into a function: its arguments and result as they were.
struct Detached {
    args: Vec<(Option<Binding>, naga::Handle<naga::Type>)>,
}

/// Moves the entry point of `m` into its functions as `name`.
fn detach(m: &mut Module, name: &str, path: &Path) -> Result<Detached, SlangError> {
    if m.entry_points.len() != 1 {
        return Err(unsupported(
            path,
            "a stage with several entry points",
            "one per stage",
        ));
    }
    let mut ep = m.entry_points.remove(0);
    let args = ep
        .function
        .arguments
        .iter_mut()
        .map(|a| (a.binding.take(), a.ty))
        .collect();
    if let Some(r) = &mut ep.function.result {
        r.binding = None;
    }
    ep.function.name = Some(name.to_string());
    m.functions.append(ep.function, naga::Span::UNDEFINED);
    Ok(Detached { args })
}

/// `vs_stage(Position, TexCoord)` at the quad point `at` (a WGSL `vec2<f32>`):
/// the quad's corners are `Position = (u, v, 0, 1)` and `TexCoord = (u, v)`.
fn vertex_call(m: &Module, vs: &Detached, at: &str, path: &Path) -> Result<String, SlangError> {
    let mut args = Vec::new();
    for (binding, ty) in &vs.args {
        let vec4 = matches!(
            m.types[*ty].inner,
            TypeInner::Vector {
                size: naga::VectorSize::Quad,
                ..
            }
        );
        let arg = match binding {
            Some(Binding::Location { location: 0, .. }) if vec4 => {
                format!("vec4<f32>({at}, 0.0, 1.0)")
            }
            Some(Binding::Location {
                location: 0 | 1, ..
            }) => at.to_string(),
            other => {
                return Err(unsupported(
                    path,
                    &format!("the vertex input {}", binding_words(other.as_ref())),
                    "the quad provides Position (location 0) and TexCoord (location 1)",
                ))
            }
        };
        args.push(arg);
    }
    Ok(format!("vs_stage({})", args.join(", ")))
}

/// The fragment function's arguments: vertex outputs by location, `pos`.
fn fragment_args(
    outputs: &[(u32, String)],
    fs: &Detached,
    path: &Path,
) -> Result<String, SlangError> {
    let mut args = Vec::new();
    for (binding, _) in &fs.args {
        let arg = match binding {
            Some(Binding::BuiltIn(BuiltIn::Position { .. })) => "pos".to_string(),
            Some(Binding::BuiltIn(BuiltIn::FrontFacing)) => "true".to_string(),
            Some(Binding::Location { location, .. }) => outputs
                .iter()
                .find(|(l, _)| l == location)
                .map(|(_, access)| access.clone())
                .ok_or_else(|| {
                    unsupported(
                        path,
                        &format!("fragment input at location {location}"),
                        "the vertex stage does not write it",
                    )
                })?,
            other => {
                return Err(unsupported(
                    path,
                    &format!("the fragment input {}", binding_words(other.as_ref())),
                    "fxgraph provides the position",
                ))
            }
        };
        args.push(arg);
    }
    Ok(args.join(", "))
}

/// `(location, WGSL access on v)` of each vertex output.
fn vertex_outputs(result: Option<(&Module, naga::FunctionResult)>) -> Vec<(u32, String)> {
    let Some((m, r)) = result else {
        return Vec::new();
    };
    match &m.types[r.ty].inner {
        TypeInner::Struct { members, .. } => members
            .iter()
            .filter_map(|mem| match &mem.binding {
                Some(Binding::Location { location, .. }) => Some((
                    *location,
                    format!("v.{}", mem.name.clone().unwrap_or_default()),
                )),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// How the colour at location 0 is read from the fragment function's result: a
/// `vec4` itself, or its member at location 0.
fn fragment_color(
    result: Option<(&Module, naga::FunctionResult)>,
    path: &Path,
) -> Result<String, SlangError> {
    let none = || {
        unsupported(
            path,
            "a fragment stage without a colour at location 0",
            "a pass writes one colour",
        )
    };
    let (m, r) = result.ok_or_else(none)?;
    match &m.types[r.ty].inner {
        TypeInner::Struct { members, .. } => members
            .iter()
            .find(|mem| matches!(mem.binding, Some(Binding::Location { location: 0, .. })))
            .map(|mem| format!(".{}", mem.name.clone().unwrap_or_default()))
            .ok_or_else(none),
        _ => Ok(String::new()),
    }
}

fn write(m: &Module, path: &Path) -> Result<String, SlangError> {
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(m)
    .map_err(|e| {
        let message = e.emit_to_string("");
        SlangError::Translate {
            path: path.to_path_buf(),
            class: super::FailureClass::of(&message),
            message,
        }
    })?;
    naga::back::wgsl::write_string(m, &info, naga::back::wgsl::WriterFlags::empty())
        .map_err(|e| unsupported(path, "writing WGSL", &e.to_string()))
}

/// The vertex text without its copy of `struct Params` and `var<uniform>
/// params` (the fragment text declares both, identically).
fn shared_params_removed(text: &str) -> String {
    let mut out = String::new();
    let mut in_struct = false;
    let mut pending_attr: Option<&str> = None;
    for line in text.lines() {
        if in_struct {
            in_struct = line.trim() != "}";
            continue;
        }
        if line.trim_start().starts_with("struct Params {") {
            in_struct = !line.contains('}');
            continue;
        }
        if line.contains("var<uniform> params: Params;") {
            pending_attr = None;
            continue;
        }
        if let Some(a) = pending_attr.take() {
            out.push_str(a);
            out.push('\n');
        }
        if line.trim_start().starts_with("@group(") && !line.contains("var") {
            pending_attr = Some(line);
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// A stage input's binding in words, as a message names it (never naga's
/// `Debug` form).
fn binding_words(b: Option<&Binding>) -> String {
    match b {
        Some(Binding::Location { location, .. }) => format!("at location {location}"),
        Some(Binding::BuiltIn(builtin)) => format!("built-in `{}`", builtin_name(builtin)),
        None => "without a binding".to_string(),
    }
}

/// GLSL's name of a built-in a stage may read.
fn builtin_name(b: &BuiltIn) -> &'static str {
    match b {
        BuiltIn::Position { .. } => "gl_FragCoord",
        BuiltIn::VertexIndex => "gl_VertexIndex",
        BuiltIn::InstanceIndex => "gl_InstanceIndex",
        BuiltIn::FrontFacing => "gl_FrontFacing",
        BuiltIn::SampleIndex => "gl_SampleID",
        BuiltIn::SampleMask => "gl_SampleMask",
        BuiltIn::PrimitiveIndex => "gl_PrimitiveID",
        BuiltIn::ViewIndex => "gl_ViewIndex",
        _ => "(another)",
    }
}

fn unsupported(path: &Path, feature: &str, why: &str) -> SlangError {
    SlangError::Unsupported {
        path: path.to_path_buf(),
        feature: feature.to_string(),
        why: why.to_string(),
    }
}
