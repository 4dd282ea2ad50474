//! Source files, spans and diagnostics rendered as `path:line:col: severity: message`
//! followed by the source line and a caret under the span (rustc/naga style).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Index of a file in a [`SourceMap`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default, serde::Serialize)]
pub struct FileId(pub u32);

/// A byte range in one source file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Self {
        Span {
            file,
            start: start as u32,
            end: end as u32,
        }
    }
    /// The smallest span covering both (same file assumed).
    pub fn to(self, other: Span) -> Span {
        Span {
            file: self.file,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
}

/// A value with the span of the text it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Spanned<T> {
    pub node: T,
    pub span: Span,
}

impl<T> Spanned<T> {
    pub fn new(node: T, span: Span) -> Self {
        Spanned { node, span }
    }
}

/// One loaded source file (an `.fx` script or a `.wgsl` shader).
#[derive(Debug, Clone)]
pub struct SourceFile {
    pub name: String,
    pub text: Arc<str>,
    /// The file on disk it was read from (None: built-in, `--set`, generated text).
    pub path: Option<PathBuf>,
    line_starts: Vec<usize>,
}

impl SourceFile {
    fn new(name: String, text: Arc<str>, path: Option<PathBuf>) -> Self {
        let mut line_starts = vec![0];
        line_starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        SourceFile {
            name,
            text,
            path,
            line_starts,
        }
    }

    /// 0-based line index and 1-based column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = floor_char_boundary(&self.text, offset);
        let line = match self.line_starts.binary_search(&offset) {
            Ok(l) => l,
            Err(l) => l - 1,
        };
        let start = self.line_starts[line];
        let col = self.text[start..offset].chars().count() + 1;
        (line, col)
    }

    /// The text of a 0-based line, without its line break.
    pub fn line_text(&self, line: usize) -> &str {
        let start = self.line_starts[line];
        let end = self
            .line_starts
            .get(line + 1)
            .copied()
            .unwrap_or(self.text.len());
        self.text[start..end].trim_end_matches(['\n', '\r'])
    }
}

/// The largest character boundary of `text` at or before `offset` (clamped to the
/// text's length).
fn floor_char_boundary(text: &str, offset: usize) -> usize {
    let mut o = offset.min(text.len());
    while !text.is_char_boundary(o) {
        o -= 1;
    }
    o
}

/// All source files of one compilation, so spans can be rendered.
#[derive(Debug, Default, Clone)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn add(&mut self, name: impl Into<String>, text: impl Into<Arc<str>>) -> FileId {
        let id = FileId(self.files.len() as u32);
        self.files
            .push(SourceFile::new(name.into(), text.into(), None));
        id
    }

    /// [`SourceMap::add`] for a file read from `path` on disk (see [`SourceMap::disk_paths`]).
    pub fn add_disk(
        &mut self,
        name: impl Into<String>,
        text: impl Into<Arc<str>>,
        path: &Path,
    ) -> FileId {
        let id = FileId(self.files.len() as u32);
        self.files.push(SourceFile::new(
            name.into(),
            text.into(),
            Some(path.to_path_buf()),
        ));
        id
    }

    /// The files on disk that were read (effect files, `INCLUDE`s, shaders and their
    /// `#include`s), each once, in the order they were read; built-in files are not
    /// among them. `fxrun --watch` watches these.
    pub fn disk_paths(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = Vec::new();
        for p in self.files.iter().filter_map(|f| f.path.as_ref()) {
            if !out.contains(p) {
                out.push(p.clone());
            }
        }
        out
    }

    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }

    pub fn find(&self, name: &str) -> Option<FileId> {
        self.files
            .iter()
            .position(|f| f.name == name)
            .map(|i| FileId(i as u32))
    }

    pub fn text(&self, span: Span) -> &str {
        let f = self.get(span.file);
        // A span from another tool (naga) may end inside a character: whole
        // characters are shown.
        let s = floor_char_boundary(&f.text, span.start as usize);
        let e = floor_char_boundary(&f.text, (span.end as usize).max(s));
        &f.text[s..e]
    }

    /// `path:line:col` of the start of a span.
    pub fn location(&self, span: Span) -> String {
        let f = self.get(span.file);
        let (line, col) = f.line_col(span.start as usize);
        format!("{}:{}:{}", f.name, line + 1, col)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub enum Severity {
    Note,
    Warning,
    Error,
}

impl Severity {
    fn word(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

/// A label on a span: the primary one gets `^^^`, secondary ones `---`.
#[derive(Debug, Clone, PartialEq)]
pub struct Label {
    pub span: Span,
    pub message: String,
    pub primary: bool,
}

/// One message for the user. Build with [`Diagnostic::error`] and friends.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub message: String,
    pub labels: Vec<Label>,
    pub notes: Vec<String>,
}

impl Diagnostic {
    pub fn new(severity: Severity, message: impl Into<String>) -> Self {
        Diagnostic {
            severity,
            message: message.into(),
            labels: Vec::new(),
            notes: Vec::new(),
        }
    }
    pub fn error(message: impl Into<String>) -> Self {
        Self::new(Severity::Error, message)
    }
    pub fn warning(message: impl Into<String>) -> Self {
        Self::new(Severity::Warning, message)
    }
    pub fn note_diag(message: impl Into<String>) -> Self {
        Self::new(Severity::Note, message)
    }
    /// The main place the message is about.
    pub fn at(mut self, span: Span, label: impl Into<String>) -> Self {
        self.labels.push(Label {
            span,
            message: label.into(),
            primary: true,
        });
        self
    }
    /// A related place (shown with `---`).
    pub fn also(mut self, span: Span, label: impl Into<String>) -> Self {
        self.labels.push(Label {
            span,
            message: label.into(),
            primary: false,
        });
        self
    }
    /// A trailing `= note: ...` line.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    pub fn primary_span(&self) -> Option<Span> {
        self.labels.iter().find(|l| l.primary).map(|l| l.span)
    }

    /// Render as text:
    ///
    /// ```text
    /// glow.fx:7:19: error: unknown pass `blurZ`
    ///   |
    /// 7 |             img = PASS.blurZ
    ///   |                   ^^^^^^^^^^ no pass named `blurZ`
    ///   = note: ...
    /// ```
    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        if let Some(span) = self.primary_span().or(self.labels.first().map(|l| l.span)) {
            let _ = write!(out, "{}: ", sources.location(span));
        }
        let _ = writeln!(out, "{}: {}", self.severity.word(), self.message);
        // Width of the line-number gutter.
        let width = self
            .labels
            .iter()
            .map(|l| {
                let f = sources.get(l.span.file);
                (f.line_col(l.span.start as usize).0 + 1).to_string().len()
            })
            .max()
            .unwrap_or(1);
        let pad = " ".repeat(width);
        let mut last_file = None;
        for label in &self.labels {
            let f = sources.get(label.span.file);
            if last_file.is_some() && last_file != Some(label.span.file) || !label.primary {
                let _ = writeln!(out, "{pad}--> {}", sources.location(label.span));
            }
            last_file = Some(label.span.file);
            let (line, col) = f.line_col(label.span.start as usize);
            let text = f.line_text(line);
            let (end_line, end_col) = f.line_col(label.span.end as usize);
            let caret_len = if end_line == line {
                end_col.saturating_sub(col).max(1)
            } else {
                (text.chars().count() + 1).saturating_sub(col).max(1)
            };
            let mark = if label.primary { "^" } else { "-" };
            let display_text = text.replace('\t', "    ");
            // Columns shift by 3 for every tab before the span.
            let tabs_before = text.chars().take(col - 1).filter(|&c| c == '\t').count();
            let _ = writeln!(out, "{pad} |");
            let _ = writeln!(out, "{:>width$} | {}", line + 1, display_text);
            let _ = write!(
                out,
                "{pad} | {}{}",
                " ".repeat(col - 1 + tabs_before * 3),
                mark.repeat(caret_len)
            );
            if label.message.is_empty() {
                out.push('\n');
            } else {
                let _ = writeln!(out, " {}", label.message);
            }
        }
        for note in &self.notes {
            let _ = writeln!(out, "{pad} = note: {note}");
        }
        out
    }
}

/// Diagnostics collected over a whole compilation.
#[derive(Debug, Default, Clone)]
pub struct Diagnostics {
    pub list: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn push(&mut self, d: Diagnostic) {
        self.list.push(d);
    }
    pub fn extend(&mut self, other: Diagnostics) {
        self.list.extend(other.list);
    }
    pub fn has_errors(&self) -> bool {
        self.list.iter().any(|d| d.severity == Severity::Error)
    }
    pub fn error_count(&self) -> usize {
        self.count(Severity::Error)
    }
    pub fn warning_count(&self) -> usize {
        self.count(Severity::Warning)
    }
    fn count(&self, s: Severity) -> usize {
        self.list.iter().filter(|d| d.severity == s).count()
    }
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// (errors and warnings, notes): notes are informational (an automatic
    /// conversion), which `fxrun` shows with `-v` only.
    pub fn split_notes(self) -> (Diagnostics, Diagnostics) {
        let (notes, rest) = self
            .list
            .into_iter()
            .partition(|d| d.severity == Severity::Note);
        (Diagnostics { list: rest }, Diagnostics { list: notes })
    }

    /// Sort by file and position (stable for equal positions), so output order
    /// follows the source and does not depend on the order of the checks.
    pub fn sort(&mut self) {
        self.list.sort_by_key(|d| {
            d.primary_span()
                .map(|s| (s.file, s.start))
                .unwrap_or((FileId(u32::MAX), u32::MAX))
        });
    }

    /// All diagnostics, then a summary line when there is anything to report.
    /// One that renders exactly as an earlier one is shown and counted once: a
    /// shader that two passes use with different defines is checked twice, and
    /// an error outside the defined parts is the same error in both.
    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        let mut seen = std::collections::HashSet::new();
        let (mut e, mut w) = (0, 0);
        for d in &self.list {
            let text = d.render(sources);
            if !seen.insert(text.clone()) {
                continue;
            }
            match d.severity {
                Severity::Error => e += 1,
                Severity::Warning => w += 1,
                _ => {}
            }
            out.push_str(&text);
            out.push('\n');
        }
        if e > 0 || w > 0 {
            let plural = |n: usize, word: &str| {
                if n == 1 {
                    format!("{n} {word}")
                } else {
                    format!("{n} {word}s")
                }
            };
            let _ = writeln!(out, "{}, {}", plural(e, "error"), plural(w, "warning"));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shader checked once per pass (two files of the same text, as two
    /// variants are): its error is shown and counted once.
    #[test]
    fn the_same_diagnostic_twice_is_reported_once() {
        let mut sources = SourceMap::default();
        let text = "let a = 1;\nlet bad = i32(1) & params;\n";
        let mut all = Diagnostics::default();
        for _ in 0..2 {
            let f = sources.add("pencil_blur.wgsl", text);
            all.push(
                Diagnostic::error("operator `&` can't work with `i32` and `Params`")
                    .at(Span::new(f, 21, 36), ""),
            );
        }
        let f = sources.add("other.wgsl", text);
        all.push(Diagnostic::warning("unused").at(Span::new(f, 4, 5), ""));
        let out = all.render(&sources);
        assert_eq!(out.matches("can't work with").count(), 1, "{out}");
        assert!(out.ends_with("1 error, 1 warning\n"), "{out}");
    }
}
