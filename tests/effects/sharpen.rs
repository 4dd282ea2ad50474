//! `sharpen` (an unsharp mask) against an f64 oracle on 8-bit and float images; flat
//! images and amount 0 stay unchanged.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::gpu::executor::Execution;
use fxgraph::script::types::Format;

/// Unsharp mask oracle: max(in + amount * d, 0) where |d| >= threshold, d = in - blur.
fn sharpen_f64(src: &[f64], w: u32, h: u32, amount: f64, sigma: f64, threshold: f64) -> Vec<f64> {
    let blur = blur_f64(src, w, h, sigma);
    src.iter()
        .zip(&blur)
        .enumerate()
        .map(|(i, (&s, &b))| {
            let d = s - b;
            if i % 4 == 3 || d.abs() < threshold {
                s
            } else {
                (s + amount * d).max(0.0)
            }
        })
        .collect()
}

#[test]
fn sharpen_matches_oracle_8bit() {
    let mut images = vec![
        ("pattern", pattern_u8(128, 96)),
        ("odd", pattern_u8(67, 41)),
    ];
    images.extend(coffee_crop().map(|c| ("coffee crop", c)));
    for (name, img) in &images {
        for (amount, sigma) in [(1.0, 1.5), (0.5, 3.0), (2.0, 1.0)] {
            let Some(mut eng) = engine() else { return };
            let sets = format!("amount={amount} sigma={sigma}");
            let (w, h, px) =
                run_raw(&mut eng, &["sharpen"], &words(&sets), img, Format::Rgba8).unwrap();
            let want = sharpen_f64(&stored_u8(img), w, h, amount, sigma, 0.0);
            let d = u8_diff(u8s(&px), &want);
            eprintln!("sharpen {name} amount {amount} sigma {sigma}: {d:?}");
            // Errors of the blur are scaled by the amount.
            let tol = if amount > 1.0 { 2 } else { 1 };
            assert!(
                d.max_lsb <= tol,
                "{name} amount {amount} sigma {sigma}: {d:?}"
            );
        }
    }
}

#[test]
fn sharpen_matches_oracle_float() {
    let img = pattern_f32(96, 64);
    let src = uploaded_f16(&img);
    for (amount, sigma, threshold) in [(1.0, 1.5, 0.0), (3.0, 2.0, 0.0), (1.5, 1.0, 0.05)] {
        let Some(mut eng) = engine() else { return };
        let sets = format!("amount={amount} sigma={sigma} threshold={threshold}");
        let (w, h, px) = run(&mut eng, &["sharpen"], &words(&sets), &img, Format::Rgba32f).unwrap();
        let out = f32s(&px);
        assert_finite(out, "sharpen");
        let want = sharpen_f64(&src, w, h, amount, sigma, threshold);
        // Samples whose |d| is within 1e-3 of the threshold may go either way.
        let blur = blur_f64(&src, w, h, sigma);
        let mut d = 0.0f64;
        for i in 0..out.len() {
            if threshold > 0.0 && ((src[i] - blur[i]).abs() - threshold).abs() < 1e-3 {
                continue;
            }
            d = d.max((out[i] as f64 - want[i]).abs());
        }
        eprintln!("sharpen float amount {amount} sigma {sigma} threshold {threshold}: max abs diff {d:.2e}");
        assert!(
            d < 1e-3 * amount.max(1.0),
            "amount {amount} sigma {sigma} threshold {threshold}: max abs diff {d}"
        );
    }
}

/// The `sharpen` pass as a compute pass (its `@compute` entry point: compute
/// execution, an rgba16f output) against the oracle.
#[test]
fn sharpen_compute_matches_oracle() {
    let img = pattern_f32(96, 64);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    with_execution(&mut eng, Execution::Compute, |eng| {
        for (amount, sigma) in [(1.0, 1.5), (3.0, 2.0)] {
            let sets = format!("amount={amount} sigma={sigma}");
            let (w, h, px) = run(eng, &["sharpen"], &words(&sets), &img, Format::Rgba16f).unwrap();
            let want = sharpen_f64(&src, w, h, amount, sigma, 0.0);
            let d = max_diff(f32s(&px), &want);
            eprintln!("sharpen compute amount {amount} sigma {sigma}: max abs diff {d:.2e}");
            // sharpen_matches_oracle_float's bound, and one rgba16f step of
            // the output (2^-10 up to 2, 2^-9 up to 4).
            assert!(
                d < 1e-3 * amount + 2e-3,
                "amount {amount} sigma {sigma}: max abs diff {d}"
            );
        }
    });
}

#[test]
fn sharpen_flat_and_identity() {
    let Some(mut eng) = engine() else { return };
    // A flat image stays flat.
    let flat = image_f32(50, 40, |_, _| [0.4, 0.1, 0.9, 1.0]);
    let src = uploaded_f16(&flat);
    let px = apply_fx(
        &mut eng,
        "sharpen",
        &["amount=5", "sigma=4"],
        &flat,
        Format::Rgba32f,
    );
    let d = max_diff(f32s(&px), &src);
    assert!(d < 1e-6, "flat float image changed by {d}");
    let flat8 = image_u8(50, 40, |_, _| [12, 200, 99, 255]);
    let px = apply_fx(
        &mut eng,
        "sharpen",
        &["amount=5"],
        &flat8,
        Format::Rgba8Srgb,
    );
    assert_eq!(u8s(&px), u8s(&flat8.pixels), "flat 8-bit image changed");
    // amount 0 is the identity.
    let img = pattern_u8(96, 64);
    let px = apply_fx(&mut eng, "sharpen", &["amount=0"], &img, Format::Rgba8Srgb);
    assert_eq!(
        u8s(&px),
        u8s(&img.pixels),
        "amount 0 changed an 8-bit image"
    );
    let img = pattern_f32(96, 64);
    let px = apply_fx(&mut eng, "sharpen", &["amount=0"], &img, Format::Rgba32f);
    assert_eq!(
        max_diff(f32s(&px), &uploaded_f16(&img)),
        0.0,
        "amount 0 changed a float image"
    );
    // A threshold above every difference leaves the image unchanged too.
    let px = apply_fx(
        &mut eng,
        "sharpen",
        &["amount=2", "threshold=1"],
        &img,
        Format::Rgba32f,
    );
    assert_eq!(
        max_diff(f32s(&px), &uploaded_f16(&img)),
        0.0,
        "threshold 1 changed a float image"
    );
}
