//! What HDR streams come out as: an identity effect keeps HDR10 codes and tags and
//! carries the mastering-display and content-light metadata over; `tonemap` writes
//! SDR BT.709 with matching tags; `--output-color` forces a signal; and the bad
//! inputs of issue 27 give a clear message or their documented behaviour.

use super::*;
use crate::common::cli::exits_with;
use crate::common::video::y4m;

/// The x265 parameters of an HDR10 clip with metadata (G, B, R, white in
/// 1/50000, luminance in 1/10000 cd/m²).
pub const MASTER: &str = "master-display=G(13250,34500)B(7500,3000)R(34000,16000)WP(15635,16450)L(10000000,50):max-cll=1000,400";

/// Re-encode `src` losslessly with libx265, its HDR metadata in SEI.
pub fn with_metadata(src: &Path, dst: &Path) {
    ffmpeg(&[
        "-i",
        src.to_str().unwrap(),
        "-c:v",
        "libx265",
        "-x265-params",
        &format!("log-level=error:lossless=1:hdr10=1:{MASTER}"),
        "-color_trc",
        "smpte2084",
        "-color_primaries",
        "bt2020",
        "-colorspace",
        "bt2020nc",
        "-color_range",
        "tv",
        dst.to_str().unwrap(),
    ]);
}

/// An identity effect on an HDR10 clip (lossless FFV1 out) changes no luma code
/// by more than 2 and keeps the tags; with the default encoder (libx265) the
/// mastering display and MaxCLL / MaxFALL of the input are in the output.
#[test]
fn hdr10_through_an_identity_effect_stays_hdr10() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    legal_clip(&d.join("pq.mkv"), "smpte2084", 1000, 3);
    run_ok(
        d,
        &["id.fx", "-i", "pq.mkv", "--codec", "ffv1", "-o", "id.mkv"],
    );
    let (a, b) = (
        raw_u16(&d.join("pq.mkv"), "yuv420p10le"),
        raw_u16(&d.join("id.mkv"), "yuv420p10le"),
    );
    assert_eq!(a.len(), b.len());
    let n = 96 * 64;
    let frame = n * 3 / 2;
    let mut worst = 0;
    for f in 0..a.len() / frame {
        for i in 0..n {
            worst = worst.max((a[f * frame + i] as i32 - b[f * frame + i] as i32).abs());
        }
    }
    eprintln!("identity: largest luma code change {worst}");
    assert!(worst <= 2, "{worst}");
    assert_eq!(
        tags(&d.join("id.mkv")),
        ["tv", "bt2020nc", "smpte2084", "bt2020", "yuv420p10le"].map(String::from)
    );
    // Metadata: through the default encoder.
    with_metadata(&d.join("pq.mkv"), &d.join("meta.mkv"));
    run_ok(d, &["id.fx", "-i", "meta.mkv", "-o", "meta_out.mkv"]);
    let sd = frame_side_data(&d.join("meta_out.mkv"));
    let text = sd.to_string();
    for needle in [
        "\"max_content\":1000",
        "\"max_average\":400",
        "\"max_luminance\":\"10000000/10000\"",
        "\"min_luminance\":\"50/10000\"",
        "\"red_x\":\"34000/50000\"",
    ] {
        assert!(text.contains(needle), "no {needle} in {text}");
    }
    assert_eq!(tags(&d.join("meta_out.mkv"))[2], "smpte2084");
}

/// `tonemap` on HDR10 writes SDR: BT.709 primaries, matrix and transfer, 8 bits;
/// `--output-color hdr10` forces HDR10 after it, `hlg` HLG; `--output-color sdr`
/// without tonemap writes SDR tags too.
#[test]
fn outputs_are_tagged_with_what_their_pixels_are() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    legal_clip(&d.join("pq.mkv"), "smpte2084", 1000, 2);
    run_ok(d, &["tonemap", "-i", "pq.mkv", "-o", "sdr.mp4"]);
    assert_eq!(
        tags(&d.join("sdr.mp4")),
        ["tv", "bt709", "bt709", "bt709", "yuv420p"].map(String::from)
    );
    run_ok(
        d,
        &[
            "id.fx",
            "-i",
            "pq.mkv",
            "-o",
            "hlg.mkv",
            "--output-color",
            "hlg",
        ],
    );
    assert_eq!(
        tags(&d.join("hlg.mkv")),
        ["tv", "bt2020nc", "arib-std-b67", "bt2020", "yuv420p10le"].map(String::from)
    );
    run_ok(
        d,
        &[
            "id.fx",
            "-i",
            "pq.mkv",
            "-o",
            "forced.mkv",
            "--output-color",
            "sdr",
        ],
    );
    assert_eq!(
        tags(&d.join("forced.mkv"))[1..4],
        ["bt709", "bt709", "bt709"].map(String::from)
    );
    // A y4m input told it is PQ, written as video: tagged HDR10.
    let (w, h) = (16usize, 16usize);
    let grey = vec![600u16; w * h];
    let chroma = vec![512u16; w * h / 4];
    let bytes = y4m(
        &format!("W{w} H{h} F25:1 Ip C420p10"),
        10,
        &[vec![grey, chroma.clone(), chroma]],
    );
    std::fs::write(d.join("g.y4m"), bytes).unwrap();
    run_ok(
        d,
        &[
            "id.fx",
            "--input-color",
            "transfer=pq",
            "-i",
            "g.y4m",
            "-o",
            "g.mkv",
        ],
    );
    assert_eq!(
        tags(&d.join("g.mkv"))[1..4],
        ["bt2020nc", "smpte2084", "bt2020"].map(String::from)
    );
}

/// The bad inputs of issue 27: an unknown transfer is refused (exit 1, what to
/// do); tags that contradict each other warn; a 10-bit y4m without
/// `--input-color` warns; a 12-bit HLG stream is decoded at 12 bits; NaN and
/// infinities going to PQ are reported once and written as black and peak.
#[test]
fn bad_hdr_inputs_say_what_happens() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    legal_clip(&d.join("pq.mkv"), "smpte2084", 1000, 1);
    // Unknown transfer.
    ffmpeg(&[
        "-i",
        &p(d, "pq.mkv"),
        "-c",
        "copy",
        "-color_trc",
        "log100",
        &p(d, "log.mkv"),
    ]);
    let o = fxrun_in(d, &["id.fx", "-i", "log.mkv", "-o", "x.mkv"]);
    exits_with(&o, 1, &["log.mkv", "transfer `log100`", "--input-color"]);
    // The colour options where they would do nothing.
    let o = fxrun_in(
        d,
        &[
            "id.fx",
            "-i",
            "pq.mkv",
            "-o",
            "f/%04d.exr",
            "--output-color",
            "hdr10",
        ],
    );
    exits_with(&o, 1, &["--output-color is for y4m and video outputs"]);
    let o = fxrun_in(
        d,
        &[
            "id.fx",
            "-i",
            "pq.mkv",
            "-o",
            "x.mkv",
            "--output-color",
            "hdr",
        ],
    );
    exits_with(&o, 1, &["--output-color", "expected hdr10, hlg or sdr"]);
    let o = fxrun_in(
        d,
        &[
            "id.fx",
            "-i",
            "pq.mkv",
            "-o",
            "x.mkv",
            "--input-color",
            "transfer=log",
        ],
    );
    exits_with(&o, 1, &["--input-color transfer=log", "unknown value"]);
    // Contradicting tags: PQ with BT.709 primaries.
    ffmpeg(&[
        "-i",
        &p(d, "pq.mkv"),
        "-c",
        "copy",
        "-color_primaries",
        "bt709",
        &p(d, "odd.mkv"),
    ]);
    let e = run_ok(d, &["id.fx", "-i", "odd.mkv", "-o", "odd/%04d.exr"]);
    assert!(e.contains("contradict"), "{e}");
    // A 10-bit y4m says nothing of its colour.
    let (w, h) = (16usize, 16usize);
    let grey = vec![600u16; w * h];
    let chroma = vec![512u16; w * h / 4];
    let bytes = y4m(
        &format!("W{w} H{h} F25:1 Ip C420p10"),
        10,
        &[vec![grey, chroma.clone(), chroma]],
    );
    std::fs::write(d.join("g.y4m"), bytes).unwrap();
    let e = run_ok(d, &["id.fx", "-i", "g.y4m", "-o", "g/%04d.exr"]);
    assert!(e.contains("--input-color transfer=pq"), "{e}");
    // 12-bit HLG: decoded at 12 bits (code 2048 of 12 bits = signal 0.5 → a
    // display light of 1000 (1/12)^1.2 / 203 on the working scale).
    let grey = vec![(256.0 + 3504.0 * 0.5f64) as u16; w * h];
    let chroma = vec![2048u16; w * h];
    let bytes = y4m(
        &format!("W{w} H{h} F25:1 Ip C444p12"),
        12,
        &[vec![grey, chroma.clone(), chroma]],
    );
    std::fs::write(d.join("hlg12.y4m"), bytes).unwrap();
    run_ok(
        d,
        &[
            "id.fx",
            "--input-color",
            "transfer=hlg",
            "-i",
            "hlg12.y4m",
            "-o",
            "h/%04d.exr",
            "--bit-depth",
            "32",
        ],
    );
    let (_, _, v) = read_exr(&d.join("h/0000.exr"));
    let want = 1000.0 * (1.0f64 / 12.0).powf(1.2) / 203.0;
    assert!(
        (v[0] as f64 - want).abs() / want < 1e-3,
        "{} vs {want}",
        v[0]
    );
    // NaN and infinities to PQ.
    let mut px = vec![0.5f32; 16 * 16 * 4];
    px[0] = f32::NAN;
    px[1] = f32::NAN;
    px[2] = f32::NAN;
    px[4] = f32::INFINITY;
    px[5] = f32::INFINITY;
    px[6] = f32::INFINITY;
    std::fs::create_dir_all(d.join("nan")).unwrap();
    write_exr(&d.join("nan/0000.exr"), 16, 16, px);
    let e = run_ok(
        d,
        &[
            "id.fx",
            "-i",
            "nan/%04d.exr",
            "-o",
            "nan.y4m",
            "--output-color",
            "hdr10",
        ],
    );
    assert!(
        e.contains("NaN or infinite") && e.contains("reported once"),
        "{e}"
    );
    let bytes = std::fs::read(d.join("nan.y4m")).unwrap();
    let (_, frames) =
        crate::common::video::read_y4m(&bytes, 10, crate::common::video::samples_420(16, 16));
    // NaN: black (code 64); +Inf: PQ's peak (940); rounding of 4:2:0 aside.
    assert_eq!(frames[0][0], 64, "NaN pixel");
    assert_eq!(frames[0][1], 940, "+Inf pixel");
}
