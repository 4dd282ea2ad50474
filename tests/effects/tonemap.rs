//! `tonemap` against the documented operators on an HDR gradient, and its 8-bit output.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::script::types::Format;

/// The tone curves of `tonemap` (per channel), `op` 0 = reinhard, 1 = aces.
fn tonemap_f64(v: f64, exposure: f64, op: u32, white: f64) -> f64 {
    let x = v.max(0.0) * exposure.exp2();
    let y = match op {
        0 if white > 0.0 => x * (1.0 + x / (white * white)) / (1.0 + x),
        0 => x / (1.0 + x),
        _ => x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14),
    };
    y.clamp(0.0, 1.0)
}

#[test]
fn tonemap_matches_oracle_on_hdr_gradient() {
    // Values 0..20 along x (r, g, b at different scales), a few rows.
    let w = 512;
    let img = image_f32(w, 4, |x, y| {
        let v = 20.0 * x as f32 / (w - 1) as f32;
        [v, v * 0.5, v * 0.05 * (y + 1) as f32, 1.0]
    });
    let src = uploaded_f16(&img);
    let cases: [(&str, f64, u32, f64); 6] = [
        ("aces", 0.0, 1, 0.0),
        ("aces", -1.5, 1, 0.0),
        ("aces", 2.0, 1, 0.0),
        ("reinhard", 0.0, 0, 0.0),
        ("reinhard", 1.0, 0, 0.0),
        ("reinhard", 0.0, 0, 8.0),
    ];
    for (op_name, exposure, op, white) in cases {
        let Some(mut eng) = engine() else { return };
        let sets = format!("operator={op_name} exposure={exposure} white={white}");
        let (_, h, px) = run(&mut eng, &["tonemap"], &words(&sets), &img, Format::Rgba32f).unwrap();
        let out = f32s(&px);
        assert_finite(out, "tonemap");
        let want: Vec<f64> = src
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if i % 4 == 3 {
                    v
                } else {
                    tonemap_f64(v, exposure, op, white)
                }
            })
            .collect();
        let d = max_diff(out, &want);
        eprintln!("tonemap {op_name} exposure {exposure} white {white}: max abs diff {d:.2e}");
        assert!(
            d < 2e-3,
            "{op_name} exposure {exposure} white {white}: max abs diff {d}"
        );
        // 0 maps to 0; monotonic along the gradient; within [0, 1].
        for y in 0..h {
            for c in 0..3 {
                assert_eq!(at(out, w, 0, y, c), 0.0, "{op_name}: 0 does not map to 0");
                for x in 1..w {
                    let (a, b) = (at(out, w, x - 1, y, c), at(out, w, x, y, c));
                    assert!(
                        b >= a && (0.0..=1.0).contains(&b),
                        "{op_name}: not monotonic at x {x}: {a} -> {b}"
                    );
                }
            }
        }
        // Reinhard extended: the white point maps to 1.
        if white > 0.0 {
            let x_white = ((white / 20.0) * (w - 1) as f64).round() as u32;
            assert!(
                at(out, w, x_white + 1, 0, 0) > 0.999,
                "white point does not reach 1"
            );
        }
    }
}

#[test]
fn tonemap_writes_8bit_output() {
    // An HDR input written to an 8-bit sRGB target: the oracle encoded to sRGB.
    let img = image_f32(64, 8, |x, y| {
        let v = 0.05 * (x * (y + 1)) as f32;
        [v, v * 0.3, v * 2.0, 1.0]
    });
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    let px = apply_fx(
        &mut eng,
        "tonemap",
        &["operator=reinhard"],
        &img,
        Format::Rgba8Srgb,
    );
    let want: Vec<f64> = src
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            255.0
                * if i % 4 == 3 {
                    v
                } else {
                    linear_to_srgb(tonemap_f64(v, 0.0, 0, 0.0) as f32) as f64
                }
        })
        .collect();
    let d = u8_diff(u8s(&px), &want);
    eprintln!("tonemap to rgba8-srgb: {d:?}");
    assert!(d.max_lsb <= 1, "{d:?}");
}
