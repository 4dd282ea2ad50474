//! `fxrun --view` live on a real X server (Xvfb; lavapipe presents through its
//! software WSI): a reload after an edited shader, and after a broken one (the last
//! image stays, the error is shown in the window); the X display shows the
//! window's image as the output (exactly for an 8-bit output at 1:1, PSNR >= 50 dB
//! where presentation converts a float pass); errors at the start; no display is
//! exit 1 with a clear message.
//!
//! References: normal runs of the same fxrun binary, and ImageMagick's `import
//! -window root` (and x11-utils' `xwininfo`) for what the display shows. Skipped
//! without an adapter or an X display, failed under FX_REQUIRE_GPU=1.

mod common;

use common::cli::{code, stderr, write};
use common::display::{fxrun_view, grab_screen, window_names};
use common::viewer::{
    assert_same_image, image_rect, normal, photo, pixels, region_psnr, scaling_effect, screen_psnr,
    scripted, setup_with_photo, tempdir, view_with_edit, write_scale_shader, Running,
};
use fxgraph::io::Pixels;
use std::time::{Duration, Instant};

#[test]
fn a_reload_shows_the_edited_shader_and_a_broken_one_keeps_the_last_image() {
    let Some((d, _gpu, dir)) = setup_with_photo() else {
        return;
    };
    scaling_effect(dir.path(), "0.5");
    normal(dir.path(), &["k.fx", "-i", "in.png", "-o", "half.png"]);
    let (status, err) = view_with_edit(&d, dir.path(), "edited.png", "c.rgb * 0.25");
    assert_eq!(status, 0, "{err}");
    assert!(err.contains("reloaded"), "{err}");
    normal(dir.path(), &["k.fx", "-i", "in.png", "-o", "quarter.png"]);
    assert_same_image(
        &dir.path().join("edited.png"),
        &dir.path().join("quarter.png"),
    );
    // A broken shader: the error with its place, and the last good image stays.
    let (status, err) = view_with_edit(&d, dir.path(), "broken.png", "c.rgb * undefined_name");
    assert_eq!(status, 0, "{err}");
    assert!(
        err.contains("reload failed") && err.contains("scale.wgsl:4:"),
        "{err}"
    );
    assert!(err.contains("undefined_name"), "{err}");
    assert_same_image(
        &dir.path().join("broken.png"),
        &dir.path().join("quarter.png"),
    );
}

#[test]
fn the_x_display_shows_the_output_in_the_window() {
    let Some((d, _gpu, dir)) = setup_with_photo() else {
        return;
    };
    normal(dir.path(), &["glow", "-i", "in.png", "-o", "n.png"]);
    // Panel hidden, 1:1 pixels, paused after frame 2.
    let glow = ["glow", "-i", "in.png"];
    let one_to_one = ["1:key Tab", "1:key 1"];
    let script = scripted(&glow, 3, &[&one_to_one[..], &["2:pause"]].concat(), None);
    let mut v = Running::start(&d, dir.path(), &script);
    let line = v.wait_for("paused at frame");
    let (x, y, w, h) = image_rect(&line);
    assert_eq!((w, h), (96, 64), "{line}");
    let (_, _, Pixels::U8(want)) = pixels(&dir.path().join("n.png")) else {
        panic!("an 8-bit output")
    };
    let psnr = screen_psnr(&d, dir.path(), (x, y, w, h), |col, row| {
        let t = ((row * w + col) * 4) as usize;
        [0, 1, 2].map(|c| want[t + c] as f32 / 255.0)
    });
    v.resume();
    let (status, err) = v.finish();
    assert_eq!(status, 0, "{err}");
    assert!(psnr >= 50.0, "the screen shows the output at {psnr:.1} dB");

    // Where presentation converts: an inspected float pass (blurX, half size, so
    // magnified twice in the output's place), sRGB-encoded for the display.
    let inspect = [&one_to_one[..], &["1:inspect blurX", "2:pause"]].concat();
    let mut v = Running::start(
        &d,
        dir.path(),
        &scripted(&glow, 3, &inspect, Some("blurx.exr")),
    );
    let line = v.wait_for("paused at frame");
    let (x, y, w, h) = image_rect(&line);
    // The pass's values are written at the end (the screenshot, after the pause).
    let mut screens = Vec::new();
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(3) || screens.is_empty() {
        screens.push(grab_screen(&d, dir.path()));
        std::thread::sleep(Duration::from_millis(300));
    }
    v.resume();
    let (status, err) = v.finish();
    assert_eq!(status, 0, "{err}");
    let (bw, bh, Pixels::F32(values)) = pixels(&dir.path().join("blurx.exr")) else {
        panic!("a float pass")
    };
    assert_eq!((bw * 2, bh * 2), (w, h));
    let expected = |col: u32, row: u32| {
        let t = (((row / 2) * bw + col / 2) * 4) as usize;
        [0, 1, 2].map(|c| common::linear_to_srgb(values[t + c].clamp(0.0, 1.0)))
    };
    let psnr = screens
        .iter()
        .map(|s| region_psnr(s, (x, y, w, h), expected))
        .fold(0.0, f64::max);
    assert!(
        psnr >= 50.0,
        "the inspected pass on the screen: {psnr:.1} dB"
    );
}

#[test]
fn errors_are_refused_at_the_start_and_shown_in_the_window_after_a_reload() {
    let Some((d, _gpu, dir)) = setup_with_photo() else {
        return;
    };
    write(
        dir.path(),
        "bad.fx",
        "EFFECT.bad = { PASS = { s = SHADER.nosuchshader { img = IN } } OUT = s }",
    );
    // An effect that does not compile at the start is an input error (exit 1).
    let o = fxrun_view(
        &d,
        dir.path(),
        &scripted(&["bad.fx", "-i", "in.png"], 1, &[], None),
    );
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.fx:1:"), "{}", stderr(&o));
    // A scripted set out of range is refused, naming the range.
    let out_of_range = ["1:set brightPass.threshold=-3"];
    let o = fxrun_view(
        &d,
        dir.path(),
        &scripted(&["glow", "-i", "in.png"], 1, &out_of_range, None),
    );
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("out of range"), "{}", stderr(&o));
    // After a broken reload the window's title says so (the panel shows the error).
    scaling_effect(dir.path(), "0.5");
    let reload_then_pause = ["1:wait-reload", "2:pause"];
    let script = scripted(&["k.fx", "-i", "in.png"], 2, &reload_then_pause, None);
    let mut v = Running::start(&d, dir.path(), &script);
    v.wait_for("watching");
    write_scale_shader(dir.path(), "c.rgb * undefined_name");
    v.wait_for("paused at frame");
    let names = window_names(&d);
    v.resume();
    let (status, err) = v.finish();
    assert_eq!(status, 0, "{err}");
    assert!(names.contains("error (see the panel)"), "{names}");
}

#[test]
fn without_a_display_the_viewer_is_refused_with_exit_1() {
    let dir = tempdir();
    photo(dir.path(), "in.png");
    let run = |display: Option<&str>| {
        let mut c = common::cli::command(["glow", "-i", "in.png", "--view"]);
        c.current_dir(dir.path())
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("WAYLAND_SOCKET");
        match display {
            Some(d) => c.env("DISPLAY", d),
            None => c.env_remove("DISPLAY"),
        };
        c.output().unwrap()
    };
    let o = run(None);
    assert_eq!(code(&o), 1);
    assert!(
        stderr(&o).contains("--view needs a display"),
        "{}",
        stderr(&o)
    );
    // A display that no server answers: the same, never a panic.
    let o = run(Some(":239"));
    assert_eq!(code(&o), 1);
    let e = stderr(&o);
    assert!(
        e.contains("cannot open the display (DISPLAY=:239)")
            && !e.contains("panicked")
            && !e.contains(".rs:"),
        "{e}"
    );
    // The viewer's options alone are refused.
    let o = common::cli::fxrun_in(
        dir.path(),
        &["glow", "-i", "in.png", "-o", "x.png", "--view-frames", "2"],
    );
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("options of --view"));
}
