//! The seed `glow` and its downsampling blurs: the halo is isotropic (no stripes
//! from skipped input columns), the downsampling blurX/blurY match a CPU oracle
//! that prefilters, the whole effect matches a CPU model, its plan peaks at the
//! lower bound, and the defaults visibly glow on an ordinary photo.

use crate::common::samples::{f16r, f32s};
use crate::common::*;
use crate::oracle::*;
use fxgraph::io::Pixels;
use fxgraph::script::types::Format;
use std::path::PathBuf;

/// Float pixels as f64 samples.
fn f64s(p: &Pixels) -> Vec<f64> {
    match p {
        Pixels::F32(v) => v.iter().map(|&x| x as f64).collect(),
        Pixels::U8(_) => panic!("expected float pixels"),
    }
}

/// A one-pass effect file `SHADER.{shader} { img = IN  OUT.SCALE = scale  sigma }`
/// in a temporary folder (the shader comes from the built-in library).
fn one_pass_effect(name: &str, shader: &str, scale: f64, sigma: f64) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fxgraph-glow-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.fx"));
    std::fs::write(
        &path,
        format!(
            "EFFECT.{name} = {{\n    PASS = {{\n        b = SHADER.{shader} {{ img = IN  OUT.SCALE = {scale}  sigma = {sigma} }}\n    }}\n    OUT = b\n}}\n"
        ),
    )
    .unwrap();
    path
}

/// Mean absolute second difference of channel 0 along x and along y over the
/// pixels of `region` (x and y ranges, the same for both) outside `skip`.
fn second_differences(
    v: &[f64],
    w: u32,
    region: std::ops::Range<u32>,
    skip: std::ops::Range<u32>,
) -> (f64, f64) {
    let at = |x: u32, y: u32| v[((y * w + x) * 4) as usize];
    let (mut dx, mut dy, mut n) = (0.0, 0.0, 0.0);
    for y in region.clone() {
        for x in region.clone() {
            if skip.contains(&x) && skip.contains(&y) {
                continue;
            }
            dx += (at(x + 1, y) - 2.0 * at(x, y) + at(x - 1, y)).abs();
            dy += (at(x, y + 1) - 2.0 * at(x, y) + at(x, y - 1)).abs();
            n += 1.0;
        }
    }
    (dx / n, dy / n)
}

#[test]
fn glow_halo_is_isotropic() {
    let Some(mut eng) = engine() else { return };
    // An 8x8 white square on black, 128x128, placed symmetrically in x and y.
    let (w, h) = (128, 128);
    let img = image_f32(w, h, |x, y| {
        let v = if (60..68).contains(&x) && (60..68).contains(&y) {
            1.0
        } else {
            0.0
        };
        [v, v, v, 1.0]
    });
    let src = f64s(&img.pixels);
    let mut ratios = Vec::new();
    for sigma in [2.0, 4.0, 8.0] {
        let sx = format!("blurX.sigma={sigma}");
        let sy = format!("blurY.sigma={sigma}");
        let px = apply_fx(&mut eng, "glow", &[&sx, &sy], &img, Format::Rgba32f);
        // The halo: what glow adds.
        let halo: Vec<f64> = f64s(&px).iter().zip(&src).map(|(a, b)| a - b).collect();
        let peak = halo.iter().cloned().fold(0.0, f64::max);
        // Around the square (within 20 px), off it and its edges.
        let (dx, dy) = second_differences(&halo, w, 40..88, 58..70);
        let ratio = dx / dy;
        eprintln!(
            "glow sigma {sigma}: halo peak {peak:.4}, second differences x {dx:.3e} y {dy:.3e}, ratio {ratio:.3}"
        );
        assert!(peak > 0.01, "sigma {sigma}: no halo");
        ratios.push((sigma, ratio));
    }
    for (sigma, ratio) in ratios {
        assert!(
            (ratio - 1.0).abs() < 0.1,
            "sigma {sigma}: second differences along x are {ratio:.3}x those along y"
        );
    }
}

#[test]
fn downsampling_blurs_match_the_prefiltering_oracle() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(64, 48), (67, 41)] {
        // Hard edges, thin lines and single HDR pixels: what skipped columns miss.
        let img = image_f32(w, h, |x, y| {
            let (fx, fy) = (x as f64, y as f64);
            let mut c = [0.1 + 0.5 * fx / w as f64, 0.2, 0.1 + 0.4 * fy / h as f64];
            if (fx - 20.0).powi(2) + (fy - 15.0).powi(2) < 30.0 {
                c = [3.0, 2.0, 1.0];
            }
            if x % 9 == 4 {
                c[1] = 2.5;
            }
            if y % 7 == 3 {
                c[2] = 1.5;
            }
            if (x * 7 + y * 13) % 97 == 0 {
                c = [8.0, 8.0, 8.0];
            }
            [f16r(c[0]) as f32, f16r(c[1]) as f32, f16r(c[2]) as f32, 1.0]
        });
        let src = f64s(&img.pixels);
        for (shader, horizontal) in [("blurX", true), ("blurY", false)] {
            for (scale, sigma) in [(0.5, 1.5), (0.5, 4.0), (0.25, 2.0)] {
                let fx = one_pass_effect(&format!("down_{shader}"), shader, scale, sigma);
                let (ow, oh, px) = run(
                    &mut eng,
                    &[fx.to_str().unwrap()],
                    &[],
                    &img,
                    Format::Rgba32f,
                )
                .unwrap();
                let expect_size = (
                    ((w as f64 * scale).round() as u32),
                    ((h as f64 * scale).round() as u32),
                );
                assert_eq!((ow, oh), expect_size);
                let pass = BlurPass {
                    from: (w, h),
                    to: (ow, oh),
                    sigma,
                    horizontal,
                };
                let want = pass.prefiltered(&src);
                let got = f64s(&px);
                // Half-float storage is modelled; what remains is f32 arithmetic,
                // the sampler's weight precision and rounding-boundary flips:
                // relative to max(1, |value|).
                let err = got
                    .iter()
                    .zip(&want)
                    .map(|(g, o)| (g - o).abs() / o.abs().max(1.0))
                    .fold(0.0, f64::max);
                eprintln!("{shader} {w}x{h} -> {ow}x{oh} sigma {sigma}: max error {err:.2e}");
                assert!(
                    err < 2e-3,
                    "{shader} {w}x{h} scale {scale} sigma {sigma}: {err} from the oracle"
                );
            }
        }
    }
}

/// PSNR (8-bit samples, RGB) of glow's output on the README's photo against the
/// input, and the share of pixels newly clipped (a channel at 255 that was not).
fn photo_psnr(eng: &mut fxgraph::gpu::executor::Engine, overrides: &[&str]) -> (f64, f64) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/data/rocket.jpg");
    let img = fxgraph::io::load_image(std::path::Path::new(path), &Default::default()).unwrap();
    let (_, _, px) = run(eng, &["glow"], overrides, &img, Format::Rgba8Srgb).unwrap();
    let (Pixels::U8(a), Pixels::U8(b)) = (&px, &img.pixels) else {
        panic!("expected 8-bit pixels")
    };
    let rgb = |v: &[u8]| -> Vec<f32> {
        v.chunks(4)
            .flat_map(|c| [c[0], c[1], c[2]])
            .map(|x| x as f32 / 255.0)
            .collect()
    };
    let clipped = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(o, i)| (0..3).any(|c| o[c] == 255 && i[c] < 255))
        .count() as f64
        / (a.len() / 4) as f64;
    (psnr(&rgb(a), &rgb(b), 1.0), clipped)
}

#[test]
fn default_glow_visibly_glows_on_a_photo_without_blowing_it_out() {
    let Some(mut eng) = engine() else { return };
    // The defaults (threshold 0.4, knee 0.3, intensity 1): 35.5 dB against the
    // input; the shaders' earlier defaults (0.7, 0.2) gave 46.5 dB, barely visible.
    let (q, clipped) = photo_psnr(&mut eng, &[]);
    let (q_old, _) = photo_psnr(
        &mut eng,
        &["brightPass.threshold=0.7", "brightPass.knee=0.2"],
    );
    eprintln!(
        "glow on rocket.jpg: PSNR {q:.2} dB (earlier defaults {q_old:.2} dB), newly clipped {:.2} %",
        clipped * 100.0
    );
    assert!((30.0..40.0).contains(&q), "default glow: PSNR {q:.2} dB");
    assert!(
        clipped < 0.01,
        "default glow clips {:.2} % of the pixels",
        clipped * 100.0
    );
}

/// CPU model of the seed `glow` (effects/glow.fx) on a float image: brightPass at
/// full size, blurX at half size (a prefiltering downsampling blur, sigma 4 in
/// half-size pixels) and blurY at half size (the shader's tap positions and paired
/// weights, bilinear sampling, clamp to edge),
/// then add with a bilinear upsample. rgba16f intermediates are rounded to half.
fn glow_oracle(src: &[f64], w: u32, h: u32) -> Vec<f64> {
    let (threshold, knee, sigma): (f64, f64, f64) = (0.4, 0.3, 4.0);
    let bright: Vec<f64> = src
        .chunks(4)
        .flat_map(|c| {
            let luma = luma709(c);
            let soft = (luma - threshold + knee).clamp(0.0, 2.0 * knee);
            let contribution = (soft * soft / (4.0 * knee)).max(luma - threshold);
            let scale = contribution.max(0.0) / luma.max(1e-5);
            [
                f16r(c[0] * scale),
                f16r(c[1] * scale),
                f16r(c[2] * scale),
                f16r(c[3]),
            ]
        })
        .collect();
    let hs = half_size(w, h);
    let bx = BlurPass::along_x((w, h), hs, sigma).prefiltered(&bright);
    let by = BlurPass::along_y(hs, hs, sigma).bilinear(&bx);
    let mut out = Vec::with_capacity(src.len());
    for y in 0..h {
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            for c in 0..3 {
                out.push(src[i + c] + upsample(&by, hs, x, y, (w, h), c));
            }
            out.push(src[i + 3]);
        }
    }
    out
}

#[test]
fn glow_matches_the_cpu_model() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(64, 48), (67, 41)] {
        // A dim gradient with HDR highlights (a bright disc, a line, single pixels)
        // and a soft-knee band around the threshold.
        let img = image_f32(w, h, |x, y| {
            let (fx, fy) = (x as f64, y as f64);
            let disc = (fx - 20.0).powi(2) + (fy - 15.0).powi(2) < 25.0;
            let mut c = [0.1 + 0.6 * fx / w as f64, 0.2, 0.15 + 0.5 * fy / h as f64];
            if disc {
                c = [3.0, 2.5, 1.0];
            }
            if y == 30 && x > 30 {
                c = [0.2, 1.5, 4.0];
            }
            if (x * 7 + y * 13) % 97 == 0 {
                c = [8.0, 8.0, 8.0];
            }
            [f16r(c[0]) as f32, f16r(c[1]) as f32, f16r(c[2]) as f32, 1.0]
        });
        let src = f64s(&img.pixels);
        let want = glow_oracle(&src, w, h);
        let px = apply_fx(&mut eng, "glow", &[], &img, Format::Rgba32f);
        let got = f32s(&px);
        // Error relative to the glow added (output - input), in units of the
        // largest glow value.
        let glow_max = want
            .iter()
            .zip(&src)
            .map(|(a, b)| a - b)
            .fold(0.0, f64::max);
        let mut max_abs: f64 = 0.0;
        for (&g, &o) in got.iter().zip(&want) {
            // Half-float rounding of the intermediates is modelled; what remains is
            // f32 vs f64 arithmetic, the sampler's weight precision and
            // rounding-boundary flips of the halves: relative to max(1, |value|).
            max_abs = max_abs.max((g as f64 - o).abs() / o.abs().max(1.0));
        }
        eprintln!("glow {w}x{h}: max error {max_abs:.2e} (largest glow {glow_max:.3})");
        assert!(glow_max > 0.5, "test image does not glow");
        assert!(max_abs < 2e-3, "glow {w}x{h}: {max_abs} from the CPU model");
    }
}

#[test]
fn glow_plan_peak_is_the_lower_bound() {
    for (w, h) in [(64, 64), (67, 41), (1920, 1080)] {
        let (p, warnings, _) = plan_for(&["effects/glow.fx"], w, h);
        assert_eq!(warnings, 0);
        assert_eq!(p.peak_bytes, p.lower_bound_bytes, "{w}x{h}");
        assert_eq!(p.validate(), Ok(p.peak_bytes));
        // brightPass (full, rgba16f) is still alive while blurX (half) runs; then
        // blurX and blurY (both half) are alive together.
        let (w2, h2) = (
            ((w as f64) * 0.5).round() as u64,
            ((h as f64) * 0.5).round() as u64,
        );
        let full = w as u64 * h as u64 * 8;
        let half = w2 * h2 * 8;
        assert_eq!(p.lower_bound_bytes, (full + half).max(2 * half), "{w}x{h}");
    }
}
