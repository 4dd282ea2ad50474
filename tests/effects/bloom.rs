//! `bloom` (downsample and upsample chains): a bright spot spreads, energy is kept,
//! and images below the threshold stay unchanged.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::io::Image;
use fxgraph::script::types::Format;

/// 256x256 black with a 4x4 spot of `value` whose top-left corner is (at, at).
fn spot_image(value: f32, at: u32) -> Image {
    image_f32(256, 256, |x, y| {
        if (at..at + 4).contains(&x) && (at..at + 4).contains(&y) {
            [value, value * 0.8, value * 0.6, 1.0]
        } else {
            [0.0, 0.0, 0.0, 1.0]
        }
    })
}

#[test]
fn bloom_spreads_a_bright_spot() {
    let img = spot_image(50.0, 62);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    let (w, h, px) = run(&mut eng, &["bloom"], &[], &img, Format::Rgba32f).unwrap();
    assert_eq!((w, h), (256, 256));
    let out = f32s(&px);
    assert_finite(out, "bloom");
    let bloom =
        |x: u32, y: u32, c: usize| at(out, w, x, y, c) as f64 - src[((y * w + x) * 4) as usize + c];
    // Brighter next to the spot, and on the spot itself.
    assert!(
        bloom(68, 63, 0) > 0.05,
        "bloom 2 px right of the spot: {}",
        bloom(68, 63, 0)
    );
    assert!(
        bloom(63, 63, 0) > 0.05,
        "bloom on the spot: {}",
        bloom(63, 63, 0)
    );
    // Falling off monotonically away from the spot: right, down, left, up, diagonal.
    let rays: [(i32, i32, i32, i32); 5] = [
        (66, 63, 1, 0),
        (63, 66, 0, 1),
        (61, 63, -1, 0),
        (63, 61, 0, -1),
        (66, 66, 1, 1),
    ];
    for (x0, y0, dx, dy) in rays {
        let mut prev = f64::INFINITY;
        let (mut x, mut y) = (x0, y0);
        while (0..256).contains(&x) && (0..256).contains(&y) {
            for c in 0..3 {
                let b = bloom(x as u32, y as u32, c);
                assert!(b >= -1e-6, "negative bloom {b} at ({x}, {y})");
                if c == 0 {
                    assert!(
                        b <= prev * (1.0 + 2e-3) + 1e-6,
                        "bloom rises from {prev} to {b} at ({x}, {y}) going ({dx}, {dy})"
                    );
                    prev = b;
                }
            }
            x += dx;
            y += dy;
        }
    }
    // Colour of the spot is kept in the bloom (r : g : b = 1 : 0.8 : 0.6).
    let (r, g, b) = (bloom(72, 63, 0), bloom(72, 63, 1), bloom(72, 63, 2));
    assert!(
        (g / r - 0.8).abs() < 0.01 && (b / r - 0.6).abs() < 0.01,
        "bloom colour {r} {g} {b}"
    );
    // Far from the spot nothing changes.
    let mut far = 0.0f64;
    for y in 200..256 {
        for x in 200..256 {
            for c in 0..4 {
                far = far.max(bloom(x, y, c).abs());
            }
        }
    }
    eprintln!(
        "bloom: near {:.4}, at 20 px {:.5}, at 60 px {:.6}, far max {far:.2e}",
        bloom(68, 63, 0),
        bloom(86, 63, 0),
        bloom(126, 63, 0)
    );
    assert!(far <= 1e-3, "far pixels changed by {far}");
    // Alpha is the input's.
    assert!((0..(w * h) as usize).all(|i| out[i * 4 + 3] == 1.0));
}

#[test]
fn bloom_energy_and_identity() {
    // In the middle, so that the widest level does not reach the border.
    let img = spot_image(50.0, 126);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    // intensity 0: exactly the input.
    let px = apply_fx(&mut eng, "bloom", &["intensity=0"], &img, Format::Rgba32f);
    assert_eq!(
        max_diff(f32s(&px), &src),
        0.0,
        "bloom with intensity 0 changed the image"
    );
    // No threshold: the bloom carries the input's energy times the intensity; a
    // larger radius moves more of it far from the spot.
    for intensity in [1.0, 0.25] {
        let mut at_40px = 0.0;
        for radius in [0.3, 0.7, 1.0] {
            let sets = format!("intensity={intensity} radius={radius} threshold=0 knee=0");
            let px = apply_fx(&mut eng, "bloom", &words(&sets), &img, Format::Rgba32f);
            let out = f32s(&px);
            assert_finite(out, "bloom");
            let added: f64 = (0..out.len())
                .filter(|i| i % 4 == 0)
                .map(|i| out[i] as f64 - src[i])
                .sum();
            let energy: f64 = (0..src.len()).filter(|i| i % 4 == 0).map(|i| src[i]).sum();
            let ratio = added / (intensity * energy);
            eprintln!("bloom intensity {intensity} radius {radius}: added energy / (intensity * input energy) = {ratio:.4}");
            assert!((ratio - 1.0).abs() < 0.01, "energy ratio {ratio}");
            let far = at(out, 256, 128 + 40, 128, 0) as f64;
            assert!(
                far > at_40px,
                "radius {radius}: bloom 40 px away {far} <= {at_40px} with a smaller radius"
            );
            at_40px = far;
        }
    }
}

#[test]
fn bloom_threshold_keeps_dim_images() {
    // Below threshold - knee nothing blooms: the output is the input.
    let img = pattern_f32(64, 48);
    let src = uploaded_f16(&img);
    let Some(mut eng) = engine() else { return };
    let px = apply_fx(
        &mut eng,
        "bloom",
        &["threshold=2", "knee=0.5"],
        &img,
        Format::Rgba32f,
    );
    assert_eq!(max_diff(f32s(&px), &src), 0.0);
    // An 8-bit photo-like input and odd size: runs, stays finite, only brightens.
    let img = pattern_u8(67, 41);
    let (w, h, px) = run(
        &mut eng,
        &["bloom"],
        &["threshold=0.5"],
        &img,
        Format::Rgba16f,
    )
    .unwrap();
    assert_eq!((w, h), (67, 41));
    let out = f32s(&px);
    assert_finite(out, "bloom");
    let lin = linear(&img.pixels);
    let brighter = out.iter().zip(&lin).all(|(o, i)| *o >= i - 2e-3);
    assert!(brighter, "bloom darkened a pixel");
    assert!(
        out.iter().zip(&lin).any(|(o, i)| *o > i + 0.01),
        "nothing bloomed"
    );
}
