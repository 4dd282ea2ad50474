//! Hostile inputs found by the fuzz campaign of issue 19, through the real `fxrun`:
//! each must be rejected with exit status 1 and our own message (at
//! `path:line:col` where the input is text), never with a dependency's panic text,
//! `Debug` dump, log line or validation chain, and never abort.

use crate::common;

use common::cli::{code, fxrun_in, stderr};
use std::path::Path;

/// What no message may contain: a panic's text, its backtrace hint, the png crate's
/// `Debug` chunk type, naga's log target, wgpu's validation chain.
const FORBIDDEN: &[&str] = &[
    "panicked at",
    "RUST_BACKTRACE",
    "ChunkType {",
    "naga::",
    "Caused by:",
    "Validation Error",
    "Some(",
];

fn clean(text: &str) {
    for f in FORBIDDEN {
        assert!(!text.contains(f), "`{f}` in:\n{text}");
    }
}

/// `fxrun ARGS` in `dir`: exit status 1, stderr free of [`FORBIDDEN`] and holding
/// each of `needles`; the stderr.
#[track_caller]
fn rejected(dir: &Path, args: &[&str], needles: &[&str]) -> String {
    let out = fxrun_in(dir, args);
    let err = stderr(&out);
    assert_eq!(code(&out), 1, "fxrun {args:?}:\n{err}");
    clean(&err);
    for n in needles {
        assert!(err.contains(n), "no `{n}` in:\n{err}");
    }
    err
}

// ---- Nesting ------------------------------------------------------------------

/// `dir/copy.wgsl`: IN as it is.
fn write_copy_shader(dir: &Path) {
    std::fs::write(
        dir.join("copy.wgsl"),
        "@group(0) @binding(0) var img: texture_2d<f32>;\n@fragment\nfn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {\n    return textureLoad(img, vec2<i32>(pos.xy), 0);\n}\n",
    )
    .unwrap();
}

/// `e0` instantiates `e1`, which instantiates `e2`, ... `e{n-1}` runs a shader
/// (`e0.fx`: the file's main effect is the one named like it).
fn nested_effects(n: usize) -> String {
    let mut s = String::new();
    for i in 0..n - 1 {
        s.push_str(&format!(
            "EFFECT.e{i} = {{ PASS = {{ x = EFFECT.e{} {{ IN = IN }} }} OUT = x }}\n",
            i + 1
        ));
    }
    s.push_str(&format!(
        "EFFECT.e{} = {{ PASS = {{ c = SHADER.copy {{ img = IN }} }} OUT = c }}\n",
        n - 1
    ));
    s
}

/// 4,000 nested instances aborted with a stack overflow (exit 134).
#[test]
fn four_thousand_nested_instances_are_an_error_not_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    write_copy_shader(dir.path());
    std::fs::write(dir.path().join("e0.fx"), nested_effects(4000)).unwrap();
    // `e64` (line 65), itself at level 64, instantiates `e65`: the 65th level.
    let err = rejected(
        dir.path(),
        &["e0.fx", "--check"],
        &[
            "e0.fx:65:36: error: effect instances are nested more than 64 deep",
            "e0 → e1 → e2 → e3 → … → e62 → e63 → e64 → e65",
        ],
    );
    assert_eq!(err.matches("error:").count(), 1, "{err}");
}

/// The limit itself: 64 levels compile (on a test thread's 2 MiB stack), 65 do not.
#[test]
fn sixty_four_levels_compile_sixty_five_do_not() {
    for (n, ok) in [(65, true), (66, false)] {
        let dir = tempfile::tempdir().unwrap();
        write_copy_shader(dir.path());
        let path = dir.path().join("e0.fx");
        std::fs::write(&path, nested_effects(n)).unwrap();
        let (graph, diags, sources) = common::compile::compile_file(&path);
        assert_eq!(
            graph.is_some(),
            ok,
            "{n} effects: {}",
            diags.render(&sources)
        );
    }
}

/// Instances side by side add no level: 4,000 in a chain compile; declared in
/// reverse order (each reads the one after it) they are expanded recursively and
/// hit the limit.
#[test]
fn a_chain_of_instances_is_not_nesting() {
    let dir = tempfile::tempdir().unwrap();
    write_copy_shader(dir.path());
    let chain = |reverse: bool| {
        let mut passes: Vec<String> = (0..4000)
            .map(|i| {
                let input = if i == 0 {
                    "IN".to_string()
                } else {
                    format!("PASS.p{}", i - 1)
                };
                format!("p{i} = EFFECT.leaf {{ IN = {input} }}")
            })
            .collect();
        if reverse {
            passes.reverse();
        }
        format!(
            "EFFECT.leaf = {{ PASS = {{ c = SHADER.copy {{ img = IN }} }} OUT = c }}\n\
             EFFECT.chain = {{ PASS = {{\n{}\n}} OUT = p3999 }}\n",
            passes.join("\n")
        )
    };
    std::fs::write(dir.path().join("chain.fx"), chain(false)).unwrap();
    let out = fxrun_in(dir.path(), &["chain.fx", "--check"]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    std::fs::write(dir.path().join("chain.fx"), chain(true)).unwrap();
    rejected(
        dir.path(),
        &["chain.fx", "--check"],
        &["error: effect instances are nested more than 64 deep"],
    );
}

// ---- glTF -------------------------------------------------------------------

#[test]
fn gltf_position_naming_a_missing_accessor() {
    let dir = tempfile::tempdir().unwrap();
    let mut json = common::gltf_gen::spheres_gltf_json(&Default::default());
    json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 999.into();
    common::gltf_gen::write_gltf(dir.path(), "bad.gltf", &json);
    let err = rejected(
        dir.path(),
        &["--scene", "bad.gltf", "-o", "out.png"],
        &[
            "bad.gltf",
            "meshes[0].primitives[0].attributes.POSITION: accessor 999 does not exist (the file has 4 accessors)",
        ],
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!dir.path().join("out.png").exists());
}

#[test]
fn gltf_image_without_uri_or_buffer_view() {
    let dir = tempfile::tempdir().unwrap();
    let mut json = common::gltf_gen::spheres_gltf_json(&Default::default());
    json["images"] = serde_json::json!([{ "name": "nowhere" }]);
    common::gltf_gen::write_gltf(dir.path(), "bad.gltf", &json);
    rejected(
        dir.path(),
        &["--scene", "bad.gltf", "-o", "out.png"],
        &["images[0]: neither `uri` nor `bufferView` says where the image is"],
    );
    json["images"] = serde_json::json!([{ "bufferView": 0 }]);
    common::gltf_gen::write_gltf(dir.path(), "bad.gltf", &json);
    rejected(
        dir.path(),
        &["--scene", "bad.gltf", "-o", "out.png"],
        &["images[0]: an image in a `bufferView` needs a `mimeType`"],
    );
}

// ---- Images -------------------------------------------------------------------

/// CRC-32 of PNG chunks (ISO 3309), bit by bit.
fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc_input = kind.to_vec();
    crc_input.extend_from_slice(data);
    out.extend_from_slice(&crc32(&crc_input).to_be_bytes());
    out
}

/// A 4x4 RGBA PNG whose IDAT is one stored (uncompressed) deflate block, so a
/// byte of pixel data can be changed and the stream stays valid deflate: only the
/// Adler-32 at its end tells. `damage` changes a pixel byte and the Adler-32 (the
/// chunk's CRC is computed over the damaged data, so it matches).
fn stored_png(damage: bool) -> Vec<u8> {
    let (w, h) = (4u32, 4u32);
    let mut raw = Vec::new();
    for y in 0..h {
        raw.push(0); // filter: none
        for x in 0..w {
            raw.extend_from_slice(&[(x * 60) as u8, (y * 60) as u8, 128, 255]);
        }
    }
    let adler = {
        let (mut a, mut b) = (1u32, 0u32);
        for &x in &raw {
            a = (a + u32::from(x)) % 65521;
            b = (b + a) % 65521;
        }
        (b << 16) | a
    };
    let mut z = vec![0x78, 0x01, 0x01];
    z.extend_from_slice(&(raw.len() as u16).to_le_bytes());
    z.extend_from_slice(&(!(raw.len() as u16)).to_le_bytes());
    z.extend_from_slice(&raw);
    z.extend_from_slice(&adler.to_be_bytes());
    if damage {
        z[3 + 4 + 10] ^= 0x5a;
        let n = z.len();
        z[n - 1] ^= 0x21;
    }
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &z));
    png.extend(chunk(b"IEND", &[]));
    png
}

#[test]
fn png_with_damaged_deflate_data_and_adler32_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    // The undamaged file decodes (the test's PNG writer is right).
    std::fs::write(dir.path().join("good.png"), stored_png(false)).unwrap();
    let out = fxrun_in(dir.path(), &["vignette", "-i", "good.png", "-o", "out.png"]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    std::fs::write(dir.path().join("bad.png"), stored_png(true)).unwrap();
    rejected(
        dir.path(),
        &["vignette", "-i", "bad.png", "-o", "bad_out.png"],
        &["bad.png: not a valid PNG file: corrupt compressed data (wrong checksum)"],
    );
    assert!(!dir.path().join("bad_out.png").exists());
}

#[test]
fn png_with_a_wrong_crc_names_the_chunk_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let mut png = stored_png(false);
    // IDAT's CRC (the 4 bytes after its data, before IEND's length and type).
    let iend = png.windows(4).position(|w| w == b"IEND").unwrap();
    png[iend - 5] ^= 0x40;
    std::fs::write(dir.path().join("crc.png"), png).unwrap();
    rejected(
        dir.path(),
        &["vignette", "-i", "crc.png", "-o", "out.png"],
        &[
            "crc.png: not a valid PNG file: CRC error",
            "while decoding IDAT chunk",
        ],
    );
}

#[test]
fn webp_cut_by_one_byte_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let img = common::pattern_u8(23, 17);
    let path = dir.path().join("whole.webp");
    fxgraph::io::save_image(&path, 23, 17, &img.pixels, &Default::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let out = fxrun_in(
        dir.path(),
        &["vignette", "-i", "whole.webp", "-o", "out.png"],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    std::fs::write(dir.path().join("cut.webp"), &bytes[..bytes.len() - 1]).unwrap();
    let args = ["vignette", "-i", "cut.webp", "-o", "cut.png"];
    rejected(
        dir.path(),
        &args,
        &["cut.webp: not a valid WebP file: the file is truncated"],
    );
}

// ---- WGSL ---------------------------------------------------------------------

/// `fxrun fx.fx --check` and `fxrun fx.fx -i in.png -o out.png` in `dir`, each
/// rejected (see [`rejected`]) with each of `needles` and no log line.
#[track_caller]
fn rejected_checked_and_run(dir: &Path, needles: &[&str]) {
    for args in [
        &["fx.fx", "--check"][..],
        &["fx.fx", "-i", "in.png", "-o", "out.png"],
    ] {
        let err = rejected(dir, args, needles);
        assert!(
            !err.contains("ERROR") && !err.contains("WARN"),
            "a log line: {err}"
        );
    }
}

/// `dir/fx.fx` running `SHADER.s` over IN, with `dir/s.wgsl` = `wgsl`.
fn effect_with_shader(dir: &Path, wgsl: &str) {
    std::fs::write(
        dir.join("fx.fx"),
        "EFFECT.fx = { PASS = { p = SHADER.s { img = IN } } OUT = p }\n",
    )
    .unwrap();
    std::fs::write(dir.join("s.wgsl"), wgsl).unwrap();
    let img = common::pattern_u8(8, 8);
    fxgraph::io::save_image(&dir.join("in.png"), 8, 8, &img.pixels, &Default::default()).unwrap();
}

#[test]
fn wgsl_function_returning_nothing_points_at_the_function() {
    let dir = tempfile::tempdir().unwrap();
    effect_with_shader(
        dir.path(),
        "@group(0) @binding(0) var img: texture_2d<f32>;\n\n@fragment\nfn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {\n    let c = textureLoad(img, vec2<i32>(pos.xy), 0);\n}\n",
    );
    rejected_checked_and_run(
        dir.path(),
        &["s.wgsl:4:1: error: WGSL validation: `fs_main` must return a `vec4<f32>` value, but it can end (or `return`) without one"],
    );
}

#[test]
fn fragment_input_beyond_the_vertex_stage_is_a_diagnostic() {
    let dir = tempfile::tempdir().unwrap();
    effect_with_shader(
        dir.path(),
        "@group(0) @binding(0) var img: texture_2d<f32>;\n\n@fragment\nfn fs_main(@builtin(position) pos: vec4<f32>,\n           @location(65536) uv: vec2<f32>) -> @location(0) vec4<f32> {\n    return textureLoad(img, vec2<i32>(pos.xy), 0) + vec4<f32>(uv, 0.0, 0.0);\n}\n",
    );
    rejected_checked_and_run(
        dir.path(),
        &[
            "s.wgsl:5:12: error: fragment input `uv` at `@location(65536)` is not an output of the vertex stage",
            "locations between the stages are 0 to 15",
        ],
    );
    assert!(!dir.path().join("out.png").exists());
}

// ---- Panics -------------------------------------------------------------------

/// A panic that nothing caught: one line, exit status 2.
#[test]
fn an_internal_panic_is_one_line_and_exit_2() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fxrun"))
        .arg("--list")
        .env("FXRUN_TEST_INTERNAL_PANIC", "1")
        .env("RUST_BACKTRACE", "1")
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(code(&out), 2, "{err}");
    assert!(
        err.starts_with(
            "fxrun: internal error (a bug): FXRUN_TEST_INTERNAL_PANIC is set (at src/bin/fxrun.rs:"
        ),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    clean(&err);
}

/// A panic inside the library's `catch_quiet` prints nothing (checked in a child
/// process: this test binary run again with `FX_QUIET_PANIC_CHILD` set).
#[test]
fn a_caught_panic_prints_nothing() {
    if std::env::var_os("FX_QUIET_PANIC_CHILD").is_some() {
        let r = fxgraph::unwind::catch_quiet(|| {
            std::thread::scope(|s| {
                s.spawn(|| fxgraph::unwind::quietly(|| panic!("quiet-worker-panic")));
            });
        });
        assert!(r.is_err());
        let r: Result<(), String> = fxgraph::unwind::catch_quiet(|| panic!("quiet-main-panic"));
        assert_eq!(r, Err("quiet-main-panic".to_string()));
        return;
    }
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            &common::test_name(module_path!(), "a_caught_panic_prints_nothing"),
            "--nocapture",
        ])
        .env("FX_QUIET_PANIC_CHILD", "1")
        .output()
        .unwrap();
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    // The child ran this test (a name that matches none passes vacuously).
    let listed = String::from_utf8_lossy(&out.stdout);
    assert!(listed.contains("1 passed"), "{listed}");
    clean(&err);
    assert!(!err.contains("quiet-"), "{err}");
}
