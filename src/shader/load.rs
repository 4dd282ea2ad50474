//! Loading every shader of a plan: find, preprocess, reflect and check the script's
//! bindings against it. Needs no GPU, so `fxrun --check` runs it too.

use super::include::{assemble, IncludeOrigin, RealFs};
use super::reflect::{bind_pass, std_value, FieldType, Reflection, UniformLayout};
use super::{find_shader, preprocess, reflect, ShaderFile};
use crate::graph::plan::{PassShader, Plan};
use crate::graph::{CompileRequest, Graph, ShaderReference};
use crate::script::types::{ColorSpace, Value};
use crate::script::{Diagnostic, Diagnostics, FileId, SourceMap, Span};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// A shader file (as shown) with its defines.
type ShaderKey = (String, Vec<(String, i64)>);

/// A shader file loaded with its defines: its WGSL and reflection (`None`: it has
/// errors), and its diagnostics.
type Loaded = (Option<(Arc<str>, Reflection)>, Diagnostics);

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

/// Shader files loaded (assembled, preprocessed, reflected) for one
/// [`SourceMap`], by file and defines, with the diagnostics of each: what
/// [`preload_graph_shaders`] does before a device exists, for
/// [`load_plan_shaders_with`] to find.
#[derive(Default)]
pub struct ShaderCache {
    files: HashMap<String, FileId>,
    loaded: HashMap<ShaderKey, Loaded>,
}

impl ShaderCache {
    /// The loaded shader of `file` with `defines` (loaded now if it is not yet),
    /// and its diagnostics.
    fn load(
        &mut self,
        file: &ShaderFile,
        defines: &[(String, i64)],
        sources: &mut SourceMap,
    ) -> &Loaded {
        let key = (file.shown.clone(), defines.to_vec());
        if !self.loaded.contains_key(&key) {
            let mut diags = Diagnostics::default();
            let loaded = load_file(file, defines, sources, &mut self.files, &mut diags);
            self.loaded.insert(key.clone(), (loaded, diags));
        }
        &self.loaded[&key]
    }
}

/// Load the shaders of `graph`'s script passes into `cache`, each with its
/// defines (no device needed: a run does it while its device is created). Only
/// a head start: what cannot be found is left to [`load_plan_shaders_with`],
/// which reports it.
pub fn preload_graph_shaders(
    graph: &Graph,
    sources: &mut SourceMap,
    extra_dirs: &[PathBuf],
    cache: &mut ShaderCache,
) {
    for &n in &graph.schedule {
        let crate::graph::Node::Pass(pn) = &graph.graph[n] else {
            continue;
        };
        if let Some(file) = find_shader(&pn.shader, pn.shader_dir.as_deref(), extra_dirs) {
            cache.load(&file, &pn.defines, sources);
        }
    }
}

/// Load the shader of every pass of `plan` (in order). A pass whose shader has a
/// problem gets `None` and diagnostics (WGSL files are added to `sources`).
pub fn load_plan_shaders(
    graph: &Graph,
    plan: &Plan,
    sources: &mut SourceMap,
    extra_dirs: &[PathBuf],
) -> (Vec<Option<LoadedShader>>, Diagnostics) {
    load_plan_shaders_with(
        graph,
        plan,
        sources,
        extra_dirs,
        &mut ShaderCache::default(),
    )
}

/// [`load_plan_shaders`] with the shaders `cache` holds already (loaded for the
/// same `sources`), adding those it loads.
pub fn load_plan_shaders_with(
    graph: &Graph,
    plan: &Plan,
    sources: &mut SourceMap,
    extra_dirs: &[PathBuf],
    cache: &mut ShaderCache,
) -> (Vec<Option<LoadedShader>>, Diagnostics) {
    let mut diags = Diagnostics::default();
    // Each shader's diagnostics are reported once.
    let mut reported: std::collections::HashSet<ShaderKey> = Default::default();
    let mut out = Vec::with_capacity(plan.passes.len());
    for p in &plan.passes {
        let (file, defines, node) = match &p.shader {
            PassShader::Script { name } => {
                let n = p.node.expect("script pass has a node");
                let pn = graph.pass(n);
                let Some(file) = find_shader(name, pn.shader_dir.as_deref(), extra_dirs) else {
                    diags.push(missing_shader(name, pn.shader_span));
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
            PassShader::Blit | PassShader::Mips => (
                find_shader("_blit", None, &[]).expect("built-in shader"),
                Vec::new(),
                None,
            ),
        };
        let label = file.shown.clone();
        let (loaded, file_diags) = cache.load(&file, &defines, sources);
        if reported.insert((label.clone(), defines.clone())) {
            diags.extend(file_diags.clone());
        }
        let Some((wgsl, reflection)) = loaded.clone() else {
            out.push(None);
            continue;
        };
        let layout = match node {
            Some(n) => match bind_pass(graph.pass(n), &reflection, &label) {
                Ok(l) => l,
                Err(ds) => {
                    ds.into_iter()
                        .for_each(|d| diags.push(with_origin(d, &file.text)));
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

/// Find-independent half of loading: register `file` in `sources` (once per label),
/// assemble its includes, preprocess with `defines` and reflect it. Problems go to
/// `diags`, pointing into the file (or the included file they lie in).
fn load_file(
    file: &ShaderFile,
    defines: &[(String, i64)],
    sources: &mut SourceMap,
    files: &mut HashMap<String, FileId>,
    diags: &mut Diagnostics,
) -> Option<(Arc<str>, Reflection)> {
    let label = file.shown.clone();
    let file_id = *files
        .entry(label.clone())
        .or_insert_with(|| match &file.path {
            Some(path) => sources.add_disk(label.clone(), file.text.clone(), path),
            None => sources.add(label.clone(), file.text.clone()),
        });
    // `#include "lib/..."` (the built-in library) or a file beside the shader:
    // included text is appended, so the file's own lines and columns stay as they
    // are.
    let assembly = if file.text.contains("#include") {
        let origin = match &file.path {
            Some(p) => IncludeOrigin::Disk(p.clone()),
            None => IncludeOrigin::Memory,
        };
        match assemble(file_id, &label, &file.text, origin, &RealFs, sources) {
            Ok(a) => Some(a),
            Err(ds) => {
                ds.into_iter().for_each(|d| diags.push(d));
                return None;
            }
        }
    } else {
        None
    };
    let text = assembly
        .as_ref()
        .map_or(file.text.as_str(), |a| a.text.as_str());
    let (wgsl, _) = match preprocess(text, defines) {
        Err(e) => {
            diags.push(Diagnostic::error(e.message).at(Span::new(file_id, e.start, e.end), ""));
            return None;
        }
        Ok(x) => x,
    };
    // The preprocessed text keeps the lines and columns of the file (plus constants
    // at the end), so its spans read as the file's.
    let id = if wgsl == file.text {
        file_id
    } else {
        sources.add(label.clone(), wgsl.clone())
    };
    match reflect(&wgsl, id) {
        Ok(r) => Some((Arc::<str>::from(wgsl), r)),
        Err(ds) => {
            for mut d in ds {
                // Spans past the file's own text lie in an included file: point
                // there.
                if let Some(a) = &assembly {
                    for l in &mut d.labels {
                        if l.span.file == id && l.span.start as usize >= file.text.len() {
                            if let Some(sp) = a.map_span(l.span.start as usize, l.span.end as usize)
                            {
                                l.span = sp;
                            }
                        }
                    }
                }
                diags.push(with_origin(d, &file.text));
            }
            None
        }
    }
}

/// The first line of a shader fxgraph generated from another file (the slang
/// lowering writes its WGSL with it): `// fxgraph: generated from FILE ...`.
pub const GENERATED_FROM: &str = "// fxgraph: generated from ";

/// `d`, with a note naming the file a generated shader `text` was made from: its
/// spans point into the generated WGSL, which the user did not write.
fn with_origin(d: Diagnostic, text: &str) -> Diagnostic {
    match text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix(GENERATED_FROM))
    {
        Some(origin) => d.note(format!(
            "fxgraph generated this WGSL from {origin}; the shader cannot run as translated"
        )),
        None => d,
    }
}

/// Compile, and when the scripts have errors, check the shaders they name too, so
/// that one report holds every problem of the run (`--set`, script and WGSL).
pub fn compile_all(req: &CompileRequest) -> (Option<Graph>, Diagnostics, SourceMap) {
    let mut r = crate::graph::compile_report(req);
    if r.graph.is_none() {
        let shader_diags = check_references(&r.shaders, &mut r.sources, &[]);
        r.diags.extend(shader_diags);
        r.diags.sort();
    }
    (r.graph, r.diags, r.sources)
}

/// Check the shaders a script names when the script itself has errors (so no plan
/// exists): each is found, preprocessed and validated on its own, so its WGSL
/// errors are reported in the same run as the script's. Bindings against the
/// script are not checked (that needs the compiled graph).
pub fn check_references(
    refs: &[ShaderReference],
    sources: &mut SourceMap,
    extra_dirs: &[PathBuf],
) -> Diagnostics {
    let mut diags = Diagnostics::default();
    let mut files = HashMap::new();
    for r in refs {
        match find_shader(&r.name, r.dir.as_deref(), extra_dirs) {
            Some(file) => {
                load_file(&file, &r.defines, sources, &mut files, &mut diags);
            }
            None => diags.push(missing_shader(&r.name, r.span)),
        }
    }
    diags
}

fn missing_shader(name: &str, span: Span) -> Diagnostic {
    Diagnostic::error(format!("no shader `{name}.wgsl`")).at(
        span,
        "not found next to the effect file, in its shaders/ folder, or in the built-in library",
    )
}

/// A parameter of a pass that `--set PASS.NAME=VALUE` can set: a field of the
/// pass shader's uniform struct that is not a standard value.
#[derive(Debug, Clone)]
pub struct PassParamInfo {
    /// The pass's path (`glow/blurX`).
    pub pass: String,
    /// The pass's own name (`blurX`), what `--set` takes before the dot.
    pub pass_name: String,
    pub name: String,
    pub ty: FieldType,
    /// The value the script (or `--set`) gives it, if any.
    pub set: Option<Value>,
    /// From `// @default(...)`.
    pub default: Option<Value>,
    /// From `// @range(min, max)`.
    pub range: Option<(f64, f64)>,
    /// The text after the annotations of the field's comment.
    pub description: String,
}

/// The settable parameters of every scheduled pass of `graph`, in execution order
/// and the shader's field order. Passes whose shader cannot be found, included,
/// preprocessed or reflected are skipped (`--check` reports them).
pub fn pass_parameters(graph: &Graph, extra_dirs: &[PathBuf]) -> Vec<PassParamInfo> {
    let mut out = Vec::new();
    for &n in &graph.schedule {
        let pn = graph.pass(n);
        let Some(file) = find_shader(&pn.shader, pn.shader_dir.as_deref(), extra_dirs) else {
            continue;
        };
        let mut sources = SourceMap::new();
        let id = sources.add(file.shown.clone(), file.text.clone());
        let assembled;
        let text = if file.text.contains("#include") {
            let origin = match &file.path {
                Some(p) => IncludeOrigin::Disk(p.clone()),
                None => IncludeOrigin::Memory,
            };
            match assemble(id, &file.shown, &file.text, origin, &RealFs, &mut sources) {
                Ok(a) => {
                    assembled = a.text;
                    assembled.as_str()
                }
                Err(_) => continue,
            }
        } else {
            file.text.as_str()
        };
        let Ok((wgsl, _)) = preprocess(text, &pn.defines) else {
            continue;
        };
        let Ok(refl) = reflect(&wgsl, id) else {
            continue;
        };
        let Some(u) = refl.uniform else { continue };
        let inputs: Vec<String> = pn.inputs.iter().map(|i| i.name.clone()).collect();
        let pass_name = pn.path.rsplit('/').next().unwrap_or(&pn.path).to_string();
        for m in u.members {
            if std_value(&m.name, &inputs).is_some() {
                continue;
            }
            out.push(PassParamInfo {
                pass: pn.path.clone(),
                pass_name: pass_name.clone(),
                set: pn
                    .params
                    .iter()
                    .find(|p| p.name == m.name)
                    .map(|p| p.value.clone()),
                name: m.name,
                ty: m.ty,
                default: m.default,
                range: m.range,
                description: m.description,
            });
        }
    }
    out
}
