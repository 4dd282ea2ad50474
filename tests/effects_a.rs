//! GPU tests of the built-in effects gaussian_blur, bloom, tonemap, color_grade,
//! vignette and sharpen against CPU oracles (f64 implementations of the formulas
//! documented in each effect's header).
//!
//! Run with `FX_REQUIRE_GPU=1 XDG_RUNTIME_DIR=/tmp cargo test --test effects_a`;
//! without an adapter (and without FX_REQUIRE_GPU) the GPU tests skip.

mod common;

use common::*;
use fxgraph::io::{Image, Pixels};
use fxgraph::script::types::Format;

// ---------------------------------------------------------------- helpers

fn u8s(p: &Pixels) -> &[u8] {
    match p {
        Pixels::U8(v) => v,
        Pixels::F32(_) => panic!("expected 8-bit pixels"),
    }
}

fn f32s(p: &Pixels) -> &[f32] {
    match p {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("expected float pixels"),
    }
}

/// `x` rounded to the nearest half float (what an rgba16f texture stores).
fn f16r(x: f64) -> f64 {
    half::f16::from_f64(x).to_f64()
}

/// The samples of a float image as the GPU sees them (uploaded as rgba16f).
fn uploaded_f16(img: &Image) -> Vec<f64> {
    f32s(&img.pixels).iter().map(|&x| f16r(x as f64)).collect()
}

/// The samples of an 8-bit image as stored, 0..255.
fn stored_u8(img: &Image) -> Vec<f64> {
    u8s(&img.pixels).iter().map(|&b| b as f64).collect()
}

/// Largest |a - b|.
fn max_diff(a: &[f32], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "sample counts differ");
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y).abs())
        .fold(0.0, f64::max)
}

fn assert_finite(v: &[f32], what: &str) {
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        panic!("{what}: sample {i} is {}", v[i]);
    }
}

/// Differences of an 8-bit GPU result from an f64 oracle (in 0..255).
#[derive(Debug, Clone, Copy, Default)]
struct U8Diff {
    /// Largest |gpu - round(oracle)| in LSB.
    max_lsb: u8,
    /// Largest |gpu - oracle| in LSB (oracle not rounded).
    max_err: f64,
    /// Fraction of samples where gpu != round(oracle).
    off: f64,
}

fn u8_diff(got: &[u8], want: &[f64]) -> U8Diff {
    assert_eq!(got.len(), want.len(), "sample counts differ");
    let mut d = U8Diff::default();
    let mut off = 0usize;
    for (&g, &o) in got.iter().zip(want) {
        let o = o.clamp(0.0, 255.0);
        let l = g.abs_diff(o.round() as u8);
        off += usize::from(l != 0);
        d.max_lsb = d.max_lsb.max(l);
        d.max_err = d.max_err.max((g as f64 - o).abs());
    }
    d.off = off as f64 / got.len() as f64;
    d
}

/// The normalised Gaussian kernel of `gaussian_blur`: radius (ksize - 1) / 2 with
/// ksize = round(6 sigma + 1) | 1 (OpenCV's 8-bit rule, half to even).
fn gauss_kernel(sigma: f64) -> Vec<f64> {
    let ksize = ((sigma * 6.0 + 1.0).round_ties_even() as i64) | 1;
    let r = (ksize - 1) / 2;
    let w: Vec<f64> = (-r..=r)
        .map(|i| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|x| x / s).collect()
}

/// Separable Gaussian blur of an RGBA buffer in f64, replicated border.
fn blur_f64(v: &[f64], w: u32, h: u32, sigma: f64) -> Vec<f64> {
    let k = gauss_kernel(sigma);
    let r = (k.len() / 2) as i64;
    let (wi, hi) = (w as i64, h as i64);
    let idx = |x: i64, y: i64, c: usize| ((y * wi + x) * 4) as usize + c;
    let mut tmp = vec![0.0; v.len()];
    for y in 0..hi {
        for x in 0..wi {
            for c in 0..4 {
                tmp[idx(x, y, c)] = (-r..=r)
                    .map(|i| k[(i + r) as usize] * v[idx((x + i).clamp(0, wi - 1), y, c)])
                    .sum();
            }
        }
    }
    let mut out = vec![0.0; v.len()];
    for y in 0..hi {
        for x in 0..wi {
            for c in 0..4 {
                out[idx(x, y, c)] = (-r..=r)
                    .map(|i| k[(i + r) as usize] * tmp[idx(x, (y + i).clamp(0, hi - 1), c)])
                    .sum();
            }
        }
    }
    out
}

/// A crop of an 8-bit image.
fn crop(img: &Image, x0: u32, y0: u32, w: u32, h: u32) -> Image {
    let src = u8s(&img.pixels);
    image_u8(w, h, |x, y| {
        let i = (((y0 + y) * img.width + x0 + x) * 4) as usize;
        [src[i], src[i + 1], src[i + 2], src[i + 3]]
    })
}

/// A 128x96 crop of the corpus photo coffee.png, if the corpus is there.
fn coffee_crop() -> Option<Image> {
    let path = std::path::Path::new("/work/shared/corpus/photos/coffee.png");
    match fxgraph::io::load_image(path, &Default::default()) {
        Ok(img) => Some(crop(&img, 200, 120, 128, 96)),
        Err(e) => {
            eprintln!("skipping the coffee.png crop: {e}");
            None
        }
    }
}

/// A smooth, colourful linear float image with edges, values in [0, 1].
fn pattern_f32(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        let fx = x as f32 / w as f32;
        let fy = y as f32 / h as f32;
        let checker = if (x / 6 + y / 4) % 2 == 0 { 0.85 } else { 0.1 };
        [
            fx,
            0.5 + 0.5 * (fx * 9.0 + fy * 4.0).sin(),
            checker * (0.3 + 0.7 * fy),
            1.0,
        ]
    })
}

// ---------------------------------------------------------------- gaussian_blur

/// Blur `img` (8-bit, values as stored, like OpenCV) on the GPU and compare with
/// the f64 oracle.
fn gaussian_u8_diff(img: &Image, sigma: f64, exact: bool) -> Option<U8Diff> {
    let mut eng = engine()?;
    let sets = [format!("sigma={sigma}"), format!("exact={exact}")];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let (w, h, px) = run_raw(&mut eng, &["gaussian_blur"], &sets, img, Format::Rgba8).unwrap();
    assert_eq!((w, h), (img.width, img.height));
    let want = blur_f64(&stored_u8(img), w, h, sigma);
    Some(u8_diff(u8s(&px), &want))
}

fn check_gaussian_u8(name: &str, img: &Image, sigmas: &[f64]) {
    for &sigma in sigmas {
        for exact in [false, true] {
            let Some(d) = gaussian_u8_diff(img, sigma, exact) else {
                return;
            };
            eprintln!(
                "gaussian_blur {name} {}x{} sigma {sigma} exact={exact}: {d:?}",
                img.width, img.height
            );
            assert!(
                d.max_lsb <= 1,
                "{name} sigma {sigma} exact={exact}: {d:?} (more than 1 LSB off)"
            );
        }
    }
}

#[test]
fn gaussian_blur_matches_oracle_on_pattern() {
    check_gaussian_u8("pattern", &pattern_u8(128, 96), &[1.0, 2.5, 8.0]);
}

#[test]
fn gaussian_blur_matches_oracle_on_photo() {
    if let Some(img) = coffee_crop() {
        check_gaussian_u8("coffee crop", &img, &[1.0, 2.5, 8.0]);
    }
}

#[test]
fn gaussian_blur_odd_and_thin_sizes() {
    // Radii larger than the image (sigma 8: r = 24 on 41 rows) exercise the border.
    check_gaussian_u8("pattern", &pattern_u8(67, 41), &[1.0, 2.5, 8.0]);
    check_gaussian_u8("1 px wide", &pattern_u8(1, 57), &[1.0, 2.5, 8.0]);
    check_gaussian_u8("1 px high", &pattern_u8(57, 1), &[2.5]);
}

#[test]
fn gaussian_blur_flat_image_stays_flat() {
    let img = image_u8(40, 30, |_, _| [37, 128, 250, 255]);
    for sigma in [0.5, 3.0, 20.0] {
        let Some(mut eng) = engine() else { return };
        let set = format!("sigma={sigma}");
        let (_, _, px) =
            run_raw(&mut eng, &["gaussian_blur"], &[&set], &img, Format::Rgba8).unwrap();
        assert_eq!(u8s(&px), u8s(&img.pixels), "sigma {sigma}");
    }
}

#[test]
fn gaussian_blur_float_matches_oracle() {
    let img = pattern_f32(96, 64);
    let src = uploaded_f16(&img);
    for sigma in [1.0, 4.0] {
        for exact in [false, true] {
            let Some(mut eng) = engine() else { return };
            let sets = [format!("sigma={sigma}"), format!("exact={exact}")];
            let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
            let (w, h, px) =
                run(&mut eng, &["gaussian_blur"], &sets, &img, Format::Rgba32f).unwrap();
            let want = blur_f64(&src, w, h, sigma);
            let d = max_diff(f32s(&px), &want);
            eprintln!("gaussian_blur float sigma {sigma} exact={exact}: max abs diff {d:.2e}");
            // The intermediate is rgba16f, written with round-towards-zero on
            // lavapipe: up to one 2^-11 step.
            assert!(d < 1e-3, "sigma {sigma} exact={exact}: max abs diff {d}");
        }
    }
}

/// Colour 8-bit inputs are blurred in linear light: decode, blur, encode.
#[test]
fn gaussian_blur_srgb_blurs_linear_light() {
    let img = pattern_u8(96, 64);
    let lin: Vec<f64> = u8s(&img.pixels)
        .iter()
        .enumerate()
        .map(|(i, &b)| {
            if i % 4 == 3 {
                b as f64 / 255.0
            } else {
                srgb_to_linear(b as f32 / 255.0) as f64
            }
        })
        .collect();
    for sigma in [1.0, 4.0] {
        let Some(mut eng) = engine() else { return };
        let set = format!("sigma={sigma}");
        let (w, h, px) = run(
            &mut eng,
            &["gaussian_blur"],
            &[&set],
            &img,
            Format::Rgba8Srgb,
        )
        .unwrap();
        let want: Vec<f64> = blur_f64(&lin, w, h, sigma)
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                255.0
                    * if i % 4 == 3 {
                        v
                    } else {
                        linear_to_srgb(v as f32) as f64
                    }
            })
            .collect();
        let d = u8_diff(u8s(&px), &want);
        eprintln!("gaussian_blur sRGB sigma {sigma}: {d:?}");
        // lavapipe's sRGB decode and encode are approximations (measured: up to
        // 0.34 of a code step, and 0.63 LSB instead of 0.5); still within 1 LSB.
        assert!(d.max_lsb <= 1, "sigma {sigma}: {d:?}");
    }
}

// ---------------------------------------------------------------- bloom

/// 256x256 black with a 4x4 spot of `value` whose top-left corner is (at, at).
fn spot_image(value: f32, at: u32) -> Image {
    image_f32(256, 256, |x, y| {
        if (at..at + 4).contains(&x) && (at..at + 4).contains(&y) {
            [value, value * 0.8, value * 0.6, 1.0]
        } else {
            [0.0, 0.0, 0.0, 1.0]
        }
    })
}

#[test]
fn bloom_spreads_a_bright_spot() {
    let img = spot_image(50.0, 62);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    let (w, h, px) = run(&mut eng, &["bloom"], &[], &img, Format::Rgba32f).unwrap();
    assert_eq!((w, h), (256, 256));
    let out = f32s(&px);
    assert_finite(out, "bloom");
    let bloom =
        |x: u32, y: u32, c: usize| at(out, w, x, y, c) as f64 - src[((y * w + x) * 4) as usize + c];
    // Brighter next to the spot, and on the spot itself.
    assert!(
        bloom(68, 63, 0) > 0.05,
        "bloom 2 px right of the spot: {}",
        bloom(68, 63, 0)
    );
    assert!(
        bloom(63, 63, 0) > 0.05,
        "bloom on the spot: {}",
        bloom(63, 63, 0)
    );
    // Falling off monotonically away from the spot: right, down, left, up, diagonal.
    let rays: [(i32, i32, i32, i32); 5] = [
        (66, 63, 1, 0),
        (63, 66, 0, 1),
        (61, 63, -1, 0),
        (63, 61, 0, -1),
        (66, 66, 1, 1),
    ];
    for (x0, y0, dx, dy) in rays {
        let mut prev = f64::INFINITY;
        let (mut x, mut y) = (x0, y0);
        while (0..256).contains(&x) && (0..256).contains(&y) {
            for c in 0..3 {
                let b = bloom(x as u32, y as u32, c);
                assert!(b >= -1e-6, "negative bloom {b} at ({x}, {y})");
                if c == 0 {
                    assert!(
                        b <= prev * (1.0 + 2e-3) + 1e-6,
                        "bloom rises from {prev} to {b} at ({x}, {y}) going ({dx}, {dy})"
                    );
                    prev = b;
                }
            }
            x += dx;
            y += dy;
        }
    }
    // Colour of the spot is kept in the bloom (r : g : b = 1 : 0.8 : 0.6).
    let (r, g, b) = (bloom(72, 63, 0), bloom(72, 63, 1), bloom(72, 63, 2));
    assert!(
        (g / r - 0.8).abs() < 0.01 && (b / r - 0.6).abs() < 0.01,
        "bloom colour {r} {g} {b}"
    );
    // Far from the spot nothing changes.
    let mut far = 0.0f64;
    for y in 200..256 {
        for x in 200..256 {
            for c in 0..4 {
                far = far.max(bloom(x, y, c).abs());
            }
        }
    }
    eprintln!(
        "bloom: near {:.4}, at 20 px {:.5}, at 60 px {:.6}, far max {far:.2e}",
        bloom(68, 63, 0),
        bloom(86, 63, 0),
        bloom(126, 63, 0)
    );
    assert!(far <= 1e-3, "far pixels changed by {far}");
    // Alpha is the input's.
    assert!((0..(w * h) as usize).all(|i| out[i * 4 + 3] == 1.0));
}

#[test]
fn bloom_energy_and_identity() {
    // In the middle, so that the widest level does not reach the border.
    let img = spot_image(50.0, 126);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    // intensity 0: exactly the input.
    let (_, _, px) = run(
        &mut eng,
        &["bloom"],
        &["intensity=0"],
        &img,
        Format::Rgba32f,
    )
    .unwrap();
    assert_eq!(
        max_diff(f32s(&px), &src),
        0.0,
        "bloom with intensity 0 changed the image"
    );
    // No threshold: the bloom carries the input's energy times the intensity; a
    // larger radius moves more of it far from the spot.
    for intensity in [1.0, 0.25] {
        let mut at_40px = 0.0;
        for radius in [0.3, 0.7, 1.0] {
            let sets = [
                format!("intensity={intensity}"),
                format!("radius={radius}"),
                "threshold=0".to_string(),
                "knee=0".to_string(),
            ];
            let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
            let (_, _, px) = run(&mut eng, &["bloom"], &sets, &img, Format::Rgba32f).unwrap();
            let out = f32s(&px);
            assert_finite(out, "bloom");
            let added: f64 = (0..out.len())
                .filter(|i| i % 4 == 0)
                .map(|i| out[i] as f64 - src[i])
                .sum();
            let energy: f64 = (0..src.len()).filter(|i| i % 4 == 0).map(|i| src[i]).sum();
            let ratio = added / (intensity * energy);
            eprintln!("bloom intensity {intensity} radius {radius}: added energy / (intensity * input energy) = {ratio:.4}");
            assert!((ratio - 1.0).abs() < 0.01, "energy ratio {ratio}");
            let far = at(out, 256, 128 + 40, 128, 0) as f64;
            assert!(
                far > at_40px,
                "radius {radius}: bloom 40 px away {far} <= {at_40px} with a smaller radius"
            );
            at_40px = far;
        }
    }
}

#[test]
fn bloom_threshold_keeps_dim_images() {
    // Below threshold - knee nothing blooms: the output is the input.
    let img = pattern_f32(64, 48);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    let (_, _, px) = run(
        &mut eng,
        &["bloom"],
        &["threshold=2", "knee=0.5"],
        &img,
        Format::Rgba32f,
    )
    .unwrap();
    assert_eq!(max_diff(f32s(&px), &src), 0.0);
    // An 8-bit photo-like input and odd size: runs, stays finite, only brightens.
    let img = pattern_u8(67, 41);
    let (w, h, px) = run(
        &mut eng,
        &["bloom"],
        &["threshold=0.5"],
        &img,
        Format::Rgba16f,
    )
    .unwrap();
    assert_eq!((w, h), (67, 41));
    let out = f32s(&px);
    assert_finite(out, "bloom");
    let lin = linear(&img.pixels);
    let brighter = out.iter().zip(&lin).all(|(o, i)| *o >= i - 2e-3);
    assert!(brighter, "bloom darkened a pixel");
    assert!(
        out.iter().zip(&lin).any(|(o, i)| *o > i + 0.01),
        "nothing bloomed"
    );
}

// ---------------------------------------------------------------- tonemap

/// The tone curves of `tonemap` (per channel), `op` 0 = reinhard, 1 = aces.
fn tonemap_f64(v: f64, exposure: f64, op: u32, white: f64) -> f64 {
    let x = v.max(0.0) * exposure.exp2();
    let y = match op {
        0 if white > 0.0 => x * (1.0 + x / (white * white)) / (1.0 + x),
        0 => x / (1.0 + x),
        _ => x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14),
    };
    y.clamp(0.0, 1.0)
}

#[test]
fn tonemap_matches_oracle_on_hdr_gradient() {
    // Values 0..20 along x (r, g, b at different scales), a few rows.
    let w = 512;
    let img = image_f32(w, 4, |x, y| {
        let v = 20.0 * x as f32 / (w - 1) as f32;
        [v, v * 0.5, v * 0.05 * (y + 1) as f32, 1.0]
    });
    let src = uploaded_f16(&img);
    let cases: [(&str, f64, u32, f64); 6] = [
        ("aces", 0.0, 1, 0.0),
        ("aces", -1.5, 1, 0.0),
        ("aces", 2.0, 1, 0.0),
        ("reinhard", 0.0, 0, 0.0),
        ("reinhard", 1.0, 0, 0.0),
        ("reinhard", 0.0, 0, 8.0),
    ];
    for (op_name, exposure, op, white) in cases {
        let Some(mut eng) = engine() else { return };
        let sets = [
            format!("operator={op_name}"),
            format!("exposure={exposure}"),
            format!("white={white}"),
        ];
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (_, h, px) = run(&mut eng, &["tonemap"], &sets, &img, Format::Rgba32f).unwrap();
        let out = f32s(&px);
        assert_finite(out, "tonemap");
        let want: Vec<f64> = src
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if i % 4 == 3 {
                    v
                } else {
                    tonemap_f64(v, exposure, op, white)
                }
            })
            .collect();
        let d = max_diff(out, &want);
        eprintln!("tonemap {op_name} exposure {exposure} white {white}: max abs diff {d:.2e}");
        assert!(
            d < 2e-3,
            "{op_name} exposure {exposure} white {white}: max abs diff {d}"
        );
        // 0 maps to 0; monotonic along the gradient; within [0, 1].
        for y in 0..h {
            for c in 0..3 {
                assert_eq!(at(out, w, 0, y, c), 0.0, "{op_name}: 0 does not map to 0");
                for x in 1..w {
                    let (a, b) = (at(out, w, x - 1, y, c), at(out, w, x, y, c));
                    assert!(
                        b >= a && (0.0..=1.0).contains(&b),
                        "{op_name}: not monotonic at x {x}: {a} -> {b}"
                    );
                }
            }
        }
        // Reinhard extended: the white point maps to 1.
        if white > 0.0 {
            let x_white = ((white / 20.0) * (w - 1) as f64).round() as u32;
            assert!(
                at(out, w, x_white + 1, 0, 0) > 0.999,
                "white point does not reach 1"
            );
        }
    }
}

#[test]
fn tonemap_writes_8bit_output() {
    // An HDR input written to an 8-bit sRGB target: the oracle encoded to sRGB.
    let img = image_f32(64, 8, |x, y| {
        let v = 0.05 * (x * (y + 1)) as f32;
        [v, v * 0.3, v * 2.0, 1.0]
    });
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    let (_, _, px) = run(
        &mut eng,
        &["tonemap"],
        &["operator=reinhard"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let want: Vec<f64> = src
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            255.0
                * if i % 4 == 3 {
                    v
                } else {
                    linear_to_srgb(tonemap_f64(v, 0.0, 0, 0.0) as f32) as f64
                }
        })
        .collect();
    let d = u8_diff(u8s(&px), &want);
    eprintln!("tonemap to rgba8-srgb: {d:?}");
    assert!(d.max_lsb <= 1, "{d:?}");
}

// ---------------------------------------------------------------- color_grade

#[derive(Clone, Copy)]
struct Grade {
    slope: [f64; 3],
    offset: [f64; 3],
    power: [f64; 3],
    saturation: f64,
    lift: [f64; 3],
    gamma: [f64; 3],
    gain: [f64; 3],
    clamp: bool,
}

impl Grade {
    const IDENTITY: Grade = Grade {
        slope: [1.0; 3],
        offset: [0.0; 3],
        power: [1.0; 3],
        saturation: 1.0,
        lift: [0.0; 3],
        gamma: [1.0; 3],
        gain: [1.0; 3],
        clamp: true,
    };

    fn sets(&self) -> Vec<String> {
        let v = |n: &str, a: [f64; 3]| format!("{n}=({},{},{})", a[0], a[1], a[2]);
        vec![
            v("slope", self.slope),
            v("offset", self.offset),
            v("power", self.power),
            format!("saturation={}", self.saturation),
            v("lift", self.lift),
            v("gamma", self.gamma),
            v("gain", self.gain),
            format!("clamp={}", self.clamp),
        ]
    }

    /// The documented formula: CDL SOP, CDL saturation, lift/gamma/gain.
    fn apply(&self, rgb: [f64; 3]) -> [f64; 3] {
        let pow_pos = |v: f64, e: f64| if v > 0.0 { v.powf(e) } else { v };
        let clamp = |v: f64| if self.clamp { v.clamp(0.0, 1.0) } else { v };
        let sop = |c: usize| {
            pow_pos(
                clamp(rgb[c] * self.slope[c] + self.offset[c]),
                self.power[c],
            )
        };
        let v = [sop(0), sop(1), sop(2)];
        let luma = 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        let rest = |c: usize| {
            let s = clamp(luma + self.saturation * (v[c] - luma));
            pow_pos(
                self.gain[c] * (s + self.lift[c] * (1.0 - s)),
                1.0 / self.gamma[c],
            )
        };
        [rest(0), rest(1), rest(2)]
    }
}

fn grade_oracle(g: &Grade, src: &[f64]) -> Vec<f64> {
    src.chunks(4)
        .flat_map(|p| {
            let o = g.apply([p[0], p[1], p[2]]);
            [o[0], o[1], o[2], p[3]]
        })
        .collect()
}

fn check_grade(name: &str, g: &Grade, img: &Image) {
    let src = uploaded_f16(img);
    let Some(mut eng) = engine() else { return };
    let sets = g.sets();
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let (_, _, px) = run(&mut eng, &["color_grade"], &sets, img, Format::Rgba32f).unwrap();
    assert_finite(f32s(&px), "color_grade");
    let d = max_diff(f32s(&px), &grade_oracle(g, &src));
    eprintln!("color_grade {name}: max abs diff {d:.2e}");
    assert!(d < 1e-3, "{name}: max abs diff {d}");
}

#[test]
fn color_grade_matches_oracle() {
    let img = pattern_f32(64, 48);
    let warm = Grade {
        slope: [1.2, 0.9, 1.05],
        offset: [0.02, -0.01, 0.0],
        power: [0.9, 1.1, 1.3],
        saturation: 1.3,
        lift: [0.05, 0.0, -0.02],
        gamma: [1.2, 1.0, 0.8],
        gain: [1.1, 1.0, 0.95],
        clamp: true,
    };
    check_grade("warm", &warm, &img);
    check_grade(
        "desaturate",
        &Grade {
            saturation: 0.0,
            ..Grade::IDENTITY
        },
        &img,
    );
    check_grade(
        "cdl only",
        &Grade {
            slope: [0.7, 1.4, 1.0],
            offset: [0.1, 0.0, -0.05],
            power: [2.2, 0.45, 1.0],
            ..Grade::IDENTITY
        },
        &img,
    );
    check_grade(
        "lift gamma gain",
        &Grade {
            lift: [0.1, -0.05, 0.2],
            gamma: [0.5, 2.0, 1.5],
            gain: [0.8, 1.2, 1.0],
            ..Grade::IDENTITY
        },
        &img,
    );
    // HDR values above 1 survive without the clamp.
    let hdr = image_f32(64, 8, |x, y| {
        let v = 4.0 * x as f32 / 63.0;
        [v, v * (y as f32 / 7.0), 4.0 - v, 1.0]
    });
    check_grade(
        "hdr no clamp",
        &Grade {
            clamp: false,
            ..warm
        },
        &hdr,
    );
    check_grade("hdr clamp", &warm, &hdr);
}

#[test]
fn color_grade_identity_is_identity() {
    let Some(mut eng) = engine() else { return };
    // Float: the default parameters change nothing (clamp off for values above 1).
    let img = image_f32(64, 8, |x, y| [x as f32 / 16.0, y as f32 / 7.0, 0.3, 0.5]);
    let src = uploaded_f16(&img);
    let (_, _, px) = run(
        &mut eng,
        &["color_grade"],
        &["clamp=false"],
        &img,
        Format::Rgba32f,
    )
    .unwrap();
    let d = max_diff(f32s(&px), &src);
    assert!(d < 1e-6, "identity changed a float image by {d}");
    // 8-bit sRGB: bit-exact.
    let img = pattern_u8(96, 64);
    let (_, _, px) = run(&mut eng, &["color_grade"], &[], &img, Format::Rgba8Srgb).unwrap();
    assert_eq!(
        u8s(&px),
        u8s(&img.pixels),
        "identity changed an 8-bit image"
    );
}

// ---------------------------------------------------------------- vignette

/// Parameters of `vignette`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Vignette {
    strength: f64,
    radius: f64,
    softness: f64,
    center: [f64; 2],
    roundness: f64,
}

impl Vignette {
    const DEFAULT: Vignette = Vignette {
        strength: 0.5,
        radius: 0.8,
        softness: 0.8,
        center: [0.5, 0.5],
        roundness: 1.0,
    };

    fn sets(&self) -> Vec<String> {
        vec![
            format!("strength={}", self.strength),
            format!("radius={}", self.radius),
            format!("softness={}", self.softness),
            format!("center=({},{})", self.center[0], self.center[1]),
            format!("roundness={}", self.roundness),
        ]
    }

    /// The factor of the documented formula at pixel (x, y) of a w x h image.
    fn factor(&self, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (wf, hf) = (w as f64, h as f64);
        let u = (x as f64 + 0.5) / wf;
        let v = (y as f64 + 0.5) / hf;
        let a = if wf >= hf {
            [wf / hf, 1.0]
        } else {
            [1.0, hf / wf]
        };
        let s = [
            1.0 + (a[0] - 1.0) * self.roundness,
            1.0 + (a[1] - 1.0) * self.roundness,
        ];
        let q = [
            (u - self.center[0]) * 2.0 * s[0],
            (v - self.center[1]) * 2.0 * s[1],
        ];
        let d = (q[0] * q[0] + q[1] * q[1]).sqrt();
        let t = ((d - self.radius) / self.softness.max(1e-5)).clamp(0.0, 1.0);
        1.0 - self.strength * t * t * (3.0 - 2.0 * t)
    }
}

#[test]
fn vignette_matches_oracle() {
    let d = Vignette::DEFAULT;
    let cases = [
        (128, 96, d),
        (
            128,
            96,
            Vignette {
                strength: 1.0,
                radius: 0.3,
                softness: 0.5,
                roundness: 0.0,
                ..d
            },
        ),
        (
            72,
            128,
            Vignette {
                strength: 0.7,
                radius: 0.5,
                softness: 1.0,
                roundness: 0.5,
                ..d
            },
        ),
        (
            128,
            96,
            Vignette {
                strength: 0.8,
                radius: 0.2,
                softness: 0.6,
                center: [0.3, 0.6],
                ..d
            },
        ),
    ];
    for (w, h, vg) in cases {
        let img = image_f32(w, h, |x, y| {
            [0.8, 0.5 + 0.3 * ((x + y) % 2) as f32, 0.25, 0.75]
        });
        let src = uploaded_f16(&img);
        let Some(mut eng) = engine() else { return };
        let sets = vg.sets();
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (_, _, px) = run(&mut eng, &["vignette"], &sets, &img, Format::Rgba32f).unwrap();
        let out = f32s(&px);
        let mut want = src.clone();
        for y in 0..h {
            for x in 0..w {
                let f = vg.factor(x, y, w, h);
                for c in 0..3 {
                    want[((y * w + x) * 4) as usize + c] *= f;
                }
            }
        }
        let diff = max_diff(out, &want);
        eprintln!("vignette {w}x{h} {vg:?}: max abs diff {diff:.2e}");
        assert!(diff < 1e-4, "{vg:?}: max abs diff {diff}");
        // The centre pixel is unchanged; corners are darkened.
        let (cx, cy) = (
            (vg.center[0] * w as f64) as u32,
            (vg.center[1] * h as f64) as u32,
        );
        for c in 0..4 {
            assert_eq!(
                at(out, w, cx, cy, c) as f64,
                src[((cy * w + cx) * 4) as usize + c],
                "centre pixel changed"
            );
        }
        for (x, y) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)] {
            assert!(
                at(out, w, x, y, 0) < 0.8 * 0.9,
                "corner ({x}, {y}) not darkened: {}",
                at(out, w, x, y, 0)
            );
        }
        // Centred: symmetric left/right and top/bottom.
        if vg.center == [0.5, 0.5] {
            for y in 0..h {
                for x in 0..w {
                    let f = at(out, w, x, y, 0);
                    for (mx, my) in [(w - 1 - x, y), (x, h - 1 - y)] {
                        let g = at(out, w, mx, my, 0);
                        assert!(
                            (f - g).abs() < 1e-5,
                            "not symmetric: ({x}, {y}) {f} vs ({mx}, {my}) {g}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn vignette_keeps_8bit_centre() {
    let img = pattern_u8(96, 64);
    let vg = Vignette {
        strength: 1.0,
        ..Vignette::DEFAULT
    };
    let Some(mut eng) = engine() else { return };
    let (w, h, px) = run(
        &mut eng,
        &["vignette"],
        &["strength=1"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let (got, src) = (u8s(&px), u8s(&img.pixels));
    let i = (((h / 2) * w + w / 2) * 4) as usize;
    assert_eq!(&got[i..i + 4], &src[i..i + 4], "centre pixel changed");
    // Darkened in linear light: decode, scale, encode.
    let lin = linear(&img.pixels);
    let want: Vec<f64> = (0..got.len())
        .map(|i| {
            let p = (i / 4) as u32;
            if i % 4 == 3 {
                255.0 * lin[i] as f64
            } else {
                255.0
                    * linear_to_srgb((lin[i] as f64 * vg.factor(p % w, p / w, w, h)) as f32) as f64
            }
        })
        .collect();
    let d = u8_diff(got, &want);
    eprintln!("vignette 8-bit sRGB: {d:?}");
    assert!(d.max_lsb <= 1, "{d:?}");
}

// ---------------------------------------------------------------- sharpen

/// Unsharp mask oracle: max(in + amount * d, 0) where |d| >= threshold, d = in - blur.
fn sharpen_f64(src: &[f64], w: u32, h: u32, amount: f64, sigma: f64, threshold: f64) -> Vec<f64> {
    let blur = blur_f64(src, w, h, sigma);
    src.iter()
        .zip(&blur)
        .enumerate()
        .map(|(i, (&s, &b))| {
            let d = s - b;
            if i % 4 == 3 || d.abs() < threshold {
                s
            } else {
                (s + amount * d).max(0.0)
            }
        })
        .collect()
}

#[test]
fn sharpen_matches_oracle_8bit() {
    let mut images = vec![
        ("pattern", pattern_u8(128, 96)),
        ("odd", pattern_u8(67, 41)),
    ];
    images.extend(coffee_crop().map(|c| ("coffee crop", c)));
    for (name, img) in &images {
        for (amount, sigma) in [(1.0, 1.5), (0.5, 3.0), (2.0, 1.0)] {
            let Some(mut eng) = engine() else { return };
            let sets = [format!("amount={amount}"), format!("sigma={sigma}")];
            let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
            let (w, h, px) = run_raw(&mut eng, &["sharpen"], &sets, img, Format::Rgba8).unwrap();
            let want = sharpen_f64(&stored_u8(img), w, h, amount, sigma, 0.0);
            let d = u8_diff(u8s(&px), &want);
            eprintln!("sharpen {name} amount {amount} sigma {sigma}: {d:?}");
            // Errors of the blur are scaled by the amount.
            let tol = if amount > 1.0 { 2 } else { 1 };
            assert!(
                d.max_lsb <= tol,
                "{name} amount {amount} sigma {sigma}: {d:?}"
            );
        }
    }
}

#[test]
fn sharpen_matches_oracle_float() {
    let img = pattern_f32(96, 64);
    let src = uploaded_f16(&img);
    for (amount, sigma, threshold) in [(1.0, 1.5, 0.0), (3.0, 2.0, 0.0), (1.5, 1.0, 0.05)] {
        let Some(mut eng) = engine() else { return };
        let sets = [
            format!("amount={amount}"),
            format!("sigma={sigma}"),
            format!("threshold={threshold}"),
        ];
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (w, h, px) = run(&mut eng, &["sharpen"], &sets, &img, Format::Rgba32f).unwrap();
        let out = f32s(&px);
        assert_finite(out, "sharpen");
        let want = sharpen_f64(&src, w, h, amount, sigma, threshold);
        // Samples whose |d| is within 1e-3 of the threshold may go either way.
        let blur = blur_f64(&src, w, h, sigma);
        let mut d = 0.0f64;
        for i in 0..out.len() {
            if threshold > 0.0 && ((src[i] - blur[i]).abs() - threshold).abs() < 1e-3 {
                continue;
            }
            d = d.max((out[i] as f64 - want[i]).abs());
        }
        eprintln!("sharpen float amount {amount} sigma {sigma} threshold {threshold}: max abs diff {d:.2e}");
        assert!(
            d < 1e-3 * amount.max(1.0),
            "amount {amount} sigma {sigma} threshold {threshold}: max abs diff {d}"
        );
    }
}

#[test]
fn sharpen_flat_and_identity() {
    let Some(mut eng) = engine() else { return };
    // A flat image stays flat.
    let flat = image_f32(50, 40, |_, _| [0.4, 0.1, 0.9, 1.0]);
    let src = uploaded_f16(&flat);
    let (_, _, px) = run(
        &mut eng,
        &["sharpen"],
        &["amount=5", "sigma=4"],
        &flat,
        Format::Rgba32f,
    )
    .unwrap();
    let d = max_diff(f32s(&px), &src);
    assert!(d < 1e-6, "flat float image changed by {d}");
    let flat8 = image_u8(50, 40, |_, _| [12, 200, 99, 255]);
    let (_, _, px) = run(
        &mut eng,
        &["sharpen"],
        &["amount=5"],
        &flat8,
        Format::Rgba8Srgb,
    )
    .unwrap();
    assert_eq!(u8s(&px), u8s(&flat8.pixels), "flat 8-bit image changed");
    // amount 0 is the identity.
    let img = pattern_u8(96, 64);
    let (_, _, px) = run(
        &mut eng,
        &["sharpen"],
        &["amount=0"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    assert_eq!(
        u8s(&px),
        u8s(&img.pixels),
        "amount 0 changed an 8-bit image"
    );
    let img = pattern_f32(96, 64);
    let (_, _, px) = run(&mut eng, &["sharpen"], &["amount=0"], &img, Format::Rgba32f).unwrap();
    assert_eq!(
        max_diff(f32s(&px), &uploaded_f16(&img)),
        0.0,
        "amount 0 changed a float image"
    );
    // A threshold above every difference leaves the image unchanged too.
    let (_, _, px) = run(
        &mut eng,
        &["sharpen"],
        &["amount=2", "threshold=1"],
        &img,
        Format::Rgba32f,
    )
    .unwrap();
    assert_eq!(
        max_diff(f32s(&px), &uploaded_f16(&img)),
        0.0,
        "threshold 1 changed a float image"
    );
}
