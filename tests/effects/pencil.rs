//! `pencil` against the dodge oracle (half-size blurs of the luma, regularised dodge):
//! grey-white on flat areas, dark at edges, deterministic.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::gpu::executor::{Engine, Execution};
use fxgraph::script::types::Format;

/// The `pencil` sketch level s of an 8-bit image (sRGB-encoded samples): luma,
/// half-size blurs (sigma / 2 half-size pixels, r16f storage), bilinear upsample,
/// regularised dodge, darkness.
fn pencil_oracle(enc: &[f64], w: u32, h: u32, sigma: f64, darkness: f64) -> Vec<f64> {
    let lum: Vec<f64> = enc
        .chunks(4)
        .flat_map(|c| {
            let y = luma709(c);
            [y, y, y, 1.0]
        })
        .collect();
    let hs = half_size(w, h);
    let sigma = sigma * 0.5;
    let bh = BlurPass::along_x((w, h), hs, sigma).bilinear(&lum);
    let g = BlurPass::along_y(hs, hs, sigma).bilinear(&bh);
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let gv = upsample(&g, hs, x, y, (w, h), 0);
            let s =
                ((lum[((y * w + x) * 4) as usize] + 0.01) / (gv.max(0.0) + 0.01)).clamp(0.0, 1.0);
            out.push(s.powf(darkness));
        }
    }
    out
}

/// Tolerance: the oracle models the maths and the half-float storage; the GPU's
/// bilinear taps on the 8-bit input use the sampler's sub-texel precision (8 bits
/// on lavapipe, as D3D/Vulkan hardware commonly has), which moves a tap's value by
/// up to 1/512 of the step between the two texels. The dodge divides by the
/// blurred luma, so in dark areas (G ~ 0.05) that becomes up to ~2 LSB, and the
/// darkness exponent multiplies relative errors by `darkness`: allowed
/// 2 LSB * max(1, darkness), with a PSNR floor of 45 dB.
#[test]
fn pencil_matches_the_dodge_oracle() {
    let Some(mut eng) = engine() else { return };
    matches_the_dodge_oracle(&mut eng);
}

/// The same with the blurs as compute passes (their `@compute` entry points,
/// which run under compute execution).
#[test]
fn pencil_compute_blurs_match_the_dodge_oracle() {
    let Some(mut eng) = engine() else { return };
    with_execution(&mut eng, Execution::Compute, matches_the_dodge_oracle);
}

fn matches_the_dodge_oracle(eng: &mut Engine) {
    let how = eng.execution();
    for (w, h, sigma, darkness) in [(67, 41, 2.0, 1.0), (96, 64, 5.0, 1.0), (67, 41, 3.0, 2.5)] {
        let img = pattern_u8(w, h);
        let set = [format!("sigma={sigma}"), format!("darkness={darkness}")];
        let set: Vec<&str> = set.iter().map(|s| s.as_str()).collect();
        let px = apply_fx(eng, "pencil", &set, &img, Format::Rgba8Srgb);
        let s = pencil_oracle(&unit_u8(&img), w, h, sigma, darkness);
        let want: Vec<f64> = s
            .iter()
            .flat_map(|&v| [255.0 * v, 255.0 * v, 255.0 * v, 255.0])
            .collect();
        let (max, off) = lsb_diff(u8s(&px), &want, |_| true);
        let got: Vec<f32> = u8s(&px).iter().map(|&b| b as f32).collect();
        let want32: Vec<f32> = want.iter().map(|&v| v.round() as f32).collect();
        let q = psnr(&got, &want32, 255.0);
        eprintln!("pencil ({how}) {w}x{h} sigma {sigma} darkness {darkness}: max {max} LSB, {:.2}% off, PSNR {q:.1} dB", off * 100.0);
        let allowed = (2.0 * darkness.max(1.0)) as u8;
        assert!(
            max <= allowed,
            "pencil ({how}) {w}x{h} sigma {sigma}: {max} LSB from the dodge oracle (allowed {allowed})"
        );
        assert!(
            q > 45.0,
            "pencil ({how}) {w}x{h} sigma {sigma}: PSNR {q} dB"
        );
    }
}

#[test]
fn pencil_is_grey_white_on_flat_areas_dark_at_edges_and_deterministic() {
    let Some(mut eng) = engine() else { return };
    // Grey: r = g = b on a colourful pattern.
    let img = pattern_u8(67, 41);
    let a = apply_fx(&mut eng, "pencil", &[], &img, Format::Rgba8Srgb);
    assert!(
        u8s(&a)
            .chunks(4)
            .all(|p| p[0].abs_diff(p[1]) <= 1 && p[1].abs_diff(p[2]) <= 1),
        "pencil output is not grey"
    );
    // Deterministic, with and without paper grain.
    let b = apply_fx(&mut eng, "pencil", &[], &img, Format::Rgba8Srgb);
    assert_eq!(u8s(&a), u8s(&b));
    let g1 = apply_fx(&mut eng, "pencil", &["paper=0.4"], &img, Format::Rgba8Srgb);
    let g2 = apply_fx(&mut eng, "pencil", &["paper=0.4"], &img, Format::Rgba8Srgb);
    assert_eq!(u8s(&g1), u8s(&g2), "paper grain is not deterministic");
    assert_ne!(u8s(&g1), u8s(&a), "paper grain changes nothing");
    // Flat areas are white, whatever their colour (black included).
    for c in [[0, 0, 0, 255], [30, 140, 60, 255], [255, 255, 255, 255]] {
        assert_flat_becomes(&mut eng, "pencil", (40, 30), c, [255, 255, 255, 255]);
    }
    // A vertical step 60 | 200: a dark stroke on the dark side of the edge, white
    // on the bright side and far from the edge.
    let step = grey_step_u8(80, 20, 40, 60, 200);
    let (w, _, px) = run(&mut eng, &["pencil"], &[], &step, Format::Rgba8Srgb).unwrap();
    let v = u8s(&px);
    let row: Vec<u8> = (0..w).map(|x| at_u8(v, w, x, 10)).collect();
    assert!(row[39] < 200, "no stroke beside the edge: {row:?}");
    assert!(
        row[..39].windows(2).all(|p| p[0] >= p[1]),
        "stroke does not darken towards the edge: {row:?}"
    );
    assert_eq!(row[5], 255, "far from the edge is not white: {row:?}");
    assert!(
        row[40..].iter().all(|&b| b == 255),
        "bright side not white: {row:?}"
    );
}
