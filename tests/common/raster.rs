//! CPU rendering of analytic 2-D scenes for the temporal-effect tests (taa,
//! motion_blur): point samples at the pixel centre plus a jitter (what a
//! rasteriser without anti-aliasing produces), box-filtered supersampled
//! references, and the error measure. Coordinates are in pixels, origin at the
//! top-left corner of the top-left pixel, y down (pixel centres at i + 0.5).

use super::image_f32;
use fxgraph::io::Image;

/// One sample per pixel at (x + 0.5 + jitter.x, y + 0.5 + jitter.y); alpha 1.
pub fn point_sampled(w: u32, h: u32, jitter: [f32; 2], f: impl Fn(f32, f32) -> [f32; 3]) -> Image {
    image_f32(w, h, |x, y| {
        let c = f(x as f32 + 0.5 + jitter[0], y as f32 + 0.5 + jitter[1]);
        [c[0], c[1], c[2], 1.0]
    })
}

/// The pixel-area average (box filter) estimated with n x n samples at the
/// centres of an n x n grid of sub-pixels; alpha 1.
pub fn supersampled(w: u32, h: u32, n: u32, f: impl Fn(f32, f32) -> [f32; 3]) -> Image {
    image_f32(w, h, |x, y| {
        let mut s = [0.0f64; 3];
        for b in 0..n {
            for a in 0..n {
                let c = f(
                    x as f32 + (a as f32 + 0.5) / n as f32,
                    y as f32 + (b as f32 + 0.5) / n as f32,
                );
                for k in 0..3 {
                    s[k] += c[k] as f64;
                }
            }
        }
        let m = (n * n) as f64;
        [(s[0] / m) as f32, (s[1] / m) as f32, (s[2] / m) as f32, 1.0]
    })
}

/// A constant image (aux inputs: motion in r, g; depth in r).
pub fn constant(w: u32, h: u32, v: [f32; 4]) -> Image {
    image_f32(w, h, |_, _| v)
}

/// Root-mean-square difference of r, g, b over the pixels at least `border`
/// pixels from the edges of a `w` x `h` RGBA image.
pub fn rgb_rmse(a: &[f32], b: &[f32], w: u32, h: u32, border: u32) -> f64 {
    let mut s = 0.0f64;
    let mut n = 0usize;
    for y in border..h - border {
        for x in border..w - border {
            let i = ((y * w + x) * 4) as usize;
            for c in 0..3 {
                s += ((a[i + c] - b[i + c]) as f64).powi(2);
                n += 1;
            }
        }
    }
    (s / n as f64).sqrt()
}

/// AUX.motion and AUX.depth of an object over a background, taken at the pixel
/// centres: `object` = (motion, depth) where `on_object(x, y)`, `background`
/// elsewhere. Motion in pixels in r, g; depth in r, g, b.
pub fn object_aux(
    w: u32,
    h: u32,
    on_object: impl Fn(f32, f32) -> bool,
    object: ([f32; 2], f32),
    background: ([f32; 2], f32),
) -> Vec<(String, Image)> {
    let at = |x: u32, y: u32| {
        if on_object(x as f32 + 0.5, y as f32 + 0.5) {
            object
        } else {
            background
        }
    };
    let motion = image_f32(w, h, |x, y| {
        let m = at(x, y).0;
        [m[0], m[1], 0.0, 1.0]
    });
    let depth = image_f32(w, h, |x, y| {
        let d = at(x, y).1;
        [d, d, d, 1.0]
    });
    vec![("motion".into(), motion), ("depth".into(), depth)]
}
