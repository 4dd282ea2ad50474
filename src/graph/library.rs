//! Finding effect files: paths on disk, `INCLUDE`s, and the embedded library.

use crate::script::ast::{EffectDef, Module};
use crate::script::{parse_module, Diagnostic, Diagnostics, FileId, SourceMap, Span};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

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

/// The embedded text of `shaders/<name>`.
pub fn embedded_shader(file_name: &str) -> Option<&'static str> {
    EMBEDDED_SHADERS
        .iter()
        .find(|(n, _)| *n == file_name)
        .map(|(_, t)| *t)
}

/// The effect a file stands for: the one named like the file, else the last one.
pub fn main_effect<'m>(m: &'m Module, stem: &str) -> Option<&'m EffectDef> {
    m.effects
        .iter()
        .find(|e| e.name.node == stem)
        .or_else(|| m.effects.last())
}

/// Where a loaded file came from.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    Disk(PathBuf),
    Embedded(String),
}

/// Every effect file loaded for one compilation, with includes followed.
#[derive(Debug, Default)]
pub struct Loader {
    pub sources: SourceMap,
    pub modules: Vec<(Origin, Module)>,
    /// Folders searched for `.fx` files before the embedded library (e.g. `./effects`).
    pub search_dirs: Vec<PathBuf>,
    loaded: HashMap<String, usize>,
}

/// Read an effect file given on the command line: a regular file (not a device or a
/// pipe) of at most [`MAX_INCLUDE_BYTES`](crate::shader::include::MAX_INCLUDE_BYTES).
fn read_effect_file(path: &Path) -> std::io::Result<String> {
    use crate::shader::include::MAX_INCLUDE_BYTES;
    use std::io::Read as _;
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    let too_big = || {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("larger than {} KiB", MAX_INCLUDE_BYTES / 1024),
        )
    };
    if meta.len() > MAX_INCLUDE_BYTES {
        return Err(too_big());
    }
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(MAX_INCLUDE_BYTES + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > MAX_INCLUDE_BYTES {
        return Err(too_big());
    }
    Ok(text)
}

impl Loader {
    pub fn new() -> Self {
        Self::default()
    }

    /// Load an effect given on the command line: a path to an `.fx` file, or a
    /// built-in name. Returns the index of its module and the name of its main effect.
    pub fn load_entry(&mut self, arg: &str, diags: &mut Diagnostics) -> Option<(usize, String)> {
        let path = Path::new(arg);
        let as_file = path.extension().is_some_and(|e| e == "fx") || path.components().count() > 1;
        let idx = if as_file || path.is_file() {
            match read_effect_file(path) {
                Ok(text) => self.add_module(
                    Origin::Disk(path.to_path_buf()),
                    arg.to_string(),
                    text,
                    diags,
                ),
                Err(e) => {
                    diags.push(Diagnostic::error(format!(
                        "cannot read effect file `{arg}`: {e}"
                    )));
                    return None;
                }
            }
        } else {
            match self.find_named(arg, diags) {
                Some(i) => i,
                None => {
                    let names: Vec<String> =
                        builtin_effects().into_iter().map(|(n, _)| n).collect();
                    let mut d = Diagnostic::error(format!(
                        "no effect file or built-in effect named `{arg}`"
                    ));
                    if let Some(s) =
                        crate::script::ast::suggest(arg, names.iter().map(|s| s.as_str()))
                    {
                        d = d.note(format!("did you mean `{s}`?"));
                    }
                    diags.push(d.note(format!("built-in effects: {}", names.join(", "))));
                    return None;
                }
            }
        };
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

    /// Load `<name>.fx`: from the search folders (in order), then the current
    /// folder (`./NAME.fx`), then `./effects/NAME.fx`, then the embedded library.
    /// A file on disk named like a built-in effect overrides it (logged).
    fn find_named(&mut self, name: &str, diags: &mut Diagnostics) -> Option<usize> {
        let file = format!("{name}.fx");
        let mut dirs = self.search_dirs.clone();
        dirs.push(PathBuf::from("."));
        dirs.push(PathBuf::from("effects"));
        for dir in dirs {
            let p = dir.join(&file);
            if !p.is_file() {
                continue;
            }
            match read_effect_file(&p) {
                Ok(text) => {
                    let shown = p.display().to_string();
                    if embedded_effect(&file).is_some() {
                        log::info!("{shown} overrides the built-in effect `{name}`");
                    }
                    return Some(self.add_module(Origin::Disk(p), shown, text, diags));
                }
                Err(e) => {
                    diags.push(Diagnostic::error(format!(
                        "cannot read effect file `{}`: {e}",
                        p.display()
                    )));
                    return None;
                }
            }
        }
        let text = embedded_effect(&file)?;
        Some(self.add_module(
            Origin::Embedded(file.clone()),
            format!("<builtin>/effects/{file}"),
            text.to_string(),
            diags,
        ))
    }

    fn add_module(
        &mut self,
        origin: Origin,
        shown: String,
        text: String,
        diags: &mut Diagnostics,
    ) -> usize {
        let key = match &origin {
            Origin::Disk(p) => std::fs::canonicalize(p)
                .unwrap_or(p.clone())
                .display()
                .to_string(),
            Origin::Embedded(n) => format!("<builtin>/{n}"),
        };
        if let Some(&i) = self.loaded.get(&key) {
            return i;
        }
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

    /// `INCLUDE "file.fx"`: a path relative to the including file's folder, confined to
    /// it (no `..`, no absolute path, symbolic links resolved and checked, a regular file
    /// of at most [`MAX_INCLUDE_BYTES`](crate::shader::include::MAX_INCLUDE_BYTES)), or
    /// a file of the built-in library. A refused file is never read.
    fn include(&mut self, from: &Origin, target: &str, span: Span, diags: &mut Diagnostics) {
        use crate::shader::include::{check_relative, read_confined, RealFs};
        let parts = match check_relative(target) {
            Ok(p) => p,
            Err(m) => {
                diags.push(
                    Diagnostic::error(format!("cannot include `{target}`: {m}"))
                        .at(span, "refused; the file is not read"),
                );
                return;
            }
        };
        if let Origin::Disk(p) = from {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            if let Ok(dir_canon) = std::fs::canonicalize(dir) {
                match read_confined(&dir_canon, &parts, &RealFs) {
                    Ok(Some((canon, text))) => {
                        let shown = dir
                            .join(parts.iter().collect::<PathBuf>())
                            .display()
                            .to_string();
                        self.add_module(Origin::Disk(canon), shown, text, diags);
                        return;
                    }
                    Ok(None) => {}
                    Err(m) => {
                        diags.push(
                            Diagnostic::error(format!(
                                "cannot include `{target}`: {}",
                                m.replace("{path}", target)
                            ))
                            .at(span, "refused; the file is not read"),
                        );
                        return;
                    }
                }
            }
        }
        let file = Path::new(target)
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or(target);
        if let Some(text) = embedded_effect(file) {
            self.add_module(
                Origin::Embedded(file.to_string()),
                format!("<builtin>/effects/{file}"),
                text.to_string(),
                diags,
            );
            return;
        }
        diags.push(
            Diagnostic::error(format!("cannot find included file `{target}`")).at(
                span,
                "no such file next to this one, nor in the built-in library",
            ),
        );
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
