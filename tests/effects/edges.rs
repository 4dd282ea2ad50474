//! `edges` against a CPU Sobel on Rec.709 luma: flat areas give 0, a step gives the
//! analytic magnitude, and the overlay mixes the edge colour into the image.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::script::types::Format;

/// The `edges` grey level v (before 8-bit storage) of an image of sRGB-encoded
/// samples: Sobel on Rec.709 luma, replicated border, |G| / 4.
fn sobel_oracle(enc: &[f64], w: u32, h: u32, scale: f64, threshold: f64, invert: bool) -> Vec<f64> {
    let lum: Vec<f64> = enc
        .chunks(4)
        .flat_map(|c| [luma709(c), 0.0, 0.0, 0.0])
        .collect();
    let mut out = Vec::with_capacity(enc.len());
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let l = |dx: i64, dy: i64| clamped(&lum, w, h, x + dx, y + dy, 0);
            let gx = (l(1, -1) + 2.0 * l(1, 0) + l(1, 1)) - (l(-1, -1) + 2.0 * l(-1, 0) + l(-1, 1));
            let gy = (l(-1, 1) + 2.0 * l(0, 1) + l(1, 1)) - (l(-1, -1) + 2.0 * l(0, -1) + l(1, -1));
            let mut e = scale * 0.25 * (gx * gx + gy * gy).sqrt();
            if e < threshold {
                e = 0.0;
            }
            let v = if invert { 1.0 - e } else { e }.clamp(0.0, 1.0);
            out.extend([v, v, v, clamped(enc, w, h, x, y, 3)]);
        }
    }
    out
}

#[test]
fn edges_matches_cpu_sobel() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(67, 41), (128, 96)] {
        let img = pattern_u8(w, h);
        let enc = unit_u8(&img);
        for (set, scale, threshold, invert) in [
            (vec![], 1.0, 0.0, false),
            (vec!["scale=2.5"], 2.5, 0.0, false),
            (vec!["threshold=0.3", "invert=true"], 1.0, 0.3, true),
        ] {
            let (ow, oh, px) = run(&mut eng, &["edges"], &set, &img, Format::Rgba8Srgb).unwrap();
            assert_eq!((ow, oh), (w, h));
            let want: Vec<f64> = sobel_oracle(&enc, w, h, scale, threshold, invert)
                .iter()
                .map(|v| v * 255.0)
                .collect();
            // Threshold decisions within float error of the cut are ambiguous: skip those pixels.
            let ambiguous = |i: usize| {
                let p = i / 4;
                let e =
                    sobel_oracle_e(&enc, w, h, (p % w as usize) as i64, (p / w as usize) as i64)
                        * scale;
                threshold > 0.0 && (e - threshold).abs() < 1e-4
            };
            let (max, off) = lsb_diff(u8s(&px), &want, |i| !ambiguous(i));
            eprintln!(
                "edges {w}x{h} {set:?}: max {max} LSB, {:.2}% off by one",
                off * 100.0
            );
            assert!(
                max <= 1,
                "edges {w}x{h} {set:?}: {max} LSB from the CPU Sobel"
            );
        }
    }
}

/// Unscaled |G| / 4 at one pixel (for the threshold ambiguity test).
fn sobel_oracle_e(enc: &[f64], w: u32, h: u32, x: i64, y: i64) -> f64 {
    let l = |dx: i64, dy: i64| {
        let c: Vec<f64> = (0..3)
            .map(|c| clamped(enc, w, h, x + dx, y + dy, c))
            .collect();
        luma709(&c)
    };
    let gx = (l(1, -1) + 2.0 * l(1, 0) + l(1, 1)) - (l(-1, -1) + 2.0 * l(-1, 0) + l(-1, 1));
    let gy = (l(-1, 1) + 2.0 * l(0, 1) + l(1, 1)) - (l(-1, -1) + 2.0 * l(0, -1) + l(1, -1));
    0.25 * (gx * gx + gy * gy).sqrt()
}

#[test]
fn edges_flat_is_zero_and_step_gives_the_analytic_magnitude() {
    let Some(mut eng) = engine() else { return };
    // Flat colour: no gradient anywhere, borders included.
    assert_flat_becomes(
        &mut eng,
        "edges",
        (67, 41),
        [90, 140, 200, 255],
        [0, 0, 0, 255],
    );
    // Vertical step of grey 40 | 200 between x = 29 and x = 30: |G| / 4 = 160 / 255 on
    // both columns beside it, 0 elsewhere (also at the replicated borders).
    let step = grey_step_u8(67, 41, 30, 40, 200);
    let (w, _, px) = run(&mut eng, &["edges"], &[], &step, Format::Rgba8Srgb).unwrap();
    let v = u8s(&px);
    for y in 0..41u32 {
        for x in 0..67u32 {
            let i = ((y * w + x) * 4) as usize;
            let want = if x == 29 || x == 30 { 160 } else { 0 };
            assert!(
                v[i].abs_diff(want) <= 1 && v[i] == v[i + 1] && v[i] == v[i + 2],
                "({x}, {y}): {:?}, want {want}",
                &v[i..i + 4]
            );
        }
    }
    // Float input (linear light): read through an inserted linear -> sRGB
    // conversion pass (rgba16f); a 0 | 1 step gives 1 beside the edge. lavapipe
    // rounds rgba16f render-target writes toward zero, so 1.0 is stored there as
    // 1 - 2^-11 and decoded as 1 - 2.4 * 2^-11: tolerance 2e-3.
    let fstep = image_f32(33, 17, |x, _| {
        if x < 16 {
            [0.0, 0.0, 0.0, 1.0]
        } else {
            [1.0, 1.0, 1.0, 1.0]
        }
    });
    let (w, _, px) = run(&mut eng, &["edges"], &[], &fstep, Format::Rgba32f).unwrap();
    let v = f32s(&px);
    for x in 0..33u32 {
        let want = if x == 15 || x == 16 { 1.0 } else { 0.0 };
        assert!(
            (at(v, w, x, 8, 0) - want).abs() < 2e-3,
            "float step at x = {x}: {}",
            at(v, w, x, 8, 0)
        );
    }
}

#[test]
fn edges_overlay_mixes_the_edge_colour_into_the_image() {
    let Some(mut eng) = engine() else { return };
    let step = grey_step_u8(40, 20, 20, 40, 200);
    let (w, _, px) = run(
        &mut eng,
        &["edges"],
        &["mode=overlay", "color=(1, 0, 0)"],
        &step,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let v = u8s(&px);
    let p = |x: u32| &v[((10 * w + x) * 4) as usize..((10 * w + x) * 4 + 4) as usize];
    // Away from the edge: the image unchanged.
    assert_eq!(p(5), [40, 40, 40, 255]);
    assert_eq!(p(35), [200, 200, 200, 255]);
    // Beside it: mix(image', red, 160/255) in sRGB-encoded values.
    let e = 160.0 / 255.0;
    for (x, base) in [(19u32, 40.0), (20, 200.0)] {
        let want = [
            base * (1.0 - e) + 255.0 * e,
            base * (1.0 - e),
            base * (1.0 - e),
        ];
        for c in 0..3 {
            assert!(
                (p(x)[c] as f64 - want[c]).abs() <= 1.0,
                "overlay at x = {x}: {:?}, want {want:?}",
                p(x)
            );
        }
    }
}
