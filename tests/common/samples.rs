//! Sample buffers of the GPU tests: typed views of pixels, half-float rounding,
//! channels and regions of RGBA buffers, and their statistics.
#![allow(dead_code)]

use fxgraph::io::{Image, Pixels};

/// The samples of 8-bit pixels (panics on float pixels).
pub fn u8s(p: &Pixels) -> &[u8] {
    match p {
        Pixels::U8(v) => v,
        Pixels::F32(_) => panic!("expected 8-bit pixels"),
    }
}

/// The samples of float pixels (panics on 8-bit pixels).
pub fn f32s(p: &Pixels) -> &[f32] {
    match p {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("expected float pixels"),
    }
}

/// `x` rounded to the nearest half float (what an rgba16f texture stores).
pub fn f16r(x: f64) -> f64 {
    half::f16::from_f64(x).to_f64()
}

/// [`f16r`] of an f32.
pub fn f16r32(x: f32) -> f32 {
    half::f16::from_f32(x).to_f32()
}

/// A float image of `w` x `h` RGBA samples.
pub fn float_image(w: u32, h: u32, px: Vec<f32>) -> Image {
    let mut img = super::image_f32(w, h, |_, _| [0.0; 4]);
    img.pixels = Pixels::F32(px);
    img
}

/// Panics, naming the first one, if a sample is NaN or infinite.
#[track_caller]
pub fn assert_finite(v: &[f32], what: &str) {
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        panic!("{what}: sample {i} is {}", v[i]);
    }
}

/// Channel `c` of every pixel.
pub fn channel(v: &[f32], c: usize) -> Vec<f32> {
    v.chunks_exact(4).map(|p| p[c]).collect()
}

/// Samples of `v` (one per pixel) over the rectangle [x0, x1) x [y0, y1).
pub fn region(v: &[f32], w: u32, x0: u32, x1: u32, y0: u32, y1: u32) -> Vec<f32> {
    let mut out = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            out.push(v[(y * w + x) as usize]);
        }
    }
    out
}

pub fn min_of(v: &[f32]) -> f32 {
    v.iter().copied().fold(f32::INFINITY, f32::min)
}

pub fn max_of(v: &[f32]) -> f32 {
    v.iter().copied().fold(f32::NEG_INFINITY, f32::max)
}

pub fn mean(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

pub fn variance(v: &[f32]) -> f64 {
    let m = mean(v);
    v.iter().map(|&x| (x as f64 - m).powi(2)).sum::<f64>() / v.len() as f64
}

pub fn std_dev(v: &[f32]) -> f64 {
    variance(v).sqrt()
}

/// RGB samples (alpha left out) of the pixels of a `w` x `h` RGBA buffer where
/// `keep(x, y)`.
pub fn select_rgb(v: &[f32], w: u32, h: u32, keep: impl Fn(u32, u32) -> bool) -> Vec<f32> {
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if keep(x, y) {
                let i = ((y * w + x) * 4) as usize;
                out.extend_from_slice(&v[i..i + 3]);
            }
        }
    }
    out
}
