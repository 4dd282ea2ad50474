//! The file layer (`fxgraph::io`), one module per topic: the sRGB curve, PNG, EXR,
//! round trips of the other formats, files that are rejected, atomic writes, timings;
//! frame sequences on disk (`fxgraph::io::sequence`: pattern parsing and matching,
//! folder and wildcard inputs, `--frames`, output naming, cleanup of interrupted
//! writes) and YUV4MPEG2 streams (`fxgraph::io::y4m`: headers, frames, the Y'CbCr <->
//! RGB conversions, and a comparison against ffmpeg when it is installed).
//!
//! One test binary; this file holds the helpers its modules share.
#![cfg(feature = "gpu")]

#[path = "../common/mod.rs"]
mod common;

mod atomic_writes;
mod exr_files;
mod ffmpeg;
mod png_files;
mod rejected_files;
mod round_trips;
mod sequence_inputs;
mod sequence_outputs;
mod sequence_patterns;
mod srgb_curve;
mod timing;
mod y4m_frames;
mod y4m_headers;
mod yuv_conversion;

use common::rng::Rng;
use png::{BitDepth, ColorType};

use std::fs;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use fxgraph::io::sequence::{
    atomic_temporary_pid, parse_frames, remove_stale_temporaries, FramePattern, FrameRange,
    InputSequence, OutputPattern, Padding, SequenceSpec,
};
use fxgraph::io::y4m::{
    image_to_yuv, rgba_f32_to_yuv, rgba_u8_to_yuv, yuv_to_image, yuv_to_rgba_f32, yuv_to_rgba_u8,
    Chroma, ChromaFields, Interlace, Matrix, Range, RgbKind, Y4mError, Y4mHeader, Y4mReader,
    Y4mWriter, YuvConversion, YuvFrame,
};
use fxgraph::io::{
    load_image, load_image_from_memory, save_image, srgb, write_atomic, FileFormat, Image, IoError,
    LoadOptions, Pixels, SaveOptions,
};

// ---------------------------------------------------------------- image files

fn corpus() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/corpus"))
}

/// A corpus sub-folder, or `None` (with a message) when the corpus is not installed.
fn corpus_dir(sub: &str) -> Option<PathBuf> {
    let d = corpus().join(sub);
    if d.is_dir() {
        Some(d)
    } else {
        eprintln!("skipping: corpus folder {} is absent", d.display());
        None
    }
}

fn load(p: &Path) -> Image {
    load_image(p, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn save(p: &Path, w: u32, h: u32, px: &Pixels, bits: Option<u8>) {
    let opts = SaveOptions {
        bit_depth: bits,
        ..Default::default()
    };
    save_image(p, w, h, px, &opts).unwrap_or_else(|e| panic!("{e}"));
}

fn u8s(img: &Image) -> &[u8] {
    match &img.pixels {
        Pixels::U8(v) => v,
        Pixels::F32(_) => panic!("expected U8 pixels, got F32 ({:?})", img.source),
    }
}

fn f32s(img: &Image) -> &[f32] {
    match &img.pixels {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("expected F32 pixels, got U8 ({:?})", img.source),
    }
}

/// Deterministic RGBA bytes with every alpha value in use.
fn pattern_u8(w: u32, h: u32) -> Vec<u8> {
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            v.extend_from_slice(&[
                (x * 7 + y * 3) as u8,
                (i.wrapping_mul(2654435761) >> 24) as u8,
                (y * 11) as u8,
                (i * 13 + 5) as u8,
            ]);
        }
    }
    v
}

fn opaque(mut v: Vec<u8>) -> Vec<u8> {
    for p in v.chunks_exact_mut(4) {
        p[3] = 255;
    }
    v
}

/// Linear floats in [0, 1] covering dark and bright values, alpha varied.
fn pattern_f32(w: u32, h: u32) -> Vec<f32> {
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let fx = x as f32 / (w.max(2) - 1) as f32;
            let fy = y as f32 / (h.max(2) - 1) as f32;
            v.extend_from_slice(&[fx * fx * fx, fy, (fx + fy) * 0.5, 1.0 - fx * 0.75]);
        }
    }
    v
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn dir_names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A PNG of `data` in the given colour type and bit depth, written by the png crate.
fn write_raw_png(p: &Path, w: u32, h: u32, color: ColorType, depth: BitDepth, data: &[u8]) {
    let f = std::fs::File::create(p).unwrap();
    let mut e = png::Encoder::new(f, w, h);
    e.set_color(color);
    e.set_depth(depth);
    let mut wr = e.write_header().unwrap();
    wr.write_image_data(data).unwrap();
    wr.finish().unwrap();
}

// ---------------------------------------------------------------- sequences and y4m

fn touch(p: &Path) {
    if let Some(d) = p.parent() {
        fs::create_dir_all(d).unwrap();
    }
    fs::write(p, b"x").unwrap();
}

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// The input sequence `-i SPEC` names.
fn open_input(spec: &str) -> Result<InputSequence, IoError> {
    InputSequence::open(&SequenceSpec::parse_input(spec))
}

/// The output pattern `-o SPEC` names (its folder created).
fn open_output(spec: &str) -> Result<OutputPattern, IoError> {
    OutputPattern::new(&SequenceSpec::parse_output(spec))
}

/// A temporary folder holding an empty file (one byte) for each of `names`.
fn folder_with(names: &[&str]) -> tempfile::TempDir {
    let dir = tmp();
    for name in names {
        touch(&dir.path().join(name));
    }
    dir
}

fn numbers(seq: &InputSequence) -> Vec<u64> {
    seq.frames.iter().map(|f| f.0).collect()
}

fn names(seq: &InputSequence) -> Vec<String> {
    seq.frames
        .iter()
        .map(|f| f.1.file_name().unwrap().to_str().unwrap().to_string())
        .collect()
}

fn conv(matrix: Matrix, range: Range) -> YuvConversion {
    YuvConversion {
        matrix,
        range,
        chroma_fields: ChromaFields::Auto,
        clip: true,
        color: Default::default(),
    }
}

fn header(w: u32, h: u32, c: Chroma) -> Y4mHeader {
    Y4mHeader::new(w, h, c)
}

fn random_frame(h: &Y4mHeader, rng: &mut Rng) -> YuvFrame {
    let (yn, cn) = h.plane_bytes();
    YuvFrame {
        y: rng.bytes(yn),
        u: rng.bytes(cn),
        v: rng.bytes(cn),
        params: Vec::new(),
    }
}

fn read_err(bytes: Vec<u8>) -> Y4mError {
    match Y4mReader::new(Cursor::new(bytes), "stdin") {
        Ok(_) => panic!("header accepted"),
        Err(e) => e,
    }
}

/// The error of reading the second frame of the y4m stream `bytes` (named
/// `name`), whose header and first frame must read.
fn second_frame_error(bytes: Vec<u8>, name: &str) -> Y4mError {
    let mut r = Y4mReader::new(Cursor::new(bytes), name).unwrap();
    r.next_frame().unwrap();
    r.next_frame().unwrap_err()
}

/// (max, mean) absolute difference of the RGB channels of two RGBA byte buffers.
fn rgb_diff(a: &[u8], b: &[u8]) -> (u8, f64) {
    assert_eq!(a.len(), b.len());
    let mut max = 0u8;
    let mut sum = 0u64;
    let mut n = 0u64;
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for c in 0..3 {
            let d = pa[c].abs_diff(pb[c]);
            max = max.max(d);
            sum += d as u64;
            n += 1;
        }
    }
    (max, sum as f64 / n as f64)
}
