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
