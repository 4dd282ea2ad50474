//! HDR video (docs/cli.md, "HDR video"): PQ and HLG decoded and encoded against the
//! published formulas (written again here in f64: SMPTE ST 2084, ITU-R BT.2100), a
//! real HDR photo encoded to 10-bit PQ by an independent encoder (zimg, through
//! ffmpeg's `zscale`), the primaries against ITU-R BT.2087, the tags and side data
//! of every output with ffprobe, the BT.2390 tone mapping against libplacebo
//! (ffmpeg's `vf_libplacebo`), and the bad inputs of issue 27.

#[path = "../common/mod.rs"]
mod common;

mod formulas;
mod streams;
mod tonemap;

use common::cli::{exits, fxrun_in};
use common::video::{ffmpeg, have_ffmpeg};
use fxgraph::io::Pixels;
use std::path::Path;

/// An identity effect.
pub const IDENTITY: &str = "EFFECT.id = { OUT = IN }";

/// A scratch folder with `id.fx`, or `None` without a GPU or ffmpeg (in CI, where
/// FX_REQUIRE_GPU is set: a panic).
pub fn setup() -> Option<tempfile::TempDir> {
    let dir = common::gpu_scratch()?;
    if !have_ffmpeg() {
        return None;
    }
    std::fs::write(dir.path().join("id.fx"), IDENTITY).unwrap();
    Some(dir)
}

/// `d/name` as a string argument.
pub fn p(d: &Path, name: &str) -> String {
    d.join(name).to_str().unwrap().to_string()
}

/// `fxrun ARGS` in `d`, which must succeed; returns its stderr.
#[track_caller]
pub fn run_ok(d: &Path, args: &[&str]) -> String {
    let o = fxrun_in(d, args);
    exits(&o, 0)
}

/// The RGBA floats of an EXR file.
pub fn read_exr(path: &Path) -> (u32, u32, Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let img = fxgraph::io::decode_image(&bytes, path, &Default::default()).unwrap();
    match img.pixels {
        Pixels::F32(v) => (img.width, img.height, v),
        Pixels::U8(_) => panic!("{}: not float", path.display()),
    }
}

/// Write RGBA floats as a 32-bit EXR.
pub fn write_exr(path: &Path, w: u32, h: u32, v: Vec<f32>) {
    let opts = fxgraph::io::SaveOptions {
        bit_depth: Some(32),
        assume_linear: false,
    };
    fxgraph::io::save_image(path, w, h, &Pixels::F32(v), &opts).unwrap();
}

/// ffprobe's first video frame's side data (`-show_frames`), as JSON.
pub fn frame_side_data(path: &Path) -> serde_json::Value {
    let out = std::process::Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-print_format",
            "json",
            "-show_frames",
            "-read_intervals",
            "%+#1",
            "-select_streams",
            "v:0",
        ])
        .arg(path)
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["frames"][0]["side_data_list"].clone()
}

/// The colour tags of the first video stream: (range, space, transfer, primaries,
/// pixel format).
pub fn tags(path: &Path) -> [String; 5] {
    let pr = common::video::probe(path);
    let v = common::video::streams(&pr, "video")[0];
    [
        "color_range",
        "color_space",
        "color_transfer",
        "color_primaries",
        "pix_fmt",
    ]
    .map(|k| v[k].as_str().unwrap_or("").to_string())
}

/// A PQ (or `trc`) clip of testsrc2 made by zscale: 96x64, `frames` frames, 10-bit
/// 4:2:0, lossless (FFV1), tagged; every code in the legal range (SDR white at
/// `npl` cd/m²).
pub fn legal_clip(path: &Path, trc: &str, npl: u32, frames: u32) {
    let vf = format!(
        "format=gbrp,zscale=tin=709:min=gbr:pin=709:rin=pc:t={trc}:p=2020:m=2020_ncl:r=tv:npl={npl},format=yuv420p10le"
    );
    ffmpeg(&[
        "-f",
        "lavfi",
        "-i",
        &format!("testsrc2=s=96x64:r=25:d={}", frames as f64 / 25.0),
        "-vf",
        &vf,
        "-c:v",
        "ffv1",
        "-color_trc",
        trc,
        "-color_primaries",
        "bt2020",
        "-colorspace",
        "bt2020nc",
        "-color_range",
        "tv",
        path.to_str().unwrap(),
    ]);
}

/// The raw `pix_fmt` samples of every frame of a video, decoded by ffmpeg.
pub fn raw_u16(path: &Path, pix_fmt: &str) -> Vec<u16> {
    let out = path.with_extension("raw");
    ffmpeg(&[
        "-i",
        path.to_str().unwrap(),
        "-f",
        "rawvideo",
        "-pix_fmt",
        pix_fmt,
        out.to_str().unwrap(),
    ]);
    std::fs::read(&out)
        .unwrap()
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect()
}
