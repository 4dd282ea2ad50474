//! Chroma resampling: the taps of vertical up/downsampling (per frame or per field)
//! and the horizontal row filters, at each layout's chroma siting.

use super::super::y4m::Siting;

/// A 2-tap linear interpolation: `a[i0] + w * (a[i1] - a[i0])`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tap {
    pub(crate) i0: u32,
    pub(crate) i1: u32,
    pub(crate) w: f32,
}

/// For each luma row, the chroma rows it interpolates between.
pub(crate) fn vertical_up_taps(h: usize, ch: usize, siting: Siting, fields: bool) -> Vec<Tap> {
    let lerp = |p: f32, n: usize| -> (usize, usize, f32) {
        let p = p.clamp(0.0, (n - 1) as f32);
        let i0 = p.floor() as usize;
        let i1 = (i0 + 1).min(n - 1);
        (i0, i1, p - i0 as f32)
    };
    (0..h)
        .map(|y| {
            if siting == Siting::Full {
                return Tap {
                    i0: y as u32,
                    i1: y as u32,
                    w: 0.0,
                };
            }
            if fields {
                let mut f = y & 1;
                // Chroma rows of field f: f, f + 2, ...
                let mut nk = (ch + 1 - f) / 2;
                if nk == 0 {
                    f = 0;
                    nk = ch.div_ceil(2);
                }
                let off = if y & 1 == 0 { 0.25 } else { 0.75 };
                let (k0, k1, w) = lerp(((y / 2) as f32 - off) / 2.0, nk);
                return Tap {
                    i0: (2 * k0 + f) as u32,
                    i1: (2 * k1 + f) as u32,
                    w,
                };
            }
            let p = match siting {
                Siting::Between => (y as f32 - 0.5) / 2.0,
                _ => y as f32 / 2.0,
            };
            let (i0, i1, w) = lerp(p, ch);
            Tap {
                i0: i0 as u32,
                i1: i1 as u32,
                w,
            }
        })
        .collect()
}

/// For each chroma row, up to three (luma row, weight) taps of the downsampling filter.
pub(crate) fn vertical_down_taps(
    h: usize,
    ch: usize,
    siting: Siting,
    fields: bool,
) -> Vec<[(u32, f32); 3]> {
    let last = h - 1;
    (0..ch)
        .map(|c| {
            if siting == Siting::Full {
                return [(c as u32, 1.0), (0, 0.0), (0, 0.0)];
            }
            if fields {
                let (f, k) = (c & 1, c >> 1);
                let r0 = 4 * k + f;
                let r1 = if r0 + 2 <= last { r0 + 2 } else { r0 };
                let (w0, w1) = if f == 0 { (0.75, 0.25) } else { (0.25, 0.75) };
                return [(r0 as u32, w0), (r1 as u32, w1), (0, 0.0)];
            }
            let r = 2 * c;
            match siting {
                Siting::Between => [(r as u32, 0.5), ((r + 1).min(last) as u32, 0.5), (0, 0.0)],
                _ => [
                    (r.saturating_sub(1) as u32, 0.25),
                    (r as u32, 0.5),
                    ((r + 1).min(last) as u32, 0.25),
                ],
            }
        })
        .collect()
}

/// Upsample one chroma row (`src`, chroma width `n`) to luma width (`dst`, `2n - 1` or
/// `2n`): bilinear at the siting's sample positions, edges clamped.
#[inline]
pub(crate) fn upsample_row(src: &[f32], dst: &mut [f32], siting: Siting) {
    let n = src.len();
    if siting == Siting::Full {
        dst.copy_from_slice(src);
        return;
    }
    // Pairs (2i, 2i+1) for i in 1..n-1 from src[i-1], src[i], src[i+1]; the first and
    // the last pair below.
    if n >= 3 {
        let inner = dst[2..2 * (n - 1)].chunks_exact_mut(2);
        let it = inner.zip(src.iter().zip(&src[1..]).zip(&src[2..]));
        match siting {
            Siting::Between => {
                for (d, ((&p, &c), &nx)) in it {
                    d[0] = 0.75 * c + 0.25 * p;
                    d[1] = 0.75 * c + 0.25 * nx;
                }
            }
            _ => {
                for (d, ((_, &c), &nx)) in it {
                    d[0] = c;
                    d[1] = 0.5 * (c + nx);
                }
            }
        }
    }
    for i in [0, n - 1] {
        let c = src[i];
        let (p, nx) = (src[i.saturating_sub(1)], src[(i + 1).min(n - 1)]);
        let (even, odd) = match siting {
            Siting::Between => (0.75 * c + 0.25 * p, 0.75 * c + 0.25 * nx),
            _ => (c, 0.5 * (c + nx)),
        };
        dst[2 * i] = even;
        if let Some(o) = dst.get_mut(2 * i + 1) {
            *o = odd;
        }
    }
}

/// Downsample one full-width row (`src`) to chroma width (`dst`): a 2-tap box for
/// chroma between columns, [1 2 1]/4 for co-sited chroma, edges clamped.
#[inline]
pub(crate) fn downsample_row(src: &[f32], dst: &mut [f32], siting: Siting) {
    let n = dst.len();
    let last = src.len() - 1;
    match siting {
        Siting::Full => dst.copy_from_slice(src),
        Siting::Between => {
            for (d, pair) in dst.iter_mut().zip(src.chunks_exact(2)) {
                *d = 0.5 * (pair[0] + pair[1]);
            }
            if src.len() % 2 == 1 {
                dst[n - 1] = src[last];
            }
        }
        Siting::CoSited => {
            dst[0] = 0.75 * src[0] + 0.25 * src[1.min(last)];
            if n >= 2 {
                // dst[i] from src[2i-1], src[2i], src[2i+1] for i in 1..
                // (the last one clamped when the width is odd: src[2i+1] missing).
                let pairs = src[1..].chunks_exact(2).zip(src[2..].chunks(2));
                for (d, (ab, next)) in dst[1..].iter_mut().zip(pairs) {
                    let (a, b) = (ab[0], ab[1]);
                    let c = next.get(1).copied().unwrap_or(b);
                    *d = 0.25 * a + 0.5 * b + 0.25 * c;
                }
            }
        }
    }
}
