//! RGBA to Y'CbCr frames: the matrix, then chroma downsampled at its siting (per
//! field for interlaced 4:2:0), rounded to codes of the frame's depth.

use super::resample::{downsample_row, vertical_down_taps};
use super::samples::{Bytes, Coeffs, Store, Words};
use super::{check_rgba, threads_for, YuvConversion};
use crate::io::y4m::{Chroma, Y4mHeader, YuvFrame};

/// Convert RGBA pixels of any type to a frame: `load(in_row, r, g, b)` stores the R'G'B'
/// values of one input row into three planar rows (alpha is ignored). `frame.params` are
/// kept (they decide the chroma fields of `Im` streams).
pub(crate) fn rgba_to_yuv<T: Sync>(
    rgba: &[T],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
    load: impl Fn(&[T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) -> Result<(), String> {
    check_rgba(header, rgba.len())?;
    if header.depth > 8 {
        convert::<T, Words>(rgba, header, conv, frame, load);
    } else {
        convert::<T, Bytes>(rgba, header, conv, frame, load);
    }
    Ok(())
}

/// [`rgba_to_yuv`] for samples stored as `S` (sizes checked by the caller).
fn convert<T: Sync, S: Store>(
    rgba: &[T],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
    load: impl Fn(&[T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) {
    let (w, h) = (header.width as usize, header.height as usize);
    let chroma = header.colorspace;
    let (cw, ch) = chroma.chroma_size(header.width, header.height);
    let k = Coeffs::new(conv, header.depth);
    frame.y.resize(w * h * S::BYTES, 0);
    frame.u.resize(cw * ch * S::BYTES, 0);
    frame.v.resize(cw * ch * S::BYTES, 0);
    let fields = frame.field_chroma(header, conv);
    let g = Geometry {
        w,
        h,
        cw,
        ch,
        chroma,
        threads: threads_for(w * h, h),
    };
    // Pass 1: luma, and Pb / Pr (in code units, without the c_mid offset) of every row,
    // downsampled across to chroma width.
    let mut pb = vec![0f32; if chroma.has_chroma() { cw * h } else { 0 }];
    let mut pr = vec![0f32; pb.len()];
    luma_and_row_chroma::<T, S>(rgba, &g, &k, &mut frame.y, (&mut pb, &mut pr), load);
    if !chroma.has_chroma() {
        return;
    }
    // Pass 2: vertical downsampling into the chroma planes.
    vertical_chroma::<S>(&g, &k, fields, (&pb, &pr), (&mut frame.u, &mut frame.v));
}

/// The sizes and chroma layout of a frame being converted, and the threads its rows
/// are shared among.
struct Geometry {
    w: usize,
    h: usize,
    /// The chroma planes' size.
    cw: usize,
    ch: usize,
    chroma: Chroma,
    threads: usize,
}

/// Pass 1: the luma plane `yplane`, and Pb / Pr (in code units, without the c_mid
/// offset) of every row downsampled across to chroma width into `pb` and `pr` (rows
/// shared among the threads).
fn luma_and_row_chroma<T: Sync, S: Store>(
    rgba: &[T],
    g: &Geometry,
    k: &Coeffs,
    yplane: &mut [u8],
    (pb, pr): (&mut [f32], &mut [f32]),
    load: impl Fn(&[T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) {
    let (w, h, cw, chroma, threads) = (g.w, g.h, g.cw, g.chroma, g.threads);
    let hsiting = chroma.horizontal_siting();
    // Y' code = y_off + y_scale * Y'; chroma code = c_mid + c_scale * P.
    let (ky_r, ky_g, ky_b) = (k.y_scale * k.kr, k.y_scale * k.kg, k.y_scale * k.kb);
    let (pb_s, pr_s) = (0.5 / (1.0 - k.kb), 0.5 / (1.0 - k.kr));
    let band = h.div_ceil(threads);
    let pass1 = |y0: usize, yout: &mut [u8], pbo: &mut [f32], pro: &mut [f32]| {
        let mut rr = vec![0f32; w];
        let mut gg = vec![0f32; w];
        let mut bb = vec![0f32; w];
        for (dy, yrow) in yout.chunks_exact_mut(w * S::BYTES).enumerate() {
            let y = y0 + dy;
            load(&rgba[y * w * 4..(y + 1) * w * 4], &mut rr, &mut gg, &mut bb);
            if !chroma.has_chroma() {
                for ((g, &r), &b) in gg.iter_mut().zip(&rr).zip(&bb) {
                    *g = k.y_off + ky_r * r + ky_g * *g + ky_b * b;
                }
                S::store(&gg, yrow, k.max);
                continue;
            }
            // The luma code in place of G'; Pb and Pr in place of B' and R'.
            for (r, (g, b)) in rr.iter_mut().zip(gg.iter_mut().zip(bb.iter_mut())) {
                let yl = k.kr * *r + k.kg * *g + k.kb * *b;
                *g = k.y_off + k.y_scale * yl;
                *b = k.c_scale * pb_s * (*b - yl);
                *r = k.c_scale * pr_s * (*r - yl);
            }
            S::store(&gg, yrow, k.max);
            downsample_row(&bb, &mut pbo[dy * cw..(dy + 1) * cw], hsiting);
            downsample_row(&rr, &mut pro[dy * cw..(dy + 1) * cw], hsiting);
        }
    };
    if threads == 1 {
        pass1(0, yplane, pb, pr);
    } else {
        std::thread::scope(|s| {
            let cband = if chroma.has_chroma() { band * cw } else { 1 };
            let mut pbc = pb.chunks_mut(cband);
            let mut prc = pr.chunks_mut(cband);
            for (i, yc) in yplane.chunks_mut(band * w * S::BYTES).enumerate() {
                let pbo = pbc.next().unwrap_or_default();
                let pro = prc.next().unwrap_or_default();
                let pass1 = &pass1;
                s.spawn(move || pass1(i * band, yc, pbo, pro));
            }
        });
    }
}

/// Pass 2: the rows of `pb` and `pr` downsampled vertically (per field when `fields`)
/// into the chroma planes `u` and `v` (rows shared among the threads).
fn vertical_chroma<S: Store>(
    g: &Geometry,
    k: &Coeffs,
    fields: bool,
    (pb, pr): (&[f32], &[f32]),
    (u, v): (&mut [u8], &mut [u8]),
) {
    let (h, cw, ch, chroma, threads) = (g.h, g.cw, g.ch, g.chroma, g.threads);
    let taps = vertical_down_taps(h, ch, chroma.vertical_siting(), fields);
    let band = ch.div_ceil(threads);
    let cb = cw * S::BYTES;
    let pass2 = |c0: usize, uo: &mut [u8], vo: &mut [u8]| {
        let mut row = vec![0f32; cw];
        for (dc, (urow, vrow)) in uo
            .chunks_exact_mut(cb)
            .zip(vo.chunks_exact_mut(cb))
            .enumerate()
        {
            let t = taps[c0 + dc];
            for (src, dst) in [(pb, urow), (pr, vrow)] {
                let r0 = &src[t[0].0 as usize * cw..][..cw];
                let r1 = &src[t[1].0 as usize * cw..][..cw];
                let r2 = &src[t[2].0 as usize * cw..][..cw];
                let (w0, w1, w2) = (t[0].1, t[1].1, t[2].1);
                for (d, ((&a, &b), &c)) in row.iter_mut().zip(r0.iter().zip(r1).zip(r2)) {
                    *d = k.c_mid + w0 * a + w1 * b + w2 * c;
                }
                S::store(&row, dst, k.max);
            }
        }
    };
    if threads == 1 {
        pass2(0, u, v);
    } else {
        std::thread::scope(|s| {
            for (i, (uc, vc)) in u
                .chunks_mut(band * cb)
                .zip(v.chunks_mut(band * cb))
                .enumerate()
            {
                let pass2 = &pass2;
                s.spawn(move || pass2(i * band, uc, vc));
            }
        });
    }
}
