//! `fxrun --scene`: the built-in scene renders through the default chain with each
//! technique, and broken scenes, sizes and materials files are input errors (exit 1)
//! that name what is wrong.

use crate::common::cli::{code, exits, exits_with, fxrun, fxrun_line, stderr, stdout};
use crate::common::{gpu_scratch, linear};
use std::path::Path;

#[test]
fn renders_the_built_in_scene_through_the_default_chain() {
    let Some(dir) = gpu_scratch() else { return };
    let out = dir.path().join("scene.png");
    let gb = dir.path().join("gbuffer");
    let o = fxrun_line("-o {} --size 96x54 --gbuffer {} --lights 16", &[&out, &gb]);
    exits(&o, 0);
    let img = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((img.width, img.height), (96, 54));
    let v = linear(&img.pixels);
    let mean: f32 = v.iter().sum::<f32>() / v.len() as f32;
    assert!(
        mean > 0.05 && mean < 0.95,
        "a lit, not blank, image: mean {mean}"
    );
    for f in ["depth.png", "normal.png", "albedo.png", "scene.exr"] {
        assert!(gb.join(f).exists(), "missing G-buffer image {f}");
    }
    // Each technique renders.
    for r in ["forward", "light-prepass"] {
        let line = format!("fog --scene builtin:room --renderer {r} --size 48x27 -o {{}}");
        let o = fxrun_line(&line, &[&out]);
        assert_eq!(code(&o), 0, "{r}: {}", stderr(&o));
    }
    let raytraced = fxrun_line("--scene builtin:room --renderer raytraced -o {}", &[&out]);
    assert_eq!(code(&raytraced), 1);
    // The visibility buffer renders; an unknown layout is rejected.
    let line = "fog --scene builtin:room --gbuffer-layout visibility --size 48x27 -o {}";
    let o = fxrun_line(line, &[&out]);
    assert_eq!(code(&o), 0, "visibility: {}", stderr(&o));
    let bogus = fxrun_line("--scene builtin:room --gbuffer-layout thin -o {}", &[&out]);
    assert_eq!(code(&bogus), 1);
    assert!(
        stderr(&bogus).contains("--gbuffer-layout thin"),
        "{}",
        stderr(&bogus)
    );
}

#[test]
fn malformed_gltf_is_rejected_with_exit_1() {
    let Some(dir) = gpu_scratch() else { return };
    let broken = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/gltf/broken");
    let Ok(entries) = std::fs::read_dir(&broken) else {
        eprintln!("skipping: {} is absent", broken.display());
        return;
    };
    // Each broken model is in a folder of its own.
    let file = entries
        .map(|e| e.unwrap().path())
        .filter(|d| d.is_dir())
        .flat_map(|d| std::fs::read_dir(d).unwrap().map(|e| e.unwrap().path()))
        .find(|p| {
            p.extension().is_some_and(|e| e == "gltf")
                && p.to_string_lossy().contains("IndexOutOfRange")
        })
        .expect("a broken .gltf");
    let out = dir.path().join("o.png");
    let o = fxrun_line("--scene {} -o {} --size 32x32", &[&file, &out]);
    let e = exits(&o, 1);
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn scene_errors_name_the_scene() {
    let Some(dir) = gpu_scratch() else { return };
    let o = fxrun_line("--scene builtin:nope -o {}", &[&dir.path().join("o.png")]);
    let e = exits(&o, 1);
    assert!(e.starts_with("fxrun: error: builtin:nope: "), "{e}");
    assert!(!e.contains("error: : "), "{e}");
}

#[test]
fn a_render_size_over_the_device_limit_is_an_input_error() {
    let Some(max) = crate::device_limit() else {
        return;
    };
    let size = format!("{}x16", max + 1);
    let o = fxrun(&["--scene", "builtin:room", "--size", &size, "-o", "o.png"]);
    exits_with(&o, 1, &["builtin:room: the render size"]);
}

#[test]
fn a_device_as_the_materials_file_is_refused() {
    if !crate::gpu() || !Path::new("/dev/zero").exists() {
        return;
    }
    let o = fxrun_line("--scene builtin:room --materials /dev/zero -o o.png", &[]);
    exits_with(&o, 1, &["/dev/zero: not a regular file"]);
}

/// `--timings-json` alone (no `--timings`) on a scene job (issue 29, point 5): the
/// JSON holds every effect pass's GPU time and the renderer's passes whenever the
/// adapter has timestamps (lavapipe has them), for a still and for `--time`. The
/// reference is the same run with `--timings`: the same passes, all timed.
#[test]
fn timings_json_alone_holds_the_gpu_times_of_a_scene_job() {
    let Some(dir) = gpu_scratch() else { return };
    let timestamps = crate::common::engine().is_some_and(|e| e.ctx.timestamps);
    let out = dir.path().join("s.png");
    let json = dir.path().join("t.json");
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    for extra in ["", "--time 0.1", "--timings"] {
        let line = format!(
            "fog tonemap --scene builtin:room --size 96x54 -o {{}} --timings-json {{}} {extra}"
        );
        let o = fxrun_line(&line, &[&out, &json]);
        exits(&o, 0);
        let t = read(&json);
        let passes = t["passes"].as_array().expect("passes");
        let render = t["scene"]["render_passes"]
            .as_array()
            .expect("render_passes");
        let timed = passes
            .iter()
            .filter(|p| p["gpu_ms"].as_f64().is_some_and(|x| x >= 0.0))
            .count();
        let render_timed = render
            .iter()
            .filter(|p| p[1].as_f64().is_some_and(|x| x >= 0.0))
            .count();
        eprintln!(
            "`{extra}`: {timed} of {} effect passes and {render_timed} render passes with a GPU time (timestamps: {timestamps})",
            passes.len()
        );
        assert!(passes.len() >= 2, "fog and tonemap: {t}");
        if timestamps {
            assert_eq!(timed, passes.len(), "`{extra}`: {t}");
            assert!(
                render_timed >= 2 && render_timed == render.len(),
                "`{extra}`: {t}"
            );
        }
        // only --timings prints them
        assert_eq!(
            stdout(&o).contains("total"),
            extra == "--timings",
            "{}",
            stdout(&o)
        );
    }
}

/// A glTF camera named `orbit` (issue 29, point 6): `--camera orbit` stays the
/// turntable, with a warning that names `--camera name:orbit`, which renders that
/// camera: the same bytes as `--camera 0` (its index), not the turntable's.
#[test]
fn a_camera_named_orbit_is_warned_about_and_named_with_name_colon() {
    let Some(dir) = gpu_scratch() else { return };
    let d = dir.path();
    let mut doc = crate::common::gltf_gen::spheres_gltf_json(&Default::default());
    doc["cameras"][0]["name"] = serde_json::json!("orbit");
    let model = crate::common::gltf_gen::write_gltf(d, "orbit_camera.gltf", &doc);
    let run = |camera: &str, name: &str| {
        let out = d.join(name);
        let o = fxrun_line(
            &format!("tonemap --scene {{}} --size 64x48 --camera {camera} -o {{}}"),
            &[&model, &out],
        );
        (exits(&o, 0), std::fs::read(&out).unwrap())
    };
    let (warned, turntable) = run("orbit", "turntable.png");
    let line = "orbit_camera.gltf: --camera orbit is the built-in turntable";
    assert!(
        warned.contains("fxrun: warning: ") && warned.contains(line),
        "{warned}"
    );
    assert!(warned.contains("--camera name:orbit"), "{warned}");
    assert_eq!(warned.matches(line).count(), 1, "said once: {warned}");
    let (quiet, named) = run("name:orbit", "named.png");
    assert!(!quiet.contains("warning"), "{quiet}");
    let (_, by_index) = run("0", "index.png");
    assert_eq!(named, by_index, "name:orbit is camera 0");
    assert_ne!(named, turntable, "name:orbit is not the turntable");
    // an unknown name lists the cameras
    let o = fxrun_line(
        "tonemap --scene {} --size 64x48 --camera name:front -o {}",
        &[&model, &d.join("x.png")],
    );
    exits_with(&o, 1, &["no scene camera named `front`", "`orbit`"]);
}
