//! `vignette` against its documented falloff, and the centre of an 8-bit image kept.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::script::types::Format;

/// Parameters of `vignette`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Vignette {
    strength: f64,
    radius: f64,
    softness: f64,
    center: [f64; 2],
    roundness: f64,
}

impl Vignette {
    const DEFAULT: Vignette = Vignette {
        strength: 0.5,
        radius: 0.8,
        softness: 0.8,
        center: [0.5, 0.5],
        roundness: 1.0,
    };

    fn sets(&self) -> Vec<String> {
        vec![
            format!("strength={}", self.strength),
            format!("radius={}", self.radius),
            format!("softness={}", self.softness),
            format!("center=({},{})", self.center[0], self.center[1]),
            format!("roundness={}", self.roundness),
        ]
    }

    /// The factor of the documented formula at pixel (x, y) of a w x h image.
    fn factor(&self, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (wf, hf) = (w as f64, h as f64);
        let u = (x as f64 + 0.5) / wf;
        let v = (y as f64 + 0.5) / hf;
        let a = if wf >= hf {
            [wf / hf, 1.0]
        } else {
            [1.0, hf / wf]
        };
        let s = [
            1.0 + (a[0] - 1.0) * self.roundness,
            1.0 + (a[1] - 1.0) * self.roundness,
        ];
        let q = [
            (u - self.center[0]) * 2.0 * s[0],
            (v - self.center[1]) * 2.0 * s[1],
        ];
        let d = (q[0] * q[0] + q[1] * q[1]).sqrt();
        let t = ((d - self.radius) / self.softness.max(1e-5)).clamp(0.0, 1.0);
        1.0 - self.strength * t * t * (3.0 - 2.0 * t)
    }
}

#[test]
fn vignette_matches_oracle() {
    let d = Vignette::DEFAULT;
    let cases = [
        (128, 96, d),
        (
            128,
            96,
            Vignette {
                strength: 1.0,
                radius: 0.3,
                softness: 0.5,
                roundness: 0.0,
                ..d
            },
        ),
        (
            72,
            128,
            Vignette {
                strength: 0.7,
                radius: 0.5,
                softness: 1.0,
                roundness: 0.5,
                ..d
            },
        ),
        (
            128,
            96,
            Vignette {
                strength: 0.8,
                radius: 0.2,
                softness: 0.6,
                center: [0.3, 0.6],
                ..d
            },
        ),
    ];
    for (w, h, vg) in cases {
        let img = image_f32(w, h, |x, y| {
            [0.8, 0.5 + 0.3 * ((x + y) % 2) as f32, 0.25, 0.75]
        });
        let src = uploaded_f16(&img);
        let Some(mut eng) = engine() else { return };
        let sets = vg.sets();
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let px = apply_fx(&mut eng, "vignette", &sets, &img, Format::Rgba32f);
        let out = f32s(&px);
        let mut want = src.clone();
        for y in 0..h {
            for x in 0..w {
                let f = vg.factor(x, y, w, h);
                for c in 0..3 {
                    want[((y * w + x) * 4) as usize + c] *= f;
                }
            }
        }
        let diff = max_diff(out, &want);
        eprintln!("vignette {w}x{h} {vg:?}: max abs diff {diff:.2e}");
        assert!(diff < 1e-4, "{vg:?}: max abs diff {diff}");
        // The centre pixel is unchanged; corners are darkened.
        let (cx, cy) = (
            (vg.center[0] * w as f64) as u32,
            (vg.center[1] * h as f64) as u32,
        );
        for c in 0..4 {
            assert_eq!(
                at(out, w, cx, cy, c) as f64,
                src[((cy * w + cx) * 4) as usize + c],
                "centre pixel changed"
            );
        }
        for (x, y) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)] {
            assert!(
                at(out, w, x, y, 0) < 0.8 * 0.9,
                "corner ({x}, {y}) not darkened: {}",
                at(out, w, x, y, 0)
            );
        }
        // Centred: symmetric left/right and top/bottom.
        if vg.center == [0.5, 0.5] {
            for y in 0..h {
                for x in 0..w {
                    let f = at(out, w, x, y, 0);
                    for (mx, my) in [(w - 1 - x, y), (x, h - 1 - y)] {
                        let g = at(out, w, mx, my, 0);
                        assert!(
                            (f - g).abs() < 1e-5,
                            "not symmetric: ({x}, {y}) {f} vs ({mx}, {my}) {g}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn vignette_keeps_8bit_centre() {
    let img = pattern_u8(96, 64);
    let vg = Vignette {
        strength: 1.0,
        ..Vignette::DEFAULT
    };
    let Some(mut eng) = engine() else { return };
    let (w, h, px) = run(
        &mut eng,
        &["vignette"],
        &["strength=1"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let (got, src) = (u8s(&px), u8s(&img.pixels));
    let i = (((h / 2) * w + w / 2) * 4) as usize;
    assert_eq!(&got[i..i + 4], &src[i..i + 4], "centre pixel changed");
    // Darkened in linear light: decode, scale, encode.
    let lin = linear(&img.pixels);
    let want: Vec<f64> = (0..got.len())
        .map(|i| {
            let p = (i / 4) as u32;
            if i % 4 == 3 {
                255.0 * lin[i] as f64
            } else {
                255.0
                    * linear_to_srgb((lin[i] as f64 * vg.factor(p % w, p / w, w, h)) as f32) as f64
            }
        })
        .collect();
    let d = u8_diff(got, &want);
    eprintln!("vignette 8-bit sRGB: {d:?}");
    assert!(d.max_lsb <= 1, "{d:?}");
}
