//! GPU tests of the built-in effects edges, pencil, chroma_key (+ chroma_composite),
//! format_convert and fxaa against CPU oracles, and a CPU oracle of the seed `glow`.
//!
//! Run with `FX_REQUIRE_GPU=1 XDG_RUNTIME_DIR=/tmp cargo test --test effects_b`;
//! without an adapter (and without FX_REQUIRE_GPU) the GPU tests skip.

mod common;

use common::*;
use fxgraph::app::apply_in_memory;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use fxgraph::graph::{compile, CompileRequest};
use fxgraph::io::{Image, Pixels};
use fxgraph::script::types::Format;

// ---------------------------------------------------------------- helpers

fn u8s(p: &Pixels) -> &[u8] {
    match p {
        Pixels::U8(v) => v,
        Pixels::F32(_) => panic!("expected 8-bit pixels"),
    }
}

fn f32s(p: &Pixels) -> &[f32] {
    match p {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("expected float pixels"),
    }
}

/// `x` rounded to the nearest half float (what an rgba16f texture stores).
fn f16r(x: f64) -> f64 {
    half::f16::from_f64(x).to_f64()
}

/// Rec.709 luma weights.
const W709: [f64; 3] = [0.2126, 0.7152, 0.0722];

fn luma709(c: &[f64]) -> f64 {
    W709[0] * c[0] + W709[1] * c[1] + W709[2] * c[2]
}

fn srgb_encode(x: f64) -> f64 {
    let a = x.abs();
    let e = if a <= 0.0031308 {
        a * 12.92
    } else {
        1.055 * a.powf(1.0 / 2.4) - 0.055
    };
    e.copysign(x)
}

fn srgb_decode(x: f64) -> f64 {
    let a = x.abs();
    let l = if a <= 0.04045 {
        a / 12.92
    } else {
        ((a + 0.055) / 1.055).powf(2.4)
    };
    l.copysign(x)
}

/// Largest |got - round(want)| in LSB over the samples where `mask(i)` holds, and
/// the fraction of those that differ at all.
fn lsb_diff(got: &[u8], want: &[f64], mask: impl Fn(usize) -> bool) -> (u8, f64) {
    assert_eq!(got.len(), want.len());
    let (mut max, mut off, mut n) = (0u8, 0usize, 0usize);
    for (i, (&g, &w)) in got.iter().zip(want).enumerate() {
        if !mask(i) {
            continue;
        }
        let d = g.abs_diff(w.round().clamp(0.0, 255.0) as u8);
        max = max.max(d);
        off += usize::from(d != 0);
        n += 1;
    }
    (max, off as f64 / n.max(1) as f64)
}

/// Sample (x, y, c) of an RGBA buffer with clamped (replicated) coordinates.
fn clamped(v: &[f64], w: u32, h: u32, x: i64, y: i64, c: usize) -> f64 {
    let x = x.clamp(0, w as i64 - 1) as usize;
    let y = y.clamp(0, h as i64 - 1) as usize;
    v[(y * w as usize + x) * 4 + c]
}

/// Bilinear sample at texel-space coordinates (texel centres at integers), clamp
/// to edge: what a linear, clamp-to-edge sampler returns.
fn bilinear(v: &[f64], w: u32, h: u32, x: f64, y: f64, c: usize) -> f64 {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let t = |dx: i64, dy: i64| clamped(v, w, h, x0 + dx, y0 + dy, c);
    (1.0 - fy) * ((1.0 - fx) * t(0, 0) + fx * t(1, 0)) + fy * ((1.0 - fx) * t(0, 1) + fx * t(1, 1))
}

/// An 8-bit image's samples / 255 (as stored: sRGB-encoded for colour).
fn unit_u8(img: &Image) -> Vec<f64> {
    u8s(&img.pixels).iter().map(|&b| b as f64 / 255.0).collect()
}

fn greenscreen() -> Option<(Image, Image)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/greenscreen");
    let load = |n: &str| fxgraph::io::load_image(&dir.join(n), &Default::default());
    match (load("greenscreen.jpg"), load("background.jpg")) {
        (Ok(a), Ok(b)) => Some((a, b)),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!(
                "skipping the greenscreen photo test: {e} (corpus folder ../shared/corpus absent?)"
            );
            None
        }
    }
}

/// Compile effects (names or paths) and plan them for an 8-bit `w`x`h` input.
fn plan_for(effects: &[&str], w: u32, h: u32) -> (fxgraph::graph::Plan, usize, usize) {
    let req = CompileRequest {
        source: Some(std::sync::Arc::new(fxgraph::lookup::DiskEffects::default())),
        effects: effects.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    let (graph, diags, sources) = compile(&req);
    let graph = graph
        .unwrap_or_else(|| panic!("{effects:?} does not compile:\n{}", diags.render(&sources)));
    let warnings = diags.warning_count();
    let (p, notes) = plan(
        &graph,
        &InputDesc::rgba8_srgb(w, h),
        &PlanOptions::default(),
    )
    .unwrap_or_else(|d| panic!("{effects:?} does not plan:\n{}", d.render(&sources)));
    (p, warnings, notes.warning_count())
}

// ---------------------------------------------------------------- all effects

#[test]
fn effects_compile_without_warnings_and_plan_at_the_lower_bound() {
    for name in [
        "edges",
        "pencil",
        "chroma_key",
        "format_convert",
        "fxaa",
        "glow",
    ] {
        let path = format!("effects/{name}.fx");
        for (w, h) in [(64, 64), (67, 41), (1920, 1080)] {
            let (p, warnings, plan_warnings) = plan_for(&[&path], w, h);
            assert_eq!((warnings, plan_warnings), (0, 0), "{name}: warnings");
            assert_eq!(
                p.peak_bytes, p.lower_bound_bytes,
                "{name} {w}x{h}: peak above the lower bound"
            );
            assert_eq!(
                p.validate(),
                Ok(p.peak_bytes),
                "{name} {w}x{h}: invalid plan"
            );
            // 8-bit inputs need no inserted colour-space conversion pass.
            assert!(
                p.passes
                    .iter()
                    .all(|q| !q.path.contains(":linear") && !q.path.contains(":srgb")),
                "{name}: conversion pass in {:?}",
                p.passes
            );
        }
    }
    // chroma_composite reads AUX.background: plan it with that image provided.
    let req = CompileRequest {
        source: Some(std::sync::Arc::new(fxgraph::lookup::DiskEffects::default())),
        effects: vec!["effects/chroma_composite.fx".into()],
        ..Default::default()
    };
    let (graph, diags, sources) = compile(&req);
    let graph = graph.unwrap_or_else(|| panic!("chroma_composite:\n{}", diags.render(&sources)));
    assert_eq!(diags.warning_count(), 0);
    let mut input = InputDesc::rgba8_srgb(640, 360);
    input.aux.push(("background".into(), Format::Rgba8Srgb));
    let (p, notes) = plan(&graph, &input, &PlanOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render(&sources)));
    assert_eq!(
        (notes.warning_count(), p.passes.len(), p.peak_bytes),
        (0, 1, 0)
    );
    // The built-ins are embedded and listed with their descriptions.
    let list = fxgraph::graph::library::builtin_effects();
    for name in [
        "edges",
        "pencil",
        "chroma_key",
        "chroma_composite",
        "format_convert",
        "fxaa",
    ] {
        let d = list
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} is not built in"));
        assert!(!d.1.is_empty(), "{name} has no DESCRIPTION");
    }
}

// ---------------------------------------------------------------- edges

/// The `edges` grey level v (before 8-bit storage) of an image of sRGB-encoded
/// samples: Sobel on Rec.709 luma, replicated border, |G| / 4.
fn sobel_oracle(enc: &[f64], w: u32, h: u32, scale: f64, threshold: f64, invert: bool) -> Vec<f64> {
    let lum: Vec<f64> = enc
        .chunks(4)
        .flat_map(|c| [luma709(c), 0.0, 0.0, 0.0])
        .collect();
    let mut out = Vec::with_capacity(enc.len());
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let l = |dx: i64, dy: i64| clamped(&lum, w, h, x + dx, y + dy, 0);
            let gx = (l(1, -1) + 2.0 * l(1, 0) + l(1, 1)) - (l(-1, -1) + 2.0 * l(-1, 0) + l(-1, 1));
            let gy = (l(-1, 1) + 2.0 * l(0, 1) + l(1, 1)) - (l(-1, -1) + 2.0 * l(0, -1) + l(1, -1));
            let mut e = scale * 0.25 * (gx * gx + gy * gy).sqrt();
            if e < threshold {
                e = 0.0;
            }
            let v = if invert { 1.0 - e } else { e }.clamp(0.0, 1.0);
            out.extend([v, v, v, clamped(enc, w, h, x, y, 3)]);
        }
    }
    out
}

#[test]
fn edges_matches_cpu_sobel() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(67, 41), (128, 96)] {
        let img = pattern_u8(w, h);
        let enc = unit_u8(&img);
        for (set, scale, threshold, invert) in [
            (vec![], 1.0, 0.0, false),
            (vec!["scale=2.5"], 2.5, 0.0, false),
            (vec!["threshold=0.3", "invert=true"], 1.0, 0.3, true),
        ] {
            let (ow, oh, px) = run(&mut eng, &["edges"], &set, &img, Format::Rgba8Srgb).unwrap();
            assert_eq!((ow, oh), (w, h));
            let want: Vec<f64> = sobel_oracle(&enc, w, h, scale, threshold, invert)
                .iter()
                .map(|v| v * 255.0)
                .collect();
            // Threshold decisions within float error of the cut are ambiguous: skip those pixels.
            let ambiguous = |i: usize| {
                let p = i / 4;
                let e =
                    sobel_oracle_e(&enc, w, h, (p % w as usize) as i64, (p / w as usize) as i64)
                        * scale;
                threshold > 0.0 && (e - threshold).abs() < 1e-4
            };
            let (max, off) = lsb_diff(u8s(&px), &want, |i| !ambiguous(i));
            eprintln!(
                "edges {w}x{h} {set:?}: max {max} LSB, {:.2}% off by one",
                off * 100.0
            );
            assert!(
                max <= 1,
                "edges {w}x{h} {set:?}: {max} LSB from the CPU Sobel"
            );
        }
    }
}

/// Unscaled |G| / 4 at one pixel (for the threshold ambiguity test).
fn sobel_oracle_e(enc: &[f64], w: u32, h: u32, x: i64, y: i64) -> f64 {
    let l = |dx: i64, dy: i64| {
        let c: Vec<f64> = (0..3)
            .map(|c| clamped(enc, w, h, x + dx, y + dy, c))
            .collect();
        luma709(&c)
    };
    let gx = (l(1, -1) + 2.0 * l(1, 0) + l(1, 1)) - (l(-1, -1) + 2.0 * l(-1, 0) + l(-1, 1));
    let gy = (l(-1, 1) + 2.0 * l(0, 1) + l(1, 1)) - (l(-1, -1) + 2.0 * l(0, -1) + l(1, -1));
    0.25 * (gx * gx + gy * gy).sqrt()
}

#[test]
fn edges_flat_is_zero_and_step_gives_the_analytic_magnitude() {
    let Some(mut eng) = engine() else { return };
    // Flat colour: no gradient anywhere, borders included.
    let flat = image_u8(67, 41, |_, _| [90, 140, 200, 255]);
    let (_, _, px) = run(&mut eng, &["edges"], &[], &flat, Format::Rgba8Srgb).unwrap();
    assert!(
        u8s(&px).chunks(4).all(|p| p == [0, 0, 0, 255]),
        "flat image has edges"
    );
    // Vertical step of grey 40 | 200 between x = 29 and x = 30: |G| / 4 = 160 / 255 on
    // both columns beside it, 0 elsewhere (also at the replicated borders).
    let step = image_u8(67, 41, |x, _| {
        if x < 30 {
            [40, 40, 40, 255]
        } else {
            [200, 200, 200, 255]
        }
    });
    let (w, _, px) = run(&mut eng, &["edges"], &[], &step, Format::Rgba8Srgb).unwrap();
    let v = u8s(&px);
    for y in 0..41u32 {
        for x in 0..67u32 {
            let i = ((y * w + x) * 4) as usize;
            let want = if x == 29 || x == 30 { 160 } else { 0 };
            assert!(
                v[i].abs_diff(want) <= 1 && v[i] == v[i + 1] && v[i] == v[i + 2],
                "({x}, {y}): {:?}, want {want}",
                &v[i..i + 4]
            );
        }
    }
    // Float input (linear light): read through an inserted linear -> sRGB
    // conversion pass (rgba16f); a 0 | 1 step gives 1 beside the edge. lavapipe
    // rounds rgba16f render-target writes toward zero, so 1.0 is stored there as
    // 1 - 2^-11 and decoded as 1 - 2.4 * 2^-11: tolerance 2e-3.
    let fstep = image_f32(33, 17, |x, _| {
        if x < 16 {
            [0.0, 0.0, 0.0, 1.0]
        } else {
            [1.0, 1.0, 1.0, 1.0]
        }
    });
    let (w, _, px) = run(&mut eng, &["edges"], &[], &fstep, Format::Rgba32f).unwrap();
    let v = f32s(&px);
    for x in 0..33u32 {
        let want = if x == 15 || x == 16 { 1.0 } else { 0.0 };
        assert!(
            (at(v, w, x, 8, 0) - want).abs() < 2e-3,
            "float step at x = {x}: {}",
            at(v, w, x, 8, 0)
        );
    }
}

#[test]
fn edges_overlay_mixes_the_edge_colour_into_the_image() {
    let Some(mut eng) = engine() else { return };
    let step = image_u8(40, 20, |x, _| {
        if x < 20 {
            [40, 40, 40, 255]
        } else {
            [200, 200, 200, 255]
        }
    });
    let (w, _, px) = run(
        &mut eng,
        &["edges"],
        &["mode=overlay", "color=(1, 0, 0)"],
        &step,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let v = u8s(&px);
    let p = |x: u32| &v[((10 * w + x) * 4) as usize..((10 * w + x) * 4 + 4) as usize];
    // Away from the edge: the image unchanged.
    assert_eq!(p(5), [40, 40, 40, 255]);
    assert_eq!(p(35), [200, 200, 200, 255]);
    // Beside it: mix(image', red, 160/255) in sRGB-encoded values.
    let e = 160.0 / 255.0;
    for (x, base) in [(19u32, 40.0), (20, 200.0)] {
        let want = [
            base * (1.0 - e) + 255.0 * e,
            base * (1.0 - e),
            base * (1.0 - e),
        ];
        for c in 0..3 {
            assert!(
                (p(x)[c] as f64 - want[c]).abs() <= 1.0,
                "overlay at x = {x}: {:?}, want {want:?}",
                p(x)
            );
        }
    }
}

// ---------------------------------------------------------------- pencil

/// The taps of blurX/blurY/pencil_blur for a standard deviation of `sigma` output
/// pixels: (offset, weight) with the centre (0, 1) first and the exact Gaussian
/// weights w(i) = exp(-i^2 / (2 sigma^2)), i <= r = ceil(3 sigma), paired two by two
/// into one bilinear tap each; and the normalising total.
fn blur_taps(sigma: f64) -> (Vec<(f64, f64)>, f64) {
    let r = (3.0 * sigma).ceil() as i64;
    let wt = |i: i64| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp();
    let mut taps = vec![(0.0, 1.0)];
    let mut i = 1;
    while i <= r {
        let w1 = wt(i);
        let w2 = if i + 1 > r { 0.0 } else { wt(i + 1) };
        taps.push(((i as f64 * w1 + (i + 1) as f64 * w2) / (w1 + w2), w1 + w2));
        i += 2;
    }
    let total = 1.0 + 2.0 * taps[1..].iter().map(|t| t.1).sum::<f64>();
    (taps, total)
}

/// One blurX/blurY-style pass: the output (`ow` x `oh`) samples `src` (`iw` x `ih`,
/// RGBA) bilinearly, clamp to edge, at its pixel centres +- the tap offsets in
/// output pixels along x (`horizontal`) or y. Results rounded to half floats
/// (rgba16f / r16f storage).
fn blur_pass(
    src: &[f64],
    (iw, ih): (u32, u32),
    (ow, oh): (u32, u32),
    sigma: f64,
    horizontal: bool,
) -> Vec<f64> {
    let (taps, total) = blur_taps(sigma);
    let mut out = vec![0.0; (ow * oh * 4) as usize];
    for y in 0..oh {
        for x in 0..ow {
            let (u, v) = ((x as f64 + 0.5) / ow as f64, (y as f64 + 0.5) / oh as f64);
            for c in 0..4 {
                let s = |o: f64| {
                    let (uu, vv) = if horizontal {
                        (u + o / ow as f64, v)
                    } else {
                        (u, v + o / oh as f64)
                    };
                    bilinear(src, iw, ih, uu * iw as f64 - 0.5, vv * ih as f64 - 0.5, c)
                };
                let mut sum = s(0.0);
                for &(o, p) in &taps[1..] {
                    sum += p * (s(o) + s(-o));
                }
                out[((y * ow + x) * 4) as usize + c] = f16r(sum / total);
            }
        }
    }
    out
}

/// blurX reading a larger input (at most twice as large): each output texel's
/// input footprint box-filtered by one bilinear fetch at its centre, then the exact
/// weights exp(-i^2 / (2 sigma^2)), |i| <= ceil(3 sigma), at every output column
/// (edge columns repeated). Rounded to half floats.
fn down_blur_x(src: &[f64], (iw, ih): (u32, u32), (ow, oh): (u32, u32), sigma: f64) -> Vec<f64> {
    let r = (3.0 * sigma).ceil() as i64;
    let mut out = vec![0.0; (ow * oh * 4) as usize];
    for y in 0..oh {
        for x in 0..ow as i64 {
            for c in 0..4 {
                let (mut sum, mut total) = (0.0, 0.0);
                for i in -r..=r {
                    let px = (x + i).clamp(0, ow as i64 - 1) as u32;
                    let w = (-((i * i) as f64) / (2.0 * sigma * sigma)).exp();
                    sum += w * upsample(src, (iw, ih), px, y, (ow, oh), c);
                    total += w;
                }
                out[((y * ow + x as u32) * 4) as usize + c] = f16r(sum / total);
            }
        }
    }
    out
}

/// Bilinear upsample of `src` (`sw` x `sh`) at the pixel centres of a `w` x `h` image.
fn upsample(
    src: &[f64],
    (sw, sh): (u32, u32),
    x: u32,
    y: u32,
    (w, h): (u32, u32),
    c: usize,
) -> f64 {
    let (u, v) = ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
    bilinear(src, sw, sh, u * sw as f64 - 0.5, v * sh as f64 - 0.5, c)
}

/// Size of a pass with OUT.SCALE = (0.5, 0.5) (rounded as the planner does).
fn half_size(w: u32, h: u32) -> (u32, u32) {
    (
        ((w as f64) * 0.5).round() as u32,
        ((h as f64) * 0.5).round() as u32,
    )
}

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
    let bh = blur_pass(&lum, (w, h), hs, sigma * 0.5, true);
    let g = blur_pass(&bh, hs, hs, sigma * 0.5, false);
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
    for (w, h, sigma, darkness) in [(67, 41, 2.0, 1.0), (96, 64, 5.0, 1.0), (67, 41, 3.0, 2.5)] {
        let img = pattern_u8(w, h);
        let set = [format!("sigma={sigma}"), format!("darkness={darkness}")];
        let set: Vec<&str> = set.iter().map(|s| s.as_str()).collect();
        let (_, _, px) = run(&mut eng, &["pencil"], &set, &img, Format::Rgba8Srgb).unwrap();
        let s = pencil_oracle(&unit_u8(&img), w, h, sigma, darkness);
        let want: Vec<f64> = s
            .iter()
            .flat_map(|&v| [255.0 * v, 255.0 * v, 255.0 * v, 255.0])
            .collect();
        let (max, off) = lsb_diff(u8s(&px), &want, |_| true);
        let got: Vec<f32> = u8s(&px).iter().map(|&b| b as f32).collect();
        let want32: Vec<f32> = want.iter().map(|&v| v.round() as f32).collect();
        let q = psnr(&got, &want32, 255.0);
        eprintln!("pencil {w}x{h} sigma {sigma} darkness {darkness}: max {max} LSB, {:.2}% off, PSNR {q:.1} dB", off * 100.0);
        let allowed = (2.0 * darkness.max(1.0)) as u8;
        assert!(
            max <= allowed,
            "pencil {w}x{h} sigma {sigma}: {max} LSB from the dodge oracle (allowed {allowed})"
        );
        assert!(q > 45.0, "pencil {w}x{h} sigma {sigma}: PSNR {q} dB");
    }
}

#[test]
fn pencil_is_grey_white_on_flat_areas_dark_at_edges_and_deterministic() {
    let Some(mut eng) = engine() else { return };
    // Grey: r = g = b on a colourful pattern.
    let img = pattern_u8(67, 41);
    let (_, _, a) = run(&mut eng, &["pencil"], &[], &img, Format::Rgba8Srgb).unwrap();
    assert!(
        u8s(&a)
            .chunks(4)
            .all(|p| p[0].abs_diff(p[1]) <= 1 && p[1].abs_diff(p[2]) <= 1),
        "pencil output is not grey"
    );
    // Deterministic, with and without paper grain.
    let (_, _, b) = run(&mut eng, &["pencil"], &[], &img, Format::Rgba8Srgb).unwrap();
    assert_eq!(u8s(&a), u8s(&b));
    let (_, _, g1) = run(
        &mut eng,
        &["pencil"],
        &["paper=0.4"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let (_, _, g2) = run(
        &mut eng,
        &["pencil"],
        &["paper=0.4"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    assert_eq!(u8s(&g1), u8s(&g2), "paper grain is not deterministic");
    assert_ne!(u8s(&g1), u8s(&a), "paper grain changes nothing");
    // Flat areas are white, whatever their colour (black included).
    for c in [[0, 0, 0, 255], [30, 140, 60, 255], [255, 255, 255, 255]] {
        let flat = image_u8(40, 30, |_, _| c);
        let (_, _, px) = run(&mut eng, &["pencil"], &[], &flat, Format::Rgba8Srgb).unwrap();
        assert!(
            u8s(&px).chunks(4).all(|p| p == [255, 255, 255, 255]),
            "flat {c:?} is not white"
        );
    }
    // A vertical step 60 | 200: a dark stroke on the dark side of the edge, white
    // on the bright side and far from the edge.
    let step = image_u8(80, 20, |x, _| {
        if x < 40 {
            [60, 60, 60, 255]
        } else {
            [200, 200, 200, 255]
        }
    });
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

fn at_u8(v: &[u8], w: u32, x: u32, y: u32) -> u8 {
    v[((y * w + x) * 4) as usize]
}

// ---------------------------------------------------------------- chroma_key

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
    let (_, _, off) = run(
        &mut eng,
        &["chroma_key"],
        &["spill=0"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
    let (_, _, on) = run(
        &mut eng,
        &["chroma_key"],
        &["spill=1"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
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
    let (_, _, st) = run(&mut eng, &["chroma_key"], &[], &img, Format::Rgba32f).unwrap();
    let (_, _, pm) = run(
        &mut eng,
        &["chroma_key"],
        &["output=premultiplied"],
        &img,
        Format::Rgba32f,
    )
    .unwrap();
    let (_, _, mt) = run(
        &mut eng,
        &["chroma_key"],
        &["output=matte"],
        &img,
        Format::Rgba8Srgb,
    )
    .unwrap();
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
    for (x, y) in [(20u32, 20u32), (600, 300), (500, 50)] {
        let i = ((y * w + x) * 4) as usize;
        assert!(
            (0..3).all(|c| comp[i + c].abs_diff(bg[i + c]) <= 1),
            "backdrop ({x}, {y}): {:?} vs background {:?}",
            &comp[i..i + 4],
            &bg[i..i + 4]
        );
    }
    for (x, y) in [(300u32, 120u32), (310, 70)] {
        let i = ((y * w + x) * 4) as usize;
        assert!(
            (0..3).all(|c| comp[i + c].abs_diff(v[i + c]) <= 1),
            "person ({x}, {y}): {:?} vs keyed {:?}",
            &comp[i..i + 4],
            &v[i..i + 4]
        );
    }
    let path = save_for_review(
        "chroma_composite_greenscreen",
        w,
        h,
        &Pixels::U8(comp.to_vec()),
    );
    eprintln!("composite written to {}", path.display());
}

// ---------------------------------------------------------------- format_convert

/// Kr, Kb of BT.709 and BT.601.
fn coeffs(matrix: &str) -> (f64, f64) {
    match matrix {
        "bt709" => (0.2126, 0.0722),
        _ => (0.299, 0.114),
    }
}

/// rgb_to_ycbcr of one colour (after the transfer, if any).
fn to_ycbcr(e: [f64; 3], matrix: &str, limited: bool) -> [f64; 3] {
    let (kr, kb) = coeffs(matrix);
    let y = kr * e[0] + (1.0 - kr - kb) * e[1] + kb * e[2];
    let pb = (e[2] - y) / (2.0 * (1.0 - kb));
    let pr = (e[0] - y) / (2.0 * (1.0 - kr));
    if limited {
        [
            (16.0 + 219.0 * y) / 255.0,
            (128.0 + 224.0 * pb) / 255.0,
            (128.0 + 224.0 * pr) / 255.0,
        ]
    } else {
        [y, pb + 0.5, pr + 0.5]
    }
}

/// A float image of f16-exact values over [0, 1] with varied hues.
fn colour_grid() -> Image {
    image_f32(37, 23, |x, y| {
        let q = |v: f64| f16r(v) as f32;
        [
            q(x as f64 / 36.0),
            q(y as f64 / 22.0),
            q(((x * 7 + y * 3) % 29) as f64 / 28.0),
            q(0.25 + (x % 4) as f64 * 0.25),
        ]
    })
}

#[test]
fn format_convert_known_values() {
    let Some(mut eng) = engine() else { return };
    let img = image_f32(4, 1, |x, _| match x {
        0 => [1.0, 1.0, 1.0, 1.0],
        1 => [1.0, 0.0, 0.0, 0.5],
        2 => [0.0, 0.0, 0.0, 1.0],
        _ => [0.0, 0.0, 1.0, 1.0],
    });
    let get = |eng: &mut fxgraph::gpu::executor::Engine, set: &[&str]| -> Vec<f32> {
        let (_, _, px) = run(eng, &["format_convert"], set, &img, Format::Rgba32f).unwrap();
        f32s(&px).to_vec()
    };
    let close = |a: &[f32], b: [f64; 3], what: &str| {
        assert!(
            a.iter().zip(b).all(|(&x, y)| (x as f64 - y).abs() < 1e-5),
            "{what}: {a:?}, want {b:?}"
        );
    };
    // BT.709 full range: white -> (1, 0.5, 0.5), black -> (0, 0.5, 0.5).
    let v = get(&mut eng, &[]);
    close(&v[0..3], [1.0, 0.5, 0.5], "bt709 white");
    close(&v[8..11], [0.0, 0.5, 0.5], "bt709 black");
    close(
        &v[12..15],
        [0.0722, 1.0, 0.5 - 0.0722 / (2.0 * (1.0 - 0.2126))],
        "bt709 blue",
    );
    // BT.601: pure red -> Y' = 0.299, Cr = 1; alpha passes through.
    let v = get(&mut eng, &["matrix=bt601"]);
    close(
        &v[4..7],
        [0.299, 0.5 - 0.299 / (2.0 * 0.886), 1.0],
        "bt601 red",
    );
    assert_eq!(v[7], 0.5, "alpha");
    // Limited range: white -> 235/255, black -> 16/255, chroma 128/255.
    let v = get(&mut eng, &["range=limited"]);
    close(
        &v[0..3],
        [235.0 / 255.0, 128.0 / 255.0, 128.0 / 255.0],
        "limited white",
    );
    close(
        &v[8..11],
        [16.0 / 255.0, 128.0 / 255.0, 128.0 / 255.0],
        "limited black",
    );
    // And back.
    let lim = image_f32(2, 1, |x, _| {
        if x == 0 {
            [235.0 / 255.0, 128.0 / 255.0, 128.0 / 255.0, 1.0]
        } else {
            [16.0 / 255.0, 128.0 / 255.0, 128.0 / 255.0, 1.0]
        }
    });
    let (_, _, px) = run(
        &mut eng,
        &["format_convert"],
        &["direction=ycbcr_to_rgb", "range=limited"],
        &lim,
        Format::Rgba32f,
    )
    .unwrap();
    let v = f32s(&px);
    // The inputs are f16-rounded (rgba16f upload): 1e-3 covers that.
    assert!(
        v[0..3].iter().all(|&c| (c - 1.0).abs() < 1e-3) && v[4..7].iter().all(|&c| c.abs() < 1e-3),
        "{v:?}"
    );
}

#[test]
fn format_convert_ycbcr_matches_the_matrices_and_round_trips() {
    let Some(mut eng) = engine() else { return };
    let img = colour_grid();
    let src: Vec<f64> = f32s(&img.pixels).iter().map(|&x| x as f64).collect();
    let mut worst_fwd: f64 = 0.0;
    let mut worst_rt: f64 = 0.0;
    for matrix in ["bt709", "bt601"] {
        for range in ["full", "limited"] {
            for transfer in ["srgb", "none"] {
                let m = format!("matrix={matrix}");
                let r = format!("range={range}");
                let t = format!("transfer={transfer}");
                // Forward, against the f64 matrices.
                let (_, _, px) = run(
                    &mut eng,
                    &["format_convert"],
                    &[&m, &r, &t],
                    &img,
                    Format::Rgba32f,
                )
                .unwrap();
                let got = f32s(&px);
                for (p, q) in src.chunks(4).zip(got.chunks(4)) {
                    let e = if transfer == "srgb" {
                        [srgb_encode(p[0]), srgb_encode(p[1]), srgb_encode(p[2])]
                    } else {
                        [p[0], p[1], p[2]]
                    };
                    let want = to_ycbcr(e, matrix, range == "limited");
                    for c in 0..3 {
                        worst_fwd = worst_fwd.max((q[c] as f64 - want[c]).abs());
                    }
                    assert_eq!(q[3] as f64, p[3], "alpha");
                }
                // Round trip through two instances (rgba32f between them).
                let (_, _, px) = run(
                    &mut eng,
                    &["format_convert", "format_convert"],
                    &[
                        "format_convert.direction=rgb_to_ycbcr",
                        "format_convert#2.direction=ycbcr_to_rgb",
                        &m,
                        &r,
                        &t,
                    ],
                    &img,
                    Format::Rgba32f,
                )
                .unwrap();
                let e = max_abs_diff(f32s(&px), f32s(&img.pixels)) as f64;
                eprintln!(
                    "format_convert {matrix} {range} {transfer}: round trip max error {e:.2e}"
                );
                worst_rt = worst_rt.max(e);
            }
        }
    }
    eprintln!("format_convert: forward max error {worst_fwd:.2e}, round trip {worst_rt:.2e}");
    assert!(worst_fwd < 2e-6, "forward conversion off by {worst_fwd}");
    assert!(worst_rt < 1e-4, "round trip off by {worst_rt}");
}

#[test]
fn format_convert_srgb_curves_are_exact() {
    let Some(mut eng) = engine() else { return };
    // f16-exact inputs over [0, 1] (dense near 0, where the linear segment is),
    // plus values above 1 and below 0 (the curve is extended).
    let vals: Vec<f32> = (0..=400)
        .map(|i| {
            let t = i as f64 / 400.0;
            f16r(t * t) as f32
        })
        .chain([1.5, 4.0, -0.25, f16r(-0.002) as f32])
        .collect();
    let n = vals.len() as u32;
    let img = image_f32(n, 1, |x, _| {
        let v = vals[x as usize];
        [v, v, v, 1.0]
    });
    let mut report = Vec::new();
    for (dir, f) in [
        ("linear_to_srgb", srgb_encode as fn(f64) -> f64),
        ("srgb_to_linear", srgb_decode),
    ] {
        let set = format!("direction={dir}");
        let (_, _, px) = run(
            &mut eng,
            &["format_convert"],
            &[&set],
            &img,
            Format::Rgba32f,
        )
        .unwrap();
        let got = f32s(&px);
        let mut worst: f64 = 0.0;
        for (i, &v) in vals.iter().enumerate() {
            let want = f(v as f64);
            let e = (got[i * 4] as f64 - want).abs() / want.abs().max(1e-3);
            worst = worst.max(e);
        }
        report.push(format!("{dir}: max relative error {worst:.2e}"));
        assert!(worst < 2e-5, "{dir}: relative error {worst}");
    }
    eprintln!("format_convert curves: {}", report.join(", "));
}

#[test]
fn format_convert_on_bytes_with_assume_linear() {
    let Some(mut eng) = engine() else { return };
    // With --assume-linear the numbers are the file's bytes: transfer = none gives
    // the JPEG-style Y'CbCr (BT.601 full range) of the 8-bit R'G'B'.
    let img = pattern_u8(67, 41);
    let (_, _, px) = run_raw(
        &mut eng,
        &["format_convert"],
        &["matrix=bt601", "transfer=none"],
        &img,
        Format::Rgba8,
    )
    .unwrap();
    let src = unit_u8(&img);
    let want: Vec<f64> = src
        .chunks(4)
        .flat_map(|p| {
            let y = to_ycbcr([p[0], p[1], p[2]], "bt601", false);
            [255.0 * y[0], 255.0 * y[1], 255.0 * y[2], 255.0 * p[3]]
        })
        .collect();
    let (max, off) = lsb_diff(u8s(&px), &want, |_| true);
    eprintln!(
        "format_convert bytes bt601: max {max} LSB, {:.2}% off",
        off * 100.0
    );
    assert!(max <= 1, "{max} LSB");
}

// ---------------------------------------------------------------- fxaa

/// A binary staircase: white below the line y = 12 + x / 4 (shallow, 4-px stairs).
fn staircase(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        let v = if y as f64 + 0.5 > 12.0 + x as f64 / 4.0 {
            1.0
        } else {
            0.0
        };
        [v, v, v, 1.0]
    })
}

#[test]
fn fxaa_smooths_a_staircase_and_stays_in_range() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(64, 40), (67, 41)] {
        let img = staircase(w, h);
        let (_, _, px) = run(&mut eng, &["fxaa"], &[], &img, Format::Rgba32f).unwrap();
        let out = f32s(&px);
        let inp = f32s(&img.pixels);
        assert!(
            out.iter().all(|&v| (0.0..=1.0).contains(&v)),
            "output outside [0, 1]"
        );
        let mid = |v: &[f32]| v.chunks(4).filter(|p| p[0] > 0.02 && p[0] < 0.98).count();
        assert_eq!(mid(inp), 0);
        let intermediate = mid(out);
        // Largest jump between horizontal neighbours (the stair risers) and the
        // number of pixels changed.
        let step = |v: &[f32]| {
            let mut m: f32 = 0.0;
            for y in 0..h {
                for x in 0..w - 1 {
                    m = m.max((at(v, w, x + 1, y, 0) - at(v, w, x, y, 0)).abs());
                }
            }
            m
        };
        let changed = inp
            .chunks(4)
            .zip(out.chunks(4))
            .filter(|(a, b)| a != b)
            .count();
        eprintln!(
            "fxaa staircase {w}x{h}: {intermediate} intermediate pixels, {changed} changed, max horizontal step {} -> {}",
            step(inp),
            step(out)
        );
        assert!(
            intermediate >= (w as usize) / 2,
            "only {intermediate} intermediate pixels along the edge"
        );
        assert!(
            step(out) <= 0.75,
            "staircase risers not reduced: {}",
            step(out)
        );
        // Only pixels next to the edge change.
        for y in 0..h {
            for x in 0..w {
                let d = (y as f64 + 0.5 - (12.0 + x as f64 / 4.0)).abs();
                if d > 3.0 {
                    assert_eq!(
                        at(out, w, x, y, 0),
                        at(inp, w, x, y, 0),
                        "({x}, {y}) far from the edge changed"
                    );
                }
            }
        }
        // Alpha stays 1 (it is resampled like the colour).
        assert!(out.chunks(4).all(|p| p[3] == 1.0));
    }
}

#[test]
fn fxaa_leaves_flat_and_low_contrast_areas_exactly_unchanged() {
    let Some(mut eng) = engine() else { return };
    // Flat 8-bit image: bytes identical.
    let flat = image_u8(67, 41, |_, _| [37, 120, 201, 255]);
    let (_, _, px) = run(&mut eng, &["fxaa"], &[], &flat, Format::Rgba8Srgb).unwrap();
    assert_eq!(u8s(&px), u8s(&flat.pixels));
    // A smooth horizontal ramp (constant down each column, contrast below the
    // threshold): identical floats.
    let ramp = image_f32(67, 41, |x, _| {
        let v = 0.3 + 0.002 * x as f64;
        [f16r(v) as f32, f16r(v * 0.5) as f32, f16r(0.2) as f32, 1.0]
    });
    let (_, _, px) = run(&mut eng, &["fxaa"], &[], &ramp, Format::Rgba32f).unwrap();
    let d = max_abs_diff(f32s(&px), f32s(&ramp.pixels));
    assert!(d == 0.0, "low-contrast ramp changed by {d}");
    // An 8-bit pattern: every pixel whose local contrast (luma of the sRGB-encoded
    // values over the centre and its 4 neighbours) is clearly below FXAA's
    // threshold max(0.0312, 0.125 * max) keeps its exact bytes.
    let img = pattern_u8(67, 41);
    let (w, h, px) = run(&mut eng, &["fxaa"], &[], &img, Format::Rgba8Srgb).unwrap();
    let (a, b) = (u8s(&img.pixels), u8s(&px));
    let idx = |x: i64, y: i64| {
        ((y.clamp(0, h as i64 - 1) * w as i64 + x.clamp(0, w as i64 - 1)) * 4) as usize
    };
    let luma = |x: i64, y: i64| {
        let i = idx(x, y);
        luma709(&[
            a[i] as f64 / 255.0,
            a[i + 1] as f64 / 255.0,
            a[i + 2] as f64 / 255.0,
        ])
    };
    let (mut checked, mut processed) = (0, 0);
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let l = [
                luma(x, y),
                luma(x, y - 1),
                luma(x, y + 1),
                luma(x - 1, y),
                luma(x + 1, y),
            ];
            let (lo, hi) = l
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            let threshold = (0.0312f64).max(0.125 * hi);
            if hi - lo < 0.9 * threshold {
                let i = idx(x, y);
                assert_eq!(
                    b[i..i + 4],
                    a[i..i + 4],
                    "low-contrast pixel ({x}, {y}) changed"
                );
                checked += 1;
            } else if hi - lo > 1.1 * threshold {
                processed += 1;
            }
        }
    }
    eprintln!(
        "fxaa pattern: {checked} low-contrast pixels unchanged, {processed} above the threshold"
    );
    assert!(
        checked > 500 && processed > 100,
        "{checked} low-contrast, {processed} high-contrast pixels"
    );
}

#[test]
fn fxaa_keeps_a_straight_horizontal_edge_without_subpixel_blend() {
    let Some(mut eng) = engine() else { return };
    // A perfectly horizontal hard edge is not aliased: with subpix = 0 the edge
    // search runs out on both sides equally, the offset is 0, and the pixel is
    // resampled at its own centre.
    let (lo, hi) = (f16r(0.1) as f32, f16r(0.9) as f32);
    let img = image_f32(67, 41, |_, y| {
        if y < 20 {
            [lo, lo, lo, 1.0]
        } else {
            [hi, hi, hi, 1.0]
        }
    });
    let (_, _, px) = run(&mut eng, &["fxaa"], &["subpix=0"], &img, Format::Rgba32f).unwrap();
    let d = max_abs_diff(f32s(&px), f32s(&img.pixels));
    eprintln!("fxaa horizontal edge, subpix 0: max change {d:.2e}");
    assert!(d == 0.0, "straight edge changed by {d}");
    // With the default subpix, FXAA 3.11 softens it slightly (its 3x3 low-pass sees
    // a third of a step): bounded.
    let (_, _, px) = run(&mut eng, &["fxaa"], &[], &img, Format::Rgba32f).unwrap();
    let d = max_abs_diff(f32s(&px), f32s(&img.pixels));
    eprintln!("fxaa horizontal edge, default subpix: max change {d:.3}");
    assert!(d < 0.1, "straight edge changed by {d}");
}

// ---------------------------------------------------------------- glow

/// CPU model of the seed `glow` (effects/glow.fx) on a float image: brightPass at
/// full size, blurX at half size (a prefiltering downsampling blur, sigma 4 in
/// half-size pixels) and blurY at half size (the shader's tap positions and paired
/// weights, bilinear sampling, clamp to edge),
/// then add with a bilinear upsample. rgba16f intermediates are rounded to half.
fn glow_oracle(src: &[f64], w: u32, h: u32) -> Vec<f64> {
    let (threshold, knee, sigma): (f64, f64, f64) = (0.4, 0.3, 4.0);
    let bright: Vec<f64> = src
        .chunks(4)
        .flat_map(|c| {
            let luma = luma709(c);
            let soft = (luma - threshold + knee).clamp(0.0, 2.0 * knee);
            let contribution = (soft * soft / (4.0 * knee)).max(luma - threshold);
            let scale = contribution.max(0.0) / luma.max(1e-5);
            [
                f16r(c[0] * scale),
                f16r(c[1] * scale),
                f16r(c[2] * scale),
                f16r(c[3]),
            ]
        })
        .collect();
    let hs = half_size(w, h);
    let bx = down_blur_x(&bright, (w, h), hs, sigma);
    let by = blur_pass(&bx, hs, hs, sigma, false);
    let mut out = Vec::with_capacity(src.len());
    for y in 0..h {
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            for c in 0..3 {
                out.push(src[i + c] + upsample(&by, hs, x, y, (w, h), c));
            }
            out.push(src[i + 3]);
        }
    }
    out
}

#[test]
fn glow_matches_the_cpu_model() {
    let Some(mut eng) = engine() else { return };
    for (w, h) in [(64, 48), (67, 41)] {
        // A dim gradient with HDR highlights (a bright disc, a line, single pixels)
        // and a soft-knee band around the threshold.
        let img = image_f32(w, h, |x, y| {
            let (fx, fy) = (x as f64, y as f64);
            let disc = (fx - 20.0).powi(2) + (fy - 15.0).powi(2) < 25.0;
            let mut c = [0.1 + 0.6 * fx / w as f64, 0.2, 0.15 + 0.5 * fy / h as f64];
            if disc {
                c = [3.0, 2.5, 1.0];
            }
            if y == 30 && x > 30 {
                c = [0.2, 1.5, 4.0];
            }
            if (x * 7 + y * 13) % 97 == 0 {
                c = [8.0, 8.0, 8.0];
            }
            [f16r(c[0]) as f32, f16r(c[1]) as f32, f16r(c[2]) as f32, 1.0]
        });
        let src: Vec<f64> = f32s(&img.pixels).iter().map(|&v| v as f64).collect();
        let want = glow_oracle(&src, w, h);
        let (_, _, px) = run(&mut eng, &["glow"], &[], &img, Format::Rgba32f).unwrap();
        let got = f32s(&px);
        // Error relative to the glow added (output - input), in units of the
        // largest glow value.
        let glow_max = want
            .iter()
            .zip(&src)
            .map(|(a, b)| a - b)
            .fold(0.0, f64::max);
        let mut max_abs: f64 = 0.0;
        for (&g, &o) in got.iter().zip(&want) {
            // Half-float rounding of the intermediates is modelled; what remains is
            // f32 vs f64 arithmetic, the sampler's weight precision and
            // rounding-boundary flips of the halves: relative to max(1, |value|).
            max_abs = max_abs.max((g as f64 - o).abs() / o.abs().max(1.0));
        }
        eprintln!("glow {w}x{h}: max error {max_abs:.2e} (largest glow {glow_max:.3})");
        assert!(glow_max > 0.5, "test image does not glow");
        assert!(max_abs < 2e-3, "glow {w}x{h}: {max_abs} from the CPU model");
    }
}

#[test]
fn glow_plan_peak_is_the_lower_bound() {
    for (w, h) in [(64, 64), (67, 41), (1920, 1080)] {
        let (p, warnings, _) = plan_for(&["effects/glow.fx"], w, h);
        assert_eq!(warnings, 0);
        assert_eq!(p.peak_bytes, p.lower_bound_bytes, "{w}x{h}");
        assert_eq!(p.validate(), Ok(p.peak_bytes));
        // brightPass (full, rgba16f) is still alive while blurX (half) runs; then
        // blurX and blurY (both half) are alive together.
        let (w2, h2) = (
            ((w as f64) * 0.5).round() as u64,
            ((h as f64) * 0.5).round() as u64,
        );
        let full = w as u64 * h as u64 * 8;
        let half = w2 * h2 * 8;
        assert_eq!(p.lower_bound_bytes, (full + half).max(2 * half), "{w}x{h}");
    }
}
