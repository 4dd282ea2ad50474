//! Every shipped image effect at its defaults on real photos (issue 10): the
//! defaults must visibly do the documented thing on an ordinary photo.
//!
//! Needs the corpus at `../shared/corpus` (skips with a message when absent).

use crate::common::*;
use fxgraph::io::{Image, Pixels};
use fxgraph::script::types::Format;
use std::path::PathBuf;

fn corpus(rel: &str) -> Option<PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/corpus")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipping: corpus file {} absent", p.display());
        None
    }
}

fn load(rel: &str) -> Option<Image> {
    let p = corpus(rel)?;
    Some(fxgraph::io::load_image(&p, &Default::default()).unwrap())
}

/// Linear RGBA of an image as the effects see it.
fn lin(img: &Image) -> Vec<f32> {
    linear(&img.pixels)
}

fn rgb_psnr(a: &[f32], b: &[f32]) -> f64 {
    // PSNR over the sRGB-encoded RGB samples (what a viewer sees).
    let enc = |v: &[f32]| -> Vec<f32> {
        v.chunks(4)
            .flat_map(|p| {
                [
                    linear_to_srgb(p[0].min(1.0)),
                    linear_to_srgb(p[1].min(1.0)),
                    linear_to_srgb(p[2].min(1.0)),
                ]
            })
            .collect()
    };
    psnr(&enc(a), &enc(b), 1.0)
}

/// Mean squared Laplacian of the sRGB-encoded luma: high-frequency energy.
fn hf_energy(v: &[f32], w: u32, h: u32) -> f64 {
    let l = |x: u32, y: u32| -> f64 {
        let i = ((y * w + x) * 4) as usize;
        linear_to_srgb(0.2126 * v[i] + 0.7152 * v[i + 1] + 0.0722 * v[i + 2]) as f64
    };
    let mut s = 0.0;
    let mut n = 0.0;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let d = 4.0 * l(x, y) - l(x - 1, y) - l(x + 1, y) - l(x, y - 1) - l(x, y + 1);
            s += d * d;
            n += 1.0;
        }
    }
    s / n
}

fn run_default(effect: &str, sets: &[&str], img: &Image) -> (u32, u32, Vec<f32>) {
    let mut eng = engine().expect("engine");
    let (w, h, px) = run(&mut eng, &[effect], sets, img, Format::Rgba32f).unwrap();
    let v = match px {
        Pixels::F32(v) => v,
        Pixels::U8(_) => unreachable!(),
    };
    (w, h, v)
}

const PHOTOS: [&str; 4] = [
    "photos/rocket.jpg",
    "photos/astronaut.png",
    "photos/coffee.png",
    "photos/chelsea.png",
];

/// One effect at its defaults on every photo: (photo, PSNR dB, high-frequency
/// energy in, out, mean linear RGB in, out). Writes the outputs for review.
fn on_photos(effect: &str, sets: &[&str]) -> Vec<(String, f64, f64, f64, f64, f64)> {
    let mut rows = Vec::new();
    for photo in PHOTOS {
        let Some(img) = load(photo) else {
            return Vec::new();
        };
        let src = lin(&img);
        let (w, h, out) = run_default(effect, sets, &img);
        let short = photo
            .trim_start_matches("photos/")
            .split('.')
            .next()
            .unwrap();
        save_for_review(
            &format!("defaults_{effect}_{short}"),
            w,
            h,
            &Pixels::F32(out.clone()),
        );
        let mean = |v: &[f32]| -> f64 {
            v.chunks(4)
                .map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0)
                .sum::<f64>()
                / (w * h) as f64
        };
        let row = (
            short.to_string(),
            rgb_psnr(&out, &src),
            hf_energy(&src, w, h),
            hf_energy(&out, w, h),
            mean(&src),
            mean(&out),
        );
        eprintln!(
            "{effect} {sets:?} on {:10} psnr {:6.2} dB, hf {:.5} -> {:.5}, mean {:.4} -> {:.4}",
            row.0, row.1, row.2, row.3, row.4, row.5
        );
        rows.push(row);
    }
    rows
}

#[test]
fn defaults_change_ordinary_photos_visibly() {
    // PSNR against the input, over the sRGB-encoded RGB, at the defaults:
    // below ~40 dB the change is visible; the bands are those measured on the
    // four photos with a margin.
    if engine().is_none() {
        return;
    }
    for (effect, lo, hi) in [
        ("glow", 18.0, 40.0),
        ("gaussian_blur", 20.0, 33.0),
        ("tonemap", 19.0, 30.0),
        ("vignette", 20.0, 36.0),
        ("sharpen", 22.0, 33.0),
        ("fxaa", 30.0, 45.0),
    ] {
        for (photo, q, ..) in on_photos(effect, &[]) {
            assert!(
                (lo..=hi).contains(&q),
                "{effect} on {photo}: PSNR {q:.2} dB outside [{lo}, {hi}]"
            );
        }
    }
}

#[test]
fn defaults_do_the_documented_thing() {
    if engine().is_none() {
        return;
    }
    for (photo, _, hf_in, hf_out, ..) in on_photos("gaussian_blur", &[]) {
        assert!(
            hf_out < hf_in / 20.0,
            "gaussian_blur on {photo}: hf {hf_in} -> {hf_out}"
        );
    }
    for (photo, _, hf_in, hf_out, ..) in on_photos("sharpen", &[]) {
        assert!(
            hf_out > 2.5 * hf_in,
            "sharpen on {photo}: hf {hf_in} -> {hf_out}"
        );
    }
    for (photo, _, _, _, m_in, m_out) in on_photos("glow", &[]) {
        assert!(
            m_out > m_in * 1.04,
            "glow on {photo}: mean {m_in} -> {m_out}"
        );
    }
    // color_grade's defaults are the identity (documented in its description).
    for (photo, q, ..) in on_photos("color_grade", &[]) {
        assert!(q > 55.0, "color_grade on {photo}: PSNR {q:.2} dB");
    }
    // pencil: grey strokes on white paper; edges: a dark edge map.
    for (photo, _, _, _, _, m_out) in on_photos("pencil", &[]) {
        assert!(m_out > 0.75, "pencil on {photo}: mean {m_out}");
    }
    for (photo, _, _, _, _, m_out) in on_photos("edges", &[]) {
        assert!(
            m_out < 0.05 && m_out > 0.002,
            "edges on {photo}: mean {m_out}"
        );
    }
}

#[test]
fn bloom_is_for_hdr_and_a_lower_threshold_for_photos() {
    // bloom's threshold 1 blooms only light brighter than white: on an 8-bit
    // photo it changes little (documented in its description), threshold 0.5
    // makes it visible.
    if engine().is_none() {
        return;
    }
    for (photo, q, ..) in on_photos("bloom", &[]) {
        assert!(q > 38.0, "bloom at defaults on {photo}: PSNR {q:.2} dB");
    }
    for (photo, q, _, _, m_in, m_out) in on_photos("bloom", &["threshold=0.5"]) {
        assert!(
            q < 42.0 && m_out > m_in,
            "bloom threshold 0.5 on {photo}: PSNR {q:.2} dB"
        );
    }
}

#[test]
fn vignette_defaults_darken_the_corners_by_the_strength() {
    // strength 0.5: the corners of a landscape frame (distance 1.8 > radius +
    // softness = 1.6) get exactly half, the centre is unchanged.
    let Some(img) = load("photos/rocket.jpg") else {
        return;
    };
    if engine().is_none() {
        return;
    }
    let src = lin(&img);
    let (w, h, out) = run_default("vignette", &[], &img);
    let ratio = |x0: u32, y0: u32| -> f64 {
        let (mut a, mut b) = (0.0, 0.0);
        for y in y0..y0 + 4 {
            for x in x0..x0 + 4 {
                for c in 0..3 {
                    a += at(&out, w, x, y, c) as f64;
                    b += at(&src, w, x, y, c) as f64;
                }
            }
        }
        a / b
    };
    let corners = [
        ratio(0, 0),
        ratio(w - 4, 0),
        ratio(0, h - 4),
        ratio(w - 4, h - 4),
    ];
    let centre = ratio(w / 2 - 2, h / 2 - 2);
    eprintln!("vignette: corners {corners:?}, centre {centre:.4}");
    for c in corners {
        assert!((c - 0.5).abs() < 0.02, "corner factor {c}");
    }
    assert!((centre - 1.0).abs() < 0.01, "centre factor {centre}");
}

#[test]
fn tonemap_defaults_bring_hdr_photos_into_range() {
    // The HDR photos of the corpus: most pixels above 1 are brought into range
    // (ACES, the default), none clip with reinhard.
    if engine().is_none() {
        return;
    }
    for f in ["exr/CandleGlass.exr", "exr/Desk.exr", "exr/StillLife.exr"] {
        let Some(img) = load(f) else { return };
        let src = lin(&img);
        for (sets, max_clip) in [(&[][..], 0.6), (&["operator=reinhard"][..], 0.0)] {
            let (w, h, out) = run_default("tonemap", sets, &img);
            let n = (w * h) as f64;
            let clipped = |v: &[f32]| {
                v.chunks(4)
                    .filter(|p| p[..3].iter().any(|&c| c >= 0.999))
                    .count() as f64
                    / n
            };
            let (c_in, c_out) = (clipped(&src), clipped(&out));
            eprintln!("tonemap {sets:?} on {f}: clipped {c_in:.4} -> {c_out:.4}");
            assert!(
                out.iter().all(|v| (0.0..=1.0).contains(v)),
                "{f}: out of [0, 1]"
            );
            assert!(
                c_out <= max_clip * c_in + 1e-4,
                "{f} {sets:?}: clipped {c_in} -> {c_out}"
            );
        }
    }
}
