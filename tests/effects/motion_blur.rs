//! The `motion_blur` effect (effects/motion_blur.fx) against the true blur: the
//! average of 32 CPU renders of the scene at sub-frame times across the shutter
//! (each 4 x 4 supersampled), on a scene with a moving textured disc, a static bar
//! in front of its path and a static box behind, beside it.

use crate::common::engine;
use crate::common::raster::{rgb_rmse, supersampled};
use crate::common::samples::f32s;
use crate::common::stream::{run_stream_frames, SeqFrame};
use fxgraph::io::Image;

const W: u32 = 128;
const H: u32 = 96;
/// The disc's motion in pixels per frame (x right, y down).
const VEL: [f32; 2] = [20.0, 5.0];
const RADIUS: f32 = 16.0;
const CENTRE: [f32; 2] = [56.0, 48.0];

/// Bar A: static, in front of the disc's path (depth 1).
fn in_a(x: f32, y: f32) -> bool {
    (34.0..41.0).contains(&x) && (16.0..80.0).contains(&y)
}

/// Box B: static, behind (depth 3), beyond the reach of the disc's blur but in
/// the tiles next to it (32-px tiles: the disc is in tiles 1 and 2 of 4, B in 2 and 3).
fn in_b(x: f32, y: f32) -> bool {
    (94.0..120.0).contains(&x) && (30.0..70.0).contains(&y)
}

/// The disc at time `tau` (frames from the frame time): whether (x, y) is on it,
/// and its colour there (stripes across the motion, moving with it).
fn disc(tau: f32, x: f32, y: f32) -> Option<[f32; 3]> {
    let (dx, dy) = (x - CENTRE[0] - VEL[0] * tau, y - CENTRE[1] - VEL[1] * tau);
    if dx * dx + dy * dy >= RADIUS * RADIUS {
        return None;
    }
    let stripe = ((dx + 100.0) / 4.0).floor().rem_euclid(2.0);
    Some([0.5 + 0.5 * stripe, 0.15, 0.1 + 0.2 * stripe])
}

/// The visible surface at (x, y), time `tau`: (colour, depth, moving).
fn surface(tau: f32, x: f32, y: f32) -> ([f32; 3], f32, bool) {
    if in_a(x, y) {
        return ([0.3, 0.4, 0.9], 1.0, false);
    }
    if let Some(c) = disc(tau, x, y) {
        return (c, 2.0, true);
    }
    if in_b(x, y) {
        return ([0.1, 0.8, 0.2], 3.0, false);
    }
    let stripe = (x / 8.0).floor().rem_euclid(2.0);
    (
        [0.2 + 0.15 * stripe, 0.25, 0.3 + 0.1 * y / H as f32],
        10.0,
        false,
    )
}

/// The shutter's sub-frame times: 32 evenly spaced over `shutter` of the frame
/// interval, centred on the frame time.
fn true_blur(shutter: f32) -> Image {
    let n = 32;
    let renders: Vec<Image> = (0..n)
        .map(|k| {
            let tau = shutter * ((k as f32 + 0.5) / n as f32 - 0.5);
            supersampled(W, H, 4, move |x, y| surface(tau, x, y).0)
        })
        .collect();
    crate::common::image_f32(W, H, |x, y| {
        let i = ((y * W + x) * 4) as usize;
        let mut c = [0.0f32; 4];
        for r in &renders {
            for (k, v) in c.iter_mut().enumerate() {
                *v += f32s(&r.pixels)[i + k] / n as f32;
            }
        }
        c
    })
}

/// The sharp frame (4 x 4 supersampled at the frame time) with its motion and
/// depth at the pixel centres.
fn frame() -> SeqFrame {
    let image = supersampled(W, H, 4, |x, y| surface(0.0, x, y).0);
    let at = |x: u32, y: u32| surface(0.0, x as f32 + 0.5, y as f32 + 0.5);
    let motion = crate::common::image_f32(W, H, |x, y| {
        if at(x, y).2 {
            [VEL[0], VEL[1], 0.0, 1.0]
        } else {
            [0.0, 0.0, 0.0, 1.0]
        }
    });
    let depth = crate::common::image_f32(W, H, |x, y| {
        let d = at(x, y).1;
        [d, d, d, 1.0]
    });
    SeqFrame {
        image,
        aux: vec![("motion".into(), motion), ("depth".into(), depth)],
        jitter: [0.0, 0.0],
    }
}

/// `motion_blur` with `set` on one frame.
fn blur(engine: &mut fxgraph::gpu::executor::Engine, set: &[&str], f: &SeqFrame) -> Vec<f32> {
    run_stream_frames(engine, "motion_blur", set, std::slice::from_ref(f), 25.0).remove(0)
}

/// The largest difference over r, g, b between `a` and `b` at the pixels `keep` selects.
fn max_diff(a: &[f32], b: &[f32], keep: impl Fn(u32, u32) -> bool) -> (f32, usize) {
    let (mut worst, mut n) = (0.0f32, 0);
    for y in 0..H {
        for x in 0..W {
            if !keep(x, y) {
                continue;
            }
            n += 1;
            let i = ((y * W + x) * 4) as usize;
            for c in 0..3 {
                worst = worst.max((a[i + c] - b[i + c]).abs());
            }
        }
    }
    (worst, n)
}

/// Whether a pixel's whole square, grown by `margin` px, lies in `region`.
fn inside(region: impl Fn(f32, f32) -> bool, x: u32, y: u32, margin: f32) -> bool {
    let (x0, y0) = (x as f32 - margin, y as f32 - margin);
    let (x1, y1) = (x as f32 + 1.0 + margin, y as f32 + 1.0 + margin);
    [
        (x0, y0),
        (x1 - 1e-3, y0),
        (x0, y1 - 1e-3),
        (x1 - 1e-3, y1 - 1e-3),
    ]
    .iter()
    .all(|&(px, py)| region(px, py))
}

#[test]
fn motion_blur_is_near_the_true_blur_and_keeps_static_objects_sharp() {
    let Some(mut engine) = engine() else { return };
    let f = frame();
    let sharp = f32s(&f.image.pixels).to_vec();
    for shutter in [0.5f32, 1.0] {
        let truth = true_blur(shutter);
        let set = format!("shutter={shutter}");
        let out = blur(&mut engine, &[&set], &f);
        let e_out = rgb_rmse(&out, f32s(&truth.pixels), W, H, 0);
        let e_in = rgb_rmse(&sharp, f32s(&truth.pixels), W, H, 0);
        // Static box B, behind, outside the reach of the disc's blur (its pixels 1 px
        // or more inside): unchanged (half-float output: within 2e-3).
        let (b_diff, b_n) = max_diff(&out, &sharp, |x, y| inside(in_b, x, y, 1.0));
        // Static bar A, in front of the disc's path: unchanged though the disc's blur
        // passes behind it.
        let (a_diff, a_n) = max_diff(&out, &sharp, |x, y| inside(in_a, x, y, 1.0));
        // The disc's interior (farther from its edge and from A than its blur
        // reaches: |h| = |VEL| shutter / 2): only its own colours, as in the truth.
        let reach = 0.5 * shutter * (VEL[0] * VEL[0] + VEL[1] * VEL[1]).sqrt() + 1.5;
        let interior = |x: u32, y: u32| {
            let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
            let r = ((cx - CENTRE[0]).powi(2) + (cy - CENTRE[1]).powi(2)).sqrt();
            r < RADIUS - reach && (cx > 41.0 + reach || cx < 34.0 - reach)
        };
        let (d_diff, d_n) = max_diff(&out, f32s(&truth.pixels), interior);
        let (d_sharp, _) = max_diff(&sharp, f32s(&truth.pixels), interior);
        eprintln!(
            "shutter {shutter}: RMSE to the true blur {e_out:.4} (sharp frame {e_in:.4}); static box {b_diff:.5} ({b_n} px), bar {a_diff:.5} ({a_n} px); disc interior vs truth {d_diff:.4} (sharp frame {d_sharp:.4}; {d_n} px)"
        );
        assert!(e_out < 0.5 * e_in, "shutter {shutter}: {e_out} vs {e_in}");
        assert!(b_n > 500 && b_diff <= 2e-3, "box B smeared: {b_diff}");
        assert!(a_n > 200 && a_diff <= 2e-3, "bar A smeared: {a_diff}");
        assert!(
            d_n > 20 && d_diff <= 0.5 * d_sharp,
            "disc interior: {d_diff} vs {d_sharp}"
        );
    }
}

/// With the shutter closed (0) or no motion, the frame is returned as it is.
#[test]
fn no_blur_without_exposure_time_or_motion() {
    let Some(mut engine) = engine() else { return };
    let f = frame();
    let sharp = f32s(&f.image.pixels).to_vec();
    let out = blur(&mut engine, &["shutter=0"], &f);
    assert!(crate::common::max_abs_diff(&out, &sharp) <= 2e-3);
    let still = SeqFrame {
        aux: vec![
            (
                "motion".into(),
                crate::common::raster::constant(W, H, [0.0, 0.0, 0.0, 1.0]),
            ),
            f.aux[1].clone(),
        ],
        ..frame()
    };
    let out = blur(&mut engine, &[], &still);
    assert!(crate::common::max_abs_diff(&out, &sharp) <= 2e-3);
}
