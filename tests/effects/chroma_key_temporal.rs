//! `chroma_key_temporal` through the streaming runtime: a flickering matte is
//! stabilised where the scene is static and follows where it moves.

use crate::common::rng::noise;
use crate::common::samples::*;
use crate::common::stream::run_stream;
use crate::common::*;
use fxgraph::io::Image;

const KW: u32 = 64;
const KH: u32 = 64;

/// Frame `t` of a green-screen shot: a backdrop slightly off the key colour with
/// per-frame noise (8 codes per channel), which makes chroma_key's soft band
/// flicker; a static red square; a blue square moving 4 px per frame.
fn green_screen(t: u32) -> Image {
    image_u8(KW, KH, |x, y| {
        let moving_x = 2 + 4 * t;
        if (4..20).contains(&x) && (4..20).contains(&y) {
            [200, 50, 40, 255]
        } else if (40..52).contains(&y) && (moving_x..moving_x + 12).contains(&x) {
            [50, 70, 200, 255]
        } else {
            let seed = ((t as u64 * KH as u64 + y as u64) * KW as u64 + x as u64) * 3;
            let px =
                |base: f32, c: u64| (base + noise(seed + c, 8.0)).round().clamp(0.0, 255.0) as u8;
            [px(95.0, 0), px(196.0, 1), px(74.0, 2), 255]
        }
    })
}

fn alphas(v: &[f32], keep: impl Fn(u32, u32) -> bool) -> Vec<f32> {
    let mut out = Vec::new();
    for y in 0..KH {
        for x in 0..KW {
            if keep(x, y) {
                out.push(at(v, KW, x, y, 3));
            }
        }
    }
    out
}

/// Mean squared frame-to-frame change of the alpha over `keep`, frames `from..`.
fn alpha_flicker(outs: &[Vec<f32>], from: usize, keep: impl Fn(u32, u32) -> bool + Copy) -> f64 {
    let mut sum = 0.0;
    let mut n = 0.0;
    for t in from..outs.len() {
        let (a, b) = (alphas(&outs[t], keep), alphas(&outs[t - 1], keep));
        sum += a
            .iter()
            .zip(&b)
            .map(|(p, q)| ((p - q) as f64).powi(2))
            .sum::<f64>();
        n += a.len() as f64;
    }
    sum / n
}

/// Mean over the pixels of `keep` of the alpha's variance over the frames `outs`.
fn alpha_temporal_variance(outs: &[Vec<f32>], keep: impl Fn(u32, u32) -> bool + Copy) -> f64 {
    let series: Vec<Vec<f32>> = outs.iter().map(|o| alphas(o, keep)).collect();
    let n = series[0].len();
    (0..n)
        .map(|i| {
            let v: Vec<f32> = series.iter().map(|s| s[i]).collect();
            std_dev(&v).powi(2)
        })
        .sum::<f64>()
        / n as f64
}

/// The temporally smoothed matte flickers much less than chroma_key's on a noisy
/// backdrop, starts equal to it, and follows a moving foreground at once.
#[test]
fn chroma_key_temporal_stabilises_a_flickering_matte() {
    let Some(mut engine) = engine() else {
        return;
    };
    let n = 12u32;
    let frames: Vec<Image> = (0..n).map(green_screen).collect();
    let plain = run_stream(&mut engine, "chroma_key", &[], &frames, 1);
    let temporal = run_stream(&mut engine, "chroma_key_temporal", &[], &frames, 1);
    // Frame 0: chroma_key's matte (8-bit alpha inside the effect) and colour.
    let d0 = max_abs_diff(
        &alphas(&temporal[0], |_, _| true),
        &alphas(&plain[0], |_, _| true),
    );
    // 8-bit alpha inside the effect, then the r16f matte.
    assert!(d0 <= 1.0 / 255.0, "frame 0 alpha differs by {d0}");
    let c0 = max_abs_diff(
        &select_rgb(&temporal[0], KW, KH, |_, _| true),
        &select_rgb(&plain[0], KW, KH, |_, _| true),
    );
    assert!(c0 < 0.01, "frame 0 colour differs by {c0}");
    // Backdrop only: away from the squares.
    let backdrop = |x: u32, y: u32| !((x < 23 && y < 23) || (37..55).contains(&y));
    let bg_alpha = mean(&alphas(&plain[5], backdrop));
    let f_plain = alpha_flicker(&plain, 4, backdrop);
    let f_temporal = alpha_flicker(&temporal, 4, backdrop);
    let (v_plain, v_temporal) = (
        alpha_temporal_variance(&plain[4..], backdrop),
        alpha_temporal_variance(&temporal[4..], backdrop),
    );
    println!(
        "chroma_key_temporal: backdrop mean alpha {bg_alpha:.3}; frames 4-11: mean squared frame-to-frame alpha change chroma_key {f_plain:.5}, temporal {f_temporal:.5} (ratio {:.3}); per-pixel alpha variance over time {v_plain:.5} vs {v_temporal:.5} (ratio {:.3})",
        f_temporal / f_plain,
        v_temporal / v_plain
    );
    assert!(
        f_plain > 0.002,
        "the test backdrop should flicker: {f_plain}"
    );
    assert!(f_temporal < 0.25 * f_plain, "{f_temporal} vs {f_plain}");
    assert!(v_temporal < 0.5 * v_plain, "{v_temporal} vs {v_plain}");
    // The static red square stays opaque.
    let red = |x: u32, y: u32| (5..19).contains(&x) && (5..19).contains(&y);
    for out in &temporal {
        assert!(alphas(out, red).iter().all(|&a| a > 0.999));
    }
    // The moving square: opaque where it arrives, the current matte where it left.
    let mut worst_left = 0f32;
    for t in 1..n {
        let (x0, x1) = (2 + 4 * (t - 1), 2 + 4 * t);
        let arrived = alphas(&temporal[t as usize], |x, y| {
            (41..51).contains(&y) && (x1 + 1..x1 + 11).contains(&x)
        });
        assert!(arrived.iter().all(|&a| a > 0.98), "frame {t}: {arrived:?}");
        let left = |x: u32, y: u32| (41..51).contains(&y) && (x0 + 1..x1 - 1).contains(&x);
        let d = max_abs_diff(
            &alphas(&temporal[t as usize], left),
            &alphas(&plain[t as usize], left),
        );
        worst_left = worst_left.max(d);
    }
    println!("chroma_key_temporal: max |alpha - chroma_key alpha| where the square just left: {worst_left:.4}");
    assert!(worst_left < 0.02, "{worst_left}");
    // The other output forms carry the same smoothed matte.
    let short = &frames[..4];
    let pre = run_stream(
        &mut engine,
        "chroma_key_temporal",
        &["output=premultiplied"],
        short,
        1,
    );
    let matte = run_stream(
        &mut engine,
        "chroma_key_temporal",
        &["output=matte"],
        short,
        1,
    );
    for t in 0..short.len() {
        for (i, px) in temporal[t].chunks_exact(4).enumerate() {
            let a = px[3];
            let (p, m) = (&pre[t][i * 4..i * 4 + 4], &matte[t][i * 4..i * 4 + 4]);
            for c in 0..3 {
                assert!((p[c] - px[c] * a).abs() < 1e-3, "premultiplied");
                assert!((m[c] - srgb_to_linear(a)).abs() < 1e-3, "matte");
            }
            assert!((p[3] - a).abs() < 1e-6 && m[3] == 1.0);
        }
    }
}
