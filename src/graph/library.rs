//! The embedded library, and loading a compilation's effect files (with their
//! `INCLUDE`s) from an [`EffectSource`].

pub use super::source::{Builtins, EffectSource, Found, IncludeError, Origin};
use crate::script::ast::{EffectDef, Module};
use crate::script::{parse_module, Diagnostic, Diagnostics, FileId, SourceMap, Span};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

include!(concat!(env!("OUT_DIR"), "/embedded.rs"));

/// The built-in effects: (name, one-line description).
pub fn builtin_effects() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (file, text) in EMBEDDED_EFFECTS {
        let mut sources = SourceMap::new();
        let id = sources.add(*file, *text);
        let mut diags = Diagnostics::default();
        let m = parse_module(&sources, id, &mut diags);
        let stem = file.trim_end_matches(".fx");
        if let Some(e) = main_effect(&m, stem) {
            // An effect without a DESCRIPTION (the seed's glow is kept verbatim) is
            // described by its shaders.
            let desc = match &e.description {
                Some(d) => first_line(d),
                None => {
                    let shaders: Vec<String> = e
                        .passes
                        .iter()
                        .map(|p| match &p.kind {
                            crate::script::ast::PassKind::Shader(s)
                            | crate::script::ast::PassKind::Effect(s) => s.node.clone(),
                        })
                        .collect();
                    format!("passes: {}", shaders.join(" -> "))
                }
            };
            out.push((e.name.node.clone(), desc));
        }
    }
    out.sort();
    out
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_string()
}

/// The embedded text of `effects/<name>`.
pub fn embedded_effect(file_name: &str) -> Option<&'static str> {
    EMBEDDED_EFFECTS
        .iter()
        .find(|(n, _)| *n == file_name)
        .map(|(_, t)| *t)
}

/// The embedded pass shader named `file_name` (`blurX.wgsl`): its path under
/// `shaders/` (`effects/glow/blurX.wgsl`) and its text.
pub fn embedded_shader(file_name: &str) -> Option<(&'static str, &'static str)> {
    EMBEDDED_SHADERS
        .iter()
        .find(|(n, _, _)| *n == file_name)
        .map(|(_, rel, t)| (*rel, *t))
}

/// A file of the shared WGSL library by its path under `shaders/`
/// (`lib/brdf.wgsl`).
pub fn embedded_library_file(rel: &str) -> Option<&'static str> {
    EMBEDDED_SHADER_LIBRARY
        .iter()
        .find(|(n, _)| *n == rel)
        .map(|(_, t)| *t)
}

/// The effect a file stands for: the one named like the file, else the last one.
pub fn main_effect<'m>(m: &'m Module, stem: &str) -> Option<&'m EffectDef> {
    m.effects
        .iter()
        .find(|e| e.name.node == stem)
        .or_else(|| m.effects.last())
}

/// Every effect file loaded for one compilation, with includes followed. Files
/// come from an [`EffectSource`]; the loader reads none itself.
#[derive(Debug)]
pub struct Loader {
    pub sources: SourceMap,
    pub modules: Vec<(Origin, Module)>,
    source: Arc<dyn EffectSource>,
    loaded: HashMap<String, usize>,
}

impl Loader {
    pub fn new(source: Arc<dyn EffectSource>) -> Self {
        Loader {
            sources: SourceMap::new(),
            modules: Vec::new(),
            source,
            loaded: HashMap::new(),
        }
    }

    /// Load an effect given on the command line: a path to an `.fx` file, or a
    /// built-in name. Returns the index of its module and the name of its main effect.
    pub fn load_entry(&mut self, arg: &str, diags: &mut Diagnostics) -> Option<(usize, String)> {
        let found = match self.source.entry(arg) {
            Ok(Some(f)) => f,
            Ok(None) => {
                let names: Vec<String> = builtin_effects().into_iter().map(|(n, _)| n).collect();
                let mut d =
                    Diagnostic::error(format!("no effect file or built-in effect named `{arg}`"));
                if let Some(s) = crate::script::ast::suggest(arg, names.iter().map(|s| s.as_str()))
                {
                    d = d.note(format!("did you mean `{s}`?"));
                }
                diags.push(d.note(format!("built-in effects: {}", names.join(", "))));
                return None;
            }
            Err(e) => {
                diags.push(Diagnostic::error(format!(
                    "cannot read effect file `{arg}`: {e}"
                )));
                return None;
            }
        };
        let idx = self.add_module(found, diags);
        let path = Path::new(arg);
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(arg)
            .to_string();
        let name = main_effect(&self.modules[idx].1, &stem).map(|e| e.name.node.clone());
        match name {
            Some(n) => Some((idx, n)),
            None => {
                diags.push(Diagnostic::error(format!("`{arg}` defines no effect")));
                None
            }
        }
    }

    /// Load `<name>.fx` through the source (a file on disk named like a built-in
    /// effect may override it, as the source decides).
    fn find_named(&mut self, name: &str, diags: &mut Diagnostics) -> Option<usize> {
        match self.source.named(name) {
            Ok(Some(found)) => Some(self.add_module(found, diags)),
            Ok(None) => None,
            Err(e) => {
                diags.push(Diagnostic::error(format!(
                    "cannot read effect file `{name}.fx`: {e}"
                )));
                None
            }
        }
    }

    fn add_module(&mut self, found: Found, diags: &mut Diagnostics) -> usize {
        if let Some(&i) = self.loaded.get(&found.key) {
            return i;
        }
        let Found {
            origin,
            shown,
            text,
            key,
        } = found;
        let id = match &origin {
            Origin::Disk(p) => self.sources.add_disk(shown, text, p),
            Origin::Embedded(_) => self.sources.add(shown, text),
        };
        let module = parse_module(&self.sources, id, diags);
        let idx = self.modules.len();
        self.loaded.insert(key, idx);
        let includes = module.includes.clone();
        self.modules.push((origin.clone(), module));
        for inc in includes {
            self.include(&origin, &inc.node, inc.span, diags);
        }
        idx
    }

    /// `INCLUDE "file.fx"`, served (or refused) by the source.
    fn include(&mut self, from: &Origin, target: &str, span: Span, diags: &mut Diagnostics) {
        match self.source.include(from, target) {
            Ok(found) => {
                self.add_module(found, diags);
            }
            Err(IncludeError::Refused(m)) => diags.push(
                Diagnostic::error(format!("cannot include `{target}`: {m}"))
                    .at(span, "refused; the file is not read"),
            ),
            Err(IncludeError::NotFound) => diags.push(
                Diagnostic::error(format!("cannot find included file `{target}`")).at(
                    span,
                    "no such file next to this one, nor in the built-in library",
                ),
            ),
        }
    }

    /// Find an effect by name among the loaded modules, then in the library.
    pub fn effect(&mut self, name: &str, diags: &mut Diagnostics) -> Option<(usize, usize)> {
        if let Some(found) = self.find_loaded(name) {
            return Some(found);
        }
        let mut scratch = Diagnostics::default();
        self.find_named(name, &mut scratch)?;
        diags.extend(scratch);
        self.find_loaded(name)
    }

    fn find_loaded(&self, name: &str) -> Option<(usize, usize)> {
        self.modules.iter().enumerate().find_map(|(mi, (_, m))| {
            m.effects
                .iter()
                .position(|e| e.name.node == name)
                .map(|ei| (mi, ei))
        })
    }

    pub fn effect_def(&self, at: (usize, usize)) -> &EffectDef {
        &self.modules[at.0].1.effects[at.1]
    }

    pub fn file_of(&self, module: usize) -> FileId {
        self.modules[module].1.file
    }

    /// The folder a module was read from (for finding its shaders).
    pub fn module_dir(&self, module: usize) -> Option<PathBuf> {
        match &self.modules[module].0 {
            Origin::Disk(p) => Some(p.parent().unwrap_or(Path::new(".")).to_path_buf()),
            Origin::Embedded(_) => None,
        }
    }
}
