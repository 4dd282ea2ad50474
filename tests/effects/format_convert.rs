//! `format_convert`: known values, the Y'CbCr matrices (BT.709, BT.601, full and
//! limited range) and their round trips, the exact sRGB curves, bytes with --assume-linear.

use crate::common::samples::*;
use crate::common::*;
use crate::oracle::*;
use fxgraph::io::Image;
use fxgraph::script::types::Format;

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
    let px = apply_fx(
        &mut eng,
        "format_convert",
        &["direction=ycbcr_to_rgb", "range=limited"],
        &lim,
        Format::Rgba32f,
    );
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
                let px = apply_fx(
                    &mut eng,
                    "format_convert",
                    &[&m, &r, &t],
                    &img,
                    Format::Rgba32f,
                );
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
        let px = apply_fx(&mut eng, "format_convert", &[&set], &img, Format::Rgba32f);
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
