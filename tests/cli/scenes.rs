//! `fxrun --scene`: the built-in scene renders through the default chain with each
//! technique, and broken scenes, sizes and materials files are input errors (exit 1)
//! that name what is wrong.

use crate::common::cli::{code, exits, exits_with, fxrun, fxrun_line, stderr};
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
