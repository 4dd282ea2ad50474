//! `fxaa` (FXAA 3.11): a staircase is smoothed and stays in range; flat and
//! low-contrast areas and straight edges are left exactly unchanged.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::io::Image;
use fxgraph::script::types::Format;

/// A binary staircase: white below the line y = 12 + x / 4 (shallow, 4-px stairs).
fn staircase(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        let v = if y as f64 + 0.5 > 12.0 + x as f64 / 4.0 {
            1.0
        } else {
            0.0
        };
        [v, v, v, 1.0]
    })
}

#[test]
fn fxaa_smooths_a_staircase_and_stays_in_range() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(64, 40), (67, 41)] {
        let img = staircase(w, h);
        let px = apply_fx(&mut eng, "fxaa", &[], &img, Format::Rgba32f);
        let out = f32s(&px);
        let inp = f32s(&img.pixels);
        assert!(
            out.iter().all(|&v| (0.0..=1.0).contains(&v)),
            "output outside [0, 1]"
        );
        let mid = |v: &[f32]| v.chunks(4).filter(|p| p[0] > 0.02 && p[0] < 0.98).count();
        assert_eq!(mid(inp), 0);
        let intermediate = mid(out);
        // Largest jump between horizontal neighbours (the stair risers) and the
        // number of pixels changed.
        let step = |v: &[f32]| {
            let mut m: f32 = 0.0;
            for y in 0..h {
                for x in 0..w - 1 {
                    m = m.max((at(v, w, x + 1, y, 0) - at(v, w, x, y, 0)).abs());
                }
            }
            m
        };
        let changed = inp
            .chunks(4)
            .zip(out.chunks(4))
            .filter(|(a, b)| a != b)
            .count();
        eprintln!(
            "fxaa staircase {w}x{h}: {intermediate} intermediate pixels, {changed} changed, max horizontal step {} -> {}",
            step(inp),
            step(out)
        );
        assert!(
            intermediate >= (w as usize) / 2,
            "only {intermediate} intermediate pixels along the edge"
        );
        assert!(
            step(out) <= 0.75,
            "staircase risers not reduced: {}",
            step(out)
        );
        // Only pixels next to the edge change.
        for y in 0..h {
            for x in 0..w {
                let d = (y as f64 + 0.5 - (12.0 + x as f64 / 4.0)).abs();
                if d > 3.0 {
                    assert_eq!(
                        at(out, w, x, y, 0),
                        at(inp, w, x, y, 0),
                        "({x}, {y}) far from the edge changed"
                    );
                }
            }
        }
        // Alpha stays 1 (it is resampled like the colour).
        assert!(out.chunks(4).all(|p| p[3] == 1.0));
    }
}

#[test]
fn fxaa_leaves_flat_and_low_contrast_areas_exactly_unchanged() {
    let Some(mut eng) = engine() else { return };
    // Flat 8-bit image: bytes identical.
    let flat = image_u8(67, 41, |_, _| [37, 120, 201, 255]);
    let px = apply_fx(&mut eng, "fxaa", &[], &flat, Format::Rgba8Srgb);
    assert_eq!(u8s(&px), u8s(&flat.pixels));
    // A smooth horizontal ramp (constant down each column, contrast below the
    // threshold): identical floats.
    let ramp = image_f32(67, 41, |x, _| {
        let v = 0.3 + 0.002 * x as f64;
        [f16r(v) as f32, f16r(v * 0.5) as f32, f16r(0.2) as f32, 1.0]
    });
    let px = apply_fx(&mut eng, "fxaa", &[], &ramp, Format::Rgba32f);
    let d = max_abs_diff(f32s(&px), f32s(&ramp.pixels));
    assert!(d == 0.0, "low-contrast ramp changed by {d}");
    // An 8-bit pattern: every pixel whose local contrast (luma of the sRGB-encoded
    // values over the centre and its 4 neighbours) is clearly below FXAA's
    // threshold max(0.0312, 0.125 * max) keeps its exact bytes.
    let img = pattern_u8(67, 41);
    let (w, h, px) = run(&mut eng, &["fxaa"], &[], &img, Format::Rgba8Srgb).unwrap();
    let (a, b) = (u8s(&img.pixels), u8s(&px));
    let idx = |x: i64, y: i64| {
        ((y.clamp(0, h as i64 - 1) * w as i64 + x.clamp(0, w as i64 - 1)) * 4) as usize
    };
    let luma = |x: i64, y: i64| {
        let i = idx(x, y);
        luma709(&[
            a[i] as f64 / 255.0,
            a[i + 1] as f64 / 255.0,
            a[i + 2] as f64 / 255.0,
        ])
    };
    let (mut checked, mut processed) = (0, 0);
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let l = [
                luma(x, y),
                luma(x, y - 1),
                luma(x, y + 1),
                luma(x - 1, y),
                luma(x + 1, y),
            ];
            let (lo, hi) = l
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            let threshold = (0.0312f64).max(0.125 * hi);
            if hi - lo < 0.9 * threshold {
                let i = idx(x, y);
                assert_eq!(
                    b[i..i + 4],
                    a[i..i + 4],
                    "low-contrast pixel ({x}, {y}) changed"
                );
                checked += 1;
            } else if hi - lo > 1.1 * threshold {
                processed += 1;
            }
        }
    }
    eprintln!(
        "fxaa pattern: {checked} low-contrast pixels unchanged, {processed} above the threshold"
    );
    assert!(
        checked > 500 && processed > 100,
        "{checked} low-contrast, {processed} high-contrast pixels"
    );
}

#[test]
fn fxaa_keeps_a_straight_horizontal_edge_without_subpixel_blend() {
    let Some(mut eng) = engine() else { return };
    // A perfectly horizontal hard edge is not aliased: with subpix = 0 the edge
    // search runs out on both sides equally, the offset is 0, and the pixel is
    // resampled at its own centre.
    let (lo, hi) = (f16r(0.1) as f32, f16r(0.9) as f32);
    let img = image_f32(67, 41, |_, y| {
        if y < 20 {
            [lo, lo, lo, 1.0]
        } else {
            [hi, hi, hi, 1.0]
        }
    });
    let px = apply_fx(&mut eng, "fxaa", &["subpix=0"], &img, Format::Rgba32f);
    let d = max_abs_diff(f32s(&px), f32s(&img.pixels));
    eprintln!("fxaa horizontal edge, subpix 0: max change {d:.2e}");
    assert!(d == 0.0, "straight edge changed by {d}");
    // With the default subpix, FXAA 3.11 softens it slightly (its 3x3 low-pass sees
    // a third of a step): bounded.
    let px = apply_fx(&mut eng, "fxaa", &[], &img, Format::Rgba32f);
    let d = max_abs_diff(f32s(&px), f32s(&img.pixels));
    eprintln!("fxaa horizontal edge, default subpix: max change {d:.3}");
    assert!(d < 0.1, "straight edge changed by {d}");
}
