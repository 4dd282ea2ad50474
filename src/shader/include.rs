//! `#include "path.wgsl"` for material shaders.
//!
//! WGSL module-scope declarations may appear in any order, so an include does not
//! paste text in place: the directive is blanked (its bytes become spaces) and the
//! included file is appended after the including text, once per file (include-once
//! by canonical path; nested includes are followed). Every byte of the user's file
//! therefore keeps its offset, line and column, and a [segment table](Assembly)
//! maps any range of the assembled text back to the file it came from.
//!
//! Where an include may read from:
//! - `#include "x.wgsl"`, `#include "sub/x.wgsl"`: relative to the including file's
//!   folder, and only under it: absolute paths and `..` are refused, symlinks are
//!   resolved and the target must still lie under that folder, and the target must
//!   be a regular file of at most 1 MiB. A refused file is never read.
//! - `#include "lib/NAME.wgsl"`: the including folder first (a file on disk
//!   overrides the library), then the built-in library `shaders/lib/`.
//! - Files of the built-in library (and in-memory files) include from the built-in
//!   tree only.
//!
//! Includes are unconditional: they are resolved before the `#ifdef` preprocessor.

use crate::script::{Diagnostic, FileId, SourceMap, Span};
use crate::shader::preprocess::lines_with_offsets;
use std::collections::HashSet;
use std::path::{Component, Path, PathBuf};

/// The largest file an include may read.
pub const MAX_INCLUDE_BYTES: u64 = 1 << 20;

/// How the assembler reaches files: the real file system ([`RealFs`]) or, in tests,
/// an in-memory one.
pub trait IncludeFs {
    /// The canonical form of `path` (symlinks resolved); an error if it does not exist.
    fn canonicalize(&self, path: &Path) -> std::io::Result<PathBuf>;
    /// Whether a canonical path is a regular file, and its length in bytes.
    fn file_info(&self, path: &Path) -> std::io::Result<(bool, u64)>;
    /// Read a canonical path that passed the checks.
    fn read(&self, path: &Path) -> std::io::Result<String>;
    /// A file of the built-in library (`shaders/lib/`), by its path relative to
    /// `shaders/` (`"lib/brdf.wgsl"`).
    fn builtin(&self, rel: &str) -> Option<String> {
        crate::graph::library::embedded_library_file(rel).map(str::to_string)
    }
}

/// The file system of the machine.
#[derive(Debug, Clone, Copy, Default)]
pub struct RealFs;

impl IncludeFs for RealFs {
    fn canonicalize(&self, path: &Path) -> std::io::Result<PathBuf> {
        std::fs::canonicalize(path)
    }
    fn file_info(&self, path: &Path) -> std::io::Result<(bool, u64)> {
        let m = std::fs::metadata(path)?;
        Ok((m.is_file(), m.len()))
    }
    fn read(&self, path: &Path) -> std::io::Result<String> {
        std::fs::read_to_string(path)
    }
}

/// Where a file of an assembly lives; decides where its includes are looked up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum IncludeOrigin {
    /// A file on disk (its path; made canonical by the assembler).
    Disk(PathBuf),
    /// A built-in file: a material shader by its name (`"standard.wgsl"`) or a
    /// library file by its path under `shaders/` (`"lib/brdf.wgsl"`).
    Builtin(String),
    /// Text with no folder (tests, generated text): includes come from the
    /// built-in tree's top folder.
    Memory,
}

/// One file of an assembly.
#[derive(Debug, Clone)]
pub struct AssembledFile {
    /// How the file is named in messages.
    pub shown: String,
    /// Its id in the [`SourceMap`] the assembly was made with.
    pub id: FileId,
    pub origin: IncludeOrigin,
}

/// A byte range `start..end` of the assembled text that is the text of `file`
/// from byte `file_offset` on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Segment {
    pub start: usize,
    pub end: usize,
    pub file: FileId,
    pub file_offset: usize,
}

/// A file with its includes appended, and where every part came from.
#[derive(Debug, Clone, Default)]
pub struct Assembly {
    /// The including file (directives blanked), then each included file.
    pub text: String,
    /// Ordered, non-overlapping; bytes in no segment are separators.
    pub segments: Vec<Segment>,
    /// The root file first, then the included files in the order they were appended.
    pub files: Vec<AssembledFile>,
}

impl Assembly {
    /// The file and file offset of a byte of the assembled text.
    pub fn locate(&self, offset: usize) -> Option<(FileId, usize)> {
        let i = self.segments.partition_point(|s| s.end <= offset);
        let s = self.segments.get(i)?;
        (s.start <= offset && offset < s.end || offset == s.end && i + 1 == self.segments.len())
            .then(|| (s.file, s.file_offset + offset - s.start))
    }

    /// A range of the assembled text as a span of the file it lies in (the end is
    /// clipped to that file's segment).
    pub fn map_span(&self, start: usize, end: usize) -> Option<Span> {
        let i = self.segments.partition_point(|s| s.end <= start);
        let s = self.segments.get(i).or_else(|| self.segments.last())?;
        if start < s.start || start > s.end {
            return None;
        }
        let end = end.clamp(start, s.end);
        Some(Span::new(
            s.file,
            s.file_offset + start - s.start,
            s.file_offset + end - s.start,
        ))
    }

    /// Append one more file as is (no include processing), e.g. the engine's
    /// interface declarations, registering it in `sources`.
    pub fn push_file(&mut self, shown: &str, text: &str, sources: &mut SourceMap) -> FileId {
        let id = sources.add(shown.to_string(), text.to_string());
        self.push_text(id, text);
        self.files.push(AssembledFile {
            shown: shown.to_string(),
            id,
            origin: IncludeOrigin::Memory,
        });
        id
    }

    fn push_text(&mut self, file: FileId, text: &str) {
        if !self.text.is_empty() && !self.text.ends_with('\n') {
            self.text.push('\n');
        }
        let start = self.text.len();
        self.text.push_str(text);
        self.segments.push(Segment {
            start,
            end: self.text.len(),
            file,
            file_offset: 0,
        });
    }
}

/// An `#include "..."` directive found on a line.
struct Directive {
    /// Byte range of the directive (from `#` to the end of the code on the line).
    start: usize,
    end: usize,
    /// The quoted path, or an error message for a malformed directive.
    path: Result<String, String>,
}

/// Every `#include` line of `text`.
fn directives(text: &str) -> Vec<Directive> {
    let mut out = Vec::new();
    for (line_start, line) in lines_with_offsets(text) {
        let body = line.trim_end_matches(['\n', '\r']);
        let t = body.trim_start();
        let Some(rest) = t.strip_prefix("#include") else {
            continue;
        };
        if rest.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_') {
            continue; // `#includes`: not ours (the preprocessor reports it)
        }
        let start = line_start + (body.len() - t.len());
        let code_len = t.find("//").unwrap_or(t.len());
        let end = start + t[..code_len].trim_end().len();
        let arg = rest[..code_len - "#include".len()].trim();
        let path = match arg
            .strip_prefix('"')
            .and_then(|r| r.strip_suffix('"'))
            .filter(|p| !p.contains('"'))
        {
            Some(p) if !p.is_empty() => Ok(p.to_string()),
            _ => Err(format!(
                "expected `#include \"relative/path.wgsl\"`, found `{}`",
                t[..code_len].trim_end()
            )),
        };
        out.push(Directive { start, end, path });
    }
    out
}

/// `text` with every `#include` directive replaced by spaces (same length).
fn blank_directives(text: &str, dirs: &[Directive]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for d in dirs {
        bytes[d.start..d.end].fill(b' ');
    }
    // Only whole directives (ASCII `#include`, quotes and whatever lies between on
    // one line) were replaced, so the text stays UTF-8 where it was; a multi-byte
    // character inside a path becomes spaces entirely.
    String::from_utf8(bytes).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into())
}

/// Why an include path is refused before anything is looked up, if it is.
pub(crate) fn check_relative(path: &str) -> Result<Vec<String>, String> {
    if path.contains('\0') {
        return Err("an include path may not contain NUL".into());
    }
    if path.starts_with('/') || path.starts_with('\\') || path.contains(':') {
        return Err(
            "absolute include paths are not allowed: write a path relative to this file's folder"
                .into(),
        );
    }
    if path.contains('\\') {
        return Err("write include paths with `/`".into());
    }
    let mut parts = Vec::new();
    for c in Path::new(path).components() {
        match c {
            Component::Normal(p) => parts.push(p.to_string_lossy().into_owned()),
            Component::CurDir => {}
            Component::ParentDir => {
                return Err("`..` is not allowed in include paths: an include may only read files under the including file's folder".into())
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err("absolute include paths are not allowed".into())
            }
        }
    }
    if parts.is_empty() {
        return Err("empty include path".into());
    }
    Ok(parts)
}

/// The folder part of a path in the built-in tree (`"lib/brdf.wgsl"` → `"lib"`).
fn builtin_dir(rel: &str) -> &str {
    rel.rfind('/').map(|i| &rel[..i]).unwrap_or("")
}

/// Read `dir/parts...` where `dir` is canonical, confined to `dir`: symlinks are
/// resolved and the target must lie under `dir`, be a regular file and at most
/// [`MAX_INCLUDE_BYTES`] long. `Ok(None)`: no such file. Messages name the file
/// `{path}` (for the caller to fill in); a refused file is never read.
pub(crate) fn read_confined(
    dir: &Path,
    parts: &[String],
    fs: &dyn IncludeFs,
) -> Result<Option<(PathBuf, String)>, String> {
    let candidate = dir.join(parts.iter().collect::<PathBuf>());
    let Ok(canon) = fs.canonicalize(&candidate) else {
        return Ok(None);
    };
    if !canon.starts_with(dir) {
        return Err(
            "`{path}` resolves (through a symbolic link) to a file outside the including file's folder"
                .into(),
        );
    }
    let too_big = || format!("`{{path}}` is larger than {} KiB", MAX_INCLUDE_BYTES / 1024);
    let (regular, len) = fs
        .file_info(&canon)
        .map_err(|e| format!("cannot read `{{path}}`: {e}"))?;
    if !regular {
        return Err("`{path}` is not a regular file".into());
    }
    if len > MAX_INCLUDE_BYTES {
        return Err(too_big());
    }
    let text = fs
        .read(&canon)
        .map_err(|e| format!("cannot read `{{path}}`: {e}"))?;
    if text.len() as u64 > MAX_INCLUDE_BYTES {
        return Err(too_big());
    }
    Ok(Some((canon, text)))
}

/// What an include resolved to.
struct Resolved {
    key: String,
    shown: String,
    text: String,
    origin: IncludeOrigin,
}

fn resolve(
    from: &IncludeOrigin,
    from_dir_canon: Option<&Path>,
    path: &str,
    fs: &dyn IncludeFs,
) -> Result<Resolved, String> {
    let parts = check_relative(path)?;
    let rel = parts.join("/");
    if let (IncludeOrigin::Disk(_), Some(dir)) = (from, from_dir_canon) {
        match read_confined(dir, &parts, fs) {
            Ok(Some((canon, text))) => {
                return Ok(Resolved {
                    key: canon.display().to_string(),
                    shown: dir
                        .join(parts.iter().collect::<PathBuf>())
                        .display()
                        .to_string(),
                    text,
                    origin: IncludeOrigin::Disk(canon),
                })
            }
            Ok(None) if rel.starts_with("lib/") => {} // the built-in library below
            Ok(None) => {
                return Err(format!(
                    "cannot find included file `{path}` in this file's folder"
                ))
            }
            Err(e) => return Err(e.replace("{path}", path)),
        }
    }
    let full = match from {
        IncludeOrigin::Disk(_) | IncludeOrigin::Memory => rel.clone(),
        IncludeOrigin::Builtin(me) => match builtin_dir(me) {
            "" => rel.clone(),
            d => format!("{d}/{rel}"),
        },
    };
    match fs.builtin(&full) {
        Some(text) => Ok(Resolved {
            key: format!("<builtin>/{full}"),
            shown: format!("<builtin>/shaders/{full}"),
            text,
            origin: IncludeOrigin::Builtin(full),
        }),
        None if matches!(from, IncludeOrigin::Disk(_)) => Err(format!(
            "cannot find included file `{path}` in this file's folder nor in the built-in library"
        )),
        None => Err(format!(
            "cannot find included file `{path}` in the built-in library"
        )),
    }
}

/// Assemble `text` (named `shown`, registered in `sources` as `root_id`) with its
/// includes. Included files are registered in `sources` as they are read; errors
/// point at the directive that failed.
pub fn assemble(
    root_id: FileId,
    shown: &str,
    text: &str,
    origin: IncludeOrigin,
    fs: &dyn IncludeFs,
    sources: &mut SourceMap,
) -> Result<Assembly, Vec<Diagnostic>> {
    let mut asm = Assembly::default();
    let mut diags = Vec::new();
    let mut seen: HashSet<String> = HashSet::new();
    let origin = match origin {
        IncludeOrigin::Disk(p) => match fs.canonicalize(&p) {
            Ok(c) => IncludeOrigin::Disk(c),
            Err(_) => IncludeOrigin::Disk(p),
        },
        o => o,
    };
    match &origin {
        IncludeOrigin::Disk(p) => seen.insert(p.display().to_string()),
        IncludeOrigin::Builtin(n) => seen.insert(format!("<builtin>/{n}")),
        IncludeOrigin::Memory => false,
    };
    // Depth-first, in directive order: a queue of files whose text is still to be
    // appended would change the order of appearance, which does not matter to WGSL
    // but would make the assembled text harder to read.
    let mut stack: Vec<(FileId, String, IncludeOrigin, String)> =
        vec![(root_id, shown.to_string(), origin, text.to_string())];
    while let Some((id, shown, origin, text)) = stack.pop() {
        let dirs = directives(&text);
        asm.push_text(id, &blank_directives(&text, &dirs));
        asm.files.push(AssembledFile {
            shown,
            id,
            origin: origin.clone(),
        });
        let dir_canon = match &origin {
            IncludeOrigin::Disk(p) => p.parent().map(Path::to_path_buf),
            _ => None,
        };
        let mut children = Vec::new();
        for d in &dirs {
            let span = Span::new(id, d.start, d.end);
            let path = match &d.path {
                Ok(p) => p,
                Err(msg) => {
                    diags.push(Diagnostic::error(msg.clone()).at(span, "malformed `#include`"));
                    continue;
                }
            };
            match resolve(&origin, dir_canon.as_deref(), path, fs) {
                Ok(r) => {
                    if seen.insert(r.key.clone()) {
                        let cid = match &r.origin {
                            IncludeOrigin::Disk(p) => {
                                sources.add_disk(r.shown.clone(), r.text.clone(), p)
                            }
                            _ => sources.add(r.shown.clone(), r.text.clone()),
                        };
                        children.push((cid, r.shown, r.origin, r.text));
                    }
                }
                Err(msg) => diags.push(Diagnostic::error(msg).at(span, "included here")),
            }
        }
        // Reverse so the first directive's file is appended first.
        stack.extend(children.into_iter().rev());
    }
    if diags.is_empty() {
        Ok(asm)
    } else {
        Err(diags)
    }
}

/// Maps byte offsets of a text derived line by line from another one (the
/// preprocessor and the feature conversion keep every line: a line is kept
/// verbatim, emptied, or a directive line replaced) back to the original.
#[derive(Debug, Clone)]
pub struct LineMap {
    derived_starts: Vec<usize>,
    original_starts: Vec<usize>,
    original_len: usize,
}

impl LineMap {
    pub fn new(derived: &str, original: &str) -> Self {
        let starts = |t: &str| {
            let mut v = vec![0];
            v.extend(t.match_indices('\n').map(|(i, _)| i + 1));
            v
        };
        LineMap {
            derived_starts: starts(derived),
            original_starts: starts(original),
            original_len: original.len(),
        }
    }

    /// The original offset of a derived offset; `None` past the original's lines
    /// (text appended by the derivation).
    pub fn map(&self, offset: usize) -> Option<usize> {
        let line = self.derived_starts.partition_point(|&s| s <= offset) - 1;
        let col = offset - self.derived_starts[line];
        let start = *self.original_starts.get(line)?;
        let line_end = self
            .original_starts
            .get(line + 1)
            .map(|&n| n - 1)
            .unwrap_or(self.original_len);
        if line + 1 == self.original_starts.len() && start == self.original_len && col > 0 {
            return None; // the original ends with a newline; this is appended text
        }
        Some((start + col).min(line_end))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::cell::RefCell;
    use std::collections::HashMap;

    /// An in-memory file system: canonical paths are the normalised paths; a
    /// symlink table maps a path to its target. Every read is recorded.
    #[derive(Default)]
    pub(crate) struct MemFs {
        pub files: HashMap<PathBuf, String>,
        pub links: HashMap<PathBuf, PathBuf>,
        pub reads: RefCell<Vec<PathBuf>>,
        pub builtin: HashMap<String, String>,
    }

    impl MemFs {
        pub fn file(mut self, p: &str, text: &str) -> Self {
            self.files.insert(PathBuf::from(p), text.to_string());
            self
        }
        fn normal(&self, p: &Path) -> PathBuf {
            let mut out = PathBuf::new();
            for c in p.components() {
                match c {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    c => out.push(c),
                }
                if let Some(t) = self.links.get(&out) {
                    out = t.clone();
                }
            }
            out
        }
    }

    impl IncludeFs for MemFs {
        fn canonicalize(&self, path: &Path) -> std::io::Result<PathBuf> {
            let n = self.normal(path);
            if self.files.contains_key(&n) || self.files.keys().any(|k| k.starts_with(&n)) {
                Ok(n)
            } else {
                Err(std::io::Error::new(std::io::ErrorKind::NotFound, "no file"))
            }
        }
        fn file_info(&self, path: &Path) -> std::io::Result<(bool, u64)> {
            match self.files.get(path) {
                Some(t) => Ok((true, t.len() as u64)),
                None => Ok((false, 0)),
            }
        }
        fn read(&self, path: &Path) -> std::io::Result<String> {
            self.reads.borrow_mut().push(path.to_path_buf());
            self.files
                .get(path)
                .cloned()
                .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no file"))
        }
        fn builtin(&self, rel: &str) -> Option<String> {
            self.builtin
                .get(rel)
                .cloned()
                .or_else(|| crate::graph::library::embedded_library_file(rel).map(str::to_string))
        }
    }

    fn run(fs: &MemFs, root: &str) -> (Result<Assembly, Vec<Diagnostic>>, SourceMap) {
        let mut sources = SourceMap::new();
        let text = fs.files[Path::new(root)].clone();
        let id = sources.add(root, text.clone());
        let r = assemble(
            id,
            root,
            &text,
            IncludeOrigin::Disk(PathBuf::from(root)),
            fs,
            &mut sources,
        );
        (r, sources)
    }

    fn rendered(r: Result<Assembly, Vec<Diagnostic>>, sources: &SourceMap) -> String {
        r.expect_err("an error")
            .iter()
            .map(|d| d.render(sources))
            .collect()
    }

    #[test]
    fn nested_and_once() {
        let fs = MemFs::default()
            .file(
                "/m/a.wgsl",
                "#include \"sub/b.wgsl\"\nfn a() {}\n  #include \"c.wgsl\" // again\n",
            )
            .file("/m/sub/b.wgsl", "#include \"d.wgsl\"\nfn b() {}\n")
            .file("/m/sub/d.wgsl", "fn d() {}\n#include \"d.wgsl\"\n")
            .file("/m/c.wgsl", "#include \"sub/b.wgsl\"\nfn c() {}");
        let (r, sources) = run(&fs, "/m/a.wgsl");
        let asm = r.unwrap();
        let names: Vec<&str> = asm.files.iter().map(|f| f.shown.as_str()).collect();
        assert_eq!(
            names,
            ["/m/a.wgsl", "/m/sub/b.wgsl", "/m/sub/d.wgsl", "/m/c.wgsl"]
        );
        // The root keeps every byte offset; directives are blank.
        assert!(asm
            .text
            .starts_with("                     \nfn a() {}\n                    // again\n"));
        assert_eq!(asm.text.matches("fn b()").count(), 1);
        assert_eq!(asm.text.matches("fn d()").count(), 1);
        // Spans map back into the included files.
        let at = asm.text.find("fn c()").unwrap();
        let sp = asm.map_span(at + 3, at + 4).unwrap();
        assert_eq!(sources.location(sp), "/m/c.wgsl:2:4");
        assert_eq!(sources.text(sp), "c");
        let at = asm.text.find("fn d()").unwrap();
        assert_eq!(
            sources.location(asm.map_span(at, at + 2).unwrap()),
            "/m/sub/d.wgsl:1:1"
        );
    }

    #[test]
    fn missing_file_at_directive() {
        let fs = MemFs::default().file("/m/a.wgsl", "fn a() {}\n   #include \"nope.wgsl\"\n");
        let (r, sources) = run(&fs, "/m/a.wgsl");
        assert_eq!(
            rendered(r, &sources),
            "/m/a.wgsl:2:4: error: cannot find included file `nope.wgsl` in this file's folder\n  |\n2 |    #include \"nope.wgsl\"\n  |    ^^^^^^^^^^^^^^^^^^^^ included here\n"
        );
    }

    #[test]
    fn escapes_refused_without_reading() {
        let fs = MemFs::default()
            .file(
                "/m/a.wgsl",
                "#include \"../secret.wgsl\"\n#include \"/etc/secret.wgsl\"\n#include \"link/x.wgsl\"\n#include \"./sub/../../secret.wgsl\"\n#include <x.wgsl>\n",
            )
            .file("/secret.wgsl", "TOP SECRET")
            .file("/etc/secret.wgsl", "TOP SECRET")
            .file("/elsewhere/x.wgsl", "TOP SECRET");
        let mut fs = fs;
        fs.links
            .insert(PathBuf::from("/m/link"), PathBuf::from("/elsewhere"));
        let (r, sources) = run(&fs, "/m/a.wgsl");
        let text = rendered(r, &sources);
        assert!(!text.contains("TOP SECRET"));
        assert!(!text.contains("/elsewhere"));
        assert_eq!(text.matches("error:").count(), 5, "{text}");
        assert!(text.contains("a.wgsl:1:1: error: `..` is not allowed"));
        assert!(text.contains("a.wgsl:2:1: error: absolute include paths are not allowed"));
        assert!(text.contains(
            "a.wgsl:3:1: error: `link/x.wgsl` resolves (through a symbolic link) to a file outside"
        ));
        assert!(text.contains("a.wgsl:4:1: error: `..` is not allowed"));
        assert!(text.contains("a.wgsl:5:1: error: expected `#include \"relative/path.wgsl\"`"));
        assert!(fs.reads.borrow().is_empty(), "{:?}", fs.reads.borrow());
    }

    #[test]
    fn library_fallback_and_builtin_relative() {
        let mut fs = MemFs::default().file("/m/a.wgsl", "#include \"lib/x.wgsl\"\n");
        fs.builtin.insert(
            "lib/x.wgsl".into(),
            "#include \"y.wgsl\"\nfn x() {}\n".into(),
        );
        fs.builtin.insert("lib/y.wgsl".into(), "fn y() {}\n".into());
        let (r, _) = run(&fs, "/m/a.wgsl");
        let asm = r.unwrap();
        let names: Vec<&str> = asm.files.iter().map(|f| f.shown.as_str()).collect();
        assert_eq!(
            names,
            [
                "/m/a.wgsl",
                "<builtin>/shaders/lib/x.wgsl",
                "<builtin>/shaders/lib/y.wgsl"
            ]
        );
        // A file on disk overrides the library.
        let fs = fs.file("/m/lib/x.wgsl", "fn mine() {}\n");
        let (r, _) = run(&fs, "/m/a.wgsl");
        assert!(r.unwrap().text.contains("fn mine()"));
    }

    #[test]
    fn real_symlink_escape_refused() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("mats");
        let outside = dir.path().join("outside");
        std::fs::create_dir_all(&root).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(outside.join("s.wgsl"), "SECRET").unwrap();
        std::fs::write(root.join("ok.wgsl"), "fn ok() {}\n").unwrap();
        let main = "#include \"ok.wgsl\"\n#include \"esc.wgsl\"\n#include \"dir\"\n";
        std::fs::write(root.join("a.wgsl"), main).unwrap();
        std::fs::create_dir_all(root.join("dir")).unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(outside.join("s.wgsl"), root.join("esc.wgsl")).unwrap();
        let mut sources = SourceMap::new();
        let id = sources.add("a.wgsl", main);
        let r = assemble(
            id,
            "a.wgsl",
            main,
            IncludeOrigin::Disk(root.join("a.wgsl")),
            &RealFs,
            &mut sources,
        );
        let text = rendered(r, &sources);
        assert!(!text.contains("SECRET"));
        #[cfg(unix)]
        assert!(text.contains("a.wgsl:2:1: error: `esc.wgsl` resolves (through a symbolic link)"));
        assert!(text.contains("a.wgsl:3:1: error: `dir` is not a regular file"));
    }

    #[test]
    fn line_map() {
        let orig = "a\n#ifdef X\nbcd\n#endif\n";
        let derived = "a\n\nbcd\n\nconst X = 1;\n";
        let m = LineMap::new(derived, orig);
        assert_eq!(m.map(derived.find("cd").unwrap()), orig.find("cd"));
        assert_eq!(m.map(derived.find("const").unwrap() + 2), None);
        assert_eq!(m.map(0), Some(0));
    }
}
