//! Frame patterns and sequence specs: parsing and formatting, exact matching, and
//! how arguments are classified.

use super::*;

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
