//! Loading every shader of a plan: find, preprocess, reflect and check the script's
//! bindings against it. Needs no GPU, so `fxrun --check` runs it too.

use super::include::{assemble, IncludeOrigin, RealFs};
use super::reflect::{bind_pass, Reflection, UniformLayout};
use super::{find_shader, preprocess, reflect};
use crate::graph::plan::{PassShader, Plan};
use crate::graph::Graph;
use crate::script::types::ColorSpace;
use crate::script::{Diagnostic, Diagnostics, FileId, SourceMap, Span};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// A shader file (as shown) with its defines.
type ShaderKey = (String, Vec<(String, i64)>);

/// A pass's shader, ready for pipeline creation.
#[derive(Debug, Clone)]
pub struct LoadedShader {
    /// How the shader is named in messages (its path or `<builtin>/shaders/...`).
    pub label: String,
    /// Preprocessed WGSL.
    pub wgsl: Arc<str>,
    pub reflection: Reflection,
    pub layout: UniformLayout,
}

/// Load the shader of every pass of `plan` (in order). A pass whose shader has a
/// problem gets `None` and diagnostics (WGSL files are added to `sources`).
pub fn load_plan_shaders(
    graph: &Graph,
    plan: &Plan,
    sources: &mut SourceMap,
    extra_dirs: &[PathBuf],
) -> (Vec<Option<LoadedShader>>, Diagnostics) {
    let mut diags = Diagnostics::default();
    let mut files: HashMap<String, FileId> = HashMap::new();
    let mut cache: HashMap<ShaderKey, Option<(Arc<str>, Reflection)>> = HashMap::new();
    let mut out = Vec::with_capacity(plan.passes.len());
    for p in &plan.passes {
        let (file, defines, node) = match &p.shader {
            PassShader::Script { name } => {
                let n = p.node.expect("script pass has a node");
                let pn = graph.pass(n);
                let Some(file) = find_shader(name, pn.shader_dir.as_deref(), extra_dirs) else {
                    diags.push(
                        Diagnostic::error(format!("no shader `{name}.wgsl`"))
                            .at(pn.shader_span, "not found next to the effect file, in its shaders/ folder, or in the built-in library"),
                    );
                    out.push(None);
                    continue;
                };
                (file, pn.defines.clone(), Some(n))
            }
            PassShader::Convert { to } => {
                let f = find_shader("_colorspace", None, &[]).expect("built-in shader");
                (
                    f,
                    vec![(
                        "TO_LINEAR".to_string(),
                        i64::from(*to == ColorSpace::Linear),
                    )],
                    None,
                )
            }
            PassShader::Blit => (
                find_shader("_blit", None, &[]).expect("built-in shader"),
                Vec::new(),
                None,
            ),
        };
        let label = file.shown.clone();
        let file_id = *files
            .entry(label.clone())
            .or_insert_with(|| sources.add(label.clone(), file.text.clone()));
        let key = (label.clone(), defines.clone());
        if !cache.contains_key(&key) {
            // `#include "lib/..."` (the built-in library) or a file beside the
            // shader: included text is appended, so the file's own lines and
            // columns stay as they are.
            let assembly = if file.text.contains("#include") {
                let origin = match &file.path {
                    Some(p) => IncludeOrigin::Disk(p.clone()),
                    None => IncludeOrigin::Memory,
                };
                match assemble(file_id, &label, &file.text, origin, &RealFs, sources) {
                    Ok(a) => Some(a),
                    Err(ds) => {
                        ds.into_iter().for_each(|d| diags.push(d));
                        cache.insert(key.clone(), None);
                        out.push(None);
                        continue;
                    }
                }
            } else {
                None
            };
            let text = assembly
                .as_ref()
                .map_or(file.text.as_str(), |a| a.text.as_str());
            let loaded = match preprocess(text, &defines) {
                Err(e) => {
                    diags.push(
                        Diagnostic::error(e.message).at(Span::new(file_id, e.start, e.end), ""),
                    );
                    None
                }
                Ok((wgsl, _)) => {
                    // The preprocessed text keeps the lines and columns of the file
                    // (plus constants at the end), so its spans read as the file's.
                    let id = if wgsl == file.text {
                        file_id
                    } else {
                        sources.add(label.clone(), wgsl.clone())
                    };
                    match reflect(&wgsl, id) {
                        Ok(r) => Some((Arc::<str>::from(wgsl), r)),
                        Err(ds) => {
                            for mut d in ds {
                                // Spans past the file's own text lie in an
                                // included file: point there.
                                if let Some(a) = &assembly {
                                    for l in &mut d.labels {
                                        if l.span.file == id
                                            && l.span.start as usize >= file.text.len()
                                        {
                                            if let Some(sp) = a.map_span(
                                                l.span.start as usize,
                                                l.span.end as usize,
                                            ) {
                                                l.span = sp;
                                            }
                                        }
                                    }
                                }
                                diags.push(d);
                            }
                            None
                        }
                    }
                }
            };
            cache.insert(key.clone(), loaded);
        }
        let Some((wgsl, reflection)) = cache[&key].clone() else {
            out.push(None);
            continue;
        };
        let layout = match node {
            Some(n) => match bind_pass(graph.pass(n), &reflection, &label) {
                Ok(l) => l,
                Err(ds) => {
                    ds.into_iter().for_each(|d| diags.push(d));
                    out.push(None);
                    continue;
                }
            },
            None => UniformLayout::default(),
        };
        out.push(Some(LoadedShader {
            label,
            wgsl,
            reflection,
            layout,
        }));
    }
    (out, diags)
}
