//! The CPU oracle of mip chains: a 2 x 2 box filter of 8-bit codes.

/// Level `level` of the box-filtered chain of `img` (RGBA codes, `w` x `h`,
/// sides that stay even down to that level): each level the mean of 2 x 2
/// texels of the previous one, rounded to a code (as the GPU stores each
/// level). Returns the level's width and codes.
pub fn box_level(img: &[u8], (w, h): (usize, usize), level: u32) -> (usize, Vec<u8>) {
    let (mut w, mut h, mut cur) = (w, h, img.to_vec());
    for _ in 0..level {
        assert!(w % 2 == 0 && h % 2 == 0, "{w}x{h} does not halve exactly");
        let (hw, hh) = (w / 2, h / 2);
        let mut next = vec![0u8; hw * hh * 4];
        for y in 0..hh {
            for x in 0..hw {
                for c in 0..4 {
                    let at = |xx: usize, yy: usize| f64::from(cur[4 * (yy * w + xx) + c]);
                    let sum = at(2 * x, 2 * y)
                        + at(2 * x + 1, 2 * y)
                        + at(2 * x, 2 * y + 1)
                        + at(2 * x + 1, 2 * y + 1);
                    next[4 * (y * hw + x) + c] = (sum / 4.0).round() as u8;
                }
            }
        }
        (w, h, cur) = (hw, hh, next);
    }
    (w, cur)
}

/// Level `level` of the chain of `img` (RGBA codes, `w` x `h`, any size) as
/// Vulkan's `vkCmdBlitImage` with a linear filter makes it from the level
/// above (the definition librashader's chains follow): each texel the
/// bilinear sample of the previous level at its centre, edges clamped,
/// rounded to a code. Sides halve rounding down, at least 1. Returns the
/// level's size and codes.
pub fn blit_level(img: &[u8], (w, h): (usize, usize), level: u32) -> ((usize, usize), Vec<u8>) {
    let (mut w, mut h, mut cur) = (w, h, img.to_vec());
    for _ in 0..level {
        let (dw, dh) = ((w / 2).max(1), (h / 2).max(1));
        // Source coordinate of a destination texel's centre, from the first
        // texel centre: the two texels it lies between and the weight of the second.
        let taps = |x: usize, d: usize, s: usize| {
            let p = (x as f64 + 0.5) * s as f64 / d as f64 - 0.5;
            let f = p.floor();
            let clamp = |i: f64| i.clamp(0.0, (s - 1) as f64) as usize;
            (clamp(f), clamp(f + 1.0), p - f)
        };
        let mut next = vec![0u8; dw * dh * 4];
        for y in 0..dh {
            let (y0, y1, ty) = taps(y, dh, h);
            for x in 0..dw {
                let (x0, x1, tx) = taps(x, dw, w);
                for c in 0..4 {
                    let at = |xx: usize, yy: usize| f64::from(cur[4 * (yy * w + xx) + c]);
                    let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * tx;
                    let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * tx;
                    next[4 * (y * dw + x) + c] = (top + (bottom - top) * ty).round() as u8;
                }
            }
        }
        (w, h, cur) = (dw, dh, next);
    }
    ((w, h), cur)
}
