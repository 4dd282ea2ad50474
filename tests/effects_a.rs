//! GPU tests of the built-in effects gaussian_blur, bloom, tonemap, color_grade,
//! vignette and sharpen against CPU oracles.

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

fn coffee() -> Option<Image> {
    let path = std::path::Path::new("/work/shared/corpus/photos/coffee.png");
    match fxgraph::io::load_image(path, &Default::default()) {
        Ok(img) => Some(img),
        Err(e) => {
            eprintln!("skipping the coffee.png crop: {e}");
            None
        }
    }
}

/// Differences of an 8-bit GPU result from an f64 oracle.
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
    assert_eq!(got.len(), want.len());
    let mut d = U8Diff::default();
    let mut off = 0usize;
    for (&g, &o) in got.iter().zip(want) {
        let l = g.abs_diff(o.round().clamp(0.0, 255.0) as u8);
        off += usize::from(l != 0);
        d.max_lsb = d.max_lsb.max(l);
        d.max_err = d.max_err.max((g as f64 - o.clamp(0.0, 255.0)).abs());
    }
    d.off = off as f64 / got.len() as f64;
    d
}

/// Blur `img` (8-bit, values as stored) on the GPU and compare with the f64 oracle.
fn gaussian_u8_diff(img: &Image, sigma: f64) -> Option<U8Diff> {
    let mut eng = engine()?;
    let set = format!("sigma={sigma}");
    let (w, h, px) = run_raw(&mut eng, &["gaussian_blur"], &[&set], img, Format::Rgba8).unwrap();
    assert_eq!((w, h), (img.width, img.height));
    let src: Vec<f64> = u8s(&img.pixels).iter().map(|&b| b as f64).collect();
    let want = blur_f64(&src, w, h, sigma);
    Some(u8_diff(u8s(&px), &want))
}

// ---------------------------------------------------------------- gaussian_blur

#[test]
fn gaussian_blur_matches_f64_oracle_on_pattern() {
    let img = pattern_u8(128, 96);
    for sigma in [1.0, 2.5, 8.0] {
        let Some(d) = gaussian_u8_diff(&img, sigma) else {
            return;
        };
        eprintln!("gaussian_blur pattern 128x96 sigma {sigma}: {d:?}");
        assert!(d.max_lsb <= 1, "sigma {sigma}: {d:?}");
    }
}

#[test]
fn gaussian_blur_matches_f64_oracle_on_photo() {
    let Some(photo) = coffee() else { return };
    let img = crop(&photo, 200, 120, 128, 96);
    for sigma in [1.0, 2.5, 8.0] {
        let Some(d) = gaussian_u8_diff(&img, sigma) else {
            return;
        };
        eprintln!("gaussian_blur coffee crop sigma {sigma}: {d:?}");
        assert!(d.max_lsb <= 1, "sigma {sigma}: {d:?}");
    }
}
