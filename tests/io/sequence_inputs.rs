//! Input sequences (patterns with gaps, folders sorted by the numbers in the names,
//! wildcards) and `--frames` (parsing, open ends resolved).

use super::*;

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
    let seq = open_input(&pattern).unwrap();
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
    let e = open_input(&pattern).unwrap_err();
    assert!(
        matches!(&e, IoError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound)
    );
    let msg = e.to_string();
    assert!(
        msg.contains("b_%04d.png") && msg.contains("no files match"),
        "{msg}"
    );

    let pattern = format!("{}/missing/%04d.png", s(dir.path()));
    let e = open_input(&pattern).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e}");

    let e = open_input("x/%d_%d.png").unwrap_err();
    assert!(e.is_input_error(), "{e}");
    assert!(e.to_string().contains("more than one"), "{e}");

    let e = InputSequence::open(&SequenceSpec::Stdin).unwrap_err();
    assert!(e.is_input_error(), "{e}");
}

#[test]
fn folder_input_is_sorted_by_the_numbers_in_the_names() {
    let dir = folder_with(&[
        "f10.png",
        "f2.jpg",
        "f1.png",
        "notes.txt",
        ".f3.png",
        "f4.png.fxtmp",
    ]);
    let d = dir.path();
    fs::create_dir(d.join("f5.png")).unwrap();
    let seq = open_input(&s(d)).unwrap();
    assert_eq!(numbers(&seq), [1, 2, 10]);
    assert_eq!(names(&seq), ["f1.png", "f2.jpg", "f10.png"]);
    assert_eq!(seq.gaps(), [FrameRange { start: 3, end: 9 }]);
}

#[test]
fn folder_input_without_distinct_numbers_is_sorted_by_name() {
    for (files, sorted) in [
        (["b.png", "a.png", "c.exr"], ["a.png", "b.png", "c.exr"]),
        (
            ["cam1_7.png", "cam2_7.png", "cam1_8.png"],
            ["cam1_7.png", "cam1_8.png", "cam2_7.png"],
        ),
    ] {
        let dir = folder_with(&files);
        let seq = InputSequence::open(&SequenceSpec::Dir(dir.path().into())).unwrap();
        assert_eq!(numbers(&seq), [0, 1, 2], "{files:?}");
        assert_eq!(names(&seq), sorted);
    }

    let empty = folder_with(&["readme.txt"]);
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
