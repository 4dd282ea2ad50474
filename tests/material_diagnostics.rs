//! Material diagnostics (CPU only): what a user sees for each kind of mistake in a
//! material file or a material shader, as file:line:col snapshots, all in one
//! report; mutated material files are errors, never panics; `fxrun` exits 1.

use crate::common;

use common::cli::{code, exits, exits_with, fxrun, fxrun_line, stderr, stdout};

use fxgraph::scene::material_file::load_materials;
use proptest::prelude::*;
use std::path::Path;

/// Loads `text` as `bad.fx` in `dir` and returns the rendered report with the
/// folder replaced by `<dir>`.
fn report(dir: &Path, text: &str) -> String {
    let err = load_materials("bad.fx", text, Some(dir), 0).expect_err("the file has mistakes");
    err.replace(&dir.display().to_string(), "<dir>")
}

fn dir_with(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

/// The [`report`] of the material file `text` in a folder that holds `shaders`
/// (file name, WGSL).
fn report_with(shaders: &[(&str, &str)], text: &str) -> String {
    report(dir_with(shaders).path(), text)
}

#[test]
fn unknown_shader() {
    let got = report_with(
        &[],
        "MATERIAL.a = {\n    SURFACE = SHADER.standrd\n    LIGHTING = SHADER.phong\n}\n",
    );
    assert_eq!(
        got,
        "bad.fx:2:22: error: unknown surface shader `standrd`
  |
2 |     SURFACE = SHADER.standrd
  |                      ^^^^^^^ no such shader
  = note: built-in shaders: blinn_phong, cook_torrance, lambert, phong, standard, triplanar; a user's shader is `standrd.wgsl` next to the material file

1 error, 0 warnings
"
    );
}

#[test]
fn missing_texture_and_wrong_parameter_types() {
    let got = report_with(
        &[],
        r#"MATERIAL.b = {
    SURFACE = SHADER.standard { base_color_map = "missing.png" roughness = (1, 2) metallic = 3 }
    LIGHTING = SHADER.phong { SPECULAR_POWER = "x.png" shine = 3 }
}
"#,
    );
    assert_eq!(
        got,
        r#"bad.fx:2:50: error: texture `base_color_map`: <dir>/missing.png: No such file or directory (os error 2)
  |
2 |     SURFACE = SHADER.standard { base_color_map = "missing.png" roughness = (1, 2) metallic = 3 }
  |                                                  ^^^^^^^^^^^^^ cannot load this texture

bad.fx:2:76: error: `roughness` is f32 (1 value), got 2 values
  |
2 |     SURFACE = SHADER.standard { base_color_map = "missing.png" roughness = (1, 2) metallic = 3 }
  |                                                                            ^^^^^^ wrong number of values

bad.fx:2:94: error: `metallic` = 3 is outside its range 0..1
  |
2 |     SURFACE = SHADER.standard { base_color_map = "missing.png" roughness = (1, 2) metallic = 3 }
  |                                                                                              ^ out of range

bad.fx:3:48: error: `specular_power` is a parameter (f32), not a texture
  |
3 |     LIGHTING = SHADER.phong { SPECULAR_POWER = "x.png" shine = 3 }
  |                                                ^^^^^^^ expected a number or a tuple

bad.fx:3:56: error: lighting shader `phong` has no setting `shine`
  |
3 |     LIGHTING = SHADER.phong { SPECULAR_POWER = "x.png" shine = 3 }
  |                                                        ^^^^^ unknown setting
  = note: its settings: specular_power

5 errors, 0 warnings
"#
    );
}

#[test]
fn surface_shader_with_the_wrong_signature() {
    let got = report_with(
        &[(
            "flat.wgsl",
            "fn surface(in: SurfaceInput) -> vec4<f32> {\n    return vec4<f32>(1.0);\n}\n",
        )],
        "MATERIAL.c = {\n    SURFACE = SHADER.flat\n    LIGHTING = SHADER.lambert\n}\n",
    );
    assert_eq!(
        got,
        "bad.fx:2:22: error: surface shader `flat` has 1 error
  |
2 |     SURFACE = SHADER.flat
  |                      ^^^^ used here

<dir>/flat.wgsl:1:1: error: `surface` must be `fn surface(in: SurfaceInput) -> SurfaceOutput`; found `fn surface(in: SurfaceInput) -> vec4<f32>`
  |
1 | fn surface(in: SurfaceInput) -> vec4<f32> {
  | ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^ wrong signature

2 errors, 0 warnings
"
    );
}

/// A surface shader with a type error (a `vec2` where `alpha` is an `f32`).
const TINTED: &str = "struct SurfaceParams {\n    tint: vec3<f32>, // @default(1, 1, 1)\n}\n@group(2) @binding(0) var<uniform> p: SurfaceParams;\n\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var out: SurfaceOutput;\n    out.diffuse = p.tint * 2;\n    out.normal = in.normal;\n    out.alpha = vec2<f32>(1.0);\n    return out;\n}\n";

/// A lighting shader that declares a texture.
const LIT: &str = "@group(2) @binding(0) var t: texture_2d<f32>;\nfn lighting(in: LightingInput) -> LightingOutput {\n    return LightingOutput(in.light, vec3<f32>(0.0));\n}\n";

/// A type error between an `i32` and the user's struct (issue 29: the struct was
/// written as naga's `Struct { members: [StructMember { ...` dump).
const PENCIL: &str = "struct SurfaceParams {\n    tint: vec3<f32>, // @default(1, 1, 1)\n}\n@group(2) @binding(0) var<uniform> p: SurfaceParams;\n\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var out: SurfaceOutput;\n    let steps: i32 = 3;\n    let k = steps & p;\n    out.normal = in.normal;\n    return out;\n}\n";

/// A mistake in a user's surface or lighting shader: the material file's error
/// names the shader, and the shader's own error points into the user's file, in
/// WGSL's words (not naga's internals).
#[test]
fn users_shader_errors_point_into_the_users_file() {
    // (shader file, its text, material file, first line, place in the shader, more)
    let cases = [
        (
            ("tinted.wgsl", TINTED),
            "MATERIAL.d = {\n    SURFACE = SHADER.tinted\n    LIGHTING = SHADER.lambert\n}\n",
            "bad.fx:2:22: error: surface shader `tinted` has 1 error",
            "<dir>/tinted.wgsl:10:",
            &["vec2<f32>"][..],
        ),
        (
            ("lit.wgsl", LIT),
            "MATERIAL.e = {\n    SURFACE = SHADER.standard\n    LIGHTING = SHADER.lit\n}\n",
            "bad.fx:3:23: error: lighting shader `lit` has 1 error",
            "<dir>/lit.wgsl:1:",
            &[],
        ),
        (
            ("pencil.wgsl", PENCIL),
            "MATERIAL.f = {\n    SURFACE = SHADER.pencil\n    LIGHTING = SHADER.lambert\n}\n",
            "bad.fx:2:22: error: surface shader `pencil` has 1 error",
            "<dir>/pencil.wgsl:9:13: error: WGSL validation: operator `&` can't work with `i32` and `SurfaceParams`",
            &[],
        ),
    ];
    for (shader, material, first, place, more) in cases {
        let got = report_with(&[shader], material);
        assert!(got.starts_with(first), "{got}");
        for needle in [place].iter().chain(more) {
            assert!(got.contains(needle), "{got}");
        }
        for dump in ["Vector {", "Scalar {", "Struct {", "StructMember"] {
            assert!(!got.contains(dump), "{got}");
        }
    }
}

#[test]
fn three_materials_three_mistakes_one_report() {
    let got = report_with(
        &[],
        "MATERIAL.a = { SURFACE = SHADER.nope LIGHTING = SHADER.lambert }\nMATERIAL.b = { SURFACE = SHADER.standard { roughness = 7 } LIGHTING = SHADER.lambert }\nMATERIAL.c = { SURFACE = SHADER.standard LIGHTING = SHADER.lambert ALPHA = sometimes }\n",
    );
    assert!(
        got.contains("bad.fx:1:33: error: unknown surface shader `nope`"),
        "{got}"
    );
    assert!(
        got.contains("bad.fx:2:56: error: `roughness` = 7 is outside its range 0..1"),
        "{got}"
    );
    assert!(got.contains("bad.fx:3:"), "{got}");
    assert!(got.ends_with("3 errors, 0 warnings\n"), "{got}");
}

#[test]
fn a_texture_outside_the_material_folder_is_refused_unread() {
    let outer = tempfile::tempdir().unwrap();
    std::fs::write(outer.path().join("secret.png"), "not an image: secret").unwrap();
    let inner = outer.path().join("mats");
    std::fs::create_dir(&inner).unwrap();
    for path in ["../secret.png", "/etc/passwd"] {
        let got = report(
            &inner,
            &format!("MATERIAL.x = {{ SURFACE = SHADER.standard {{ base_color_map = \"{path}\" }} LIGHTING = SHADER.lambert }}\n"),
        );
        assert!(
            got.contains("must be a relative path inside the material file's folder"),
            "{got}"
        );
        assert!(
            !got.contains("secret") || got.contains("../secret.png"),
            "{got}"
        );
        assert!(!got.contains("root:"), "{got}");
    }
}

const VALID: &str = r#"MATERIAL.m = {
    SURFACE = SHADER.standard { base_color = (0.8, 0.2, 0.1, 1) roughness = 0.4 base_color_map = "builtin:checker" }
    LIGHTING = SHADER.phong { SPECULAR_POWER = 32 }
    ALPHA = mask
    ALPHA_CUTOFF = 0.4
    DOUBLE_SIDED = true
}
"#;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64)
    ))]
    /// Random byte edits of a valid material file: accepted or an error report,
    /// never a panic.
    #[test]
    fn mutated_material_files_never_panic(edits in proptest::collection::vec((0usize..400, any::<u8>()), 1..6)) {
        let mut bytes = VALID.as_bytes().to_vec();
        for (pos, b) in edits {
            let i = pos % bytes.len();
            bytes[i] = b;
        }
        let text = String::from_utf8_lossy(&bytes);
        let dir = tempfile::tempdir().unwrap();
        if let Err(report) = load_materials("m.fx", &text, Some(dir.path()), 0) {
            prop_assert!(report.contains("error"), "{}", report);
        }
    }
}

#[test]
fn fxrun_rejects_a_bad_material_file_with_exit_1() {
    let dir = dir_with(&[("bad.fx", "MATERIAL.red = { SURFACE = SHADER.standard { roughness = 9 } LIGHTING = SHADER.lambert }\n")]);
    let out = fxrun_line(
        "--scene builtin:room --size 32x32 --materials {} -o {}",
        &[&dir.path().join("bad.fx"), &dir.path().join("out.png")],
    );
    exits_with(
        &out,
        1,
        &["bad.fx:1:58: error: `roughness` = 9 is outside its range 0..1"],
    );
    assert!(!dir.path().join("out.png").exists());
}

/// The fenced blocks of `lang` in `docs/materials.md`.
fn doc_blocks(lang: &str) -> Vec<String> {
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/materials.md")).unwrap();
    let mut out = Vec::new();
    let mut current: Option<String> = None;
    for line in doc.lines() {
        match &mut current {
            None if line.trim() == format!("```{lang}") => current = Some(String::new()),
            Some(block) if line.trim() == "```" => {
                out.push(std::mem::take(block));
                current = None;
            }
            Some(block) => {
                block.push_str(line);
                block.push('\n');
            }
            None => {}
        }
    }
    out
}

#[test]
fn every_material_example_in_the_docs_loads() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples");
    let blocks = doc_blocks("fx");
    assert!(
        blocks.len() >= 2,
        "docs/materials.md has {} fx blocks",
        blocks.len()
    );
    let mut count = 0;
    for (i, block) in blocks.iter().enumerate() {
        let file = load_materials(
            &format!("docs/materials.md block {i}"),
            block,
            Some(&examples),
            0,
        )
        .unwrap_or_else(|e| panic!("block {i}:\n{block}\n{e}"));
        count += file.materials.len();
    }
    assert!(count >= 4, "{count} materials");
    // the WGSL shown is the tested example files' code
    for block in doc_blocks("wgsl") {
        if block.contains("fn surface(") || block.contains("fn lighting(") {
            let found = ["stripes.wgsl", "wrap_lambert.wgsl"].iter().any(|f| {
                std::fs::read_to_string(examples.join(f))
                    .unwrap()
                    .contains(block.trim())
            });
            assert!(
                found,
                "a shader in docs/materials.md is not a tested example:\n{block}"
            );
        }
    }
}

#[test]
fn fxrun_describes_materials_and_checks_scene_options() {
    let out = fxrun(&[
        "--scene",
        "builtin:room",
        "--size",
        "32x32",
        "--describe-materials",
    ]);
    exits(&out, 0);
    let stdout = stdout(&out);
    assert!(
        stdout.contains("materials (preprocess variants mode):"),
        "{stdout}"
    );
    assert!(
        stdout.contains("floor: surface triplanar + lighting cook_torrance (model 0), variant [HAS_BASE_COLOR_MAP]"),
        "{stdout}"
    );
    assert!(
        stdout.contains(
            "glass: surface standard + lighting cook_torrance (model 0), variant [ALPHA_BLEND]"
        ),
        "{stdout}"
    );
    assert!(stdout.contains("pipelines compiled: "), "{stdout}");
    for (args, needle) in [
        (vec!["--variants", "fast"], "--variants fast"),
        (vec!["--ambient=-1"], "--ambient -1"),
        (vec!["--ambient", "1,2"], "--ambient 1,2"),
        (vec!["--material", "red"], "--material red"),
        (
            vec!["--material", "red=gold"],
            "--material needs --materials",
        ),
    ] {
        let mut all = vec![
            "--scene",
            "builtin:room",
            "--size",
            "32x32",
            "-o",
            "/nonexistent/x.png",
        ];
        all.extend(args.iter().copied());
        let out = fxrun(&all);
        let stderr = stderr(&out);
        assert_eq!(code(&out), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

#[test]
fn ambient_is_added_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let mean = |extra: &[&str]| -> f32 {
        let path = dir.path().join("a.exr");
        let path_s = path.to_str().unwrap().to_string();
        let mut args = vec!["--scene", "builtin:bench", "--size", "48x32", "-o", &path_s];
        args.extend_from_slice(extra);
        exits(&fxrun(&args), 0);
        let img = fxgraph::io::load_image(&path, &Default::default()).unwrap();
        let px = img.pixels.to_f32_linear(false);
        px.chunks_exact(4).map(|p| p[0] + p[1] + p[2]).sum::<f32>() / (px.len() / 4) as f32
    };
    let without = mean(&[]);
    let with = mean(&["--ambient", "0.5"]);
    assert!(with > without + 0.05, "ambient 0.5: {with} vs {without}");
}
