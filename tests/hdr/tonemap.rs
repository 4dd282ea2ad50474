//! `tonemap`'s BT.2390 EETF (fxrun's default for PQ video) against libplacebo, the
//! renderer of mpv and ffmpeg's `vf_libplacebo` (here on lavapipe), on the same
//! HDR10 clip: a real photo with mastering metadata (1,000 cd/m², MaxCLL 1,000),
//! libplacebo told the same curve (`tonemapping=bt.2390`, knee 0.5 as BT.2390
//! gives it, `tonemapping_mode=max`, no crosstalk, no peak detection, channels
//! clipped to BT.709 as its `gamut_mode=clip` does), both written as 8-bit 4:4:4
//! BT.709 and compared in RGB.
//!
//! The bar: PSNR ≥ 45 dB (measured 47.6 dB on lavapipe): what is left is the
//! rounding of two 8-bit encodes and libplacebo's 256-entry tone-mapping LUT
//! (linear interpolation in PQ), about one code; a different curve, knee, black
//! point or peak costs more than 10 dB (the default knee 1.0 of libplacebo alone
//! gives 38 dB, see below).

use super::streams::with_metadata;
use super::*;

/// PSNR (dB) of two videos in 8-bit RGB, by ffmpeg's `psnr` filter.
fn psnr(a: &Path, b: &Path) -> f64 {
    psnr_of(a, b, "[0:v]format=gbrp[a];[1:v]format=gbrp[b];[a][b]psnr")
}

/// PSNR (dB) of frame `fa` of `a` against frame `fb` of `b`, in 8-bit RGB.
fn psnr_frames(a: &Path, fa: u32, b: &Path, fb: u32) -> f64 {
    psnr_of(
        a,
        b,
        &format!(
            "[0:v]select=eq(n\\,{fa}),setpts=N,format=gbrp[a];[1:v]select=eq(n\\,{fb}),setpts=N,format=gbrp[b];[a][b]psnr"
        ),
    )
}

fn psnr_of(a: &Path, b: &Path, graph: &str) -> f64 {
    let out = std::process::Command::new("ffmpeg")
        .args(["-hide_banner", "-i"])
        .arg(a)
        .arg("-i")
        .arg(b)
        .args(["-lavfi", graph, "-f", "null", "-"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    let line = text
        .lines()
        .find(|l| l.contains("PSNR") && l.contains("average:"))
        .unwrap_or_else(|| panic!("no PSNR in {text}"));
    let v = line.split("average:").nth(1).unwrap();
    v.split_whitespace().next().unwrap().parse().unwrap()
}

/// The HDR10 test clip: corpus Desk.exr at 106x144, limited to 1,000 cd/m², PQ
/// BT.2020 4:4:4 10-bit by zimg: `photo_pq.mkv` (FFV1, no metadata) and
/// `hdr10.mkv` (lossless HEVC with the metadata of [`super::streams::MASTER`]);
/// 2 frames.
fn photo_clip(d: &Path) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/exr/Desk.exr");
    let (sw, sh, full) = read_exr(&src);
    let k = (sw as usize).div_ceil(128);
    // Even sizes, for 4:2:0.
    let (w, h) = ((sw as usize / k) & !1, (sh as usize / k) & !1);
    let mut small = vec![1f32; w * h * 4];
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut s = 0.0f64;
                for j in 0..k {
                    for i in 0..k {
                        s += full[((y * k + j) * sw as usize + x * k + i) * 4 + c] as f64;
                    }
                }
                small[(y * w + x) * 4 + c] = (s / (k * k) as f64).clamp(0.0, 1000.0 / 203.0) as f32;
            }
        }
    }
    write_exr(&d.join("photo.exr"), w as u32, h as u32, small);
    ffmpeg(&[
        "-loop",
        "1",
        "-i",
        &p(d, "photo.exr"),
        "-frames:v",
        "2",
        "-vf",
        "zscale=tin=linear:pin=709:min=gbr:t=smpte2084:p=2020:m=2020_ncl:r=tv:npl=203,format=yuv444p10le",
        "-c:v",
        "ffv1",
        &p(d, "photo_pq.mkv"),
    ]);
    with_metadata(&d.join("photo_pq.mkv"), &d.join("hdr10.mkv"));
}

/// libplacebo's BT.2390 of `input` to SDR BT.709 (8-bit 4:4:4) with knee `knee`.
fn libplacebo(input: &Path, out: &Path, knee: f64) {
    let vf = format!(
        "hwupload,libplacebo=tonemapping=bt.2390:tonemapping_param={knee}:tonemapping_mode=max:tonemapping_crosstalk=0:peak_detect=false:gamut_mode=clip:colorspace=bt709:color_primaries=bt709:color_trc=bt709:range=tv:format=yuv444p,hwdownload,format=yuv444p"
    );
    ffmpeg(&[
        "-init_hw_device",
        "vulkan",
        "-i",
        input.to_str().unwrap(),
        "-vf",
        &vf,
        "-c:v",
        "ffv1",
        out.to_str().unwrap(),
    ]);
}

#[test]
fn bt2390_matches_libplacebo() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    // The reference must exist: a missing filter fails (Debian's ffmpeg has it).
    let filters = std::process::Command::new("ffmpeg")
        .args(["-hide_banner", "-filters"])
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&filters.stdout).contains("libplacebo"),
        "this ffmpeg has no vf_libplacebo: the reference of this test"
    );
    photo_clip(d);
    libplacebo(&d.join("hdr10.mkv"), &d.join("lp.mkv"), 0.5);
    // fxrun: the HDR input makes bt2390 the default and takes the peak from MaxCLL.
    let e = run_ok(
        d,
        &[
            "tonemap",
            "--set",
            "gamut=clip",
            "-i",
            "hdr10.mkv",
            "-o",
            "ours.mkv",
            "--codec",
            "ffv1",
            "--pix-fmt",
            "yuv444p",
            "-v",
        ],
    );
    assert!(e.contains("--set tonemap.operator=bt2390"), "{e}");
    assert!(e.contains("--set tonemap.source_peak=1000"), "{e}");
    assert_eq!(
        tags(&d.join("ours.mkv")),
        ["tv", "bt709", "bt709", "bt709", "yuv444p"].map(String::from)
    );
    let db = psnr(&d.join("ours.mkv"), &d.join("lp.mkv"));
    eprintln!("BT.2390 against libplacebo: PSNR {db:.2} dB");
    assert!(db >= 45.0, "PSNR {db:.2} dB against libplacebo");
    // The bar tells curves apart: libplacebo's own default knee (1.0) is another curve.
    libplacebo(&d.join("hdr10.mkv"), &d.join("lp_knee1.mkv"), 1.0);
    let other = psnr(&d.join("ours.mkv"), &d.join("lp_knee1.mkv"));
    eprintln!("against libplacebo with knee 1.0: PSNR {other:.2} dB");
    assert!(other < db - 3.0, "{other} vs {db}");
    // The desaturating gamut mapping (the default) stays near on in-gamut content.
    run_ok(
        d,
        &[
            "tonemap",
            "-i",
            "hdr10.mkv",
            "-o",
            "desat.mkv",
            "--codec",
            "ffv1",
            "--pix-fmt",
            "yuv444p",
        ],
    );
    let desat = psnr(&d.join("desat.mkv"), &d.join("lp.mkv"));
    eprintln!("default gamut mapping (desaturate) against libplacebo's clip: PSNR {desat:.2} dB");
}

/// PQ `photo.exr` (from [`photo_clip`]) with linear 1.0 at `npl` cd/m², `frames`
/// frames, into `out` (FFV1, no metadata).
fn photo_at(d: &Path, npl: f64, frames: u32, out: &str) {
    ffmpeg(&[
        "-loop",
        "1",
        "-i",
        &p(d, "photo.exr"),
        "-frames:v",
        &frames.to_string(),
        "-vf",
        &format!("zscale=tin=linear:pin=709:min=gbr:t=smpte2084:p=2020:m=2020_ncl:r=tv:npl={npl},format=yuv444p10le"),
        "-c:v",
        "ffv1",
        "-color_trc",
        "smpte2084",
        "-color_primaries",
        "bt2020",
        "-colorspace",
        "bt2020nc",
        &p(d, out),
    ]);
}

/// Without metadata the peak is measured per frame: on the photo (peak 1,000
/// cd/m²) the output matches libplacebo told the peak by metadata (≥ 45 dB). A
/// scene cut (3 frames at a quarter of the light, then 3 at full light) restarts
/// the measurement: the first bright frame matches the bright clip tone-mapped
/// with `source_peak=1000` (≥ 45 dB), where without cut detection the smoothed
/// peak still lags (lower PSNR).
#[test]
fn the_measured_peak_follows_the_content_and_restarts_at_cuts() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    photo_clip(d);
    libplacebo(&d.join("hdr10.mkv"), &d.join("lp.mkv"), 0.5);
    let args = |input: &str, out: &str, extra: &[&str]| {
        let mut a = vec![
            "tonemap",
            "--set",
            "gamut=clip",
            "-i",
            input,
            "-o",
            out,
            "--codec",
            "ffv1",
            "--pix-fmt",
            "yuv444p",
        ];
        a.extend_from_slice(extra);
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let run = |a: Vec<String>| run_ok(d, &a.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    let e = run(args("photo_pq.mkv", "measured.mkv", &["-v"]));
    assert!(e.contains("tonemap measures each frame's peak"), "{e}");
    assert!(e.contains("tonemap runs as tonemap_video"), "{e}");
    let db = psnr(&d.join("measured.mkv"), &d.join("lp.mkv"));
    eprintln!("measured peak against libplacebo with the metadata's: PSNR {db:.2} dB");
    assert!(db >= 45.0, "{db}");
    // A cut from a quarter of the light to full light.
    photo_at(d, 203.0 / 4.0, 3, "dark.mkv");
    photo_at(d, 203.0, 3, "bright.mkv");
    ffmpeg(&[
        "-i",
        &p(d, "dark.mkv"),
        "-i",
        &p(d, "bright.mkv"),
        "-filter_complex",
        "[0:v][1:v]concat=n=2:v=1",
        "-c:v",
        "ffv1",
        "-color_trc",
        "smpte2084",
        "-color_primaries",
        "bt2020",
        "-colorspace",
        "bt2020nc",
        &p(d, "cut.mkv"),
    ]);
    run(args("cut.mkv", "cut_out.mkv", &[]));
    run(args(
        "cut.mkv",
        "lag_out.mkv",
        &["--set", "scene_low=99", "--set", "scene_high=100"],
    ));
    run(args(
        "bright.mkv",
        "ref_out.mkv",
        &["--set", "source_peak=1000"],
    ));
    let with_cut = psnr_frames(&d.join("cut_out.mkv"), 3, &d.join("ref_out.mkv"), 0);
    let without = psnr_frames(&d.join("lag_out.mkv"), 3, &d.join("ref_out.mkv"), 0);
    eprintln!("first frame after the cut: PSNR {with_cut:.2} dB with cut detection, {without:.2} dB without");
    assert!(with_cut >= 45.0, "{with_cut}");
    assert!(without < with_cut - 3.0, "{without} vs {with_cut}");
}
