//! `fxrun --view` on a real X server (Xvfb; lavapipe presents through its
//! software WSI): the scripted screenshot of an image, a batch step, sequence
//! frames and a scene (also animated, frame n as a run at n / fps) equals a normal
//! run's output of the same frame; a scene follows the window's size; a parameter changed through the panel's code path
//! (`--view-do K:set`) changes the next frame as `--set` would; an inspected pass
//! equals a run of the effect up to that pass. (Reloads, the display itself and
//! errors: `tests/viewer_live.rs`.)
//!
//! References: the normal runs of the same fxrun binary (the files a run writes).
//! Skipped without an adapter or an X display, failed under FX_REQUIRE_GPU=1.

mod common;

use common::cli::{stdout, write};
use common::viewer::{
    assert_same_image, diff_u8, normal, photo, pixels, scripted, setup, setup_with_photo, tempdir,
    view, view_shot,
};
use fxgraph::io::Pixels;
use std::path::Path;

#[test]
fn image_screenshot_equals_a_normal_run() {
    let Some((d, _gpu, dir)) = setup_with_photo() else {
        return;
    };
    normal(dir.path(), &["glow", "-i", "in.png", "-o", "n.png"]);
    view_shot(&d, dir.path(), &["glow", "-i", "in.png"], 2, &[], "v.png");
    assert_same_image(&dir.path().join("v.png"), &dir.path().join("n.png"));
    // A batch: the arrow key goes to the next image.
    let p2 = dir.path().join("b");
    std::fs::create_dir(&p2).unwrap();
    photo(&p2, "1.png");
    let img = common::image_u8(64, 48, |x, y| [(x * 4) as u8, (y * 5) as u8, 255, 255]);
    fxgraph::io::save_image(&p2.join("2.png"), 64, 48, &img.pixels, &Default::default()).unwrap();
    normal(dir.path(), &["glow", "-i", "b/2.png", "-o", "n2.png"]);
    let args = ["glow", "-i", "b/"];
    view_shot(&d, dir.path(), &args, 2, &["1:key Right"], "v2.png");
    assert_same_image(&dir.path().join("v2.png"), &dir.path().join("n2.png"));
}

/// Five frames of a moving pattern, `f0000.png` ...
fn sequence(dir: &Path) {
    for i in 0..5u32 {
        let img = common::image_u8(48, 32, |x, y| {
            [
                ((x + 7 * i) * 5) as u8,
                (y * 7) as u8,
                ((x * y + i * 40) % 256) as u8,
                255,
            ]
        });
        let p = dir.join(format!("f{i:04}.png"));
        fxgraph::io::save_image(&p, 48, 32, &img.pixels, &Default::default()).unwrap();
    }
}

#[test]
fn sequence_frames_equal_the_normal_runs_frames_also_after_going_back() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    sequence(dir.path());
    // The same frames as a .y4m file (made by ffmpeg), reopened to go back.
    let made = std::process::Command::new("ffmpeg")
        .args([
            "-v",
            "error",
            "-y",
            "-framerate",
            "25",
            "-i",
            "f%04d.png",
            "-pix_fmt",
            "yuv444p",
            "seq.y4m",
        ])
        .current_dir(dir.path())
        .status()
        .expect("run ffmpeg (the y4m file's maker)");
    assert!(made.success());
    for (effect, input) in [
        ("frame_blend", "f%04d.png"),
        ("motion_trail", "f%04d.png"),
        ("frame_blend", "seq.y4m"),
    ] {
        let name = format!("{effect}-{}", input.replace(['%', '.'], ""));
        let out = format!("{name}/%04d.png");
        normal(dir.path(), &[effect, "-i", input, "-o", &out]);
        let frame = |n: u32| dir.path().join(&name).join(format!("{n:04}.png"));
        // One frame further per frame shown: the 4th frame shown is frame 3.
        view_shot(&d, dir.path(), &[effect, "-i", input], 4, &[], "v3.png");
        assert_same_image(&dir.path().join("v3.png"), &frame(3));
        // Pause at frame 3, go back twice: frame 1, with its history replayed
        // (frame_blend reads earlier frames, motion_trail its own earlier output).
        let back = ["4:key Space", "5:key Left", "6:key Left"];
        view_shot(&d, dir.path(), &[effect, "-i", input], 6, &back, "v1.png");
        assert_same_image(&dir.path().join("v1.png"), &frame(1));
    }
}

#[test]
fn scene_screenshot_equals_a_normal_run() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    let scene = ["tonemap", "--scene", "builtin:room", "--size", "160x120"];
    normal(dir.path(), &[&scene[..], &["-o", "n.png"]].concat());
    view_shot(&d, dir.path(), &scene, 2, &[], "v.png");
    assert_same_image(&dir.path().join("v.png"), &dir.path().join("n.png"));
    // The G-buffer is in the pass list: AUX.depth is written as a run writes R32F.
    view_shot(
        &d,
        dir.path(),
        &scene,
        2,
        &["1:inspect aux:depth"],
        "depth.exr",
    );
    let (w, h, p) = pixels(&dir.path().join("depth.exr"));
    assert_eq!((w, h), (160, 120));
    let Pixels::F32(v) = p else {
        panic!("float depth")
    };
    assert!(
        v.chunks(4).all(|px| px[0] > 0.0 && px[0] == px[1]),
        "depth as grey, positive"
    );
}

#[test]
fn an_animated_scene_plays_frame_by_frame_as_a_run_at_that_time() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    // A skinned model (the corpus): the 16th frame shown is frame 15, t = 0.5 s at
    // 30 fps, which a normal run renders with --time 0.5.
    let model = common::anim_gltf::animated_corpus("RiggedSimple");
    let model = model.to_str().unwrap();
    let scene = ["tonemap", "--scene", model, "--size", "160x120"];
    normal(
        dir.path(),
        &[&scene[..], &["--time", "0.5", "-o", "n.png"]].concat(),
    );
    view_shot(&d, dir.path(), &scene, 16, &[], "v.png");
    assert_same_image(&dir.path().join("v.png"), &dir.path().join("n.png"));
    // Paused at frame 3, one back and one on, then Home: frame 0 (--time 0).
    normal(
        dir.path(),
        &[&scene[..], &["--time", "0", "-o", "n0.png"]].concat(),
    );
    let keys = ["4:key Space", "4:key Left", "5:key Right", "5:key Home"];
    view_shot(&d, dir.path(), &scene, 6, &keys, "v0.png");
    assert_same_image(&dir.path().join("v0.png"), &dir.path().join("n0.png"));
    // A moving camera (an orbit) is a clock too: --time starts there.
    let orbit = [
        "tonemap",
        "--scene",
        "builtin:room",
        "--camera",
        "orbit:period=4",
        "--size",
        "96x64",
    ];
    normal(
        dir.path(),
        &[&orbit[..], &["--time", "1", "-o", "o.png"]].concat(),
    );
    let earlier = [&orbit[..], &["--time", "0.9333333333333333"]].concat();
    view_shot(&d, dir.path(), &earlier, 3, &[], "vo.png");
    assert_same_image(&dir.path().join("vo.png"), &dir.path().join("o.png"));
}

#[test]
fn a_scene_without_size_follows_the_window_and_is_planned_again() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    // No --size: the render takes the image area; hiding the panel widens it.
    let scene = ["fxaa", "--scene", "builtin:room"];
    view_shot(&d, dir.path(), &scene, 3, &["1:key Tab"], "wide.png");
    let (w, h, _) = pixels(&dir.path().join("wide.png"));
    view_shot(&d, dir.path(), &scene, 2, &[], "narrow.png");
    let (nw, nh, _) = pixels(&dir.path().join("narrow.png"));
    assert!(
        w > nw && h == nh,
        "the panel's width: {w}x{h} against {nw}x{nh}"
    );
    // Planned for the new size: the frame a run at that size writes.
    let size = format!("{w}x{h}");
    normal(
        dir.path(),
        &[&scene[..], &["--size", &size, "-o", "n.png"]].concat(),
    );
    assert_same_image(&dir.path().join("wide.png"), &dir.path().join("n.png"));
}

#[test]
fn a_parameter_set_as_the_panel_does_changes_the_next_frame_as_set_would() {
    let Some((d, _gpu, dir)) = setup_with_photo() else {
        return;
    };
    // A pass parameter (set_param), an effect parameter feeding a uniform (applied
    // as set_param) and one that changes a #define (planned again).
    let cases: [(&str, &str, &str); 3] = [
        ("glow", "brightPass.threshold", "0.15"),
        ("tonemap", "tonemap.exposure", "1.5"),
        ("tonemap", "operator", "reinhard"),
    ];
    for (i, (effect, name, value)) in cases.iter().enumerate() {
        let set = format!("{name}={value}");
        let n = format!("n{i}.png");
        normal(
            dir.path(),
            &[effect, "-i", "in.png", "-o", &n, "--set", &set],
        );
        let v = format!("v{i}.png");
        let action = format!("1:set {set}");
        let actions = [action.as_str(), "2:copy-set"];
        let script = scripted(&[effect, "-i", "in.png"], 2, &actions, Some(&v));
        let o = view(&d, dir.path(), &script);
        assert_same_image(&dir.path().join(&v), &dir.path().join(&n));
        // "Copy as --set" gives arguments that reproduce it.
        let line = stdout(&o);
        assert!(
            line.contains(&format!("--set {set}"))
                || line.contains(&format!("--set {effect}.{set}")),
            "copy-set printed {line:?}"
        );
        // Before the change the frame was the unchanged effect's.
        let u = format!("u{i}.png");
        normal(dir.path(), &[effect, "-i", "in.png", "-o", &u]);
        assert!(
            diff_u8(&dir.path().join(&u), &dir.path().join(&v)).0 > 0,
            "{set} changes the image"
        );
    }
    // An effect parameter in a loop bound (gaussian_blur's sigma): equal within one
    // 8-bit step (lavapipe specialises shaders on uniform values it sees in loop
    // bounds, so a value set after the first frame may round differently).
    let blur = ["gaussian_blur", "-i", "in.png"];
    normal(
        dir.path(),
        &[&blur[..], &["-o", "g.png", "--set", "sigma=5"]].concat(),
    );
    view_shot(&d, dir.path(), &blur, 2, &["1:set sigma=5"], "gv.png");
    let (max, share) = diff_u8(&dir.path().join("gv.png"), &dir.path().join("g.png"));
    assert!(
        max <= 1 && share < 0.01,
        "sigma=5: {max} steps, {:.3} % of samples",
        share * 100.0
    );
}

#[test]
fn the_inspected_pass_equals_a_run_of_the_effect_up_to_that_pass() {
    let Some((d, _gpu, dir)) = setup_with_photo() else {
        return;
    };
    write(dir.path(), "upto.fx", common::UPTO_BLUR_X);
    normal(dir.path(), &["upto.fx", "-i", "in.png", "-o", "n.exr"]);
    let glow = ["glow", "-i", "in.png"];
    view_shot(&d, dir.path(), &glow, 2, &["1:inspect blurX"], "v.exr");
    assert_same_image(&dir.path().join("v.exr"), &dir.path().join("n.exr"));
    // Inspecting does not change the output: back to it, the same as a normal run.
    normal(dir.path(), &["glow", "-i", "in.png", "-o", "o.png"]);
    let inspect_and_back = ["1:inspect blurY", "2:inspect output"];
    view_shot(&d, dir.path(), &glow, 3, &inspect_and_back, "vo.png");
    assert_same_image(&dir.path().join("vo.png"), &dir.path().join("o.png"));
}
