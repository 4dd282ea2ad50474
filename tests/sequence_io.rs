//! Frame sequences on disk (`fxgraph::io::sequence`) and YUV4MPEG2 streams
//! (`fxgraph::io::y4m`): pattern parsing and matching, folder and wildcard inputs,
//! `--frames`, output naming, cleanup of interrupted writes, y4m reading and writing, and
//! the Y'CbCr <-> RGB conversions (with a comparison against ffmpeg when it is installed).
#![cfg(feature = "gpu")]

mod common;

use common::rng::Rng;

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
use fxgraph::io::{srgb, write_atomic, IoError, Pixels};

// ---------------------------------------------------------------------------------------
// helpers
// ---------------------------------------------------------------------------------------

fn touch(p: &Path) {
    if let Some(d) = p.parent() {
        fs::create_dir_all(d).unwrap();
    }
    fs::write(p, b"x").unwrap();
}

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
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

// ---------------------------------------------------------------------------------------
// patterns and sequence specs
// ---------------------------------------------------------------------------------------

#[test]
fn pattern_parsing_and_formatting() {
    let p = FramePattern::parse("out/%04d.png").unwrap();
    assert_eq!(p.format(7), PathBuf::from("out/0007.png"));
    assert_eq!(p.format(123456), PathBuf::from("out/123456.png"));
    assert_eq!(p.dir(), Path::new("out/"));
    assert_eq!(p.padding(), Padding::Zeros(4));

    let p = FramePattern::parse("%d.png").unwrap();
    assert_eq!(p.format(7), PathBuf::from("7.png"));
    assert_eq!(p.dir(), Path::new("."));
    assert_eq!(p.padding(), Padding::None);

    let p = FramePattern::parse("f%4d.tif").unwrap();
    assert_eq!(p.format(7), PathBuf::from("f   7.tif"));
    assert_eq!(p.padding(), Padding::Spaces(4));

    // `%%` is a literal %, in the folder and in the name.
    let p = FramePattern::parse("a%%dir/100%%_%03d.png").unwrap();
    assert_eq!(p.format(5), PathBuf::from("a%dir/100%_005.png"));
    assert_eq!(p.dir(), Path::new("a%dir/"));

    for (bad, why) in [
        ("frame.png", "no frame number conversion"),
        ("%d_%04d.png", "more than one"),
        ("%s.png", "unsupported conversion `%s`"),
        ("%-4d.png", "unsupported conversion `%-`"),
        ("f%d/x.png", "file name, not in a folder"),
        ("frame%", "incomplete conversion"),
        ("f%04", "incomplete conversion"),
        ("%099d.png", "too large"),
    ] {
        let e = FramePattern::parse(bad).unwrap_err();
        assert!(e.contains(why), "{bad}: {e}");
    }
}

#[test]
fn pattern_matching_is_exact() {
    let p = FramePattern::parse("d/img_%04d.png").unwrap();
    assert_eq!(p.match_file_name("img_0007.png"), Some(7));
    assert_eq!(p.match_file_name("img_0000.png"), Some(0));
    assert_eq!(p.match_file_name("img_12345.png"), Some(12345));
    assert_eq!(p.match_file_name("img_7.png"), None);
    assert_eq!(p.match_file_name("img_00007.png"), None);
    assert_eq!(p.match_file_name("img_012345.png"), None);
    assert_eq!(p.match_file_name("img_00a7.png"), None);
    assert_eq!(p.match_file_name("img_0007.jpg"), None);
    assert_eq!(p.match_file_name("img_.png"), None);
    assert_eq!(p.match_file_name("xmg_0007.png"), None);
    assert_eq!(p.match_file_name("img_-007.png"), None);

    let p = FramePattern::parse("%d.png").unwrap();
    assert_eq!(p.match_file_name("0.png"), Some(0));
    assert_eq!(p.match_file_name("42.png"), Some(42));
    assert_eq!(p.match_file_name("042.png"), None);
    assert_eq!(p.match_file_name("99999999999999999999999.png"), None);

    let p = FramePattern::parse("%3d.png").unwrap();
    assert_eq!(p.match_file_name("  7.png"), Some(7));
    assert_eq!(p.match_file_name("007.png"), None);
    assert_eq!(p.match_file_name("1234.png"), Some(1234));

    let p = FramePattern::parse("50%%_%02d.png").unwrap();
    assert_eq!(p.match_file_name("50%_03.png"), Some(3));
    assert_eq!(p.match_file_name("50%%_03.png"), None);
}

#[test]
fn arguments_are_classified() {
    let dir = tempfile::tempdir().unwrap();
    let d = s(dir.path());
    touch(&dir.path().join("still.png"));
    touch(&dir.path().join("odd[1].png"));

    assert_eq!(SequenceSpec::parse_input("-"), SequenceSpec::Stdin);
    assert_eq!(SequenceSpec::parse_output("-"), SequenceSpec::Stdout);
    assert_eq!(
        SequenceSpec::parse_input("in/%04d.png"),
        SequenceSpec::Pattern {
            pattern: "in/%04d.png".into()
        }
    );
    assert_eq!(
        SequenceSpec::parse_output("out/%d.exr"),
        SequenceSpec::Pattern {
            pattern: "out/%d.exr".into()
        }
    );
    // A malformed pattern is still a pattern, so that opening it explains the problem.
    assert!(matches!(
        SequenceSpec::parse_input("in/%d_%d.png"),
        SequenceSpec::Pattern { .. }
    ));
    assert_eq!(
        SequenceSpec::parse_input(&d),
        SequenceSpec::Dir(dir.path().to_path_buf())
    );
    assert_eq!(
        SequenceSpec::parse_output(&d),
        SequenceSpec::Dir(dir.path().to_path_buf())
    );
    assert_eq!(
        SequenceSpec::parse_output("not/yet/there/"),
        SequenceSpec::Dir("not/yet/there/".into())
    );
    let glob = format!("{d}/*.png");
    assert_eq!(
        SequenceSpec::parse_input(&glob),
        SequenceSpec::Glob(glob.clone())
    );
    // Wildcards are literal in outputs, and an existing file with `[` is a file.
    assert_eq!(
        SequenceSpec::parse_output(&glob),
        SequenceSpec::Single(glob.clone().into())
    );
    let odd = format!("{d}/odd[1].png");
    assert_eq!(
        SequenceSpec::parse_input(&odd),
        SequenceSpec::Single(odd.clone().into())
    );
    let still = format!("{d}/still.png");
    assert_eq!(
        SequenceSpec::parse_input(&still),
        SequenceSpec::Single(still.clone().into())
    );
    assert!(!SequenceSpec::parse_input(&still).is_sequence());
    // A `%` without a conversion is literal.
    assert_eq!(
        SequenceSpec::parse_input("50%.png"),
        SequenceSpec::Single("50%.png".into())
    );
    assert_eq!(
        SequenceSpec::parse_input("a%%d.png"),
        SequenceSpec::Single("a%%d.png".into())
    );
}

// ---------------------------------------------------------------------------------------
// input sequences
// ---------------------------------------------------------------------------------------

#[test]
fn pattern_input_with_gaps_not_starting_at_zero() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for n in [98, 99, 100, 103, 110] {
        touch(&d.join(format!("f_{n:04}.png")));
    }
    // Not matching: other padding, other extension, other prefix, temporaries, folders.
    for name in [
        "f_98.png",
        "f_00099.png",
        "f_0101.jpg",
        "g_0102.png",
        ".f_0104.png.fxtmp-1-1",
        "f_0105.png.bak",
    ] {
        touch(&d.join(name));
    }
    fs::create_dir(d.join("f_0106.png")).unwrap();

    let pattern = format!("{}/f_%04d.png", s(d));
    let seq = InputSequence::open(&SequenceSpec::parse_input(&pattern)).unwrap();
    assert_eq!(numbers(&seq), [98, 99, 100, 103, 110]);
    assert_eq!(seq.frames[0].1, d.join("f_0098.png"));
    assert_eq!(seq.first_number(), Some(98));
    assert_eq!(seq.last_number(), Some(110));
    assert_eq!(seq.path_of(103), Some(d.join("f_0103.png").as_path()));
    assert_eq!(seq.path_of(101), None);
    assert_eq!(
        seq.gaps(),
        [
            FrameRange {
                start: 101,
                end: 102
            },
            FrameRange {
                start: 104,
                end: 109
            }
        ]
    );

    // `%d` matches the unpadded name only.
    let seq =
        InputSequence::open(&SequenceSpec::parse_input(&format!("{}/f_%d.png", s(d)))).unwrap();
    assert_eq!(numbers(&seq), [98]);
    assert!(seq.gaps().is_empty());
}

#[test]
fn pattern_without_matches_or_folder_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    touch(&dir.path().join("a_1.png"));
    let pattern = format!("{}/b_%04d.png", s(dir.path()));
    let e = InputSequence::open(&SequenceSpec::parse_input(&pattern)).unwrap_err();
    assert!(
        matches!(&e, IoError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound)
    );
    let msg = e.to_string();
    assert!(
        msg.contains("b_%04d.png") && msg.contains("no files match"),
        "{msg}"
    );

    let pattern = format!("{}/missing/%04d.png", s(dir.path()));
    let e = InputSequence::open(&SequenceSpec::parse_input(&pattern)).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e}");

    let e = InputSequence::open(&SequenceSpec::parse_input("x/%d_%d.png")).unwrap_err();
    assert!(e.is_input_error(), "{e}");
    assert!(e.to_string().contains("more than one"), "{e}");

    let e = InputSequence::open(&SequenceSpec::Stdin).unwrap_err();
    assert!(e.is_input_error(), "{e}");
}

#[test]
fn folder_input_is_sorted_by_the_numbers_in_the_names() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for name in [
        "f10.png",
        "f2.jpg",
        "f1.png",
        "notes.txt",
        ".f3.png",
        "f4.png.fxtmp",
    ] {
        touch(&d.join(name));
    }
    fs::create_dir(d.join("f5.png")).unwrap();
    let seq = InputSequence::open(&SequenceSpec::parse_input(&s(d))).unwrap();
    assert_eq!(numbers(&seq), [1, 2, 10]);
    assert_eq!(names(&seq), ["f1.png", "f2.jpg", "f10.png"]);
    assert_eq!(seq.gaps(), [FrameRange { start: 3, end: 9 }]);
}

#[test]
fn folder_input_without_distinct_numbers_is_sorted_by_name() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["b.png", "a.png", "c.exr"] {
        touch(&dir.path().join(name));
    }
    let seq = InputSequence::open(&SequenceSpec::Dir(dir.path().into())).unwrap();
    assert_eq!(numbers(&seq), [0, 1, 2]);
    assert_eq!(names(&seq), ["a.png", "b.png", "c.exr"]);

    let dir = tempfile::tempdir().unwrap();
    for name in ["cam1_7.png", "cam2_7.png", "cam1_8.png"] {
        touch(&dir.path().join(name));
    }
    let seq = InputSequence::open(&SequenceSpec::Dir(dir.path().into())).unwrap();
    assert_eq!(numbers(&seq), [0, 1, 2]);
    assert_eq!(names(&seq), ["cam1_7.png", "cam1_8.png", "cam2_7.png"]);

    let empty = tempfile::tempdir().unwrap();
    touch(&empty.path().join("readme.txt"));
    let e = InputSequence::open(&SequenceSpec::Dir(empty.path().into())).unwrap_err();
    assert!(e.to_string().contains("no image files"), "{e}");
}

#[test]
fn glob_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for name in [
        "shot_001.png",
        "shot_002.png",
        "shot_010.png",
        "shot_abc.png",
        "shot_003.jpg",
        "take_004.png",
        ".shot_005.png",
    ] {
        touch(&d.join(name));
    }
    let open = |g: &str| InputSequence::open(&SequenceSpec::parse_input(&format!("{}/{g}", s(d))));

    let seq = open("shot_*.png").unwrap();
    // "shot_abc.png" has no number, so the files are numbered by name order.
    assert_eq!(
        names(&seq),
        [
            "shot_001.png",
            "shot_002.png",
            "shot_010.png",
            "shot_abc.png"
        ]
    );
    assert_eq!(numbers(&seq), [0, 1, 2, 3]);

    let seq = open("shot_[0-9][0-9][0-9].*").unwrap();
    assert_eq!(numbers(&seq), [1, 2, 3, 10]);
    assert_eq!(seq.frames[2].1, d.join("shot_003.jpg"));

    let seq = open("shot_00?.png").unwrap();
    assert_eq!(numbers(&seq), [1, 2]);

    let seq = open("[st][ha]*_00[!1].png").unwrap();
    assert_eq!(names(&seq), ["shot_002.png", "take_004.png"]);

    let seq = open(".shot_*").unwrap();
    assert_eq!(numbers(&seq), [5]);

    let e = open("nothing_*.png").unwrap_err();
    assert!(e.to_string().contains("no files match"), "{e}");
    let e = open("shot_[0-9.png").unwrap_err();
    assert!(e.to_string().contains("unclosed"), "{e}");
    let e = InputSequence::open(&SequenceSpec::Glob(format!("{}/*/x_*.png", s(d)))).unwrap_err();
    assert!(
        e.to_string().contains("only supported in the file name"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------
// --frames
// ---------------------------------------------------------------------------------------

#[test]
fn frames_argument_parsing() {
    let r = |a, b| FrameRange { start: a, end: b };
    assert_eq!(parse_frames("10..20"), Ok(r(10, 20)));
    assert_eq!(parse_frames("10..=20"), Ok(r(10, 20)));
    assert_eq!(parse_frames(" 3..4 "), Ok(r(3, 4)));
    assert_eq!(parse_frames("10..10"), Ok(r(10, 10)));
    assert_eq!(parse_frames("10.."), Ok(r(10, u64::MAX)));
    assert_eq!(parse_frames("..20"), Ok(r(0, 20)));
    assert_eq!(parse_frames(".."), Ok(FrameRange::ALL));
    assert_eq!(parse_frames("7"), Ok(r(7, 7)));
    assert_eq!(parse_frames("10..20").unwrap().len(), 11);
    assert_eq!(parse_frames("10..").unwrap().to_string(), "10..");
    assert_eq!(parse_frames("..20").unwrap().to_string(), "..20");
    assert_eq!(parse_frames("5..9").unwrap().to_string(), "5..9");

    for (bad, why) in [
        ("", "empty"),
        ("abc", "invalid frame number `abc`"),
        ("20..10", "ends before it starts"),
        ("1..2..3", "invalid frame range"),
        ("1...3", "invalid frame range"),
        ("-1..5", "invalid start `-1`"),
        ("1..x", "invalid end `x`"),
        ("a..b", "invalid start"),
        ("99999999999999999999999..", "too large"),
        ("1.5..3", "invalid frame range"),
    ] {
        let e = parse_frames(bad).unwrap_err();
        assert!(e.contains(why), "{bad:?}: {e}");
    }
}

#[test]
fn slicing_a_sequence_resolves_open_ends() {
    let seq = InputSequence {
        frames: [98u64, 99, 100, 103, 110]
            .iter()
            .map(|&n| (n, PathBuf::from(format!("{n}.png"))))
            .collect(),
    };
    let sl = |a: &str| seq.slice(parse_frames(a).unwrap());
    assert_eq!(numbers(&sl("100..105").unwrap()), [100, 103]);
    assert_eq!(numbers(&sl("..99").unwrap()), [98, 99]);
    assert_eq!(numbers(&sl("103..").unwrap()), [103, 110]);
    assert_eq!(numbers(&sl("..").unwrap()), [98, 99, 100, 103, 110]);
    assert_eq!(numbers(&sl("0..1000").unwrap()), [98, 99, 100, 103, 110]);
    let e = sl("101..102").unwrap_err();
    assert_eq!(
        e,
        "--frames 101..102 selects no frames (the sequence has frames 98 to 110)"
    );
    assert!(sl("200..").unwrap_err().contains("200.."));
    assert_eq!(
        seq.resolve(parse_frames("..").unwrap()),
        Some(FrameRange {
            start: 98,
            end: 110
        })
    );
    assert_eq!(
        seq.resolve(parse_frames("99..").unwrap()),
        Some(FrameRange {
            start: 99,
            end: 110
        })
    );
    assert_eq!(seq.resolve(parse_frames("104..109").unwrap()), None);
}

// ---------------------------------------------------------------------------------------
// outputs and cleanup
// ---------------------------------------------------------------------------------------

#[test]
fn output_naming_and_skip_existing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();

    let out = OutputPattern::new(&SequenceSpec::parse_output(&format!(
        "{}/a/b/f_%05d.png",
        s(d)
    )))
    .unwrap();
    assert!(d.join("a/b").is_dir(), "the output folder is created");
    assert_eq!(out.path_for(42), d.join("a/b/f_00042.png"));
    assert_eq!(out.dir(), d.join("a/b/").as_path());
    assert!(!out.exists(42));
    touch(&out.path_for(42));
    assert!(out.exists(42));
    assert!(!out.exists(43));

    let out =
        OutputPattern::new(&SequenceSpec::parse_output(&format!("{}/frames/", s(d)))).unwrap();
    assert!(d.join("frames").is_dir());
    assert_eq!(out.path_for(7), d.join("frames/000007.png"));
    assert_eq!(out.path_for(1234567), d.join("frames/1234567.png"));

    let out = OutputPattern::in_dir(&d.join("exr"), "exr").unwrap();
    assert_eq!(out.path_for(3), d.join("exr/000003.exr"));

    // Existing folder given without a trailing slash.
    let out = OutputPattern::new(&SequenceSpec::parse_output(&s(&d.join("exr")))).unwrap();
    assert_eq!(out.path_for(3), d.join("exr/000003.png"));

    let e = OutputPattern::new(&SequenceSpec::parse_output(&format!("{}/x/%04d.xyz", s(d))))
        .unwrap_err();
    assert!(
        e.is_input_error() && e.to_string().contains("extension"),
        "{e}"
    );
    let e = OutputPattern::new(&SequenceSpec::parse_output("single.png")).unwrap_err();
    assert!(e.to_string().contains("pattern such as"), "{e}");
    let e = OutputPattern::new(&SequenceSpec::Stdout).unwrap_err();
    assert!(e.is_input_error(), "{e}");
}

#[test]
fn stale_temporaries_are_removed_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let own = std::process::id();
    // A pid above Linux's maximum (2^22): never a running process.
    let dead = 4_000_000_000u32;
    let stale = [
        format!(".out_0001.png.fxtmp-{dead}-0"),
        format!(".x.fxtmp-{}-17", dead + 1),
    ];
    let kept = [
        "out_0001.png".to_string(),
        format!(".out_0002.png.fxtmp-{own}-3"), // our own, in flight
        format!("out_0003.png.fxtmp-{dead}-0"), // not hidden
        format!(".out_0004.png.fxtmp-{dead}-x"),
        format!(".out_0005.png.fxtmp-{dead}"),
        format!(".out_0006.png.fxtmp-{dead}-1.png"),
        format!("..fxtmp-{dead}-1"),
        ".hidden".to_string(),
    ];
    for n in stale.iter().chain(&kept) {
        touch(&d.join(n));
    }
    fs::create_dir(d.join(format!(".sub.fxtmp-{dead}-9"))).unwrap();
    touch(&d.join(format!("sub/.y.fxtmp-{dead}-0")));

    let removed = remove_stale_temporaries(d).unwrap();
    let mut want: Vec<PathBuf> = stale.iter().map(|n| d.join(n)).collect();
    want.sort();
    assert_eq!(removed, want);
    for n in &kept {
        assert!(d.join(n).exists(), "{n} was removed");
    }
    assert!(d.join(format!(".sub.fxtmp-{dead}-9")).is_dir());
    assert!(d.join(format!("sub/.y.fxtmp-{dead}-0")).exists());
    assert!(remove_stale_temporaries(d).unwrap().is_empty());

    // The names `write_atomic` really uses are recognised.
    let target = d.join("real.png");
    write_atomic(&target, |_| {
        let tmp: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with(".real.png"))
            .collect();
        assert_eq!(tmp.len(), 1, "{tmp:?}");
        assert_eq!(atomic_temporary_pid(&tmp[0]), Some(own));
        // In flight: ours, so kept.
        assert!(remove_stale_temporaries(d).unwrap().is_empty());
        Ok(())
    })
    .unwrap();
    assert!(target.exists());
}

// ---------------------------------------------------------------------------------------
// y4m headers
// ---------------------------------------------------------------------------------------

#[test]
fn header_fields_are_parsed_and_written_back() {
    let line =
        "YUV4MPEG2 W720 H576 F25:1 Ib A16:15 C420mpeg2 XYSCSS=420MPEG2 XCOLORRANGE=LIMITED\n";
    let h = Y4mHeader::parse(line.as_bytes()).unwrap();
    assert_eq!((h.width, h.height), (720, 576));
    assert_eq!(h.fps, (25, 1));
    assert_eq!(h.interlace, Interlace::BottomFieldFirst);
    assert_eq!(h.aspect, (16, 15));
    assert_eq!(h.colorspace, Chroma::C420Mpeg2);
    assert_eq!(h.extra, ["YSCSS=420MPEG2", "COLORRANGE=LIMITED"]);
    assert_eq!(h.range_hint(), Some(Range::Limited));
    assert_eq!(h.to_line(), line);
    assert_eq!(h.frame_bytes(), 622_080);

    // Defaults: C420jpeg, unknown rate and aspect, progressive; unknown fields ignored.
    let h = Y4mHeader::parse(b"YUV4MPEG2 H2 W4 Zwhatever").unwrap();
    assert_eq!(h.colorspace, Chroma::C420Jpeg);
    assert_eq!((h.fps, h.aspect), ((0, 0), (0, 0)));
    assert_eq!(h.interlace, Interlace::Progressive);
    assert_eq!(h.to_line(), "YUV4MPEG2 W4 H2 F0:0 Ip A0:0 C420jpeg\n");

    let h = Y4mHeader::parse(b"YUV4MPEG2 W1920 H1080 F30000:1001 It A1:1 C444 XCOLORRANGE=FULL")
        .unwrap();
    assert_eq!(h.fps, (30000, 1001));
    assert_eq!(h.interlace, Interlace::TopFieldFirst);
    assert!(h.interlace.is_interlaced());
    assert_eq!(h.range_hint(), Some(Range::Full));
    let c = YuvConversion::for_header(&h);
    assert_eq!((c.matrix, c.range), (Matrix::Bt709, Range::Full));
    let sd = Y4mHeader::parse(b"YUV4MPEG2 W720 H480").unwrap();
    let c = YuvConversion::for_header(&sd);
    assert_eq!((c.matrix, c.range), (Matrix::Bt601, Range::Limited));
}

#[test]
fn interlacing_is_reported() {
    for (code, want) in [
        ('p', Interlace::Progressive),
        ('t', Interlace::TopFieldFirst),
        ('b', Interlace::BottomFieldFirst),
        ('m', Interlace::Mixed),
        ('?', Interlace::Unknown),
    ] {
        let bytes = format!("YUV4MPEG2 W8 H8 F25:1 I{code}\n").into_bytes();
        let r = Y4mReader::new(Cursor::new(bytes), "t").unwrap();
        assert_eq!(r.header().interlace, want);
        assert_eq!(want.code(), code);
    }
    let e = read_err(b"YUV4MPEG2 W8 H8 Ix\n".to_vec());
    assert!(e.to_string().contains("invalid interlacing `Ix`"), "{e}");
}

#[test]
fn malformed_headers_are_rejected_cleanly() {
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"YUV4MPEG2 H576 F25:1\n".to_vec(), "missing W (width)"),
        (b"YUV4MPEG2 W720 F25:1\n".to_vec(), "missing H (height)"),
        (
            b"YUV4MPEG2 W0 H576\n".to_vec(),
            "width 0 is out of range (1 to 16384)",
        ),
        (
            b"YUV4MPEG2 W99999999 H576\n".to_vec(),
            "width 99999999 is out of range",
        ),
        (
            b"YUV4MPEG2 W99999999999999999999999 H576\n".to_vec(),
            "out of range",
        ),
        (
            b"YUV4MPEG2 W720 H16385\n".to_vec(),
            "height 16385 is out of range",
        ),
        (b"YUV4MPEG2 W-5 H576\n".to_vec(), "invalid width `W-5`"),
        (b"YUV4MPEG2 Wx H576\n".to_vec(), "invalid width `Wx`"),
        (
            b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec(),
            "not a YUV4MPEG2 stream (it starts with \"\\x89PNG",
        ),
        (b"YUV4MPEG W720 H576\n".to_vec(), "not a YUV4MPEG2 stream"),
        (b"YUV4MPEG2W720 H576\n".to_vec(), "not a YUV4MPEG2 stream"),
        (b"".to_vec(), "the stream is empty"),
        (
            b"YUV4MPEG2 W720 H576".to_vec(),
            "ends inside the header line",
        ),
        (
            [b"YUV4MPEG2 ".as_slice(), &[b'X'; 5000]].concat(),
            "longer than 4096 bytes",
        ),
        (
            b"YUV4MPEG2 W720 H576 C420p11\n".to_vec(),
            "unsupported colour space `C420p11`",
        ),
        (
            b"YUV4MPEG2 W720 H576 C444alpha\n".to_vec(),
            "unsupported colour space",
        ),
        (
            b"YUV4MPEG2 W720 H576 F30:0\n".to_vec(),
            "invalid frame rate `F30:0`",
        ),
        (
            b"YUV4MPEG2 W720 H576 F30\n".to_vec(),
            "invalid frame rate `F30`",
        ),
        (
            b"YUV4MPEG2 W720 H576 A1:x\n".to_vec(),
            "invalid pixel aspect ratio",
        ),
        (b"YUV4MPEG2 W720 H576 \xff\n".to_vec(), "not text"),
    ];
    for (bytes, want) in cases {
        let e = read_err(bytes.clone());
        let msg = e.to_string();
        assert!(
            msg.starts_with("stdin: y4m header: ") && msg.contains(want),
            "{:?}: {msg}",
            String::from_utf8_lossy(&bytes)
        );
        let io: IoError = e.into();
        assert!(io.is_input_error(), "{io}");
        assert_eq!(io.path(), Path::new("stdin"));
    }
}

// ---------------------------------------------------------------------------------------
// y4m frames
// ---------------------------------------------------------------------------------------

#[test]
fn write_read_round_trip_is_exact_for_every_layout() {
    let mut rng = Rng(0x1234_5678);
    for chroma in Chroma::ALL {
        for (w, h) in [(7u32, 5u32), (16, 8), (1, 1)] {
            let mut hd = header(w, h, chroma);
            hd.fps = (30000, 1001);
            hd.interlace = Interlace::TopFieldFirst;
            hd.aspect = (16, 15);
            hd.extra = vec!["COLORRANGE=LIMITED".into(), "VENDOR=fx".into()];
            let frames: Vec<YuvFrame> = (0..3)
                .map(|i| {
                    let mut f = random_frame(&hd, &mut rng);
                    if i == 1 {
                        f.params = vec!["Itpi".into(), "Xfoo=1".into()];
                    }
                    f
                })
                .collect();
            let mut w8 = Y4mWriter::new(Vec::new(), hd.clone(), "mem").unwrap();
            for f in &frames {
                w8.write_frame(f).unwrap();
            }
            assert_eq!(w8.frames_written(), 3);
            let bytes = w8.into_inner().unwrap();

            // Exact bytes: header line, then FRAME lines and the planes.
            let line = format!(
                "YUV4MPEG2 W{w} H{h} F30000:1001 It A16:15 C{} XCOLORRANGE=LIMITED XVENDOR=fx\n",
                chroma.tag()
            );
            let mut want = line.into_bytes();
            for f in &frames {
                want.extend_from_slice(b"FRAME");
                for p in &f.params {
                    want.push(b' ');
                    want.extend_from_slice(p.as_bytes());
                }
                want.push(b'\n');
                want.extend_from_slice(&f.y);
                want.extend_from_slice(&f.u);
                want.extend_from_slice(&f.v);
            }
            assert_eq!(bytes, want, "{chroma} {w}x{h}");
            let (cw, ch) = chroma.chroma_size(w, h);
            assert_eq!(
                frames[0].u.len(),
                cw * ch,
                "{chroma} {w}x{h} chroma plane size"
            );

            let mut r = Y4mReader::new(Cursor::new(bytes), "mem").unwrap();
            assert_eq!(r.header(), &hd);
            for (i, f) in frames.iter().enumerate() {
                assert_eq!(r.next_frame().unwrap().as_ref(), Some(f), "frame {i}");
            }
            assert_eq!(r.next_frame().unwrap(), None);
            assert_eq!(r.frames_read(), 3);
        }
    }
    // Plane sizes of 4:2:0 / 4:2:2 with odd sides round up.
    assert_eq!(Chroma::C420Jpeg.chroma_size(7, 5), (4, 3));
    assert_eq!(Chroma::C422.chroma_size(7, 5), (4, 5));
    assert_eq!(Chroma::C444.chroma_size(7, 5), (7, 5));
    assert_eq!(Chroma::Mono.chroma_size(7, 5), (0, 0));
    assert_eq!(Chroma::Mono.frame_bytes(7, 5), 35);
}

#[test]
fn reader_reuses_buffers_and_iterates() {
    let hd = header(32, 16, Chroma::C420Jpeg);
    let mut rng = Rng(9);
    let frames: Vec<YuvFrame> = (0..4).map(|_| random_frame(&hd, &mut rng)).collect();
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "mem").unwrap();
    for f in &frames {
        w.write_frame(f).unwrap();
    }
    let bytes = w.into_inner().unwrap();
    let mut r = Y4mReader::new(Cursor::new(bytes.clone()), "mem").unwrap();
    let mut buf = YuvFrame::default();
    assert!(r.read_frame_into(&mut buf).unwrap());
    let ptr = buf.y.as_ptr();
    assert!(r.read_frame_into(&mut buf).unwrap());
    assert_eq!(buf.y.as_ptr(), ptr, "the luma buffer is reused");
    assert_eq!(buf, frames[1]);
    let all: Vec<YuvFrame> = Y4mReader::new(Cursor::new(bytes), "mem")
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(all, frames);
}

#[test]
fn truncated_and_malformed_frames_name_the_frame() {
    let hd = header(720, 576, Chroma::C420Jpeg);
    let mut rng = Rng(77);
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "stdin").unwrap();
    for _ in 0..3 {
        w.write_frame(&random_frame(&hd, &mut rng)).unwrap();
    }
    let full = w.into_inner().unwrap();
    let header_len = hd.to_line().len();
    let frame_len = 6 + 622_080;
    assert_eq!(full.len(), header_len + 3 * frame_len);

    // Cut 1000 bytes into frame 2's planes.
    let cut = header_len + 2 * frame_len + 6 + 1000;
    let mut r = Y4mReader::new(Cursor::new(full[..cut].to_vec()), "stdin").unwrap();
    assert!(r.next_frame().unwrap().is_some());
    assert!(r.next_frame().unwrap().is_some());
    let e = r.next_frame().unwrap_err();
    assert_eq!(
        e.to_string(),
        "stdin: y4m frame 2 (0-based): truncated (got 1000 of 622080 bytes)"
    );
    assert_eq!(e.frame(), Some(2));
    let io: IoError = e.into();
    assert!(matches!(io, IoError::Decode { .. }));
    assert_eq!(
        io.to_string(),
        "stdin: y4m frame 2 (0-based): truncated (got 1000 of 622080 bytes)"
    );
    // Truncated inside the chroma planes: the count covers all planes.
    let cut = header_len + frame_len + 6 + 414_720 + 10;
    let mut r = Y4mReader::new(Cursor::new(full[..cut].to_vec()), "in.y4m").unwrap();
    r.next_frame().unwrap();
    let e = r.next_frame().unwrap_err();
    assert_eq!(
        e.to_string(),
        "in.y4m: y4m frame 1 (0-based): truncated (got 414730 of 622080 bytes)"
    );
    // The iterator stops after an error.
    let it = Y4mReader::new(Cursor::new(full[..cut].to_vec()), "in.y4m").unwrap();
    let results: Vec<bool> = it.map(|r| r.is_ok()).collect();
    assert_eq!(results, [true, false]);

    // Truncated inside the FRAME line.
    let cut = header_len + frame_len + 3;
    let mut r = Y4mReader::new(Cursor::new(full[..cut].to_vec()), "stdin").unwrap();
    r.next_frame().unwrap();
    let e = r.next_frame().unwrap_err();
    assert!(
        e.to_string().starts_with(
            "stdin: y4m frame 1 (0-based): truncated: the stream ends inside the FRAME line"
        ),
        "{e}"
    );

    // A malformed FRAME line.
    let mut bad = full.clone();
    bad[header_len + frame_len..header_len + frame_len + 5].copy_from_slice(b"FRAMX");
    let mut r = Y4mReader::new(Cursor::new(bad), "stdin").unwrap();
    r.next_frame().unwrap();
    let e = r.next_frame().unwrap_err();
    assert!(
        e.to_string()
            .starts_with("stdin: y4m frame 1 (0-based): expected a `FRAME` line, found \"FRAMX"),
        "{e}"
    );
    // Extra bytes after a frame (the frame size disagrees with the header).
    let mut bad = full[..header_len + frame_len].to_vec();
    bad.extend_from_slice(b"\0\0FRAME\n");
    let mut r = Y4mReader::new(Cursor::new(bad), "stdin").unwrap();
    r.next_frame().unwrap();
    let e = r.next_frame().unwrap_err();
    assert!(
        e.to_string()
            .contains("frame 1 (0-based): expected a `FRAME` line"),
        "{e}"
    );
    // A clean end right after the header: no frames.
    let mut r = Y4mReader::new(Cursor::new(full[..header_len].to_vec()), "stdin").unwrap();
    assert_eq!(r.next_frame().unwrap(), None);
}

#[test]
fn huge_header_with_little_data_fails_fast() {
    // 16384 x 16384 4:4:4 announces 805 MB per frame; only 10 bytes follow.
    let mut bytes = b"YUV4MPEG2 W16384 H16384 C444\nFRAME\n".to_vec();
    bytes.extend_from_slice(&[0; 10]);
    let t = Instant::now();
    let mut r = Y4mReader::new(Cursor::new(bytes), "stdin").unwrap();
    let e = r.next_frame().unwrap_err();
    assert_eq!(
        e.to_string(),
        "stdin: y4m frame 0 (0-based): truncated (got 10 of 805306368 bytes)"
    );
    assert!(t.elapsed().as_secs_f64() < 2.0, "{:?}", t.elapsed());
}

#[test]
fn writer_rejects_frames_that_do_not_fit() {
    let hd = header(8, 4, Chroma::C420Jpeg);
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "stdout").unwrap();
    let mut f = YuvFrame::black(&hd, Range::Limited);
    f.u.pop();
    let e = w.write_frame(&f).unwrap_err();
    assert_eq!(
        e.to_string(),
        "stdout: y4m frame 0 (0-based): the Cb plane has 7 bytes, the header (8x4 C420jpeg) needs 8"
    );
    let mut f = YuvFrame::black(&hd, Range::Limited);
    f.params = vec!["a b".into()];
    assert!(w.write_frame(&f).is_err());
    let mut bad = hd.clone();
    bad.width = 0;
    assert!(Y4mWriter::new(Vec::new(), bad, "stdout").is_err());
    let mut bad = hd;
    bad.extra = vec!["has space".into()];
    assert!(Y4mWriter::new(Vec::new(), bad, "stdout").is_err());
}

// ---------------------------------------------------------------------------------------
// colour conversion
// ---------------------------------------------------------------------------------------

/// Y'CbCr of one RGB byte triple through a 1x1... 2x2 4:4:4 frame.
fn yuv_of(rgb: [u8; 3], c: &YuvConversion) -> [u8; 3] {
    let hd = header(2, 2, Chroma::C444);
    let rgba: Vec<u8> = (0..4).flat_map(|_| [rgb[0], rgb[1], rgb[2], 255]).collect();
    let mut f = YuvFrame::default();
    rgba_u8_to_yuv(&rgba, &hd, c, &mut f).unwrap();
    [f.y[0], f.u[0], f.v[0]]
}

fn rgb_of(yuv: [u8; 3], c: &YuvConversion) -> [u8; 3] {
    let hd = header(2, 2, Chroma::C444);
    let f = YuvFrame {
        y: vec![yuv[0]; 4],
        u: vec![yuv[1]; 4],
        v: vec![yuv[2]; 4],
        params: vec![],
    };
    let mut out = vec![0u8; 16];
    yuv_to_rgba_u8(&f, &hd, c, &mut out).unwrap();
    assert_eq!(out[3], 255);
    [out[0], out[1], out[2]]
}

#[test]
fn known_values() {
    let bt709 = conv(Matrix::Bt709, Range::Limited);
    let bt601 = conv(Matrix::Bt601, Range::Limited);
    let full601 = conv(Matrix::Bt601, Range::Full);
    assert_eq!(yuv_of([255, 255, 255], &bt709), [235, 128, 128]);
    assert_eq!(yuv_of([0, 0, 0], &bt709), [16, 128, 128]);
    assert_eq!(yuv_of([255, 0, 0], &bt601), [81, 90, 240]);
    assert_eq!(yuv_of([0, 255, 0], &bt601), [145, 54, 34]);
    assert_eq!(yuv_of([0, 0, 255], &bt601), [41, 240, 110]);
    assert_eq!(yuv_of([255, 0, 0], &bt709), [63, 102, 240]);
    assert_eq!(yuv_of([255, 255, 255], &full601), [255, 128, 128]);
    assert_eq!(yuv_of([0, 0, 0], &full601), [0, 128, 128]);

    assert_eq!(rgb_of([235, 128, 128], &bt709), [255, 255, 255]);
    assert_eq!(rgb_of([16, 128, 128], &bt709), [0, 0, 0]);
    assert_eq!(rgb_of([126, 128, 128], &bt601), [128, 128, 128]);
    let red = rgb_of([81, 90, 240], &bt601);
    assert!(red[0] >= 254 && red[1] <= 1 && red[2] <= 1, "{red:?}");
    // Out of range codes clip.
    assert_eq!(rgb_of([255, 128, 128], &bt709), [255, 255, 255]);
    assert_eq!(rgb_of([0, 128, 128], &bt709), [0, 0, 0]);

    // The float path: linear white and black, and the sRGB decode of grey.
    let hd = header(2, 2, Chroma::C444);
    let f = YuvFrame {
        y: vec![235, 16, 126, 235],
        u: vec![128; 4],
        v: vec![128; 4],
        params: vec![],
    };
    let mut out = vec![0f32; 16];
    yuv_to_rgba_f32(&f, &hd, &bt709, &mut out).unwrap();
    // The sRGB curve is a polynomial fit within 3e-6 of the formula.
    let close = |got: &[f32], want: &[f32]| {
        assert!(
            got.iter().zip(want).all(|(a, b)| (a - b).abs() < 3e-6),
            "{got:?} vs {want:?}"
        )
    };
    close(&out[0..4], &[1.0, 1.0, 1.0, 1.0]);
    close(&out[4..8], &[0.0, 0.0, 0.0, 1.0]);
    assert_eq!((out[3], out[7]), (1.0, 1.0));
    let grey = srgb::srgb_to_linear(110.0 / 219.0);
    close(&out[8..11], &[grey; 3]);
    let mut back = YuvFrame::default();
    rgba_f32_to_yuv(&out, &hd, &bt709, &mut back).unwrap();
    assert_eq!(back.y, f.y);
    assert_eq!(back.u, f.u);
}

/// Every grey level plus random colours, `n` pixels, as a `w x h` RGBA image.
fn test_colours(w: usize, h: usize, seed: u64) -> Vec<u8> {
    let mut rng = Rng(seed);
    let mut v = Vec::with_capacity(w * h * 4);
    for i in 0..w * h {
        if i < 256 {
            v.extend_from_slice(&[i as u8, i as u8, i as u8, 255]);
        } else {
            v.extend_from_slice(&[rng.byte(), rng.byte(), rng.byte(), 255]);
        }
    }
    v
}

#[test]
fn rgb_round_trip_444_is_within_two_codes() {
    let (w, h) = (128usize, 128usize);
    let rgba = test_colours(w, h, 5);
    let hd = header(w as u32, h as u32, Chroma::C444);
    let mut report = Vec::new();
    for matrix in [Matrix::Bt601, Matrix::Bt709] {
        for range in [Range::Limited, Range::Full] {
            let c = conv(matrix, range);
            // 8-bit sRGB in and out.
            let mut f = YuvFrame::default();
            rgba_u8_to_yuv(&rgba, &hd, &c, &mut f).unwrap();
            let mut back = vec![0u8; rgba.len()];
            yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
            let (max, mean) = rgb_diff(&rgba, &back);
            // Grey stays grey.
            for p in back[..256 * 4].chunks_exact(4) {
                assert!(
                    p[0].abs_diff(p[1]) <= 1 && p[1].abs_diff(p[2]) <= 1,
                    "{p:?}"
                );
            }
            // Linear f32 in and out, compared after sRGB encoding.
            let lin: Vec<f32> = Pixels::U8(rgba.clone()).to_f32_linear(false);
            let mut f2 = YuvFrame::default();
            rgba_f32_to_yuv(&lin, &hd, &c, &mut f2).unwrap();
            // The same Y'CbCr within one code (the f32 path's sRGB tables move values
            // that sit on a rounding boundary).
            let planes = |f: &YuvFrame| [f.y.clone(), f.u.clone(), f.v.clone()].concat();
            let code_diff = planes(&f2)
                .iter()
                .zip(planes(&f))
                .map(|(a, b)| a.abs_diff(b))
                .max();
            assert_eq!(
                code_diff,
                Some(1).min(code_diff),
                "u8 and f32 inputs differ"
            );
            let mut backf = vec![0f32; lin.len()];
            yuv_to_rgba_f32(&f2, &hd, &c, &mut backf).unwrap();
            let back8 = Pixels::F32(backf).to_u8_srgb(false);
            let (max_f, mean_f) = rgb_diff(&rgba, &back8);
            report.push(format!(
                "{matrix:?}/{range:?}: u8 max {max} mean {mean:.3}, f32 max {max_f} mean {mean_f:.3}"
            ));
            // Limited range has 219 luma and 225 chroma levels for 256 RGB levels.
            assert!(max <= 2 && max_f <= 2, "{}", report.last().unwrap());
            assert!(mean < 0.75 && mean_f < 0.75, "{}", report.last().unwrap());
        }
    }
    eprintln!(
        "4:4:4 round trip (8-bit sRGB units):\n  {}",
        report.join("\n  ")
    );
}

/// A smooth colour image: slow sinusoids, about 20 % to 80 % of full scale.
fn smooth_image(w: usize, h: usize) -> Vec<u8> {
    let mut v = Vec::with_capacity(w * h * 4);
    for y in 0..h {
        for x in 0..w {
            let (xf, yf) = (x as f32, y as f32);
            let r = 128.0 + 70.0 * (xf / 23.0).sin() * (yf / 31.0).cos();
            let g = 128.0 + 60.0 * ((xf + yf) / 37.0).sin();
            let b = 128.0 + 75.0 * (yf / 19.0).cos() * (xf / 41.0).cos();
            v.extend_from_slice(&[r.round() as u8, g.round() as u8, b.round() as u8, 255]);
        }
    }
    v
}

#[test]
fn rgb_round_trip_subsampled_on_smooth_content() {
    let (w, h) = (160usize, 120usize);
    let rgba = smooth_image(w, h);
    let mut report = Vec::new();
    for chroma in [
        Chroma::C420Jpeg,
        Chroma::C420Mpeg2,
        Chroma::C420Paldv,
        Chroma::C420,
        Chroma::C422,
    ] {
        for interlace in [Interlace::Progressive, Interlace::TopFieldFirst] {
            let mut hd = header(w as u32, h as u32, chroma);
            hd.interlace = interlace;
            let c = conv(Matrix::Bt601, Range::Limited);
            let mut f = YuvFrame::default();
            rgba_u8_to_yuv(&rgba, &hd, &c, &mut f).unwrap();
            let mut back = vec![0u8; rgba.len()];
            yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
            let (max, mean) = rgb_diff(&rgba, &back);
            // Inside a two-pixel border (where the last chroma sample of co-sited layouts,
            // and of each field, is clamped instead of interpolated).
            let inner = |img: &[u8]| -> Vec<u8> {
                (2..h - 2)
                    .flat_map(|y| img[(y * w + 2) * 4..(y * w + w - 2) * 4].to_vec())
                    .collect()
            };
            let (max_in, _) = rgb_diff(&inner(&rgba), &inner(&back));
            report.push(format!(
                "C{chroma} I{}: max {max} (inside the border {max_in}) mean {mean:.3}",
                interlace.code()
            ));
            assert!(
                max <= 4 && max_in <= 3 && mean < 0.5,
                "{}",
                report.last().unwrap()
            );
        }
    }
    eprintln!(
        "4:2:0 / 4:2:2 round trip on smooth content (8-bit sRGB units):\n  {}",
        report.join("\n  ")
    );
}

#[test]
fn mono_round_trip() {
    let (w, h) = (16u32, 16u32);
    let grey: Vec<u8> = (0..256)
        .flat_map(|i| [i as u8, i as u8, i as u8, 255])
        .collect();
    let hd = header(w, h, Chroma::Mono);
    let c = conv(Matrix::Bt709, Range::Limited);
    let mut f = YuvFrame::default();
    rgba_u8_to_yuv(&grey, &hd, &c, &mut f).unwrap();
    assert!(f.u.is_empty() && f.v.is_empty());
    assert_eq!((f.y[0], f.y[255]), (16, 235));
    let mut back = vec![0u8; grey.len()];
    yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
    let (max, _) = rgb_diff(&grey, &back);
    assert!(max <= 1, "max {max}");
    // Full range mono is lossless.
    let c = conv(Matrix::Bt709, Range::Full);
    rgba_u8_to_yuv(&grey, &hd, &c, &mut f).unwrap();
    yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
    assert_eq!(back, grey);
}

#[test]
fn interlaced_chroma_is_resampled_per_field() {
    // 4:2:0, 4x8: chroma rows 0, 2 (top field) carry one colour, rows 1, 3 (bottom field)
    // another. Per field, every even luma row sees only the top colour.
    let mut hd = header(4, 8, Chroma::C420Mpeg2);
    hd.interlace = Interlace::BottomFieldFirst;
    let f = YuvFrame {
        y: vec![126; 32],
        u: [[100u8; 2], [160; 2], [100; 2], [160; 2]].concat(),
        v: [[200u8; 2], [60; 2], [200; 2], [60; 2]].concat(),
        params: vec![],
    };
    let c = conv(Matrix::Bt601, Range::Limited);
    let mut out = vec![0u8; 4 * 8 * 4];
    yuv_to_rgba_u8(&f, &hd, &c, &mut out).unwrap();
    let top = rgb_of([126, 100, 200], &c);
    let bottom = rgb_of([126, 160, 60], &c);
    for y in 0..8 {
        let want = if y % 2 == 0 { top } else { bottom };
        for x in 0..4 {
            let p = &out[(y * 4 + x) * 4..][..3];
            assert_eq!(p, want, "row {y} col {x}");
        }
    }
    // Read as progressive, the fields' colours mix.
    let progressive = YuvConversion {
        chroma_fields: ChromaFields::Progressive,
        ..c
    };
    yuv_to_rgba_u8(&f, &hd, &progressive, &mut out).unwrap();
    assert_ne!(&out[4 * 4 * 2..][..3], top);
    // And downsampling keeps the fields apart too.
    let mut back = YuvFrame::default();
    let mut rgba = vec![0u8; 4 * 8 * 4];
    yuv_to_rgba_u8(&f, &hd, &c, &mut rgba).unwrap();
    rgba_u8_to_yuv(&rgba, &hd, &c, &mut back).unwrap();
    for (a, b) in back.u.iter().zip(&f.u).chain(back.v.iter().zip(&f.v)) {
        assert!(a.abs_diff(*b) <= 1, "{:?} vs {:?}", back.u, f.u);
    }
    // Mixed streams follow each frame's `I` parameter.
    hd.interlace = Interlace::Mixed;
    let mut fm = f.clone();
    fm.params = vec!["Itii".into()];
    assert!(fm.field_chroma(&hd, &c));
    fm.params = vec!["I1pp".into()];
    assert!(!fm.field_chroma(&hd, &c));
    fm.params = vec![];
    assert!(!fm.field_chroma(&hd, &c));
}

#[test]
fn unclipped_floats_keep_colours_outside_the_rgb_cube() {
    let hd = header(2, 2, Chroma::C444);
    let f = YuvFrame {
        y: vec![240, 30, 200, 128],
        u: vec![20, 230, 128, 16],
        v: vec![230, 40, 128, 240],
        params: vec![],
    };
    let c = YuvConversion {
        clip: false,
        ..conv(Matrix::Bt709, Range::Limited)
    };
    let mut lin = vec![0f32; 16];
    yuv_to_rgba_f32(&f, &hd, &c, &mut lin).unwrap();
    assert!(
        lin.iter().any(|&v| v < 0.0) && lin.iter().any(|&v| v > 1.0),
        "{lin:?}"
    );
    let mut back = YuvFrame::default();
    rgba_f32_to_yuv(&lin, &hd, &c, &mut back).unwrap();
    assert_eq!(back, f);
    // Clipped, they change.
    let clipped = YuvConversion { clip: true, ..c };
    yuv_to_rgba_f32(&f, &hd, &clipped, &mut lin).unwrap();
    assert!(lin.iter().all(|&v| (0.0..=1.0).contains(&v)));
    rgba_f32_to_yuv(&lin, &hd, &clipped, &mut back).unwrap();
    assert_ne!(back, f);
}

#[test]
fn image_conversion_checks_sizes() {
    let hd = header(8, 6, Chroma::C420Jpeg);
    let c = YuvConversion::for_header(&hd);
    let f = YuvFrame::black(&hd, Range::Limited);
    let img = yuv_to_image(&f, &hd, &c, RgbKind::LinearF32).unwrap();
    assert_eq!((img.width, img.height), (8, 6));
    assert!(
        matches!(&img.pixels, Pixels::F32(v) if v.len() == 8 * 6 * 4 && v[0] == 0.0 && v[3] == 1.0)
    );
    let img8 = yuv_to_image(&f, &hd, &c, RgbKind::SrgbU8).unwrap();
    assert!(matches!(&img8.pixels, Pixels::U8(v) if v[..4] == [0, 0, 0, 255]));
    assert_eq!(image_to_yuv(&img, &hd, &c).unwrap(), f);
    assert_eq!(image_to_yuv(&img8, &hd, &c).unwrap(), f);
    let other = header(8, 4, Chroma::C420Jpeg);
    let e = image_to_yuv(&img, &other, &c).unwrap_err();
    assert_eq!(e, "the image is 8x6 but the y4m stream is 8x4");
    let mut short = f.clone();
    short.y.pop();
    assert!(yuv_to_image(&short, &hd, &c, RgbKind::SrgbU8).is_err());
}

/// Conversion speed of one 1920x1080 4:2:0 frame (meaningful in release builds:
/// `cargo test --release --test sequence_io conversion_speed -- --nocapture`).
#[test]
fn conversion_speed_1080p() {
    let mut hd = header(1920, 1080, Chroma::C420Mpeg2);
    hd.interlace = Interlace::TopFieldFirst;
    let c = YuvConversion::for_header(&hd);
    let rgba = smooth_image(1920, 1080);
    let mut f = YuvFrame::default();
    rgba_u8_to_yuv(&rgba, &hd, &c, &mut f).unwrap();
    let mut out8 = vec![0u8; rgba.len()];
    let mut outf = vec![0f32; rgba.len()];
    let lin = Pixels::U8(rgba.clone()).to_f32_linear(false);
    let reps = if cfg!(debug_assertions) { 1 } else { 20 };
    let time = |name: &str, run: &mut dyn FnMut()| {
        run();
        let mut best = f64::MAX;
        let mut total = 0.0;
        for _ in 0..reps {
            let t = Instant::now();
            run();
            let ms = t.elapsed().as_secs_f64() * 1e3;
            best = best.min(ms);
            total += ms;
        }
        eprintln!(
            "1080p {name}: best {best:.2} ms, mean {:.2} ms ({reps} runs)",
            total / reps as f64
        );
    };
    time("Y'CbCr 4:2:0 -> RGBA u8", &mut || {
        yuv_to_rgba_u8(&f, &hd, &c, &mut out8).unwrap()
    });
    time("Y'CbCr 4:2:0 -> RGBA f32 linear", &mut || {
        yuv_to_rgba_f32(&f, &hd, &c, &mut outf).unwrap()
    });
    let mut g = YuvFrame::default();
    time("RGBA u8 -> Y'CbCr 4:2:0", &mut || {
        rgba_u8_to_yuv(&rgba, &hd, &c, &mut g).unwrap()
    });
    time("RGBA f32 linear -> Y'CbCr 4:2:0", &mut || {
        rgba_f32_to_yuv(&lin, &hd, &c, &mut g).unwrap()
    });
    time("Y'CbCr -> Image f32 (allocating)", &mut || {
        let _ = yuv_to_image(&f, &hd, &c, RgbKind::LinearF32).unwrap();
    });
    // Reading and writing frames through memory.
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "mem").unwrap();
    for _ in 0..10 {
        w.write_frame(&f).unwrap();
    }
    let bytes = w.into_inner().unwrap();
    time("read 10 frames from memory", &mut || {
        let mut r = Y4mReader::new(Cursor::new(&bytes), "mem").unwrap();
        let mut buf = YuvFrame::default();
        while r.read_frame_into(&mut buf).unwrap() {}
    });
}

// ---------------------------------------------------------------------------------------
// ffmpeg interoperability (skipped when ffmpeg is absent)
// ---------------------------------------------------------------------------------------

fn ffmpeg() -> bool {
    let ok = Command::new("ffmpeg")
        .arg("-version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("skipping: ffmpeg is not installed");
    }
    ok
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
