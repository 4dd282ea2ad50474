//! The layers of docs/architecture.md, checked on the source: each module may use
//! only the modules listed for it (`crate::NAME` paths), and `script` and `graph`
//! touch no file (no `std::fs`). A new dependency that breaks the order fails here
//! with the file and line.

use std::path::Path;

/// (module, modules it may use besides itself, may it use `std::fs`)
const LAYERS: &[(&str, &[&str], bool)] = &[
    ("pixels", &[], false),
    // Catching a dependency's panic quietly: any layer may use it.
    ("unwind", &[], false),
    ("script", &[], false),
    ("graph", &["script"], false),
    ("shader", &["script", "graph"], true),
    // RetroArch slang presets lowered to effects (reads presets and shaders).
    ("slang", &["unwind", "shader"], true),
    ("lookup", &["script", "graph", "shader", "slang"], true),
    ("io", &["pixels", "unwind"], true),
    ("gpu", &["pixels", "script", "graph", "shader"], false),
    // The scene model: plain data and loaders, no GPU (no `gpu`, no wgpu).
    (
        "scene",
        &["pixels", "script", "shader", "io", "unwind"],
        true,
    ),
    (
        "render",
        &[
            "pixels", "script", "graph", "shader", "lookup", "gpu", "io", "scene",
        ],
        true,
    ),
    (
        "app",
        &[
            "pixels", "script", "graph", "shader", "slang", "lookup", "gpu", "io", "scene",
            "render",
        ],
        true,
    ),
];

fn rust_files(p: &Path, out: &mut Vec<std::path::PathBuf>) {
    if p.is_dir() {
        for e in std::fs::read_dir(p).unwrap() {
            rust_files(&e.unwrap().path(), out);
        }
    } else if p.is_file() && p.extension().is_some_and(|e| e == "rs") {
        out.push(p.to_path_buf());
    }
}

#[test]
fn modules_use_only_the_layers_below_them() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut problems = Vec::new();
    for (module, allowed, fs) in LAYERS {
        let mut files = Vec::new();
        rust_files(&src.join(module), &mut files);
        rust_files(&src.join(format!("{module}.rs")), &mut files);
        assert!(!files.is_empty(), "no files for {module}");
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for (n, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                let mut rest = code;
                while let Some(i) = rest.find("crate::") {
                    rest = &rest[i + 7..];
                    let used: String = rest
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    if used != *module && !allowed.contains(&used.as_str()) {
                        problems.push(format!(
                            "{}:{}: `{module}` uses `crate::{used}`",
                            f.display(),
                            n + 1
                        ));
                    }
                }
                if !fs && code.contains("std::fs") {
                    problems.push(format!(
                        "{}:{}: `{module}` reads files (`std::fs`)",
                        f.display(),
                        n + 1
                    ));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The scene model is plain data: no file under `src/scene/` names wgpu (the
/// renderer in `src/render/` turns scenes into GPU work).
#[test]
fn the_scene_layer_uses_no_wgpu() {
    let mut files = Vec::new();
    rust_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src/scene"),
        &mut files,
    );
    assert!(!files.is_empty());
    let mut problems = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.contains("wgpu") {
                problems.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The renderer's modules (the files and folders of `src/render/`) that one file
/// names: `super::NAME` (`super::super::NAME` one folder down) and
/// `crate::render::NAME`, braced groups included; an item that `render/mod.rs`
/// re-exports (`crate::render::Renderer`) names the module it comes from. Test
/// modules are left out (a test may use any sibling).
fn render_modules_named(
    text: &str,
    depth: usize,
    modules: &[String],
    reexports: &std::collections::HashMap<String, String>,
) -> Vec<String> {
    let mut prefixes = vec!["crate::render::".to_string()];
    prefixes.push("super::".repeat(depth + 1));
    let mut named = Vec::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let code = line.split("//").next().unwrap_or("").trim();
        if code.starts_with("#[cfg(test)]") {
            // `#[cfg(test)] mod tests ...` (inline or `#[path]`): the rest is tests
            let next = lines.peek().map_or("", |l| l.trim());
            if next.starts_with("mod ") || next.starts_with("#[path") {
                break;
            }
        }
        for prefix in &prefixes {
            let mut rest = code;
            while let Some(i) = rest.find(prefix.as_str()) {
                // `super::super::x` is not `super::x` of a top-level file
                let before = &rest[..i];
                rest = &rest[i + prefix.len()..];
                if prefix.starts_with("super") && before.ends_with("super::") {
                    continue;
                }
                let group: String = if let Some(inner) = rest.strip_prefix('{') {
                    inner.split('}').next().unwrap_or("").to_string()
                } else {
                    rest.chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect()
                };
                for part in group.split(',') {
                    let name: String = part
                        .trim()
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    if modules.contains(&name) {
                        named.push(name);
                    } else if let Some(m) = reexports.get(&name) {
                        named.push(m.clone());
                    }
                }
            }
        }
    }
    named
}

/// No import circle inside the renderer: its modules (the files and folders of
/// `src/render/`) form a graph without cycles, so the renderer reads top-down
/// (docs/architecture.md). A circle fails with the modules on it.
#[test]
fn the_renderer_has_no_import_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/render");
    let mut modules: Vec<String> = Vec::new();
    for e in std::fs::read_dir(&root).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if p.is_dir() || (p.extension().is_some_and(|x| x == "rs") && name != "mod") {
            modules.push(name);
        }
    }
    modules.sort();
    // `pub use MODULE::{A, B};` and `pub use MODULE::A;` in render/mod.rs
    let mut reexports = std::collections::HashMap::new();
    let root_text = std::fs::read_to_string(root.join("mod.rs")).unwrap();
    for statement in root_text.split(';') {
        let Some(path) = statement.trim().strip_prefix("pub use ") else {
            continue;
        };
        let module = path.split("::").next().unwrap_or("").trim().to_string();
        if !modules.contains(&module) {
            continue;
        }
        let items = path.rsplit(['{', ':']).next().unwrap_or("");
        let items = path
            .split_once('{')
            .map_or(items, |(_, inner)| inner.trim_end_matches('}'));
        for item in items.split(',') {
            let item = item.trim();
            if !item.is_empty() {
                reexports.insert(item.to_string(), module.clone());
            }
        }
    }
    let mut edges: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> =
        Default::default();
    for m in &modules {
        let mut files = Vec::new();
        rust_files(&root.join(m), &mut files);
        rust_files(&root.join(format!("{m}.rs")), &mut files);
        let mut to = std::collections::BTreeSet::new();
        for f in files {
            let depth = f.strip_prefix(&root).unwrap().components().count() - 1;
            let text = std::fs::read_to_string(&f).unwrap();
            to.extend(
                render_modules_named(&text, depth, &modules, &reexports)
                    .into_iter()
                    .filter(|n| n != m),
            );
        }
        edges.insert(m.clone(), to);
    }
    // depth-first search; a back edge closes a circle
    fn visit(
        m: &str,
        edges: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
        state: &mut std::collections::HashMap<String, u8>,
        path: &mut Vec<String>,
        circles: &mut Vec<String>,
    ) {
        state.insert(m.to_string(), 1);
        path.push(m.to_string());
        for n in &edges[m] {
            match state.get(n.as_str()) {
                Some(1) => {
                    let start = path.iter().position(|p| p == n).unwrap();
                    let mut circle = path[start..].to_vec();
                    circle.push(n.clone());
                    circles.push(circle.join(" -> "));
                }
                Some(_) => {}
                None => visit(n, edges, state, path, circles),
            }
        }
        path.pop();
        state.insert(m.to_string(), 2);
    }
    let mut state = std::collections::HashMap::new();
    let mut circles = Vec::new();
    for m in &modules {
        if !state.contains_key(m) {
            visit(m, &edges, &mut state, &mut Vec::new(), &mut circles);
        }
    }
    assert!(
        circles.is_empty(),
        "import circles in src/render/:\n{}",
        circles.join("\n")
    );
    // the check sees the renderer's imports at all, and the re-exports
    assert!(edges["renderer"].contains("pipelines"), "{edges:?}");
    assert_eq!(
        reexports.get("Renderer").map(String::as_str),
        Some("renderer")
    );
}
