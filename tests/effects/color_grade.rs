//! `color_grade` (ASC CDL, saturation, lift/gamma/gain) against its documented formula;
//! the identity settings change nothing.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::io::Image;
use fxgraph::script::types::Format;

#[derive(Clone, Copy)]
struct Grade {
    slope: [f64; 3],
    offset: [f64; 3],
    power: [f64; 3],
    saturation: f64,
    lift: [f64; 3],
    gamma: [f64; 3],
    gain: [f64; 3],
    clamp: bool,
}

impl Grade {
    const IDENTITY: Grade = Grade {
        slope: [1.0; 3],
        offset: [0.0; 3],
        power: [1.0; 3],
        saturation: 1.0,
        lift: [0.0; 3],
        gamma: [1.0; 3],
        gain: [1.0; 3],
        clamp: true,
    };

    fn sets(&self) -> Vec<String> {
        let v = |n: &str, a: [f64; 3]| format!("{n}=({},{},{})", a[0], a[1], a[2]);
        vec![
            v("slope", self.slope),
            v("offset", self.offset),
            v("power", self.power),
            format!("saturation={}", self.saturation),
            v("lift", self.lift),
            v("gamma", self.gamma),
            v("gain", self.gain),
            format!("clamp={}", self.clamp),
        ]
    }

    /// The documented formula: CDL SOP, CDL saturation, lift/gamma/gain.
    fn apply(&self, rgb: [f64; 3]) -> [f64; 3] {
        let pow_pos = |v: f64, e: f64| if v > 0.0 { v.powf(e) } else { v };
        let clamp = |v: f64| if self.clamp { v.clamp(0.0, 1.0) } else { v };
        let sop = |c: usize| {
            pow_pos(
                clamp(rgb[c] * self.slope[c] + self.offset[c]),
                self.power[c],
            )
        };
        let v = [sop(0), sop(1), sop(2)];
        let luma = 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
        let rest = |c: usize| {
            let s = clamp(luma + self.saturation * (v[c] - luma));
            pow_pos(
                self.gain[c] * (s + self.lift[c] * (1.0 - s)),
                1.0 / self.gamma[c],
            )
        };
        [rest(0), rest(1), rest(2)]
    }
}

fn grade_oracle(g: &Grade, src: &[f64]) -> Vec<f64> {
    src.chunks(4)
        .flat_map(|p| {
            let o = g.apply([p[0], p[1], p[2]]);
            [o[0], o[1], o[2], p[3]]
        })
        .collect()
}

fn check_grade(name: &str, g: &Grade, img: &Image) {
    let src = uploaded_f16(img);
    let Some(mut eng) = engine() else { return };
    let sets = g.sets();
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let (_, _, px) = run(&mut eng, &["color_grade"], &sets, img, Format::Rgba32f).unwrap();
    assert_finite(f32s(&px), "color_grade");
    let d = max_diff(f32s(&px), &grade_oracle(g, &src));
    eprintln!("color_grade {name}: max abs diff {d:.2e}");
    assert!(d < 1e-3, "{name}: max abs diff {d}");
}

#[test]
fn color_grade_matches_oracle() {
    let img = pattern_f32(64, 48);
    let warm = Grade {
        slope: [1.2, 0.9, 1.05],
        offset: [0.02, -0.01, 0.0],
        power: [0.9, 1.1, 1.3],
        saturation: 1.3,
        lift: [0.05, 0.0, -0.02],
        gamma: [1.2, 1.0, 0.8],
        gain: [1.1, 1.0, 0.95],
        clamp: true,
    };
    check_grade("warm", &warm, &img);
    check_grade(
        "desaturate",
        &Grade {
            saturation: 0.0,
            ..Grade::IDENTITY
        },
        &img,
    );
    check_grade(
        "cdl only",
        &Grade {
            slope: [0.7, 1.4, 1.0],
            offset: [0.1, 0.0, -0.05],
            power: [2.2, 0.45, 1.0],
            ..Grade::IDENTITY
        },
        &img,
    );
    check_grade(
        "lift gamma gain",
        &Grade {
            lift: [0.1, -0.05, 0.2],
            gamma: [0.5, 2.0, 1.5],
            gain: [0.8, 1.2, 1.0],
            ..Grade::IDENTITY
        },
        &img,
    );
    // HDR values above 1 survive without the clamp.
    let hdr = image_f32(64, 8, |x, y| {
        let v = 4.0 * x as f32 / 63.0;
        [v, v * (y as f32 / 7.0), 4.0 - v, 1.0]
    });
    check_grade(
        "hdr no clamp",
        &Grade {
            clamp: false,
            ..warm
        },
        &hdr,
    );
    check_grade("hdr clamp", &warm, &hdr);
}

#[test]
fn color_grade_identity_is_identity() {
    let Some(mut eng) = engine() else { return };
    // Float: the default parameters change nothing (clamp off for values above 1).
    let img = image_f32(64, 8, |x, y| [x as f32 / 16.0, y as f32 / 7.0, 0.3, 0.5]);
    let src = uploaded_f16(&img);
    let px = apply_fx(
        &mut eng,
        "color_grade",
        &["clamp=false"],
        &img,
        Format::Rgba32f,
    );
    let d = max_diff(f32s(&px), &src);
    assert!(d < 1e-6, "identity changed a float image by {d}");
    // 8-bit sRGB: bit-exact.
    let img = pattern_u8(96, 64);
    let px = apply_fx(&mut eng, "color_grade", &[], &img, Format::Rgba8Srgb);
    assert_eq!(
        u8s(&px),
        u8s(&img.pixels),
        "identity changed an 8-bit image"
    );
}
