//! `chroma_key` (and `chroma_composite`): the alpha is 0 on the key, 1 far from it and
//! monotonic between; spill suppression and the output forms; the greenscreen photo.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::app::apply_in_memory;
use fxgraph::io::Pixels;
use fxgraph::script::types::Format;

/// Rec.709 (Y', Cb, Cr) of sRGB-encoded values (Cb, Cr centred on 0).
fn ycc(c: &[f64]) -> [f64; 3] {
    let y = luma709(c);
    [y, (c[2] - y) / 1.8556, (c[0] - y) / 1.5748]
}

const KEY: [u8; 3] = [58, 210, 65];

/// chroma_key's alpha for sRGB-encoded colour `c`.
fn key_alpha(c: &[f64], key: &[f64], tolerance: f64, softness: f64) -> f64 {
    let (p, k) = (ycc(c), ycc(key));
    let d = ((p[1] - k[1]).powi(2) + (p[2] - k[2]).powi(2)).sqrt();
    ((d - tolerance) / softness).clamp(0.0, 1.0)
}

fn key_unit() -> Vec<f64> {
    KEY.iter().map(|&b| b as f64 / 255.0).collect()
}

#[test]
fn chroma_key_alpha_is_zero_on_the_key_one_far_from_it_and_monotonic() {
    let Some(mut eng) = engine() else { return };
    let grey = [150u8, 150, 150];
    let skin = [224u8, 172, 140];
    // Row 0..9: the key; 10..19: grey; 20..29: skin; 30..40: a ramp key -> grey.
    let img = image_u8(67, 41, |x, y| {
        let c = match y {
            0..=9 => KEY,
            10..=19 => grey,
            20..=29 => skin,
            _ => {
                let t = x as f64 / 66.0;
                let m = |a: u8, b: u8| (a as f64 + t * (b as f64 - a as f64)).round() as u8;
                [m(KEY[0], grey[0]), m(KEY[1], grey[1]), m(KEY[2], grey[2])]
            }
        };
        [c[0], c[1], c[2], 255]
    });
    let set = [
        "key=(0.22745098, 0.82352941, 0.25490196)",
        "tolerance=0.08",
        "softness=0.2",
    ];
    let (w, h, px) = run(&mut eng, &["chroma_key"], &set, &img, Format::Rgba8Srgb).unwrap();
    let v = u8s(&px);
    let alpha = |x: u32, y: u32| v[((y * w + x) * 4 + 3) as usize];
    for x in 0..w {
        assert_eq!(alpha(x, 5), 0, "key pixel not transparent");
        assert_eq!(alpha(x, 15), 255, "grey pixel not opaque");
        assert_eq!(alpha(x, 25), 255, "skin pixel not opaque");
    }
    // The ramp: alpha non-decreasing in the distance, from 0 to 255, and equal to
    // clamp((d - tolerance) / softness, 0, 1) within 1 LSB.
    let enc = unit_u8(&img);
    let mut max_err: f64 = 0.0;
    for y in 30..h {
        let row: Vec<u8> = (0..w).map(|x| alpha(x, y)).collect();
        assert!(
            row.windows(2).all(|p| p[0] <= p[1]),
            "alpha not monotonic: {row:?}"
        );
        assert_eq!((row[0], row[w as usize - 1]), (0, 255), "{row:?}");
        assert!(
            row.iter().filter(|&&a| a > 0 && a < 255).count() >= 20,
            "soft band too narrow: {row:?}"
        );
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            let want = 255.0 * key_alpha(&enc[i..i + 3], &key_unit(), 0.08, 0.2);
            max_err = max_err.max((row[x as usize] as f64 - want).abs());
        }
    }
    eprintln!("chroma_key ramp: max alpha error {max_err:.3} LSB");
    assert!(max_err <= 1.0, "alpha {max_err} LSB from the oracle");
}

#[test]
fn chroma_key_spill_suppression_and_output_forms() {
    let Some(mut eng) = engine() else { return };
    // A skin tone with a green cast (bounce light from the backdrop), and one
    // pixel in the soft band.
    let greenish_skin = [190u8, 192, 140];
    let img = image_u8(8, 2, |_, y| {
        if y == 0 {
            [greenish_skin[0], greenish_skin[1], greenish_skin[2], 255]
        } else {
            [110, 180, 100, 255]
        }
    });
    let excess = |p: &[u8]| p[1] as f64 - (p[0] as f64 + p[2] as f64) / 2.0;
    let luma8 = |p: &[u8]| luma709(&[p[0] as f64, p[1] as f64, p[2] as f64]);
    let off = apply_fx(
        &mut eng,
        "chroma_key",
        &["spill=0"],
        &img,
        Format::Rgba8Srgb,
    );
    let on = apply_fx(
        &mut eng,
        "chroma_key",
        &["spill=1"],
        &img,
        Format::Rgba8Srgb,
    );
    let (off, on) = (u8s(&off), u8s(&on));
    assert_eq!((off[3], on[3]), (255, 255), "skin must stay opaque");
    assert!(
        off[..3]
            .iter()
            .zip(greenish_skin)
            .all(|(&a, b)| a.abs_diff(b) <= 1),
        "spill=0 changed the colour: {:?}",
        &off[..4]
    );
    eprintln!(
        "spill: green excess {} -> {}, pixel {:?} -> {:?}",
        excess(&off[..3]),
        excess(&on[..3]),
        &off[..3],
        &on[..3]
    );
    assert!(
        excess(&on[..3]) < excess(&off[..3]) - 15.0,
        "spill suppression did not reduce the green excess: {:?} -> {:?}",
        &off[..3],
        &on[..3]
    );
    assert!(
        on[1] < off[1] && on[0] >= off[0],
        "despill should lower green and not lower red: {:?}",
        &on[..3]
    );
    assert!(
        (luma8(&on[..3]) - luma8(&off[..3])).abs() <= 1.5,
        "despill changed the luma: {:?} -> {:?}",
        &off[..3],
        &on[..3]
    );
    // Output forms on the soft-band pixel (row 1): straight, premultiplied, matte.
    let i = 8 * 4;
    let a_want = key_alpha(&unit_u8(&img)[i..i + 3], &key_unit(), 0.1, 0.1);
    assert!(
        a_want > 0.1 && a_want < 0.9,
        "test pixel not in the soft band: {a_want}"
    );
    let st = apply_fx(&mut eng, "chroma_key", &[], &img, Format::Rgba32f);
    let pm = apply_fx(
        &mut eng,
        "chroma_key",
        &["output=premultiplied"],
        &img,
        Format::Rgba32f,
    );
    let mt = apply_fx(
        &mut eng,
        "chroma_key",
        &["output=matte"],
        &img,
        Format::Rgba8Srgb,
    );
    let (st, pm, mt) = (f32s(&st), f32s(&pm), u8s(&mt));
    let a = st[i + 3] as f64;
    assert!(
        (a - a_want).abs() < 1.0 / 255.0 + 1e-6,
        "alpha {a} want {a_want}"
    );
    for c in 0..3 {
        // rgba8-srgb intermediate storage: straight colour within an 8-bit step.
        assert!(
            (pm[i + c] as f64 - st[i + c] as f64 * a).abs() < 0.01,
            "premultiplied {c}: {} vs {} * {a}",
            pm[i + c],
            st[i + c]
        );
        assert!(
            (mt[i + c] as f64 - 255.0 * a_want).abs() <= 1.0,
            "matte {c}: {} want {}",
            mt[i + c],
            255.0 * a_want
        );
    }
    assert_eq!(mt[i + 3], 255);
}

#[test]
fn chroma_key_on_the_greenscreen_photo() {
    let Some((photo, background)) = greenscreen() else {
        return;
    };
    let Some(mut eng) = engine() else { return };
    let (w, h, px) = run(&mut eng, &["chroma_key"], &[], &photo, Format::Rgba8Srgb).unwrap();
    assert_eq!((w, h), (640, 360));
    let v = u8s(&px);
    let alpha = |x: u32, y: u32| v[((y * w + x) * 4 + 3) as usize] as f64 / 255.0;
    let matte: Vec<u8> = v.chunks(4).flat_map(|p| [p[3], p[3], p[3], 255]).collect();
    let path = save_for_review("chroma_key_greenscreen_matte", w, h, &Pixels::U8(matte));
    eprintln!("matte written to {}", path.display());
    // Backdrop: a 12-px strip along all four borders.
    let (mut n, mut clear) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            if x < 12 || y < 12 || x >= w - 12 || y >= h - 12 {
                n += 1;
                clear += usize::from(alpha(x, y) < 0.1);
            }
        }
    }
    let frac = |x0: u32, y0: u32, x1: u32, y1: u32, f: &dyn Fn(f64) -> bool| {
        let (mut k, mut t) = (0, 0);
        for y in y0..y1 {
            for x in x0..x1 {
                k += usize::from(f(alpha(x, y)));
                t += 1;
            }
        }
        k as f64 / t as f64
    };
    let border = clear as f64 / n as f64;
    // The person: torso (shirt), head and hips, measured on the reviewed matte.
    let torso = frac(280, 100, 320, 150, &|a| a > 0.9);
    let head = frac(300, 60, 320, 80, &|a| a > 0.9);
    let hips = frac(290, 170, 340, 200, &|a| a > 0.9);
    // The backdrop between the legs and beside the body.
    let beside = frac(420, 100, 600, 300, &|a| a < 0.1);
    eprintln!("greenscreen: border clear {border:.4}, torso {torso:.4}, head {head:.4}, hips {hips:.4}, beside {beside:.4}");
    assert!(border > 0.99, "border strip: only {border} transparent");
    assert!(
        beside > 0.99,
        "backdrop beside the person: only {beside} transparent"
    );
    assert!(
        torso > 0.95 && head > 0.95 && hips > 0.95,
        "person not opaque: torso {torso}, head {head}, hips {hips}"
    );
    // Composite over the background: backdrop pixels are the background's,
    // torso pixels the keyed foreground's.
    let aux = [("background".to_string(), &background)];
    let (_, _, comp) = apply_in_memory(
        &mut eng,
        &["chroma_composite".to_string()],
        &[],
        &photo,
        &aux,
        Format::Rgba8Srgb,
        false,
    )
    .unwrap();
    let comp = u8s(&comp);
    let bg = u8s(&background.pixels);
    let backdrop = [(20u32, 20u32), (600, 300), (500, 50)];
    let person = [(300u32, 120u32), (310, 70)];
    for (what, points, want) in [("backdrop", &backdrop[..], bg), ("person", &person, v)] {
        for &(x, y) in points {
            let i = ((y * w + x) * 4) as usize;
            assert!(
                (0..3).all(|c| comp[i + c].abs_diff(want[i + c]) <= 1),
                "{what} ({x}, {y}): {:?} vs {:?}",
                &comp[i..i + 4],
                &want[i..i + 4]
            );
        }
    }
    let path = save_for_review(
        "chroma_composite_greenscreen",
        w,
        h,
        &Pixels::U8(comp.to_vec()),
    );
    eprintln!("composite written to {}", path.display());
}
