//! `gaussian_blur` against an f64 Gaussian (OpenCV's kernel size rule): 8-bit values
//! as stored, float images, odd and thin sizes, and 8-bit colour blurred in linear light.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::gpu::executor::Execution;
use fxgraph::io::Image;
use fxgraph::script::types::Format;

/// Blur `img` (8-bit, values as stored, like OpenCV) on the GPU and compare with
/// the f64 oracle.
fn gaussian_u8_diff(img: &Image, sigma: f64, exact: bool) -> Option<U8Diff> {
    let mut eng = engine()?;
    let sets = format!("sigma={sigma} exact={exact}");
    let (w, h, px) = run_raw(
        &mut eng,
        &["gaussian_blur"],
        &words(&sets),
        img,
        Format::Rgba8,
    )
    .unwrap();
    assert_eq!((w, h), (img.width, img.height));
    let want = blur_f64(&stored_u8(img), w, h, sigma);
    Some(u8_diff(u8s(&px), &want))
}

fn check_gaussian_u8(name: &str, img: &Image, sigmas: &[f64]) {
    for &sigma in sigmas {
        for exact in [false, true] {
            let Some(d) = gaussian_u8_diff(img, sigma, exact) else {
                return;
            };
            eprintln!(
                "gaussian_blur {name} {}x{} sigma {sigma} exact={exact}: {d:?}",
                img.width, img.height
            );
            assert!(
                d.max_lsb <= 1,
                "{name} sigma {sigma} exact={exact}: {d:?} (more than 1 LSB off)"
            );
        }
    }
}

#[test]
fn gaussian_blur_matches_oracle_on_pattern() {
    check_gaussian_u8("pattern", &pattern_u8(128, 96), &[1.0, 2.5, 8.0]);
}

#[test]
fn gaussian_blur_matches_oracle_on_photo() {
    if let Some(img) = coffee_crop() {
        check_gaussian_u8("coffee crop", &img, &[1.0, 2.5, 8.0]);
    }
}

#[test]
fn gaussian_blur_odd_and_thin_sizes() {
    // Radii larger than the image (sigma 8: r = 24 on 41 rows) exercise the border.
    check_gaussian_u8("pattern", &pattern_u8(67, 41), &[1.0, 2.5, 8.0]);
    check_gaussian_u8("1 px wide", &pattern_u8(1, 57), &[1.0, 2.5, 8.0]);
    check_gaussian_u8("1 px high", &pattern_u8(57, 1), &[2.5]);
}

#[test]
fn gaussian_blur_flat_image_stays_flat() {
    let img = image_u8(40, 30, |_, _| [37, 128, 250, 255]);
    for sigma in [0.5, 3.0, 20.0] {
        let Some(mut eng) = engine() else { return };
        let set = format!("sigma={sigma}");
        let (_, _, px) =
            run_raw(&mut eng, &["gaussian_blur"], &[&set], &img, Format::Rgba8).unwrap();
        assert_eq!(u8s(&px), u8s(&img.pixels), "sigma {sigma}");
    }
}

#[test]
fn gaussian_blur_float_matches_oracle() {
    let img = pattern_f32(96, 64);
    let src = uploaded_f16(&img);
    for sigma in [1.0, 4.0] {
        for exact in [false, true] {
            let Some(mut eng) = engine() else { return };
            let sets = format!("sigma={sigma} exact={exact}");
            let (w, h, px) = run(
                &mut eng,
                &["gaussian_blur"],
                &words(&sets),
                &img,
                Format::Rgba32f,
            )
            .unwrap();
            let want = blur_f64(&src, w, h, sigma);
            let d = max_diff(f32s(&px), &want);
            eprintln!("gaussian_blur float sigma {sigma} exact={exact}: max abs diff {d:.2e}");
            // The intermediate is rgba16f, written with round-towards-zero on
            // lavapipe: up to one 2^-11 step.
            assert!(d < 1e-3, "sigma {sigma} exact={exact}: max abs diff {d}");
        }
    }
}

/// The vertical pass as a compute pass (its `@compute` entry point: compute
/// execution, an rgba16f output) against the oracle; sigma 20 (r = 60) takes
/// two rounds of the staged column window (48 taps either side).
#[test]
fn gaussian_blur_compute_columns_match_oracle() {
    let img = pattern_f32(96, 64);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    with_execution(&mut eng, Execution::Compute, |eng| {
        for sigma in [1.0, 4.0, 20.0] {
            let sets = format!("sigma={sigma}");
            let (w, h, px) = run(
                eng,
                &["gaussian_blur"],
                &words(&sets),
                &img,
                Format::Rgba16f,
            )
            .unwrap();
            let want = blur_f64(&src, w, h, sigma);
            let d = max_diff(f32s(&px), &want);
            eprintln!("gaussian_blur compute columns sigma {sigma}: max abs diff {d:.2e}");
            // gaussian_blur_float_matches_oracle's bound, and one more rgba16f
            // step (2^-11 below 1) for the output.
            assert!(d < 1.5e-3, "sigma {sigma}: max abs diff {d}");
        }
    });
}

/// Colour 8-bit inputs are blurred in linear light: decode, blur, encode.
#[test]
fn gaussian_blur_srgb_blurs_linear_light() {
    let img = pattern_u8(96, 64);
    // sRGB-decoded colour, alpha / 255.
    let lin: Vec<f64> = linear(&img.pixels).iter().map(|&v| v as f64).collect();
    for sigma in [1.0, 4.0] {
        let Some(mut eng) = engine() else { return };
        let set = format!("sigma={sigma}");
        let (w, h, px) = run(
            &mut eng,
            &["gaussian_blur"],
            &[&set],
            &img,
            Format::Rgba8Srgb,
        )
        .unwrap();
        let want: Vec<f64> = blur_f64(&lin, w, h, sigma)
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                255.0
                    * if i % 4 == 3 {
                        v
                    } else {
                        linear_to_srgb(v as f32) as f64
                    }
            })
            .collect();
        let d = u8_diff(u8s(&px), &want);
        eprintln!("gaussian_blur sRGB sigma {sigma}: {d:?}");
        // lavapipe's sRGB decode and encode are approximations (measured: up to
        // 0.34 of a code step, and 0.63 LSB instead of 0.5); still within 1 LSB.
        assert!(d.max_lsb <= 1, "sigma {sigma}: {d:?}");
    }
}
