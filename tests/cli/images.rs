//! `fxrun EFFECT -i IMAGE -o IMAGE`: a run writes its output atomically, a failed
//! run leaves the old output alone, and broken or oversized inputs are rejected with
//! the file named (exit 1; a missing file: exit 2).

use crate::common::cli::{
    apply, assert_no_temporaries, code, cut, exits, exits_with, fxrun_line, input_png, save,
    stderr, stdout,
};
use crate::common::{self, gpu_scratch, image_f32, image_u8, pattern_u8};
use fxgraph::script::types::Format;
use std::path::Path;

#[test]
fn applies_glow_to_an_image() {
    let Some(dir) = gpu_scratch() else { return };
    let input = input_png(dir.path());
    let out = dir.path().join("out.png");
    let json = dir.path().join("t.json");
    let o = fxrun_line(
        "glow -i {} -o {} --timings --timings-json {}",
        &[&input, &out, &json],
    );
    exits(&o, 0);
    let img = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((img.width, img.height), (48, 32));
    let stdout = stdout(&o);
    assert!(
        stdout.contains("glow/blurX") && stdout.contains("total"),
        "{stdout}"
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(t["passes"].as_array().unwrap().len(), 4);
    let wall = t["wall_ms"].as_f64().unwrap();
    assert!(wall > 0.0);
    assert_eq!(t["job"], "image");
    // The process's own split covers the job's total and more (from the process's
    // start: before main, the arguments, the job, the rest).
    let p = &t["process"];
    let f = |k: &str| p[k].as_f64().unwrap_or_else(|| panic!("process.{k}: {p}"));
    assert!(f("since_main_ms") >= wall, "{p} vs wall {wall}");
    assert!(f("process_ms") >= f("since_main_ms"), "{p}");
    assert_eq!(f("job_ms"), wall);
    let parts = f("setup_ms") + f("job_ms") + f("rest_ms");
    assert!((parts - f("since_main_ms")).abs() < 0.01, "{p}");
    if cfg!(target_os = "linux") {
        assert!(f("before_main_ms") >= 0.0, "{p}");
    }
    assert!(
        stdout.contains("process ") && stdout.contains("before main"),
        "{stdout}"
    );
    // No temporary files are left beside the output.
    assert_no_temporaries(dir.path());
}

#[test]
fn a_failed_run_leaves_the_existing_output_untouched() {
    let Some(dir) = gpu_scratch() else { return };
    let input = input_png(dir.path());
    let out = dir.path().join("out.png");
    std::fs::write(&out, b"precious").unwrap();
    // A shader error (exit 1), a missing input (exit 2), a corrupt input (exit 1).
    exits(
        &apply("tests/shader_errors/bindings.fx", &input, &out, &[]),
        1,
    );
    let o = apply("glow", "no/such/file.png", &out, &[]);
    exits_with(&o, 2, &["no/such/file.png"]);
    let corrupt = dir.path().join("corrupt.png");
    cut(&input, &corrupt, 1, 2);
    exits_with(&apply("glow", &corrupt, &out, &[]), 1, &["corrupt.png"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
    assert_no_temporaries(dir.path());
}

#[test]
fn truncated_exr_and_unknown_output_type_are_rejected() {
    let Some(dir) = gpu_scratch() else { return };
    let exr = dir.path().join("t.exr");
    save(
        &exr,
        &image_f32(16, 8, |x, _| [x as f32 * 10.0, 1.0, 0.5, 1.0]),
    );
    cut(&exr, &exr, 2, 3);
    let out = dir.path().join("o.exr");
    exits(&apply("glow", &exr, &out, &[]), 1);
    assert!(!out.exists());
    let input = input_png(dir.path());
    exits(&apply("glow", &input, dir.path().join("o.xyz"), &[]), 1);
    let jpg = dir.path().join("o.jpg");
    exits(&apply("glow", &input, jpg, &["--bit-depth", "16"]), 1);
}

#[test]
fn hdr_values_survive_an_exr_round_trip_through_an_identity_chain() {
    let Some(dir) = gpu_scratch() else { return };
    let exr = dir.path().join("hdr.exr");
    let img = image_f32(9, 5, |x, y| [x as f32 * 50.0, y as f32 * 0.25, 413.0, 1.0]);
    save(&exr, &img);
    let id = dir.path().join("id.fx");
    std::fs::write(&id, "EFFECT.id = { OUT = IN }").unwrap();
    let out = dir.path().join("out.exr");
    exits(&apply(&id, &exr, &out, &[]), 0);
    let back = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    let (a, b) = (common::linear(&img.pixels), common::linear(&back.pixels));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= x.abs() * 1e-3 + 1e-3, "{x} vs {y}");
    }
    assert!(b.contains(&413.0));
}

/// A final pass that writes sRGB-encoded values (OUT.COLORSPACE = srgb) is not
/// encoded a second time into an 8-bit file, and is decoded for a float file.
#[test]
fn srgb_labelled_output_is_encoded_once() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let f = &crate::common::cli::write_effect(
        dir.path(),
        "enc",
        "EFFECT.enc = { PASS = { a = SHADER.half { img = IN  OUT.FORMAT = rgba8  OUT.COLORSPACE = srgb } } OUT = a }",
        (
            "half",
            "@group(0) @binding(0) var img: texture_2d<f32>;
@fragment fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(0.5, 0.5, textureLoad(img, vec2<i32>(pos.xy), 0).b * 0.0 + 0.5, 1.0);
}
",
        ),
    );
    let img = pattern_u8(6, 4);
    let run = |engine: &mut fxgraph::gpu::executor::Engine, format: Format| {
        common::run(engine, &[f], &[], &img, format).unwrap().2
    };
    let fxgraph::io::Pixels::U8(v) = run(&mut engine, Format::Rgba8Srgb) else {
        panic!()
    };
    assert_eq!(
        &v[..4],
        &[128, 128, 128, 255],
        "encoded values are stored as they are"
    );
    let px = run(&mut engine, Format::Rgba32f);
    let lin = common::linear(&px);
    assert!(
        (lin[0] - common::srgb_to_linear(0.5)).abs() < 2e-3,
        "{}",
        lin[0]
    );
}

/// A still image is a one-frame sequence: temporal effects run on it.
#[test]
fn temporal_effects_run_on_a_still_image() {
    let Some(dir) = gpu_scratch() else { return };
    let input = input_png(dir.path());
    for effect in ["deinterlace", "frame_blend", "temporal_denoise"] {
        let out = dir.path().join(format!("{effect}.png"));
        let o = apply(effect, &input, &out, &[]);
        assert_eq!(code(&o), 0, "{effect}: {}", stderr(&o));
        assert!(out.exists());
    }
}

#[test]
fn truncated_jpeg_input_is_rejected_naming_the_file() {
    let rocket = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/rocket.jpg");
    let dir = tempfile::tempdir().unwrap();
    let half = dir.path().join("half.jpg");
    cut(&rocket, &half, 1, 2);
    let out = dir.path().join("o.png");
    let o = apply("tonemap", &half, &out, &[]);
    exits_with(&o, 1, &["half.jpg: not a valid JPEG file"]);
    assert!(!out.exists());
}

#[test]
fn an_image_over_the_device_limit_is_refused_before_decoding() {
    let Some(max) = crate::device_limit() else {
        return;
    };
    if max >= 20000 {
        eprintln!("skipping: the device takes {max} pixels per side");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // The header announces 20000x20000; there are no pixels to decode.
    let big = dir.path().join("big.pgm");
    std::fs::write(&big, b"P5\n20000 20000\n255\n\0\0\0\0").unwrap();
    let o = apply("tonemap", &big, dir.path().join("o.png"), &[]);
    let message = "big.pgm: the image is 20000x20000, larger than the GPU's limit";
    exits_with(&o, 1, &[message]);
}

/// An image wider than every device is guaranteed to take (8192) is checked against
/// this device's own limit, which the decode waits for while the device is created
/// on its thread: accepted when the device takes it.
#[test]
fn an_image_over_the_guaranteed_limit_waits_for_the_devices_own() {
    let Some(max) = crate::device_limit() else {
        return;
    };
    if max < 10000 {
        eprintln!("skipping: the device takes only {max} pixels per side");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let wide = dir.path().join("wide.png");
    let img = image_u8(10000, 2, |x, y| [(x % 251) as u8, (y * 90) as u8, 7, 255]);
    save(&wide, &img);
    let out = dir.path().join("o.png");
    exits(&apply("vignette", &wide, &out, &[]), 0);
    let r = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((r.width, r.height), (10000, 2));
}

/// An auxiliary image keeps its own size: chroma_composite stretches a 20x10
/// background over a 48x32 input made of the key colour alone (alpha 0), so
/// every output pixel is the background's flat colour (within 1 code).
#[test]
fn an_auxiliary_image_of_another_size_is_sampled_by_position() {
    let Some(dir) = gpu_scratch() else { return };
    let input = dir.path().join("key.png");
    save(&input, &image_u8(48, 32, |_, _| [58, 210, 65, 255]));
    let bg = dir.path().join("bg.png");
    save(&bg, &image_u8(20, 10, |_, _| [10, 100, 200, 255]));
    let out = dir.path().join("o.png");
    let aux = format!("background={}", bg.display());
    exits(
        &apply("chroma_composite", &input, &out, &["--aux", &aux]),
        0,
    );
    let r = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((r.width, r.height), (48, 32));
    let fxgraph::io::Pixels::U8(px) = &r.pixels else {
        panic!("8-bit")
    };
    for c in px.chunks(4) {
        let d = [c[0] as i32 - 10, c[1] as i32 - 100, c[2] as i32 - 200];
        assert!(d.iter().all(|v| v.abs() <= 1), "{c:?}");
    }
}
