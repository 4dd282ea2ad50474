//! `tonemap`'s Khronos PBR Neutral and AgX operators against their reference
//! formulas, written here again from the published texts (f64, independent of
//! the WGSL), on a ramp of HDR colours.
//!
//! - PBR Neutral: the Khronos specification (KhronosGroup/ToneMapping,
//!   `PBR_Neutral/README.md`): start of compression 0.8 − 0.04, desaturation 0.15.
//! - AgX: Troy Sobotka's transform as in Blender 4, in the form of Benjamin
//!   Wrensch's "minimal AgX" (iolite-engine.com, 2023): the inset and outset
//!   matrices, log2 over [−12.47393, 4.026069] EV, the 6th-order polynomial of
//!   the base contrast sigmoid, the punchy look (power 1.35, saturation 1.4),
//!   and the 2.2 power to linear display light.

use crate::common;

use common::cli::{code, fxrun, stdout};
use common::{engine, image_f32, run, words};
use fxgraph::io::Pixels;
use fxgraph::script::types::Format;

/// Largest accepted |GPU − reference| in display-linear [0, 1] (f32 shader
/// arithmetic against f64; AgX goes through log2 and a polynomial whose terms
/// reach ±40 and cancel).
const TOLERANCE: f64 = 2e-3;

/// `x` rounded to the nearest half float (the input texture is rgba16f).
fn f16r(x: f64) -> f64 {
    half::f16::from_f64(x).to_f64()
}

/// PBR Neutral on a linear colour (after exposure).
fn pbr_neutral(c: [f64; 3]) -> [f64; 3] {
    let start_compression = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = c[0].min(c[1]).min(c[2]);
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = c.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < start_compression {
        return c;
    }
    let d = 1.0 - start_compression;
    let new_peak = 1.0 - d * d / (peak + d - start_compression);
    let c = c.map(|v| v * new_peak / peak);
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    c.map(|v| v * (1.0 - g) + new_peak * g)
}

/// Row-major 3×3 times a column vector.
fn mul(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// AgX with the base look (`punchy` false) or the punchy look.
fn agx(c: [f64; 3], punchy: bool) -> [f64; 3] {
    // rows: output red, green, blue
    let inset = [
        [0.842479062253094, 0.0784335999999992, 0.0792237451477643],
        [0.0423282422610123, 0.878468636469772, 0.0791661274605434],
        [0.0423756549057051, 0.0784336, 0.879142973793104],
    ];
    let outset = [
        [1.19687900512017, -0.0980208811401368, -0.0990297440797205],
        [-0.0528968517574562, 1.15190312990417, -0.0989611768448433],
        [-0.0529716355144438, -0.0980434501171241, 1.15107367264116],
    ];
    let (min_ev, max_ev) = (-12.47393, 4.026069);
    let v = mul(inset, c).map(|x| {
        let e = x.max(1e-10).log2().clamp(min_ev, max_ev);
        let t = (e - min_ev) / (max_ev - min_ev);
        15.5 * t.powi(6) - 40.14 * t.powi(5) + 31.96 * t.powi(4) - 6.868 * t.powi(3)
            + 0.4298 * t.powi(2)
            + 0.1191 * t
            - 0.00232
    });
    let v = if punchy {
        let luma = 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        v.map(|x| luma + 1.4 * (x.max(0.0).powf(1.35) - luma))
    } else {
        v
    };
    mul(outset, v).map(|x| x.max(0.0).powf(2.2))
}

/// A ramp of HDR colours: grey, saturated and near-black rows, values 0..64
/// (exponential along x so that the toe, the shoulder and the clip all get
/// pixels).
fn ramp() -> (u32, u32, fxgraph::io::Image) {
    let (w, h) = (256u32, 6u32);
    let tints = [
        [1.0, 1.0, 1.0],
        [1.0, 0.5, 0.05],
        [0.1, 0.8, 0.3],
        [0.05, 0.1, 1.0],
        [1.0, 0.0, 0.0],
        [0.02, 0.03, 0.025],
    ];
    let img = image_f32(w, h, |x, y| {
        let v = if x == 0 {
            0.0
        } else {
            (2f32).powf(-10.0 + 16.0 * x as f32 / (w - 1) as f32)
        };
        let t = tints[y as usize];
        [v * t[0], v * t[1], v * t[2], 1.0]
    });
    (w, h, img)
}

fn check(operator: &str, look: &str, exposure: f64, reference: impl Fn([f64; 3]) -> [f64; 3]) {
    let Some(mut eng) = engine() else { return };
    let (w, h, img) = ramp();
    let sets = format!("operator={operator} look={look} exposure={exposure}");
    let (_, _, px) = run(&mut eng, &["tonemap"], &words(&sets), &img, Format::Rgba32f).unwrap();
    let (Pixels::F32(out), Pixels::F32(src)) = (&px, &img.pixels) else {
        panic!("expected float pixels")
    };
    let mut worst = (0.0f64, 0u32, 0u32);
    for y in 0..h {
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            let c = [0, 1, 2].map(|k| f16r(src[i + k] as f64).max(0.0) * exposure.exp2());
            let want = reference(c).map(|v| v.clamp(0.0, 1.0));
            for k in 0..3 {
                let got = out[i + k] as f64;
                assert!(got.is_finite(), "{operator}: not finite at ({x}, {y})");
                let d = (got - want[k]).abs();
                if d > worst.0 {
                    worst = (d, x, y);
                }
            }
            assert_eq!(out[i + 3], 1.0, "alpha is kept");
        }
    }
    eprintln!(
        "tonemap {operator} look {look} exposure {exposure}: max |gpu - reference| {:.2e} at ({}, {})",
        worst.0, worst.1, worst.2
    );
    assert!(
        worst.0 < TOLERANCE,
        "{operator} ({look}, exposure {exposure}): {:.3e} at ({}, {}) > {TOLERANCE}",
        worst.0,
        worst.1,
        worst.2
    );
}

#[test]
fn pbr_neutral_matches_the_khronos_formula() {
    check("neutral", "base", 0.0, pbr_neutral);
    check("neutral", "base", -2.0, pbr_neutral);
}

#[test]
fn pbr_neutral_keeps_base_colours_below_the_compression_start() {
    // The specification's promise: a colour whose largest channel (after the
    // toe offset) stays under 0.76 comes out unchanged but for the offset.
    let c = [0.7, 0.4, 0.2];
    let out = pbr_neutral(c);
    for k in 0..3 {
        assert!((out[k] - (c[k] - 0.04)).abs() < 1e-12);
    }
    // and a bright one reaches at most 1, with every channel nearer its peak
    let out = pbr_neutral([20.0, 5.0, 1.0]);
    assert!(out[0] <= 1.0 && out[0] > 0.95 && out[2] / out[0] > 1.0 / 20.0);
}

#[test]
fn agx_base_matches_the_reference() {
    check("agx", "base", 0.0, |c| agx(c, false));
    check("agx", "base", 3.0, |c| agx(c, false));
}

#[test]
fn agx_punchy_matches_the_reference() {
    check("agx", "punchy", 0.0, |c| agx(c, true));
}

#[test]
fn agx_maps_middle_grey_and_black_as_blender() {
    // Scene-linear 0.18 lands near display 0.18 after AgX's base contrast (the
    // polynomial crosses its pivot near there); black stays black.
    let g = agx([0.18; 3], false)[0];
    assert!((0.14..0.24).contains(&g), "middle grey -> {g}");
    assert!(agx([0.0; 3], false)[0] < 1e-3);
}

#[test]
fn describe_lists_the_operators_and_looks() {
    let o = fxrun(&["tonemap", "--describe"]);
    assert_eq!(code(&o), 0);
    let text = stdout(&o);
    for word in ["reinhard", "aces", "neutral", "agx", "punchy"] {
        assert!(text.contains(word), "`{word}` missing from:\n{text}");
    }
}
