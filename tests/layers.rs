//! The layers of docs/architecture.md, checked on the source: each module may use
//! only the modules listed for it (`crate::NAME` paths), and `script` and `graph`
//! touch no file (no `std::fs`). A new dependency that breaks the order fails here
//! with the file and line.

use std::path::Path;

/// (module, modules it may use besides itself, may it use `std::fs`)
const LAYERS: &[(&str, &[&str], bool)] = &[
    ("pixels", &[], false),
    // Catching a dependency's panic quietly: used by the layers that call
    // decoders and parsers of files (`io`, `scene`).
    ("unwind", &[], false),
    ("script", &[], false),
    ("graph", &["script"], false),
    ("shader", &["script", "graph"], true),
    // RetroArch slang presets lowered to effects (reads presets and shaders).
    ("slang", &["unwind", "script", "shader"], true),
    ("lookup", &["script", "graph", "shader", "slang"], true),
    ("io", &["pixels", "unwind"], true),
    ("gpu", &["pixels", "script", "graph", "shader"], false),
    // The scene model: plain data and loaders, no GPU (no `gpu`, no wgpu).
    (
        "scene",
        &["pixels", "script", "shader", "io", "unwind"],
        true,
    ),
    // The renderer reads and writes no file: it imports nothing from `io` (scenes
    // come loaded, images go back to the caller; `app` writes `--gbuffer`).
    (
        "render",
        &[
            "pixels", "script", "graph", "shader", "lookup", "gpu", "scene",
        ],
        false,
    ),
    (
        "app",
        &[
            "pixels", "script", "graph", "shader", "slang", "lookup", "gpu", "io", "scene",
            "render",
        ],
        true,
    ),
    // The reusable parts of the viewer (feature `view`): no window system, the
    // library's public API; images and sequences shown are loaded through `io`
    // (the viewer itself touches no file: no `std::fs`).
    (
        "view",
        &[
            "pixels", "script", "graph", "shader", "lookup", "gpu", "io", "scene", "render", "app",
        ],
        false,
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

/// The modules of one folder (its files and subfolders, `src/render/`) that one
/// file names: `super::NAME` (`super::super::NAME` one folder down) and
/// `crate::render::NAME` (`crate_path::NAME`), braced groups included; an item
/// that the folder's `mod.rs` re-exports (`crate::render::Renderer`) names the
/// module it comes from. Test
/// modules are left out (a test may use any sibling).
fn modules_named(
    text: &str,
    crate_path: &str,
    depth: usize,
    modules: &[String],
    reexports: &std::collections::HashMap<String, String>,
) -> Vec<String> {
    let mut prefixes = vec![format!("{crate_path}::")];
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

/// The modules of one folder (its files and subfolders, `mod.rs` left out),
/// sorted, and the items its `mod.rs` re-exports (`pub use MODULE::{A, B};`),
/// each to the module it comes from.
fn folder_modules(root: &Path) -> (Vec<String>, std::collections::HashMap<String, String>) {
    let mut modules: Vec<String> = Vec::new();
    for e in std::fs::read_dir(root).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if p.is_dir() || (p.extension().is_some_and(|x| x == "rs") && name != "mod") {
            modules.push(name);
        }
    }
    modules.sort();
    let mut reexports = std::collections::HashMap::new();
    let root_text = std::fs::read_to_string(root.join("mod.rs")).unwrap_or_default();
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
    (modules, reexports)
}

type Edges = std::collections::BTreeMap<String, std::collections::BTreeSet<String>>;

/// Which modules of the folder `root` (Rust path `crate_path`, `crate::render`)
/// each of its modules names, itself left out.
fn folder_edges(root: &Path, crate_path: &str) -> Edges {
    let (modules, reexports) = folder_modules(root);
    let mut edges = Edges::new();
    for m in &modules {
        let mut files = Vec::new();
        rust_files(&root.join(m), &mut files);
        rust_files(&root.join(format!("{m}.rs")), &mut files);
        let mut to = std::collections::BTreeSet::new();
        for f in files {
            // how many `super::` lead from the file's module to the folder's
            let mut depth = f.strip_prefix(root).unwrap().components().count() - 1;
            if f.file_name().is_some_and(|n| n == "mod.rs") {
                depth -= 1;
            }
            let text = std::fs::read_to_string(&f).unwrap();
            to.extend(
                modules_named(&text, crate_path, depth, &modules, &reexports)
                    .into_iter()
                    .filter(|n| n != m),
            );
        }
        edges.insert(m.clone(), to);
    }
    edges
}

/// The circles of a module graph, each as `a -> b -> a` (depth-first search; a
/// back edge closes a circle).
fn circles(edges: &Edges) -> Vec<String> {
    fn visit(
        m: &str,
        edges: &Edges,
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
    let mut found = Vec::new();
    for m in edges.keys() {
        if !state.contains_key(m) {
            visit(m, edges, &mut state, &mut Vec::new(), &mut found);
        }
    }
    found
}

/// No import circle inside the renderer: its modules (the files and folders of
/// `src/render/`) form a graph without cycles, so the renderer reads top-down
/// (docs/architecture.md). A circle fails with the modules on it.
#[test]
fn the_renderer_has_no_import_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/render");
    let edges = folder_edges(&root, "crate::render");
    let found = circles(&edges);
    assert!(
        found.is_empty(),
        "import circles in src/render/:\n{}",
        found.join("\n")
    );
    // the check sees the renderer's imports at all, and the re-exports
    assert!(edges["renderer"].contains("pipelines"), "{edges:?}");
    let (_, reexports) = folder_modules(&root);
    assert_eq!(
        reexports.get("Renderer").map(String::as_str),
        Some("renderer")
    );
}

/// The strongly connected parts of a module graph with more than one module:
/// the modules that reach each other (one part holds every circle through it).
fn tangles(edges: &Edges) -> Vec<Vec<String>> {
    let reach = |from: &str| {
        let mut seen = std::collections::BTreeSet::new();
        let mut todo = vec![from.to_string()];
        while let Some(m) = todo.pop() {
            for n in &edges[&m] {
                if seen.insert(n.clone()) {
                    todo.push(n.clone());
                }
            }
        }
        seen
    };
    let reached: std::collections::BTreeMap<&String, _> =
        edges.keys().map(|m| (m, reach(m))).collect();
    let mut parts: Vec<Vec<String>> = Vec::new();
    for m in edges.keys() {
        let part: Vec<String> = edges
            .keys()
            .filter(|n| n == &m || (reached[m].contains(*n) && reached[n].contains(m)))
            .cloned()
            .collect();
        if part.len() > 1 && !parts.contains(&part) {
            parts.push(part);
        }
    }
    parts
}

/// Folders whose files still import each other in a circle, with the modules
/// involved (issue 30 dissolved the circles of `scene/model.rs` and the loaders,
/// `app/effect` - `pipeline` - `gpu_stage` and `gpu/transfer` - `executor`). A
/// circle among other modules, or one that grows, fails the test below; remove an
/// entry once its circle is gone.
const KNOWN_TANGLES: &[(&str, &[&str])] = &[
    ("bin/fxrun/view", &["app", "commands", "frame", "script"]),
    (
        "gpu/executor",
        &["bgra", "compute", "encode", "inspect", "record"],
    ),
    ("graph", &["library", "source"]),
    ("graph", &["lower", "salvage"]),
    ("io", &["y4m", "yuv"]),
    ("io/video", &["color", "probe"]),
    ("scene", &["animation", "camera", "environment", "model"]),
    ("script", &["ast", "material"]),
    ("shader", &["reflect", "uniforms"]),
];

/// No new file-level import circle in any folder: in every folder under `src/`
/// (the binary's `src/bin/fxrun/` included) the files and subfolders, as
/// modules, name each other without a cycle, apart from [`KNOWN_TANGLES`].
/// Counted per folder: an edge A -> B where a file of A names `super::B`
/// (`super::super::B` one folder down), `crate::FOLDER::B` or an item the
/// folder's `mod.rs` re-exports from B (test modules left out); the modules that
/// reach each other form one tangle, and the message lists each circle (a back
/// edge of a depth-first search).
#[test]
fn no_folder_has_a_new_import_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut folders = Vec::new();
    fn dirs(p: &Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(p).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                out.push(p.clone());
                dirs(&p, out);
            }
        }
    }
    dirs(&src, &mut folders);
    folders.sort();
    let mut found = Vec::new();
    let mut tangle_count = 0;
    for folder in folders {
        let rel = folder.strip_prefix(&src).unwrap();
        let crate_path = match rel.strip_prefix("bin/fxrun") {
            Ok(inner) if inner.as_os_str().is_empty() => "crate".to_string(),
            Ok(inner) => format!("crate::{}", inner.display()).replace('/', "::"),
            Err(_) if rel == Path::new("bin") => continue,
            Err(_) => format!("crate::{}", rel.display()).replace('/', "::"),
        };
        let name = rel.display().to_string();
        let edges = folder_edges(&folder, &crate_path);
        for part in tangles(&edges) {
            tangle_count += 1;
            let known = KNOWN_TANGLES.iter().any(|(f, modules)| {
                *f == name && part.iter().all(|m| modules.contains(&m.as_str()))
            });
            if !known {
                let on_it: Vec<String> = circles(&edges)
                    .into_iter()
                    .filter(|c| part.iter().any(|m| c.starts_with(&format!("{m} "))))
                    .collect();
                found.push(format!("{name}: {}", on_it.join("; ")));
            }
        }
    }
    eprintln!(
        "{tangle_count} folder tangles, {} known",
        KNOWN_TANGLES.len()
    );
    assert!(
        found.is_empty(),
        "new import circles:\n{}",
        found.join("\n")
    );
}
