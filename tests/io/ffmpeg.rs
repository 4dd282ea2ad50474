//! Interoperability with ffmpeg (skipped when ffmpeg is absent, except in CI): an interlaced MPEG-2
//! clip decoded like ffmpeg does, and y4m read from a pipe.

use super::*;

/// ffmpeg is there (in CI, where FX_REQUIRE_GPU is set, its absence fails).
fn ffmpeg() -> bool {
    common::video::have_ffmpeg()
}

fn corpus_file(rel: &str) -> Option<PathBuf> {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/corpus")).join(rel);
    if p.is_file() {
        Some(p)
    } else {
        eprintln!("skipping: corpus file {} is absent", p.display());
        None
    }
}

fn run(cmd: &mut Command) -> Vec<u8> {
    let out = cmd.output().expect("run ffmpeg");
    assert!(
        out.status.success(),
        "{cmd:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

#[test]
fn ffmpeg_interlaced_mpeg2_matches_ffmpeg_rgb() {
    if !ffmpeg() {
        return;
    }
    let Some(ts) = corpus_file("interlaced/mpeg2_field_encoding.ts") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let y4m = dir.path().join("clip.y4m");
    let bytes = run(Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(&ts)
        .args(["-frames:v", "3", "-f", "yuv4mpegpipe", "-"]));
    fs::write(&y4m, &bytes).unwrap();

    let mut r = Y4mReader::new(Cursor::new(&bytes), "clip.y4m").unwrap();
    let hd = r.header().clone();
    eprintln!("ffmpeg header: {}", hd.to_line().trim_end());
    assert_eq!((hd.width, hd.height), (720, 576));
    assert!(hd.interlace.is_interlaced(), "{:?}", hd.interlace);
    assert_eq!(hd.interlace, Interlace::BottomFieldFirst);
    assert!(hd.colorspace.is_420());
    let frames: Vec<YuvFrame> = (&mut r).map(Result::unwrap).collect();
    assert_eq!(frames.len(), 3);

    // ffmpeg's own RGB of the first frame (swscale defaults: BT.601 for untagged video,
    // limited range from XCOLORRANGE, its fast unscaled converter).
    let rgb = run(Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(&y4m)
        .args(["-frames:v", "1", "-pix_fmt", "rgb24", "-f", "rawvideo", "-"]));
    assert_eq!(rgb.len(), 720 * 576 * 3);
    let theirs: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let c = YuvConversion::for_header(&hd);
    assert_eq!((c.matrix, c.range), (Matrix::Bt601, Range::Limited));
    let mut ours = vec![0u8; theirs.len()];
    yuv_to_rgba_u8(&frames[0], &hd, &c, &mut ours).unwrap();
    let (max, mean) = rgb_diff(&ours, &theirs);
    let progressive = YuvConversion {
        chroma_fields: ChromaFields::Progressive,
        ..c
    };
    let mut ours_p = vec![0u8; theirs.len()];
    yuv_to_rgba_u8(&frames[0], &hd, &progressive, &mut ours_p).unwrap();
    let (max_p, mean_p) = rgb_diff(&ours_p, &theirs);
    eprintln!(
        "frame 0 vs ffmpeg rgb24: per-field chroma mean {mean:.3} max {max}; progressive chroma mean {mean_p:.3} max {max_p}"
    );
    assert!(mean < 2.0, "mean abs diff {mean}");
    assert!(mean_p < 2.0, "mean abs diff {mean_p}");

    // ffmpeg's accurate conversions: bilinear chroma, per field (`interl=1`) or per
    // frame. Ours should agree closely with the matching one.
    let ffmpeg_rgb = |input: &Path, vf: &str| -> Vec<u8> {
        let rgb = run(Command::new("ffmpeg")
            .args(["-v", "error", "-nostdin", "-i"])
            .arg(input)
            .args([
                "-frames:v",
                "1",
                "-vf",
                vf,
                "-pix_fmt",
                "rgb24",
                "-f",
                "rawvideo",
                "-",
            ]));
        rgb.chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect()
    };
    let flags = "flags=bilinear+full_chroma_int+full_chroma_inp+accurate_rnd";
    let fields = ffmpeg_rgb(&y4m, &format!("scale=interl=1:{flags}"));
    let frame = ffmpeg_rgb(&y4m, &format!("scale=interl=0:{flags}"));
    let (max_f, mean_f) = rgb_diff(&ours, &fields);
    let (max_pf, mean_pf) = rgb_diff(&ours_p, &frame);
    eprintln!(
        "vs ffmpeg bilinear: per-field chroma vs interl=1 mean {mean_f:.3} max {max_f}; progressive chroma vs interl=0 mean {mean_pf:.3} max {max_pf}"
    );
    assert!(mean_f < 0.5, "mean abs diff {mean_f}");
    assert!(mean_pf < 0.6, "mean abs diff {mean_pf}");

    // ffmpeg reads what we write: copy the stream through our writer, let ffmpeg decode it
    // to raw planes, and compare.
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "ours.y4m").unwrap();
    for f in &frames {
        w.write_frame(f).unwrap();
    }
    let ours_y4m = dir.path().join("ours.y4m");
    fs::write(&ours_y4m, w.into_inner().unwrap()).unwrap();
    let raw = run(Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(&ours_y4m)
        .args(["-f", "rawvideo", "-pix_fmt", "yuv420p", "-"]));
    let planes: Vec<u8> = frames
        .iter()
        .flat_map(|f| [f.y.as_slice(), &f.u, &f.v].concat())
        .collect();
    assert!(raw == planes, "ffmpeg read back different planes");

    // And a stream we write from RGB converts back by ffmpeg to nearly the same RGB.
    let img = yuv_to_image(&frames[0], &hd, &c, RgbKind::LinearF32).unwrap();
    let f2 = image_to_yuv(&img, &hd, &c).unwrap();
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "ours2.y4m").unwrap();
    w.write_frame(&f2).unwrap();
    let p2 = dir.path().join("ours2.y4m");
    fs::write(&p2, w.into_inner().unwrap()).unwrap();
    let theirs2 = ffmpeg_rgb(&p2, &format!("scale=interl=1:{flags}"));
    let (max2, mean2) = rgb_diff(&ours, &theirs2);
    eprintln!(
        "our RGB -> our y4m -> ffmpeg rgb24 (interl=1) vs our RGB: mean {mean2:.3} max {max2}"
    );
    assert!(mean2 < 1.0, "mean abs diff {mean2}");
}

#[test]
fn reading_from_a_pipe() {
    if !ffmpeg() {
        return;
    }
    // ffmpeg writes a synthetic 4:2:2 clip to a pipe; read it incrementally.
    let mut child = Command::new("ffmpeg")
        .args([
            "-v",
            "error",
            "-nostdin",
            "-f",
            "lavfi",
            "-i",
            "testsrc2=size=320x240:rate=25",
            "-frames:v",
            "5",
            "-pix_fmt",
            "yuv422p",
            "-f",
            "yuv4mpegpipe",
            "-",
        ])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("spawn ffmpeg");
    let stdout = child.stdout.take().unwrap();
    let mut r = Y4mReader::new(stdout, "pipe").unwrap();
    assert_eq!(r.header().colorspace, Chroma::C422);
    assert_eq!(r.header().fps, (25, 1));
    let mut n = 0;
    while let Some(f) = r.next_frame().unwrap() {
        assert_eq!(f.y.len(), 320 * 240);
        assert_eq!(f.u.len(), 160 * 240);
        n += 1;
    }
    assert_eq!(n, 5);
    assert!(child.wait().unwrap().success());
}
