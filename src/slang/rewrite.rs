//! A pass's fragment module in fxgraph's conventions (docs/shaders.md), rewritten
//! in naga's IR:
//! - the uniform block and the push-constant block become one `var<uniform>
//!   params` struct whose fields carry fxgraph's names: parameters keep theirs,
//!   semantics become standard values (`SourceSize` → `Source_size4`,
//!   `OutputSize` → `out_size4`, `FrameCount` → `frame` or `frame_mod_N`, ...);
//! - each sampler, split from its texture by librashader, is named
//!   `TEXTURE_sampler`, so it gets the filter and wrap modes of that input;
//! - a texture whose size a shader reads without sampling it (`OriginalSize`,
//!   `PassOutputSize1`, a LUT's size) is declared, so the pass binds it and its
//!   size is known;
//! - all bindings move to group 0, renumbered.

use super::error::SlangError;
use naga::{AddressSpace, Expression, Handle, Module, ResourceBinding, Type, TypeInner};
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

/// The uniform fields of a pass, over both of its stages: one `Params` struct
/// that the vertex and fragment code share.
#[derive(Debug, Default)]
pub struct Fields {
    /// Field names in order, with their types.
    pub names: Vec<(String, TypeInner)>,
    /// The parameter ids among them.
    pub params: Vec<String>,
    /// Textures whose size the shader reads (`SourceSize` → `Source`).
    pub sizes: BTreeSet<String>,
}

/// Plans the fields of both stages (fragment first). `frame_mod` is the pass's
/// `frame_count_mod` (0: none).
pub fn plan_fields(
    stages: [&Module; 2],
    path: &Path,
    frame_mod: u32,
    is_param: &dyn Fn(&str) -> bool,
) -> Result<Fields, SlangError> {
    let mut f = Fields::default();
    for m in stages {
        for field in uniform_fields(m, path, frame_mod, is_param, &mut f.sizes)? {
            if is_param(&field.name) && !f.params.contains(&field.name) {
                f.params.push(field.name.clone());
            }
            if !f.names.iter().any(|(n, _)| *n == field.name) {
                f.names.push((field.name, m.types[field.ty].inner.clone()));
            }
        }
    }
    Ok(f)
}

/// Rewrites the fragment module of a pass; returns the textures it binds (WGSL
/// names = script input names). `ensure` names textures the pass must bind even
/// when the shader does not sample them (`Source` for a source-relative scale).
pub fn rewrite_fragment(
    m: &mut Module,
    path: &Path,
    fields: &Fields,
    frame_mod: u32,
    is_param: &dyn Fn(&str) -> bool,
    ensure: &[&str],
) -> Result<Vec<String>, SlangError> {
    let textures = name_textures(m);
    let mut wanted: Vec<String> = fields.sizes.iter().cloned().collect();
    wanted.extend(ensure.iter().map(|s| s.to_string()));
    for t in wanted {
        let declared = m
            .global_variables
            .iter()
            .any(|(_, g)| g.name.as_deref() == Some(&t));
        if !textures.contains(&t) && !declared {
            declare_texture(m, &t);
        }
    }
    let next = renumber(m);
    merge_uniforms(m, path, fields, frame_mod, is_param, next)?;
    Ok(m.global_variables
        .iter()
        .filter(|(_, g)| matches!(m.types[g.ty].inner, TypeInner::Image { .. }))
        .filter_map(|(_, g)| g.name.clone())
        .collect())
}

/// Rewrites the vertex module of a pass: its uniform blocks become the shared
/// `Params` (it binds no texture: fxgraph's vertex stage reads none).
pub fn rewrite_vertex(
    m: &mut Module,
    path: &Path,
    fields: &Fields,
    frame_mod: u32,
    is_param: &dyn Fn(&str) -> bool,
) -> Result<(), SlangError> {
    let samples = m.global_variables.iter().any(|(_, g)| {
        matches!(
            m.types[g.ty].inner,
            TypeInner::Image { .. } | TypeInner::Sampler { .. }
        )
    });
    if samples {
        return Err(SlangError::Unsupported {
            path: path.to_path_buf(),
            feature: "textures in the vertex stage".into(),
            why: "fxgraph evaluates a pass's vertex stage inside its fragment stage, which binds the textures".into(),
        });
    }
    merge_uniforms(m, path, fields, frame_mod, is_param, 0)
}

/// One member of a uniform block: where it was and what it becomes.
struct Field {
    global: Handle<naga::GlobalVariable>,
    index: u32,
    name: String,
    ty: Handle<Type>,
}

/// The members of every uniform block, named by what they mean to fxgraph.
fn uniform_fields(
    m: &Module,
    path: &Path,
    frame_mod: u32,
    is_param: &dyn Fn(&str) -> bool,
    sizes: &mut BTreeSet<String>,
) -> Result<Vec<Field>, SlangError> {
    let mut fields = Vec::new();
    for (h, g) in m.global_variables.iter() {
        if g.space != AddressSpace::Uniform {
            continue;
        }
        let TypeInner::Struct { members, .. } = &m.types[g.ty].inner else {
            continue;
        };
        for (i, mem) in members.iter().enumerate() {
            let semantic = mem.name.clone().unwrap_or_default();
            let name = if is_param(&semantic) {
                semantic
            } else {
                std_name(&semantic, frame_mod, sizes).ok_or_else(|| SlangError::Unsupported {
                    path: path.to_path_buf(),
                    feature: format!("the semantic `{semantic}`"),
                    why: "fxgraph has no value for it (docs/slang.md lists the semantics it fills)"
                        .into(),
                })?
            };
            fields.push(Field {
                global: h,
                index: i as u32,
                name,
                ty: mem.ty,
            });
        }
    }
    Ok(fields)
}

/// The fxgraph standard value for a slang semantic (docs/shaders.md, docs/slang.md).
fn std_name(semantic: &str, frame_mod: u32, sizes: &mut BTreeSet<String>) -> Option<String> {
    let fixed = match semantic {
        "MVP" => "mvp",
        "OutputSize" => "out_size_texel",
        "FinalViewportSize" => "final_size_texel",
        "FrameDirection" => "frame_direction",
        "Rotation" => "rotation",
        "TotalSubFrames" => "total_subframes",
        "CurrentSubFrame" => "current_subframe",
        "OriginalAspect" | "OriginalAspectRotated" => "in_aspect",
        "OriginalFPS" => "fps",
        "FrameTimeDelta" => "frame_time_ms",
        "HDRMode" => "frontend_hdr_mode",
        "BrightnessNits" => "frontend_brightness_nits",
        "ExpandGamut" => "frontend_expand_gamut",
        "Scanlines" => "frontend_scanlines",
        "InverseTonemap" => "frontend_inverse_tonemap",
        "HDR10" => "frontend_hdr10",
        "SubpixelLayout" => "frontend_subpixel_layout",
        "Gyroscope" => "frontend_gyroscope",
        "Accelerometer" => "frontend_accelerometer",
        "AccelerometerRest" => "frontend_accelerometer_rest",
        "FrameCount" if frame_mod > 0 => return Some(format!("frame_mod_{frame_mod}_count")),
        "FrameCount" => "frame",
        _ => {
            let texture = semantic.strip_suffix("Size")?;
            if texture.is_empty() {
                return None;
            }
            sizes.insert(texture.to_string());
            return Some(format!("{}_size_texel", wgsl_name(texture)));
        }
    };
    Some(fixed.to_string())
}

/// A name as naga's WGSL writer spells it: a trailing digit gets a `_` (so that
/// its own `_1`, `_2` suffixes never collide).
pub fn wgsl_name(name: &str) -> String {
    if name.ends_with(|c: char| c.is_ascii_digit()) {
        format!("{name}_")
    } else {
        name.to_string()
    }
}

/// Names each sampler after the texture it was split from (same binding, group
/// 1), returning the texture names.
fn name_textures(m: &mut Module) -> Vec<String> {
    let mut by_binding: HashMap<u32, String> = HashMap::new();
    for (_, g) in m.global_variables.iter() {
        if let (TypeInner::Image { .. }, Some(b), Some(n)) =
            (&m.types[g.ty].inner, &g.binding, &g.name)
        {
            by_binding.insert(b.binding, n.clone());
        }
    }
    let mut counter = 0;
    for (_, g) in m.global_variables.iter_mut() {
        if !matches!(m.types[g.ty].inner, TypeInner::Sampler { .. }) {
            continue;
        }
        let tex = g.binding.as_ref().and_then(|b| by_binding.get(&b.binding));
        g.name = Some(match tex {
            Some(t) => format!("{}_sampler", wgsl_name(t)),
            None => {
                counter += 1;
                format!("slang_sampler{counter}")
            }
        });
    }
    by_binding.into_values().collect()
}

/// Declares `texture_2d<f32>` `name` (bound later by `renumber`).
fn declare_texture(m: &mut Module, name: &str) {
    let ty = m.types.insert(
        Type {
            name: None,
            inner: TypeInner::Image {
                dim: naga::ImageDimension::D2,
                arrayed: false,
                class: naga::ImageClass::Sampled {
                    kind: naga::ScalarKind::Float,
                    multi: false,
                },
            },
        },
        naga::Span::UNDEFINED,
    );
    m.global_variables.append(
        naga::GlobalVariable {
            name: Some(name.to_string()),
            space: AddressSpace::Handle,
            binding: Some(ResourceBinding {
                group: 0,
                binding: u32::MAX,
            }),
            ty,
            init: None,
            memory_decorations: Default::default(),
        },
        naga::Span::UNDEFINED,
    );
}

/// Moves every resource to group 0 with bindings 0, 1, ...; returns the next free
/// binding.
fn renumber(m: &mut Module) -> u32 {
    let mut next = 0;
    for (_, g) in m.global_variables.iter_mut() {
        if g.space == AddressSpace::Uniform {
            continue;
        }
        if let Some(b) = &mut g.binding {
            *b = ResourceBinding {
                group: 0,
                binding: next,
            };
            next += 1;
        }
    }
    next
}

/// One `params` struct with every field of `fields`; the old blocks stay as
/// unused private variables (naga's arenas keep their handles).
fn merge_uniforms(
    m: &mut Module,
    path: &Path,
    fields: &Fields,
    frame_mod: u32,
    is_param: &dyn Fn(&str) -> bool,
    binding: u32,
) -> Result<(), SlangError> {
    if fields.names.is_empty() {
        return Ok(());
    }
    let own = uniform_fields(m, path, frame_mod, is_param, &mut BTreeSet::new())?;
    let (members, offset) = params_members(m, path, fields)?;
    let index_of: HashMap<(Handle<naga::GlobalVariable>, u32), u32> = own
        .iter()
        .map(|f| {
            let at = fields
                .names
                .iter()
                .position(|(n, _)| *n == f.name)
                .unwrap_or(0);
            ((f.global, f.index), at as u32)
        })
        .collect();
    let span = offset.next_multiple_of(16).max(16);
    let ty = m.types.insert(
        Type {
            name: Some("Params".into()),
            inner: TypeInner::Struct { members, span },
        },
        naga::Span::UNDEFINED,
    );
    let params = m.global_variables.append(
        naga::GlobalVariable {
            name: Some("params".into()),
            space: AddressSpace::Uniform,
            binding: Some(ResourceBinding { group: 0, binding }),
            ty,
            init: None,
            memory_decorations: Default::default(),
        },
        naga::Span::UNDEFINED,
    );
    let old = retire_old_blocks(m, params);
    let mut functions: Vec<&mut naga::Function> = m.functions.iter_mut().map(|(_, f)| f).collect();
    functions.extend(m.entry_points.iter_mut().map(|e| &mut e.function));
    for f in functions {
        redirect(f, &old, params, &index_of);
    }
    Ok(())
}

/// The members of the merged `Params` struct (one per field of `fields`, laid out by
/// naga's rules) and the offset after the last.
fn params_members(
    m: &mut Module,
    path: &Path,
    fields: &Fields,
) -> Result<(Vec<naga::StructMember>, u32), SlangError> {
    let types: Vec<Handle<Type>> = fields
        .names
        .iter()
        .map(|(_, inner)| {
            let ty = Type {
                name: None,
                inner: inner.clone(),
            };
            m.types.insert(ty, naga::Span::UNDEFINED)
        })
        .collect();
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(m.to_ctx())
        .map_err(|e| SlangError::Unsupported {
            path: path.to_path_buf(),
            feature: "the uniform block's layout".into(),
            why: e.to_string(),
        })?;
    let mut members = Vec::new();
    let mut offset = 0u32;
    for ((name, _), &ty) in fields.names.iter().zip(&types) {
        let layout = layouter[ty];
        offset = layout.alignment.round_up(offset);
        members.push(naga::StructMember {
            name: Some(name.clone()),
            ty,
            binding: None,
            offset,
        });
        offset += layout.size;
    }
    Ok((members, offset))
}

/// Turns every uniform block but `params` into an unused private variable (renamed, so
/// that `params` is free); their handles.
fn retire_old_blocks(
    m: &mut Module,
    params: Handle<naga::GlobalVariable>,
) -> Vec<Handle<naga::GlobalVariable>> {
    let old: Vec<Handle<naga::GlobalVariable>> = m
        .global_variables
        .iter()
        .filter(|(h, g)| g.space == AddressSpace::Uniform && *h != params)
        .map(|(h, _)| h)
        .collect();
    for &h in &old {
        let g = &mut m.global_variables[h];
        g.space = AddressSpace::Private;
        g.binding = None;
        // Push blocks are often named `params`: free the name.
        g.name = Some(format!(
            "slang_{}_unused",
            g.name.as_deref().unwrap_or("block")
        ));
    }
    old
}

/// Points member accesses of the old blocks at `params`.
fn redirect(
    f: &mut naga::Function,
    old: &[Handle<naga::GlobalVariable>],
    params: Handle<naga::GlobalVariable>,
    index_of: &HashMap<(Handle<naga::GlobalVariable>, u32), u32>,
) {
    let globals: HashMap<Handle<Expression>, Handle<naga::GlobalVariable>> = f
        .expressions
        .iter()
        .filter_map(|(h, e)| match e {
            Expression::GlobalVariable(g) if old.contains(g) => Some((h, *g)),
            _ => None,
        })
        .collect();
    for (_, e) in f.expressions.iter_mut() {
        if let Expression::AccessIndex { base, index } = e {
            if let Some(g) = globals.get(base) {
                *index = index_of[&(*g, *index)];
            }
        }
    }
    // A block read whole (glslang never emits one) fails validation afterwards.
    for (h, e) in f.expressions.iter_mut() {
        if globals.contains_key(&h) {
            *e = Expression::GlobalVariable(params);
        }
    }
}
