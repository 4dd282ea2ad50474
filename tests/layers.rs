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
    ("lookup", &["script", "graph", "shader"], true),
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
            "pixels", "script", "graph", "shader", "lookup", "gpu", "io", "scene", "render",
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
