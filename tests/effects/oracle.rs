//! CPU oracles shared by the effect tests: f64 models of what the shaders compute
//! (Gaussian kernels, bilinear clamp-to-edge sampling, the blurX/blurY/pencil_blur
//! taps, downsampling blurs), comparisons of 8-bit results with them, and the
//! test images and plans several effects use.

use crate::common::samples::{f16r, f32s, u8s};
use crate::common::*;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use fxgraph::io::Image;

// ---------------------------------------------------------------- samples

/// The samples of a float image as the GPU sees them (uploaded as rgba16f).
pub fn uploaded_f16(img: &Image) -> Vec<f64> {
    f32s(&img.pixels).iter().map(|&x| f16r(x as f64)).collect()
}

/// The samples of an 8-bit image as stored, 0..255.
pub fn stored_u8(img: &Image) -> Vec<f64> {
    u8s(&img.pixels).iter().map(|&b| b as f64).collect()
}

/// Largest |a - b|.
pub fn max_diff(a: &[f32], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "sample counts differ");
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y).abs())
        .fold(0.0, f64::max)
}

/// Differences of an 8-bit GPU result from an f64 oracle (in 0..255).
#[derive(Debug, Clone, Copy, Default)]
pub struct U8Diff {
    /// Largest |gpu - round(oracle)| in LSB.
    pub max_lsb: u8,
    /// Largest |gpu - oracle| in LSB (oracle not rounded).
    pub max_err: f64,
    /// Fraction of samples where gpu != round(oracle).
    pub off: f64,
}

pub fn u8_diff(got: &[u8], want: &[f64]) -> U8Diff {
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
pub fn gauss_kernel(sigma: f64) -> Vec<f64> {
    let ksize = ((sigma * 6.0 + 1.0).round_ties_even() as i64) | 1;
    let r = (ksize - 1) / 2;
    let w: Vec<f64> = (-r..=r)
        .map(|i| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|x| x / s).collect()
}

/// Separable Gaussian blur of an RGBA buffer in f64, replicated border.
pub fn blur_f64(v: &[f64], w: u32, h: u32, sigma: f64) -> Vec<f64> {
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
pub fn crop(img: &Image, x0: u32, y0: u32, w: u32, h: u32) -> Image {
    let src = u8s(&img.pixels);
    image_u8(w, h, |x, y| {
        let i = (((y0 + y) * img.width + x0 + x) * 4) as usize;
        [src[i], src[i + 1], src[i + 2], src[i + 3]]
    })
}

/// A 128x96 crop of the corpus photo coffee.png, if the corpus is there.
pub fn coffee_crop() -> Option<Image> {
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
pub fn pattern_f32(w: u32, h: u32) -> Image {
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

/// Rec.709 luma weights.
pub const W709: [f64; 3] = [0.2126, 0.7152, 0.0722];

pub fn luma709(c: &[f64]) -> f64 {
    W709[0] * c[0] + W709[1] * c[1] + W709[2] * c[2]
}

pub fn srgb_encode(x: f64) -> f64 {
    let a = x.abs();
    let e = if a <= 0.0031308 {
        a * 12.92
    } else {
        1.055 * a.powf(1.0 / 2.4) - 0.055
    };
    e.copysign(x)
}

pub fn srgb_decode(x: f64) -> f64 {
    let a = x.abs();
    let l = if a <= 0.04045 {
        a / 12.92
    } else {
        ((a + 0.055) / 1.055).powf(2.4)
    };
    l.copysign(x)
}

/// Largest |got - round(want)| in LSB over the samples where `mask(i)` holds, and
/// the fraction of those that differ at all.
pub fn lsb_diff(got: &[u8], want: &[f64], mask: impl Fn(usize) -> bool) -> (u8, f64) {
    assert_eq!(got.len(), want.len());
    let (mut max, mut off, mut n) = (0u8, 0usize, 0usize);
    for (i, (&g, &w)) in got.iter().zip(want).enumerate() {
        if !mask(i) {
            continue;
        }
        let d = g.abs_diff(w.round().clamp(0.0, 255.0) as u8);
        max = max.max(d);
        off += usize::from(d != 0);
        n += 1;
    }
    (max, off as f64 / n.max(1) as f64)
}

/// Sample (x, y, c) of an RGBA buffer with clamped (replicated) coordinates.
pub fn clamped(v: &[f64], w: u32, h: u32, x: i64, y: i64, c: usize) -> f64 {
    let x = x.clamp(0, w as i64 - 1) as usize;
    let y = y.clamp(0, h as i64 - 1) as usize;
    v[(y * w as usize + x) * 4 + c]
}

/// Bilinear sample at texel-space coordinates (texel centres at integers), clamp
/// to edge: what a linear, clamp-to-edge sampler returns.
pub fn bilinear(v: &[f64], w: u32, h: u32, x: f64, y: f64, c: usize) -> f64 {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let t = |dx: i64, dy: i64| clamped(v, w, h, x0 + dx, y0 + dy, c);
    (1.0 - fy) * ((1.0 - fx) * t(0, 0) + fx * t(1, 0)) + fy * ((1.0 - fx) * t(0, 1) + fx * t(1, 1))
}

/// An 8-bit image's samples / 255 (as stored: sRGB-encoded for colour).
pub fn unit_u8(img: &Image) -> Vec<f64> {
    u8s(&img.pixels).iter().map(|&b| b as f64 / 255.0).collect()
}

pub fn greenscreen() -> Option<(Image, Image)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/greenscreen");
    let load = |n: &str| fxgraph::io::load_image(&dir.join(n), &Default::default());
    match (load("greenscreen.jpg"), load("background.jpg")) {
        (Ok(a), Ok(b)) => Some((a, b)),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!(
                "skipping the greenscreen photo test: {e} (corpus folder ../shared/corpus absent?)"
            );
            None
        }
    }
}

/// Compile effects (names or paths) and plan them for an 8-bit `w`x`h` input.
pub fn plan_for(effects: &[&str], w: u32, h: u32) -> (fxgraph::graph::Plan, usize, usize) {
    let chain: Vec<String> = effects.iter().map(|s| s.to_string()).collect();
    let (graph, diags, sources) = crate::common::compile::compile_chain(&chain, &[]);
    let graph = graph
        .unwrap_or_else(|| panic!("{effects:?} does not compile:\n{}", diags.render(&sources)));
    let warnings = diags.warning_count();
    let (p, notes) = plan(
        &graph,
        &InputDesc::rgba8_srgb(w, h),
        &PlanOptions::default(),
    )
    .unwrap_or_else(|d| panic!("{effects:?} does not plan:\n{}", d.render(&sources)));
    (p, warnings, notes.warning_count())
}

pub fn at_u8(v: &[u8], w: u32, x: u32, y: u32) -> u8 {
    v[((y * w + x) * 4) as usize]
}

/// A `w` x `h` 8-bit image: grey `lo` left of column `x0`, grey `hi` from it on.
pub fn grey_step_u8(w: u32, h: u32, x0: u32, lo: u8, hi: u8) -> Image {
    image_u8(w, h, |x, _| {
        let v = if x < x0 { lo } else { hi };
        [v, v, v, 255]
    })
}

/// Asserts that `effect` (its defaults) turns a flat `w` x `h` image of `colour`
/// into a flat image of `want`.
pub fn assert_flat_becomes(
    eng: &mut fxgraph::gpu::executor::Engine,
    effect: &str,
    (w, h): (u32, u32),
    colour: [u8; 4],
    want: [u8; 4],
) {
    let flat = image_u8(w, h, |_, _| colour);
    let px = apply_fx(
        eng,
        effect,
        &[],
        &flat,
        fxgraph::script::types::Format::Rgba8Srgb,
    );
    assert!(
        u8s(&px).chunks(4).all(|p| p == want),
        "{effect}: flat {colour:?} does not become {want:?}"
    );
}

// ---------------------------------------------------------------- blurs

/// The taps of blurX/blurY/pencil_blur for a standard deviation of `sigma` output
/// pixels: (offset, weight) with the centre (0, 1) first and the exact Gaussian
/// weights w(i) = exp(-i^2 / (2 sigma^2)), i <= r = ceil(3 sigma), paired two by two
/// into one bilinear tap each; and the normalising total.
pub fn blur_taps(sigma: f64) -> (Vec<(f64, f64)>, f64) {
    let r = (3.0 * sigma).ceil() as i64;
    let wt = |i: i64| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp();
    let mut taps = vec![(0.0, 1.0)];
    let mut i = 1;
    while i <= r {
        let w1 = wt(i);
        let w2 = if i + 1 > r { 0.0 } else { wt(i + 1) };
        taps.push(((i as f64 * w1 + (i + 1) as f64 * w2) / (w1 + w2), w1 + w2));
        i += 2;
    }
    let total = 1.0 + 2.0 * taps[1..].iter().map(|t| t.1).sum::<f64>();
    (taps, total)
}

/// One blurX/blurY-style pass: a Gaussian of `sigma` output pixels along x
/// (`horizontal`) or y, from an RGBA image of size `from` to one of size `to`.
#[derive(Debug, Clone, Copy)]
pub struct BlurPass {
    pub from: (u32, u32),
    pub to: (u32, u32),
    pub sigma: f64,
    pub horizontal: bool,
}

impl BlurPass {
    /// A blurX pass.
    pub fn along_x(from: (u32, u32), to: (u32, u32), sigma: f64) -> BlurPass {
        let horizontal = true;
        BlurPass {
            from,
            to,
            sigma,
            horizontal,
        }
    }

    /// A blurY pass.
    pub fn along_y(from: (u32, u32), to: (u32, u32), sigma: f64) -> BlurPass {
        let horizontal = false;
        BlurPass {
            horizontal,
            ..BlurPass::along_x(from, to, sigma)
        }
    }

    /// The pass as blurX/blurY sample: the output (`ow` x `oh`) samples `src`
    /// (`iw` x `ih`, RGBA) bilinearly, clamp to edge, at its pixel centres +- the
    /// tap offsets in output pixels. Results rounded to half floats (rgba16f /
    /// r16f storage).
    pub fn bilinear(&self, src: &[f64]) -> Vec<f64> {
        let ((iw, ih), (ow, oh)) = (self.from, self.to);
        let (taps, total) = blur_taps(self.sigma);
        let mut out = vec![0.0; (ow * oh * 4) as usize];
        for y in 0..oh {
            for x in 0..ow {
                let (u, v) = ((x as f64 + 0.5) / ow as f64, (y as f64 + 0.5) / oh as f64);
                for c in 0..4 {
                    let s = |o: f64| {
                        let (uu, vv) = if self.horizontal {
                            (u + o / ow as f64, v)
                        } else {
                            (u, v + o / oh as f64)
                        };
                        bilinear(src, iw, ih, uu * iw as f64 - 0.5, vv * ih as f64 - 0.5, c)
                    };
                    let mut sum = s(0.0);
                    for &(o, p) in &taps[1..] {
                        sum += p * (s(o) + s(-o));
                    }
                    out[((y * ow + x) * 4) as usize + c] = f16r(sum / total);
                }
            }
        }
        out
    }

    /// CPU oracle of a downsampling blurX (`horizontal`) or blurY: `src` (`iw` x `ih`)
    /// is box-prefiltered over the texels under each output texel (m = ceil(ratio / 2)
    /// bilinear fetches per axis, 2 input texels apart, each the mean of 2x2 texels),
    /// then blurred at the output resolution with the exact weights
    /// exp(-i^2 / (2 sigma^2)), |i| <= ceil(3 sigma), edge texels repeated.
    /// Rounded to half floats (rgba16f storage).
    pub fn prefiltered(&self, src: &[f64]) -> Vec<f64> {
        let ((iw, ih), (ow, oh)) = (self.from, self.to);
        let (rx, ry) = (iw as f64 / ow as f64, ih as f64 / oh as f64);
        let m = |r: f64| ((r * 0.5 - 1e-4).ceil() as i64).max(1);
        let (mx, my) = (m(rx), m(ry));
        let prefiltered = |px: i64, py: i64, c: usize| {
            let (u, v) = ((px as f64 + 0.5) / ow as f64, (py as f64 + 0.5) / oh as f64);
            let mut s = 0.0;
            for j in 0..my {
                for k in 0..mx {
                    let ox = (k as f64 - 0.5 * (mx - 1) as f64) * 2.0;
                    let oy = (j as f64 - 0.5 * (my - 1) as f64) * 2.0;
                    s += bilinear(
                        src,
                        iw,
                        ih,
                        u * iw as f64 - 0.5 + ox,
                        v * ih as f64 - 0.5 + oy,
                        c,
                    );
                }
            }
            s / (mx * my) as f64
        };
        let r = (3.0 * self.sigma).ceil() as i64;
        let mut out = vec![0.0; (ow * oh * 4) as usize];
        for y in 0..oh as i64 {
            for x in 0..ow as i64 {
                for c in 0..4 {
                    let (mut sum, mut total) = (0.0, 0.0);
                    for i in -r..=r {
                        let w = (-((i * i) as f64) / (2.0 * self.sigma * self.sigma)).exp();
                        let v = if self.horizontal {
                            prefiltered((x + i).clamp(0, ow as i64 - 1), y, c)
                        } else {
                            prefiltered(x, (y + i).clamp(0, oh as i64 - 1), c)
                        };
                        sum += w * v;
                        total += w;
                    }
                    out[((y as u32 * ow + x as u32) * 4) as usize + c] = f16r(sum / total);
                }
            }
        }
        out
    }
}

/// Bilinear upsample of `src` (`sw` x `sh`) at the pixel centres of a `w` x `h` image.
pub fn upsample(
    src: &[f64],
    (sw, sh): (u32, u32),
    x: u32,
    y: u32,
    (w, h): (u32, u32),
    c: usize,
) -> f64 {
    let (u, v) = ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
    bilinear(src, sw, sh, u * sw as f64 - 0.5, v * sh as f64 - 0.5, c)
}

/// Size of a pass with OUT.SCALE = (0.5, 0.5) (rounded as the planner does).
pub fn half_size(w: u32, h: u32) -> (u32, u32) {
    (
        ((w as f64) * 0.5).round() as u32,
        ((h as f64) * 0.5).round() as u32,
    )
}
