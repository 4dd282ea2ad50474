//! `fxrun` with y4m files (`-i in.y4m`, `-o out.y4m`): 8-bit and 9- to 16-bit
//! streams, outputs written whole or not at all, checked with an independent y4m
//! reader (tests/common/video.rs) and with ffmpeg/ffprobe.

use crate::common::cli::{
    assert_no_temporaries, exits_with, fxrun_line_in, fxrun_with, succeeds_in,
};
use crate::common::video::{
    assert_y4m_header, ffmpeg, have_ffmpeg, probe, read_y4m, samples_420, streams, y4m,
};
use std::path::Path;

/// The identity effect: the output is the input.
const IDENTITY: &str = "EFFECT.id = { OUT = IN }";

/// A temporary folder with `id.fx`, or `None` without a GPU (or, in CI, a panic).
fn setup() -> Option<tempfile::TempDir> {
    let dir = crate::common::gpu_scratch()?;
    std::fs::write(dir.path().join("id.fx"), IDENTITY).unwrap();
    Some(dir)
}

/// A 4:2:0 frame: luma from `y(x, y)`, constant chroma (so that chroma resampling is
/// exact and the trip through RGB only quantises).
fn frame_420(
    w: usize,
    h: usize,
    cb: u16,
    cr: u16,
    y: impl Fn(usize, usize) -> u16,
) -> Vec<Vec<u16>> {
    let c = w.div_ceil(2) * h.div_ceil(2);
    vec![
        (0..w * h).map(|i| y(i % w, i / w)).collect(),
        vec![cb; c],
        vec![cr; c],
    ]
}

/// `n` 4:2:0 frames of [`frame_420`]: frame `i` has the luma `y(i, x, y)`.
fn frames_420(
    n: usize,
    (w, h): (usize, usize),
    (cb, cr): (u16, u16),
    y: impl Fn(usize, usize, usize) -> u16,
) -> Vec<Vec<Vec<u16>>> {
    (0..n)
        .map(|i| frame_420(w, h, cb, cr, |px, py| y(i, px, py)))
        .collect()
}

/// `fxrun LINE` in `d` (expected to succeed), then the y4m file it wrote (`-o OUT`):
/// its header line and frames of `samples` samples at `depth` bits.
fn run_read(d: &Path, line: &str, depth: u8, samples: usize) -> (String, Vec<Vec<u16>>) {
    succeeds_in(d, line);
    let out = line.split(" -o ").nth(1).and_then(|o| o.split(' ').next());
    let out = out.unwrap_or_else(|| panic!("no `-o OUT` in `{line}`"));
    read_y4m(&std::fs::read(d.join(out)).unwrap(), depth, samples)
}

/// Write the y4m file `name` of one frame in `d` (see [`y4m`]).
fn put_frame(d: &Path, name: &str, header: &str, depth: u8, frame: &[Vec<u16>]) {
    std::fs::write(d.join(name), y4m(header, depth, &[frame.to_vec()])).unwrap();
}

/// Write the y4m file `name` in `d` (see [`y4m`]).
fn put(d: &Path, name: &str, header: &str, depth: u8, frames: &[Vec<Vec<u16>>]) {
    std::fs::write(d.join(name), y4m(header, depth, frames)).unwrap();
}

fn max_diff(a: &[u16], b: &[u16]) -> u16 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0)
}

#[test]
fn an_8bit_file_round_trip_equals_the_pipe() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let (w, h) = (64, 48);
    let frames = frames_420(4, (w, h), (120, 136), |i, x, y| {
        (40 + (x * 3 + y * 2 + i * 5) % 180) as u16
    });
    let input = y4m("W64 H48 F25:1 Ip A1:1 C420jpeg", 8, &frames);
    std::fs::write(d.join("in.y4m"), &input).unwrap();
    succeeds_in(d, "id.fx -i in.y4m -o out.y4m");
    let out = std::fs::read(d.join("out.y4m")).unwrap();
    let (header, got) = read_y4m(&out, 8, samples_420(w, h));
    assert_eq!(header, "YUV4MPEG2 W64 H48 F25:1 Ip A1:1 C420jpeg");
    assert_eq!(got.len(), 4);
    for (g, f) in got.iter().zip(&frames) {
        // The 8-bit R'G'B' in between quantises: within 2 codes.
        let want: Vec<u16> = f.concat();
        assert!(max_diff(g, &want) <= 2, "max diff {}", max_diff(g, &want));
    }
    // The same bytes as the stream through a pipe.
    let piped = fxrun_with(d, &["id.fx", "-i", "-", "-o", "-"], &[], &input);
    exits_with(&piped, 0, &[]);
    assert!(piped.stdout == out, "file and pipe outputs differ");
    assert_no_temporaries(d);
    if have_ffmpeg() {
        let p = probe(&d.join("out.y4m"));
        let v = streams(&p, "video");
        assert_eq!(v[0]["pix_fmt"], "yuv420p");
        assert_eq!(crate::common::video::frame_count(&d.join("out.y4m")), 4);
    }
}

#[test]
fn deinterlace_reads_and_writes_y4m_files() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let (w, h) = (64, 48);
    // Top field (even rows) and bottom field (odd rows) of a moving ramp.
    let frames = frames_420(4, (w, h), (128, 128), |i, x, y| {
        let shift = if y % 2 == 0 { 2 * i } else { 2 * i + 1 };
        (30 + ((x + shift) * 3) % 190) as u16
    });
    let input = y4m("W64 H48 F25:1 It A1:1 C420jpeg", 8, &frames);
    std::fs::write(d.join("in.y4m"), &input).unwrap();
    let (header, got) = run_read(d, "deinterlace -i in.y4m -o out.y4m", 8, samples_420(w, h));
    assert_eq!(
        header, "YUV4MPEG2 W64 H48 F25:1 Ip A1:1 C420jpeg",
        "progressive out"
    );
    assert_eq!(got.len(), 4);
    // Top field first: the even rows are kept (copied, up to the RGB quantisation).
    for (g, f) in got.iter().zip(&frames) {
        for y in (0..h).step_by(2) {
            let row = |p: &[u16]| p[y * w..(y + 1) * w].to_vec();
            assert!(max_diff(&row(g), &row(&f[0])) <= 2, "row {y}");
        }
    }
    // Field rate: two frames per input frame, at twice the rate.
    let (header, got) = run_read(
        d,
        "deinterlace -i in.y4m -o out2.y4m --rate 2",
        8,
        samples_420(w, h),
    );
    assert_eq!(header, "YUV4MPEG2 W64 H48 F50:1 Ip A1:1 C420jpeg");
    assert_eq!(got.len(), 8);
    // --frames takes part of the file.
    let (_, got) = run_read(
        d,
        "deinterlace -i in.y4m -o part.y4m --frames 1..2",
        8,
        samples_420(w, h),
    );
    assert_eq!(got.len(), 2);
    assert_no_temporaries(d);
}

#[test]
fn a_failed_run_keeps_the_existing_output() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let frames = frames_420(3, (32, 16), (128, 128), |i, x, _| (40 + x + i) as u16);
    let mut input = y4m("W32 H16 F25:1 Ip A1:1 C420jpeg", 8, &frames);
    input.truncate(input.len() - 100);
    std::fs::write(d.join("cut.y4m"), &input).unwrap();
    std::fs::write(d.join("out.y4m"), b"the old output").unwrap();
    let o = fxrun_line_in(d, "id.fx -i cut.y4m -o out.y4m");
    exits_with(&o, 1, &["frame 2"]);
    assert_eq!(std::fs::read(d.join("out.y4m")).unwrap(), b"the old output");
    assert_no_temporaries(d);
    // --skip-existing: a whole file exists, nothing to do.
    let o = fxrun_line_in(d, "id.fx -i cut.y4m -o out.y4m --skip-existing");
    exits_with(&o, 0, &["exists already"]);
    assert_eq!(std::fs::read(d.join("out.y4m")).unwrap(), b"the old output");
    // The input as the output is refused (it would be replaced).
    let o = fxrun_line_in(d, "id.fx -i cut.y4m -o ./cut.y4m");
    exits_with(&o, 1, &["would replace the input"]);
    // A good run replaces it.
    put(d, "in.y4m", "W32 H16 F25:1 Ip A1:1 C420jpeg", 8, &frames);
    succeeds_in(d, "id.fx -i in.y4m -o out.y4m");
    assert_y4m_header(&d.join("out.y4m"), "YUV4MPEG2 W32 H16");
    // Image frames to a y4m file: the rate is --fps.
    std::fs::create_dir(d.join("png")).unwrap();
    succeeds_in(d, "id.fx -i in.y4m -o png/%02d.png");
    succeeds_in(d, "id.fx -i png/%02d.png -o back.y4m --fps 29.97");
    assert_y4m_header(&d.join("back.y4m"), "YUV4MPEG2 W32 H16 F30000:1001 Ip");
    assert_no_temporaries(d);
}

/// A 4:2:0 grey ramp over every code of the range at `depth` bits (each pixel
/// another level, in steps of 7 modulo the range).
fn ramp(w: usize, h: usize, depth: u8, full: bool) -> Vec<Vec<u16>> {
    let s = 1u32 << (depth - 8);
    let (lo, hi) = if full {
        (0, (1u32 << depth) - 1)
    } else {
        (16 * s, 235 * s)
    };
    let mid = (128 * s) as u16;
    frame_420(w, h, mid, mid, |x, y| {
        (lo + ((x + y * w) as u32 * 7) % (hi - lo + 1)) as u16
    })
}

#[test]
fn ten_bit_streams_keep_every_level() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let (w, h) = (160, 64);
    for (range, full) in [("LIMITED", false), ("FULL", true)] {
        let f = ramp(w, h, 10, full);
        let header = format!("W160 H64 F25:1 Ip A1:1 C420p10 XYSCSS=420P10 XCOLORRANGE={range}");
        put(d, "in.y4m", &header, 10, &[f.clone(), f.clone()]);
        let (head, got) = run_read(d, "id.fx -i in.y4m -o out.y4m", 10, samples_420(w, h));
        assert_eq!(head, format!("YUV4MPEG2 {header}"));
        assert_eq!(got.len(), 2);
        let luma = &got[0][..w * h];
        let diff = max_diff(luma, &f[0]);
        let levels = luma.iter().collect::<std::collections::HashSet<_>>().len();
        eprintln!("10-bit {range}: max luma difference {diff}, {levels} levels");
        assert!(diff <= 1, "{range}: max difference {diff}");
        assert!(levels > 256, "{range}: only {levels} levels");
        assert!(max_diff(&got[0], &f.concat()) <= 1, "{range}: chroma");
        if have_ffmpeg() {
            let p = probe(&d.join("out.y4m"));
            let v = streams(&p, "video");
            assert_eq!(v[0]["pix_fmt"], "yuv420p10le");
            assert_eq!(v[0]["color_range"], if full { "pc" } else { "tv" });
        }
    }
    // 10 bits in, 12 bits out (--bit-depth): the same levels times 4.
    let f = ramp(w, h, 10, false);
    put_frame(d, "in.y4m", "W160 H64 F25:1 Ip A1:1 C420p10", 10, &f);
    let (head, got) = run_read(
        d,
        "id.fx -i in.y4m -o out12.y4m --bit-depth 12",
        12,
        samples_420(w, h),
    );
    assert_eq!(head, "YUV4MPEG2 W160 H64 F25:1 Ip A1:1 C420p12");
    let times4: Vec<u16> = f[0].iter().map(|v| v * 4).collect();
    assert!(max_diff(&got[0][..w * h], &times4) <= 2);
    // Depths y4m has no form for are refused up front.
    let o = fxrun_line_in(d, "id.fx -i in.y4m -o bad.y4m --bit-depth 11");
    exits_with(&o, 1, &["8, 9, 10, 12, 14, 16"]);
    assert!(!d.join("bad.y4m").exists());
    assert_no_temporaries(d);
}

#[test]
fn twelve_bit_and_mono16_are_read_and_written() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let (w, h) = (160, 64);
    let f = ramp(w, h, 12, false);
    put_frame(d, "in12.y4m", "W160 H64 F25:1 Ip A1:1 C420p12", 12, &f);
    let (head, got) = run_read(d, "id.fx -i in12.y4m -o out12.y4m", 12, samples_420(w, h));
    assert_eq!(head, "YUV4MPEG2 W160 H64 F25:1 Ip A1:1 C420p12");
    let diff = max_diff(&got[0], &f.concat());
    eprintln!("12-bit: max difference {diff}");
    assert!(diff <= 1, "12-bit: max difference {diff}");
    // Mono, 16 bits, full range: every 7th code of 0..65535 across the frame.
    let mono: Vec<u16> = (0..w * h)
        .map(|i| ((i as u32 * 7 * 6) % 65536) as u16)
        .collect();
    let header = "W160 H64 F25:1 Ip A1:1 Cmono16 XCOLORRANGE=FULL";
    put(d, "in16.y4m", header, 16, &[vec![mono.clone()]]);
    let args = "id.fx -i in16.y4m -o out16.y4m";
    let (head, got) = run_read(d, args, 16, w * h);
    assert_eq!(head, format!("YUV4MPEG2 {header}"));
    let diff = max_diff(&got[0], &mono);
    eprintln!("Cmono16: max difference {diff}");
    assert!(diff <= 1, "Cmono16: max difference {diff}");
    if have_ffmpeg() {
        let v = probe(&d.join("out16.y4m"));
        assert_eq!(streams(&v, "video")[0]["pix_fmt"], "gray16le");
        let v = probe(&d.join("out12.y4m"));
        assert_eq!(streams(&v, "video")[0]["pix_fmt"], "yuv420p12le");
    }
}

/// The 10-bit Y'CbCr → R'G'B' conversion against the BT.601 formulas (limited range,
/// 4:4:4 so that chroma siting plays no part), written as 16-bit PNG; and against
/// ffmpeg's swscale, whose own error here is about 3.3 codes (measured against the
/// same formulas), with a looser bound.
#[test]
fn ten_bit_colours_match_the_bt601_formulas() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let (w, h) = (64, 32);
    let n = w * h;
    // In-gamut colours: mid luma, moderate chroma.
    let (yf, uf, vf) = (
        |x: usize, y: usize| 300 + ((x * 9 + y * 5) % 400) as u16,
        |x: usize, _: usize| 440 + (x * 2) as u16,
        |_: usize, y: usize| 580 - (y * 3) as u16,
    );
    let plane =
        |f: &dyn Fn(usize, usize) -> u16| -> Vec<u16> { (0..n).map(|i| f(i % w, i / w)).collect() };
    let f = vec![plane(&yf), plane(&uf), plane(&vf)];
    let header = "W64 H32 F25:1 Ip A1:1 C444p10 XCOLORRANGE=LIMITED";
    put(d, "in.y4m", header, 10, &[f]);
    succeeds_in(d, "id.fx -i in.y4m -o fx/%d.png --bit-depth 16");
    let load = |p: &Path| -> Vec<f32> {
        let opts = fxgraph::io::LoadOptions {
            assume_linear: true,
        };
        crate::common::linear(&fxgraph::io::load_image(p, &opts).unwrap().pixels)
    };
    let got = load(&d.join("fx/0.png"));
    // BT.601: Y' = (Y - 64) / 876, Pb = (Cb - 512) / 896, Pr = (Cr - 512) / 896.
    let (kr, kb) = (0.299f64, 0.114f64);
    let mut worst = 0f64;
    for i in 0..n {
        let (x, y) = (i % w, i / w);
        let yy = (yf(x, y) as f64 - 64.0) / 876.0;
        let pb = (uf(x, y) as f64 - 512.0) / 896.0;
        let pr = (vf(x, y) as f64 - 512.0) / 896.0;
        let r = yy + 2.0 * (1.0 - kr) * pr;
        let b = yy + 2.0 * (1.0 - kb) * pb;
        let g = (yy - kr * r - kb * b) / (1.0 - kr - kb);
        for (c, want) in [r, g, b].into_iter().enumerate() {
            worst = worst.max((got[i * 4 + c] as f64 - want).abs() * 1023.0);
        }
    }
    eprintln!("10-bit 4:4:4 against the BT.601 formulas: max difference {worst:.3} codes");
    assert!(worst <= 0.5, "max difference {worst} 10-bit codes");
    if have_ffmpeg() {
        ffmpeg(&[
            "-i",
            d.join("in.y4m").to_str().unwrap(),
            "-vf",
            "scale=in_color_matrix=bt601:in_range=tv:flags=accurate_rnd+full_chroma_int",
            "-pix_fmt",
            "rgb48be",
            d.join("ff.png").to_str().unwrap(),
        ]);
        let diff = crate::common::max_abs_diff(&got, &load(&d.join("ff.png"))) * 1023.0;
        eprintln!("10-bit 4:4:4 against ffmpeg: max difference {diff:.3} codes");
        assert!(
            diff <= 4.0,
            "max difference {diff} 10-bit codes from ffmpeg"
        );
    }
}
