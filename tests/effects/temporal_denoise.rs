//! GPU tests of the temporal_denoise effect (motion-compensated recursive
//! filtering, spatial fallback, noise estimate): quality on moving and static
//! noisy sequences, ghosting behind a moving edge, scene cuts, the noise estimate.
//! Measured values are printed (`-- --nocapture`).
//!
//! The effect works on sRGB code values (0..1 = 0..255 in 8 bits): the frames here
//! are 8-bit images, their noise is added to the code values, and the outputs are
//! compared as code values.

use crate::common::rng::hash01;

use crate::common::stream::run_stream;
use crate::common::*;
use fxgraph::gpu::executor::Engine;
use fxgraph::io::Image;

/// Deterministic zero-mean, near-Gaussian noise of standard deviation `sigma`
/// (Box-Muller on two hashes).
fn gauss(seed: u64, sigma: f32) -> f32 {
    let u1 = hash01(2 * seed).max(1e-7);
    let u2 = hash01(2 * seed + 1);
    sigma * (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
}

/// A frame: RGB code values in 0..1, `w * h * 3`.
struct Frame {
    w: u32,
    h: u32,
    rgb: Vec<f32>,
}

impl Frame {
    fn new(w: u32, h: u32, f: impl Fn(f32, f32) -> [f32; 3]) -> Frame {
        let mut rgb = Vec::with_capacity((w * h * 3) as usize);
        for y in 0..h {
            for x in 0..w {
                rgb.extend_from_slice(&f(x as f32, y as f32));
            }
        }
        Frame { w, h, rgb }
    }

    /// The frame plus noise of `sigma` (code values), as an 8-bit image.
    fn noisy(&self, seed: u64, sigma: f32) -> (Image, Vec<f32>) {
        let q: Vec<f32> = self
            .rgb
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let n = gauss(seed.wrapping_mul(0x9e37_79b9) ^ (i as u64) << 20, sigma);
                ((c + n) * 255.0).round().clamp(0.0, 255.0) / 255.0
            })
            .collect();
        let img = image_u8(self.w, self.h, |x, y| {
            let i = ((y * self.w + x) * 3) as usize;
            [
                (q[i] * 255.0) as u8,
                (q[i + 1] * 255.0) as u8,
                (q[i + 2] * 255.0) as u8,
                255,
            ]
        });
        (img, q)
    }
}

/// RGB code values of an output (linear RGBA f32 from `run_stream`).
fn code_values(out: &[f32]) -> Vec<f32> {
    out.chunks(4)
        .flat_map(|p| {
            [
                linear_to_srgb(p[0]),
                linear_to_srgb(p[1]),
                linear_to_srgb(p[2]),
            ]
        })
        .collect()
}

/// A smooth random texture (sum of sines of several frequencies and directions)
/// seen through a window moved by (ox, oy) px: frame(x, y) = tex(x + ox, y + oy).
fn texture(x: f32, y: f32, k: f32) -> [f32; 3] {
    let a = (0.31 * x + 0.17 * y + k).sin() + 0.7 * (0.13 * x - 0.41 * y).sin();
    let b = (0.23 * x - 0.07 * y + 2.0 * k).cos() + 0.5 * (0.57 * x + 0.29 * y).sin();
    let l = 0.5 + 0.12 * a + 0.08 * b;
    [l + 0.05 * b, l, l - 0.04 * a]
}

fn run(engine: &mut Engine, overrides: &[&str], frames: &[Image]) -> Vec<Vec<f32>> {
    run_stream(engine, "temporal_denoise", overrides, frames, 1)
        .iter()
        .map(|o| code_values(o))
        .collect()
}

const SIGMA: f32 = 8.0 / 255.0;

/// A fine texture panning by (1.5, 0.75) px per frame (sub-pixel in y) with noise of
/// 8/255: after the warm-up the output is far closer to the clean frames than
/// the input, and the motion compensation matters (without it, frames = 1, the
/// gain is only the spatial filter's).
#[test]
fn moving_texture_is_denoised() {
    let Some(mut engine) = engine() else {
        return;
    };
    let (w, h, n) = (96, 64, 12u64);
    let clean: Vec<Frame> = (0..n)
        .map(|t| {
            let (ox, oy) = (1.5 * t as f32, 0.75 * t as f32);
            Frame::new(w, h, |x, y| texture(2.5 * (x + ox), 2.5 * (y + oy), 0.0))
        })
        .collect();
    let noisy: Vec<(Image, Vec<f32>)> = clean
        .iter()
        .enumerate()
        .map(|(t, f)| f.noisy(t as u64, SIGMA))
        .collect();
    let frames: Vec<Image> = noisy.iter().map(|(i, _)| i.clone()).collect();
    let outs = run(&mut engine, &[], &frames);
    let spatial_only = run(&mut engine, &["frames=1"], &frames);
    let mut gains = Vec::new();
    for t in 6..n as usize {
        let p_in = psnr(&noisy[t].1, &clean[t].rgb, 1.0);
        let p_out = psnr(&outs[t], &clean[t].rgb, 1.0);
        let p_sp = psnr(&spatial_only[t], &clean[t].rgb, 1.0);
        println!("frame {t}: noisy {p_in:.2} dB, temporal_denoise {p_out:.2} dB, spatial only {p_sp:.2} dB");
        gains.push((p_out - p_in, p_out - p_sp));
    }
    for (g, over_spatial) in gains {
        assert!(g > 5.0, "PSNR gain over the noisy input only {g:.2} dB");
        assert!(
            over_spatial > 3.0,
            "temporal gain over the spatial fallback only {over_spatial:.2} dB"
        );
    }
}

/// A bright bar (0.85) moving right by 3 px per frame over a dark noisy
/// background (0.15): behind its trailing edge, where it was during the previous
/// frames, the output has no residue of it. Column means of out - clean over the
/// background (64 rows: the noise averages out) stay below 0.02 (3% of the bar's
/// contrast), and the bar itself is not smeared ahead of or behind its position.
#[test]
fn moving_bar_leaves_no_ghost() {
    let Some(mut engine) = engine() else {
        return;
    };
    let (w, h, n) = (96u32, 64u32, 10u64);
    let left = |t: u64| 20.0 + 3.0 * t as f32;
    let clean: Vec<Frame> = (0..n)
        .map(|t| {
            Frame::new(w, h, |x, _| {
                let v = if x >= left(t) && x < left(t) + 12.0 {
                    0.85
                } else {
                    0.15
                };
                [v, v, v]
            })
        })
        .collect();
    let noisy: Vec<(Image, Vec<f32>)> = clean
        .iter()
        .enumerate()
        .map(|(t, f)| f.noisy(100 + t as u64, SIGMA))
        .collect();
    let frames: Vec<Image> = noisy.iter().map(|(i, _)| i.clone()).collect();
    let outs = run(&mut engine, &[], &frames);
    let t = (n - 1) as usize;
    let column_residue = |out: &[f32], x: u32| -> f64 {
        let mut s = 0.0;
        for y in 0..h {
            for c in 0..3 {
                let i = ((y * w + x) * 3) as usize + c;
                s += (out[i] - clean[t].rgb[i]) as f64;
            }
        }
        s / (3 * h) as f64
    };
    let l = left(t as u64) as u32;
    // Everything the bar covered in the earlier frames (x from 20 up to its
    // current left edge) and a margin ahead of it.
    let behind: Vec<f64> = (20..l).map(|x| column_residue(&outs[t], x)).collect();
    let ahead: Vec<f64> = (l + 13..w).map(|x| column_residue(&outs[t], x)).collect();
    let worst = |v: &[f64]| v.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    println!(
        "moving bar, frame {t}: worst column residue behind the bar {:.4}, ahead {:.4}; behind {:?}",
        worst(&behind),
        worst(&ahead),
        behind.iter().map(|r| format!("{r:.3}")).collect::<Vec<_>>()
    );
    assert!(worst(&behind) < 0.02, "ghost behind the bar: {behind:?}");
    assert!(worst(&ahead) < 0.02, "smear ahead of the bar: {ahead:?}");
    // The bar keeps its contrast (inside, away from its edges).
    let inside: Vec<f64> = (l + 2..l + 10)
        .map(|x| column_residue(&outs[t], x))
        .collect();
    assert!(worst(&inside) < 0.02, "the bar lost contrast: {inside:?}");
    // And the background is denoised.
    let bg = |o: &[f32]| {
        let mut e = Vec::new();
        for y in 0..h {
            for x in (0..16).chain(l + 16..w) {
                let i = ((y * w + x) * 3) as usize;
                e.extend((0..3).map(|c| o[i + c] - clean[t].rgb[i + c]));
            }
        }
        (e.iter().map(|v| (v * v) as f64).sum::<f64>() / e.len() as f64).sqrt()
    };
    let (r_in, r_out) = (bg(&noisy[t].1), bg(&outs[t]));
    println!("background rms error: noisy {r_in:.4}, output {r_out:.4}");
    assert!(r_out < 0.5 * r_in, "background {r_out} vs noisy {r_in}");
}

/// A static noisy scene is denoised strongly (more than 6 dB by frame 9), steadily
/// and without bias; a cut
/// to another scene at frame 10 does not leak the first one: from the cut on, the
/// output is that of a run that starts at the cut (no history), up to a share of
/// the old scene below 1% (the least-squares coefficient of the difference on
/// old - new, over the samples where the scenes differ by more than 3 sigma). The
/// noise level is given (sigma = 8/255) so both runs filter alike.
#[test]
fn static_scene_is_denoised_and_a_cut_does_not_leak() {
    let Some(mut engine) = engine() else {
        return;
    };
    let (w, h) = (64, 64);
    let a = Frame::new(w, h, |x, y| texture(x, y, 0.0));
    let b = Frame::new(w, h, |x, y| {
        let c = texture(y + 7.0, x + 3.0, 1.7);
        [1.0 - c[0], 0.9 - c[1], 1.0 - c[2]]
    });
    let scene = |t: usize| if t < 10 { &a } else { &b };
    let noisy: Vec<(Image, Vec<f32>)> = (0..13)
        .map(|t| scene(t).noisy(500 + t as u64, SIGMA))
        .collect();
    let frames: Vec<Image> = noisy.iter().map(|(i, _)| i.clone()).collect();
    let sigma = format!("sigma={SIGMA}");
    let outs = run(&mut engine, &[&sigma], &frames);
    let fresh = run(&mut engine, &[&sigma], &frames[10..]);
    let gain =
        |t: usize| psnr(&outs[t], &scene(t).rgb, 1.0) - psnr(&noisy[t].1, &scene(t).rgb, 1.0);
    let gains: Vec<String> = (0..13).map(|t| format!("{:.2}", gain(t))).collect();
    println!("PSNR gain per frame (cut at 10): {gains:?}");
    assert!(gain(9) > 6.0, "static gain at frame 9: {:.2} dB", gain(9));
    // The running mean converges steadily (from frame 1: frame 0 is the spatial
    // filter alone) and without bias.
    for t in 2..10 {
        assert!(
            gain(t) > gain(t - 1) - 0.05,
            "gain fell at frame {t}: {gains:?}"
        );
    }
    let bias = outs[9]
        .iter()
        .zip(&a.rgb)
        .map(|(o, c)| (o - c) as f64)
        .sum::<f64>()
        / a.rgb.len() as f64;
    println!("mean error at frame 9: {bias:.5}");
    assert!(bias.abs() < 0.002, "bias {bias}");
    assert!(gain(10) > 2.0, "the cut frame: {:.2} dB", gain(10));
    for t in 10..13 {
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for i in 0..b.rgb.len() {
            let d = (a.rgb[i] - b.rgb[i]) as f64;
            if d.abs() > 3.0 * SIGMA as f64 {
                num += (outs[t][i] - fresh[t - 10][i]) as f64 * d;
                den += d * d;
            }
        }
        let diff = max_abs_diff(&outs[t], &fresh[t - 10]);
        println!(
            "frame {t}: share of the old scene {:.4}, max |out - fresh run| {diff:.4}",
            num / den
        );
        assert!(
            den > 0.0 && (num / den).abs() < 0.01,
            "frame {t} leaks {:.4} of the old scene",
            num / den
        );
    }
}

/// The noise estimate (`view=sigma` shows it) lands within 15% of the true
/// standard deviation for two noise levels, on a textured image with flat and
/// busy parts, at the first frame (no temporal smoothing yet).
#[test]
fn noise_estimate_is_close_to_the_true_sigma() {
    let Some(mut engine) = engine() else {
        return;
    };
    let (w, h) = (128, 128);
    // Left half: a smooth ramp; right half: texture.
    let img = Frame::new(w, h, |x, y| {
        if x < 64.0 {
            let v = 0.3 + 0.3 * y / 128.0;
            [v, v + 0.05, v - 0.05]
        } else {
            texture(3.0 * x, 3.0 * y, 0.5)
        }
    });
    for sigma8 in [4.0f32, 12.0] {
        let (frame, _) = img.noisy(sigma8 as u64, sigma8 / 255.0);
        let out = run(&mut engine, &["view=sigma"], &[frame]);
        let est = out[0][0] * 255.0;
        println!("noise estimate: true sigma {sigma8}/255, estimate {est:.2}/255");
        assert!(
            (est / sigma8 - 1.0).abs() < 0.15,
            "sigma {sigma8}: estimate {est}"
        );
    }
}
