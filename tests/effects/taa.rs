//! The `taa` effect (effects/taa.fx) on CPU-made sequences: frames point-sampled at
//! the pixel centre plus that frame's Halton jitter (aliased, as a rasteriser
//! without anti-aliasing makes them), with exact motion vectors and depth as
//! AUX.motion and AUX.depth. References: the box-filtered (4 x 4 supersampled)
//! frame, the un-anti-aliased frame and `fxaa` of it.

use crate::common::engine;
use crate::common::raster::{constant, object_aux, point_sampled, rgb_rmse, supersampled};
use crate::common::samples::f32s;
use crate::common::stream::{run_stream_frames, SeqFrame};
use fxgraph::io::Image;
use fxgraph::script::halton23;
use fxgraph::script::types::Format;

const W: u32 = 96;
const H: u32 = 96;

/// A high-contrast scene: a checkerboard of 6-pixel cells rotated by 0.35 rad
/// (edges at every angle class: staircases and crawling when aliased), coloured
/// so that all three YCoCg components change across its edges.
fn checker(x: f32, y: f32) -> [f32; 3] {
    let (s, c) = 0.35f32.sin_cos();
    let u = x * c + y * s;
    let v = -x * s + y * c;
    let k = ((u / 6.0).floor() + (v / 6.0).floor()).rem_euclid(2.0);
    [0.05 + 0.9 * k, 0.1 + 0.6 * k, 0.9 - 0.8 * k]
}

/// The checkerboard translating at `vel` pixels per frame, frame `t`.
fn moved(vel: [f32; 2], t: u32) -> impl Fn(f32, f32) -> [f32; 3] {
    move |x, y| checker(x - vel[0] * t as f32, y - vel[1] * t as f32)
}

/// AUX.motion = `vel` everywhere, AUX.depth = 5: a scene moving as one.
fn uniform_aux(vel: [f32; 2]) -> Vec<(String, Image)> {
    vec![
        ("motion".into(), constant(W, H, [vel[0], vel[1], 0.0, 1.0])),
        ("depth".into(), constant(W, H, [5.0, 5.0, 5.0, 1.0])),
    ]
}

fn translating_sequence(vel: [f32; 2], frames: u32) -> Vec<SeqFrame> {
    (0..frames)
        .map(|t| SeqFrame {
            image: point_sampled(W, H, halton23(t as u64), moved(vel, t)),
            aux: uniform_aux(vel),
            jitter: halton23(t as u64),
        })
        .collect()
}

#[test]
fn taa_of_a_moving_pattern_is_closer_to_the_box_filtered_frame_than_aliased_and_fxaa() {
    let Some(mut engine) = engine() else { return };
    // A known sub-pixel velocity, not a multiple of the jitter pattern.
    let vel = [0.61, 0.27];
    let n = 24;
    let seq = translating_sequence(vel, n);
    let outs = run_stream_frames(&mut engine, "taa", &[], &seq, 25.0);
    // Mean error over the last 8 frames (the history has built up by frame 16),
    // 4 pixels from the edges, where new content enters.
    let (mut e_taa, mut e_raw, mut e_fxaa) = (0.0, 0.0, 0.0);
    for t in n - 8..n {
        let reference = supersampled(W, H, 4, moved(vel, t));
        let r = f32s(&reference.pixels);
        let raw = f32s(&seq[t as usize].image.pixels);
        let (_, _, fx) = crate::common::run(
            &mut engine,
            &["fxaa"],
            &[],
            &seq[t as usize].image,
            Format::Rgba32f,
        )
        .unwrap();
        e_taa += rgb_rmse(&outs[t as usize], r, W, H, 4) / 8.0;
        e_raw += rgb_rmse(raw, r, W, H, 4) / 8.0;
        e_fxaa += rgb_rmse(&crate::common::linear(&fx), r, W, H, 4) / 8.0;
    }
    eprintln!(
        "RMSE against the box-filtered frame: taa {e_taa:.4}, aliased {e_raw:.4}, fxaa {e_fxaa:.4}"
    );
    assert!(e_taa < 0.5 * e_raw, "taa {e_taa} vs aliased {e_raw}");
    assert!(e_taa < 0.75 * e_fxaa, "taa {e_taa} vs fxaa {e_fxaa}");
}

/// A bright square moving over a dark background, frame `t`: (image, motion,
/// depth), the square 14 px wide, from (10, 20) at `vel` px per frame, depth 2
/// (background 10). Motion and depth are those of the surface at each pixel centre.
fn square_frame(vel: [f32; 2], t: u32) -> SeqFrame {
    let (x0, y0) = (10.0 + vel[0] * t as f32, 20.0 + vel[1] * t as f32);
    let inside = move |x: f32, y: f32| x >= x0 && x < x0 + 14.0 && y >= y0 && y < y0 + 14.0;
    let j = halton23(t as u64);
    let image = point_sampled(
        W,
        H,
        j,
        |x, y| {
            if inside(x, y) {
                [1.0, 0.9, 0.8]
            } else {
                BG
            }
        },
    );
    SeqFrame {
        image,
        aux: object_aux(W, H, inside, (vel, 2.0), ([0.0, 0.0], 10.0)),
        jitter: j,
    }
}

const BG: [f32; 3] = [0.05, 0.05, 0.06];

/// Whether pixel (x, y)'s centre is in the square at frame t, and its distance in
/// pixels (Chebyshev, from the centre to the square) otherwise.
fn square_distance(vel: [f32; 2], t: u32, x: u32, y: u32) -> f32 {
    let (x0, y0) = (10.0 + vel[0] * t as f32, 20.0 + vel[1] * t as f32);
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let dx = (x0 - cx).max(cx - (x0 + 14.0)).max(0.0);
    let dy = (y0 - cy).max(cy - (y0 + 14.0)).max(0.0);
    dx.max(dy)
}

fn covered(vel: [f32; 2], t: u32, x: u32, y: u32) -> bool {
    let (x0, y0) = (10.0 + vel[0] * t as f32, 20.0 + vel[1] * t as f32);
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    cx >= x0 && cx < x0 + 14.0 && cy >= y0 && cy < y0 + 14.0
}

fn square_run(
    engine: &mut fxgraph::gpu::executor::Engine,
    set: &[&str],
    vel: [f32; 2],
    n: u32,
) -> Vec<Vec<f32>> {
    let seq: Vec<SeqFrame> = (0..n).map(|t| square_frame(vel, t)).collect();
    run_stream_frames(engine, "taa", set, &seq, 25.0)
}

#[test]
fn no_ghost_where_a_moving_object_was_four_frames_ago() {
    let Some(mut engine) = engine() else { return };
    let vel = [2.5, 0.5];
    let n = 12;
    let last = n - 1;
    let outs = square_run(&mut engine, &[], vel, n);
    let out = &outs[last as usize];
    // The pixels the square covered at frames 0 ..= last - 4 and that are now 2 px
    // or more from it (the pixels beside an edge are partly covered in the box
    // reference too): back to the background within 0.01 (1 % of the contrast).
    let (mut checked, mut worst) = (0, 0.0f32);
    for y in 0..H {
        for x in 0..W {
            let was = (0..=last - 4).any(|t| covered(vel, t, x, y));
            if !was || square_distance(vel, last, x, y) < 2.0 {
                continue;
            }
            checked += 1;
            let i = ((y * W + x) * 4) as usize;
            for c in 0..3 {
                worst = worst.max((out[i + c] - BG[c]).abs());
            }
        }
    }
    eprintln!("{checked} uncovered pixels, largest difference from the background {worst:.5}");
    assert!(checked > 300, "{checked}");
    assert!(worst <= 0.01, "ghost: {worst}");
}

#[test]
fn history_is_reset_where_it_falls_off_screen_or_is_disoccluded() {
    let Some(mut engine) = engine() else { return };
    // view = history: n / frames as grey (frames = 10).
    let vel = [2.5, 0.5];
    let n = 14;
    let last = n - 1;
    let outs = square_run(&mut engine, &["view=history"], vel, n);
    let out = &outs[last as usize];
    let conf = |x: u32, y: u32| out[((y * W + x) * 4) as usize];
    // Uncovered by the last move (the square was there one frame ago, the pixel's
    // 3x3 neighbourhood is background now: its centre 1.5 px or more from the
    // square): reset, n = 1.
    let mut uncovered = 0;
    for y in 0..H {
        for x in 0..W {
            if covered(vel, last - 1, x, y) && square_distance(vel, last, x, y) >= 1.5 {
                uncovered += 1;
                assert!(
                    (conf(x, y) - 0.1).abs() < 0.01,
                    "({x}, {y}): {}",
                    conf(x, y)
                );
            }
        }
    }
    assert!(uncovered >= 14, "{uncovered}");
    // The static background far from the square's path: a full history.
    for (x, y) in [(5, 5), (90, 90), (50, 5), (5, 60)] {
        assert!(
            (conf(x, y) - 1.0).abs() < 0.01,
            "({x}, {y}): {}",
            conf(x, y)
        );
    }
    // Content entering at the left edge (the pattern moves right 2 px per frame;
    // whole pixels, so the history is not shortened for resampling): columns 0
    // and 1 were outside the frame one frame earlier, so they are always new; the
    // interior has a full history.
    let vel = [2.0, 0.0];
    let seq = translating_sequence(vel, 12);
    let outs = run_stream_frames(&mut engine, "taa", &["view=history"], &seq, 25.0);
    let out = &outs[11];
    let conf = |x: u32, y: u32| out[((y * W + x) * 4) as usize];
    for y in 0..H {
        for x in [0, 1] {
            assert!(
                (conf(x, y) - 0.1).abs() < 0.01,
                "column {x}, row {y}: {}",
                conf(x, y)
            );
        }
        assert!(
            (conf(48, y) - 1.0).abs() < 0.01,
            "column 48, row {y}: {}",
            conf(48, y)
        );
    }
}

/// A still frame source without jitter: the output is the input (the history of a
/// static, unjittered image is that image), the first frame included.
#[test]
fn a_static_unjittered_sequence_passes_through() {
    let Some(mut engine) = engine() else { return };
    let img: Image = point_sampled(W, H, [0.0, 0.0], checker);
    let seq: Vec<SeqFrame> = (0..4)
        .map(|_| SeqFrame {
            image: img.clone(),
            aux: uniform_aux([0.0, 0.0]),
            jitter: [0.0, 0.0],
        })
        .collect();
    let outs = run_stream_frames(&mut engine, "taa", &[], &seq, 25.0);
    // The Gaussian reconstruction weighs the neighbours a little (sigma 0.4 px:
    // exp(-1 / 0.32) = 4 % each side), so edges soften slightly; flat areas are exact.
    for out in &outs {
        let e = rgb_rmse(out, f32s(&img.pixels), W, H, 0);
        assert!(e < 0.08, "{e}");
        let i = ((3 * W + 3) * 4) as usize; // inside a flat cell
        assert!((out[i] - f32s(&img.pixels)[i]).abs() < 1e-3);
    }
}

/// The current frame's jitter is taken out (the standard value `jitter`): with no
/// history (frames = 1) the output of a jittered linear ramp is much nearer the
/// unjittered ramp than the jittered frame is, and it is not when the jitter is
/// not given (reported as 0).
#[test]
fn the_jitter_is_removed_from_the_current_frame() {
    let Some(mut engine) = engine() else { return };
    let ramp = |x: f32, y: f32| [x / W as f32, y / H as f32, 0.5];
    let truth = point_sampled(W, H, [0.0, 0.0], ramp);
    let frames = |told: bool| -> Vec<SeqFrame> {
        (0..16u64)
            .map(|t| SeqFrame {
                image: point_sampled(W, H, halton23(t), ramp),
                aux: uniform_aux([0.0, 0.0]),
                jitter: if told { halton23(t) } else { [0.0, 0.0] },
            })
            .collect()
    };
    let told = frames(true);
    let raw: f64 = told
        .iter()
        .map(|f| rgb_rmse(f32s(&f.image.pixels), f32s(&truth.pixels), W, H, 2))
        .sum();
    let err = |outs: &[Vec<f32>]| -> f64 {
        outs.iter()
            .map(|o| rgb_rmse(o, f32s(&truth.pixels), W, H, 2))
            .sum()
    };
    let with = err(&run_stream_frames(
        &mut engine,
        "taa",
        &["frames=1"],
        &told,
        25.0,
    ));
    let without = err(&run_stream_frames(
        &mut engine,
        "taa",
        &["frames=1"],
        &frames(false),
        25.0,
    ));
    eprintln!("ramp error over 16 frames: jittered frames {raw:.4}, taa told the jitter {with:.4}, not told {without:.4}");
    assert!(with < 0.6 * raw, "{with} vs {raw}");
    assert!((without - raw).abs() < 0.05 * raw, "{without} vs {raw}");
}
