//! Y'CbCr frames to RGBA: chroma upsampled at its siting (per field for interlaced
//! 4:2:0), the matrix, then the caller's row store (8-bit codes or linear floats).

use super::resample::{upsample_row, vertical_up_taps, Tap};
use super::samples::{Bytes, Coeffs, Store, Words};
use super::{check_rgba, threads_for, YuvConversion};
use crate::io::y4m::{Y4mHeader, YuvFrame};

/// Convert a frame to RGBA pixels of any type. For each output row,
/// `emit(out_row, r, g, b)` stores the row from its R'G'B' values (unclipped, scaled by
/// `scale`: 1.0 is the unit range), given as three planar rows (structure of arrays, so
/// that the per-pixel arithmetic vectorises; `emit` may overwrite them).
pub(crate) fn yuv_to_rgba<T: Send>(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [T],
    scale: f32,
    emit: impl Fn(&mut [T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) -> Result<(), String> {
    check_rgba(header, out.len())?;
    frame.check_size(header)?;
    if header.depth > 8 {
        convert::<T, Words>(frame, header, conv, out, scale, emit);
    } else {
        convert::<T, Bytes>(frame, header, conv, out, scale, emit);
    }
    Ok(())
}

/// [`yuv_to_rgba`] for samples stored as `S` (sizes checked by the caller).
fn convert<T: Send, S: Store>(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [T],
    scale: f32,
    emit: impl Fn(&mut [T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) {
    let (w, h) = (header.width as usize, header.height as usize);
    let chroma = header.colorspace;
    let (cw, _) = chroma.chroma_size(header.width, header.height);
    let k = Coeffs::new(conv, header.depth);
    // Y' = (Y - y_off) * ys; Pb = (Cb - c_mid) * cs, both times `scale`.
    let ys = scale / k.y_scale;
    let y0s = -k.y_off * ys;
    let cs = scale / k.c_scale;
    let c0s = k.c_mid * cs;
    let vtaps = chroma_taps(frame, header, conv);
    let hsiting = chroma.horizontal_siting();
    let (yb, cb) = (w * S::BYTES, cw * S::BYTES);
    let threads = threads_for(w * h, h);
    let band = h.div_ceil(threads);
    let work = |y0: usize, out: &mut [T]| {
        let mut cu = vec![0f32; cw];
        let mut cv = vec![0f32; cw];
        let mut fu = vec![0f32; w];
        let mut fv = vec![0f32; w];
        let mut rr = vec![0f32; w];
        let mut gg = vec![0f32; w];
        let mut bb = vec![0f32; w];
        for (dy, orow) in out.chunks_exact_mut(w * 4).enumerate() {
            let y = y0 + dy;
            let yrow = &frame.y[y * yb..(y + 1) * yb];
            if !chroma.has_chroma() {
                for (d, l) in rr.iter_mut().zip(S::samples(yrow)) {
                    *d = l * ys + y0s;
                }
                gg.copy_from_slice(&rr);
                bb.copy_from_slice(&rr);
                emit(orow, &mut rr, &mut gg, &mut bb);
                continue;
            }
            let t = vtaps[y];
            for (plane, crow) in [(&frame.u, &mut cu), (&frame.v, &mut cv)] {
                let r0 = &plane[t.i0 as usize * cb..][..cb];
                let r1 = &plane[t.i1 as usize * cb..][..cb];
                let (w0, w1) = ((1.0 - t.w) * cs, t.w * cs);
                for ((d, a), b) in crow.iter_mut().zip(S::samples(r0)).zip(S::samples(r1)) {
                    *d = a * w0 + b * w1 - c0s;
                }
            }
            upsample_row(&cu, &mut fu, hsiting);
            upsample_row(&cv, &mut fv, hsiting);
            for (((((r, g), b), l), &pb), &pr) in rr
                .iter_mut()
                .zip(gg.iter_mut())
                .zip(bb.iter_mut())
                .zip(S::samples(yrow))
                .zip(&fu)
                .zip(&fv)
            {
                let yv = l * ys + y0s;
                *r = yv + k.rv * pr;
                *g = yv + k.gu * pb + k.gv * pr;
                *b = yv + k.bu * pb;
            }
            emit(orow, &mut rr, &mut gg, &mut bb);
        }
    };
    in_bands(out, w * 4, band, threads, work);
}

/// The vertical upsampling taps of each output row (per field for interlaced 4:2:0);
/// none without chroma.
fn chroma_taps(frame: &YuvFrame, header: &Y4mHeader, conv: &YuvConversion) -> Vec<Tap> {
    let chroma = header.colorspace;
    let (_, ch) = chroma.chroma_size(header.width, header.height);
    if chroma.has_chroma() {
        vertical_up_taps(
            header.height as usize,
            ch,
            chroma.vertical_siting(),
            frame.field_chroma(header, conv),
        )
    } else {
        Vec::new()
    }
}

/// `work(first_row, rows)` over bands of `band` rows of `out` (`row_len` items a row),
/// one thread each; on this thread with one.
fn in_bands<T: Send>(
    out: &mut [T],
    row_len: usize,
    band: usize,
    threads: usize,
    work: impl Fn(usize, &mut [T]) + Sync,
) {
    if threads == 1 {
        work(0, out);
    } else {
        std::thread::scope(|s| {
            for (i, chunk) in out.chunks_mut(band * row_len).enumerate() {
                let work = &work;
                s.spawn(move || work(i * band, chunk));
            }
        });
    }
}
