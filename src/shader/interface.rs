//! The interface between the vertex stage fxgraph supplies and a pass's fragment
//! shader: every `@location` input of the fragment entry point must be an output of
//! the vertex stage, of a type it can read from it (the same scalar kind, as many
//! components or fewer) and interpolated the same way. wgpu checks this only when
//! the pipeline is created, and reports it as a validation chain without a source
//! line; here it is a diagnostic at the `@location` of the shader.
//!
//! The vertex stage's outputs are read from its WGSL ([`crate::shader::FULLSCREEN_VS`])
//! with naga, so the check follows the stage. Inter-stage locations are also
//! checked against [`MAX_INTER_STAGE_LOCATIONS`]: a location that no vertex stage can
//! provide gets a note saying so.

use crate::script::{Diagnostic, FileId, Span};
use naga::{Binding, Interpolation, Sampling, TypeInner};

/// WebGPU's guaranteed `maxInterStageShaderVariables` (wgpu's default limit): every
/// device passes locations 0 to 15 between the stages.
pub const MAX_INTER_STAGE_LOCATIONS: u32 = 16;

/// One `@location` value passed between the stages.
#[derive(Debug, Clone, PartialEq)]
pub struct Varying {
    pub location: u32,
    pub name: String,
    pub ty: TypeInner,
    /// As WGSL writes it (`vec2<f32>`).
    pub ty_wgsl: String,
    pub interpolation: Option<Interpolation>,
    pub sampling: Option<Sampling>,
}

/// The entry point `name` of `module` for `stage`.
fn entry_point<'m>(
    module: &'m naga::Module,
    name: &str,
    stage: naga::ShaderStage,
) -> Option<&'m naga::EntryPoint> {
    module
        .entry_points
        .iter()
        .find(|e| e.name == name && e.stage == stage)
}

/// The `@location` outputs of the vertex entry point `entry` of `wgsl`.
pub fn vertex_outputs(wgsl: &str, entry: &str) -> Vec<Varying> {
    let Ok(module) = naga::front::wgsl::parse_str(wgsl) else {
        return Vec::new();
    };
    let Some(ep) = entry_point(&module, entry, naga::ShaderStage::Vertex) else {
        return Vec::new();
    };
    let Some(result) = &ep.function.result else {
        return Vec::new();
    };
    let mut out = Vec::new();
    collect(
        &module,
        "",
        result.ty,
        result.binding.as_ref(),
        &mut |v, _| out.push(v),
    );
    out
}

/// The outputs of the fullscreen vertex stage every pass uses (parsed once).
pub fn fullscreen_outputs() -> &'static [Varying] {
    static OUT: std::sync::OnceLock<Vec<Varying>> = std::sync::OnceLock::new();
    OUT.get_or_init(|| vertex_outputs(crate::shader::FULLSCREEN_VS, "vs_main"))
}

/// Calls `f` for every `@location` value of type `ty` with `binding` (a struct's
/// members when it is an I/O struct), with the span of the struct when there is one.
fn collect(
    module: &naga::Module,
    name: &str,
    ty: naga::Handle<naga::Type>,
    binding: Option<&Binding>,
    f: &mut dyn FnMut(Varying, Option<naga::Span>),
) {
    use naga::common::wgsl::TypeContext as _;
    match (binding, &module.types[ty].inner) {
        (
            Some(Binding::Location {
                location,
                interpolation,
                sampling,
                ..
            }),
            inner,
        ) => f(
            Varying {
                location: *location,
                name: name.to_string(),
                ty: inner.clone(),
                ty_wgsl: module.types.type_to_string(ty),
                interpolation: *interpolation,
                sampling: *sampling,
            },
            None,
        ),
        (None, TypeInner::Struct { members, .. }) => {
            let struct_span = module.types.get_span(ty);
            for m in members {
                collect(
                    module,
                    m.name.as_deref().unwrap_or(""),
                    m.ty,
                    m.binding.as_ref(),
                    &mut |v, _| f(v, Some(struct_span)),
                );
            }
        }
        _ => {}
    }
}

/// The scalar kind, width and component count of a scalar or vector.
fn shape(t: &TypeInner) -> Option<(naga::ScalarKind, u8, u8)> {
    match t {
        TypeInner::Scalar(s) => Some((s.kind, s.width, 1)),
        TypeInner::Vector { size, scalar } => Some((scalar.kind, scalar.width, *size as u8)),
        _ => None,
    }
}

/// Whether a fragment input of type `input` can read an output of type `output`
/// (wgpu's rule: the same kind, no wider, no more components).
fn readable(input: &TypeInner, output: &TypeInner) -> bool {
    match (shape(input), shape(output)) {
        (Some((ki, wi, ni)), Some((ko, wo, no))) => ki == ko && wi <= wo && ni <= no,
        _ => input == output,
    }
}

fn interpolation_words(i: Option<Interpolation>, s: Option<Sampling>) -> String {
    let i = match i {
        Some(Interpolation::Perspective) | None => "perspective",
        Some(Interpolation::Linear) => "linear",
        Some(Interpolation::Flat) => "flat",
        Some(Interpolation::PerVertex) => "per-vertex",
    };
    match s {
        Some(Sampling::Center) | None => i.to_string(),
        Some(Sampling::Centroid) => format!("{i}, centroid"),
        Some(Sampling::Sample) => format!("{i}, sample"),
        Some(Sampling::First) => format!("{i}, first"),
        Some(Sampling::Either) => format!("{i}, either"),
    }
}

/// Checks the `@location` inputs of fragment entry point `entry` of `module`
/// (parsed from `wgsl`, file `file` in the source map) against the vertex stage's
/// `provided` outputs. `stage` names that stage in messages.
pub fn check_fragment_inputs(
    module: &naga::Module,
    wgsl: &str,
    file: FileId,
    entry: &str,
    provided: &[Varying],
    stage: &str,
) -> Vec<Diagnostic> {
    let Some(ep) = entry_point(module, entry, naga::ShaderStage::Fragment) else {
        return Vec::new();
    };
    let header = crate::shader::wgsl_names::fn_header(wgsl, entry);
    let mut inputs = Vec::new();
    for arg in &ep.function.arguments {
        let name = arg.name.as_deref().unwrap_or("");
        collect(module, name, arg.ty, arg.binding.as_ref(), &mut |v, s| {
            inputs.push((v, s))
        });
    }
    let offered = provided
        .iter()
        .map(|p| format!("`@location({}) {}: {}`", p.location, p.name, p.ty_wgsl))
        .collect::<Vec<_>>()
        .join(", ");
    let mut diags = Vec::new();
    for (v, struct_span) in inputs {
        // The `@location(N)` of the input: in its struct's declaration, or after
        // the entry point's `fn NAME`.
        let region = match struct_span.and_then(|s| s.to_range()) {
            Some(r) => r,
            None => header
                .clone()
                .map_or(0..wgsl.len(), |h| h.start..wgsl.len()),
        };
        let at = location_attribute(wgsl, region, v.location)
            .or(header.clone())
            .map_or(Span::new(file, 0, 0), |r| Span::new(file, r.start, r.end));
        let d = match provided.iter().find(|p| p.location == v.location) {
            None => {
                let mut d = Diagnostic::error(format!(
                    "fragment input `{}` at `@location({})` is not an output of the vertex stage",
                    v.name, v.location
                ))
                .at(at, format!("{stage} provides {offered}"));
                if v.location >= MAX_INTER_STAGE_LOCATIONS {
                    d = d.note(format!(
                        "locations between the stages are 0 to {} (WebGPU's guaranteed limit)",
                        MAX_INTER_STAGE_LOCATIONS - 1
                    ));
                }
                d
            }
            Some(p) if !readable(&v.ty, &p.ty) => Diagnostic::error(format!(
                "fragment input `{}` at `@location({})` is `{}`, but the vertex stage outputs `{}` there",
                v.name, v.location, v.ty_wgsl, p.ty_wgsl
            ))
            .at(at, format!("{stage} provides `{}: {}`", p.name, p.ty_wgsl)),
            Some(p) if (v.interpolation, v.sampling) != (p.interpolation, p.sampling) => {
                Diagnostic::error(format!(
                    "fragment input `{}` at `@location({})` is interpolated {}, but the vertex stage outputs it {}",
                    v.name,
                    v.location,
                    interpolation_words(v.interpolation, v.sampling),
                    interpolation_words(p.interpolation, p.sampling)
                ))
                .at(at, "remove the `@interpolate(...)` attribute")
            }
            Some(_) => continue,
        };
        diags.push(d);
    }
    diags
}

/// The range of the first `@location(N)` in `wgsl[region]` whose value is
/// `location` (decimal or hexadecimal, with an optional `i`/`u` suffix).
fn location_attribute(
    wgsl: &str,
    region: std::ops::Range<usize>,
    location: u32,
) -> Option<std::ops::Range<usize>> {
    let text = wgsl.get(region.clone())?;
    let mut from = 0;
    while let Some(i) = text[from..].find("@location") {
        let start = from + i;
        from = start + 1;
        let rest = text[start + "@location".len()..].trim_start();
        let Some(inner) = rest.strip_prefix('(') else {
            continue;
        };
        let Some(close) = inner.find(')') else {
            continue;
        };
        let lit = inner[..close].trim().trim_end_matches(['i', 'u']);
        let value = match lit.strip_prefix("0x").or_else(|| lit.strip_prefix("0X")) {
            Some(hex) => u64::from_str_radix(hex, 16).ok(),
            None => lit.parse::<u64>().ok(),
        };
        if value == Some(u64::from(location)) {
            let end = text.len() - inner.len() + close + 1;
            return Some(region.start + start..region.start + end);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fullscreen_stage_provides_uv_at_location_0() {
        let out = fullscreen_outputs();
        assert_eq!(out.len(), 1);
        assert_eq!((out[0].location, out[0].ty_wgsl.as_str()), (0, "vec2<f32>"));
    }

    fn check(src: &str) -> Vec<String> {
        let module = naga::front::wgsl::parse_str(src).unwrap();
        let mut sources = crate::script::SourceMap::new();
        let file = sources.add("t.wgsl", src.to_string());
        check_fragment_inputs(
            &module,
            src,
            file,
            "fs_main",
            fullscreen_outputs(),
            "the pass's vertex stage",
        )
        .into_iter()
        .map(|d| {
            let mut list = crate::script::Diagnostics::default();
            list.push(d);
            list.render(&sources)
        })
        .collect()
    }

    #[test]
    fn inputs_are_checked_against_the_vertex_outputs() {
        let ok = "@fragment fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> { return vec4<f32>(uv, 0.0, 1.0); }";
        assert!(check(ok).is_empty());
        // Fewer components read the first ones.
        let x = "@fragment fn fs_main(@location(0) u: f32) -> @location(0) vec4<f32> { return vec4<f32>(u); }";
        assert!(check(x).is_empty());
        let far = "@fragment\nfn fs_main(@location(0) uv: vec2<f32>,\n    @location(65536) w: vec2<f32>) -> @location(0) vec4<f32> { return vec4<f32>(uv, w); }";
        let r = check(far);
        assert_eq!(r.len(), 1, "{r:?}");
        assert!(
            r[0].contains("t.wgsl:3:5: error: fragment input `w` at `@location(65536)`"),
            "{}",
            r[0]
        );
        assert!(
            r[0].contains("locations between the stages are 0 to 15"),
            "{}",
            r[0]
        );
        let wide = "@fragment fn fs_main(@location(0) uv: vec4<f32>) -> @location(0) vec4<f32> { return uv; }";
        assert!(check(wide)[0].contains("is `vec4<f32>`, but the vertex stage outputs `vec2<f32>`"));
        let flat = "@fragment fn fs_main(@location(0) @interpolate(flat) uv: vec2<f32>) -> @location(0) vec4<f32> { return vec4<f32>(uv, 0.0, 1.0); }";
        assert!(check(flat)[0]
            .contains("interpolated flat, but the vertex stage outputs it perspective"));
        let in_struct = "struct In {\n  @location(0) uv: vec2<f32>,\n  @location(0x7) v: f32,\n}\n@fragment fn fs_main(i: In) -> @location(0) vec4<f32> { return vec4<f32>(i.v); }";
        let r = check(in_struct);
        assert!(
            r[0].contains("t.wgsl:3:3: error: fragment input `v` at `@location(7)`"),
            "{}",
            r[0]
        );
    }
}
