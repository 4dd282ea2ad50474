//! Output naming, `--skip-existing`, and the cleanup of stale temporaries of
//! interrupted writes (and of nothing else).

use super::*;

#[test]
fn output_naming_and_skip_existing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();

    let out = open_output(&format!("{}/a/b/f_%05d.png", s(d))).unwrap();
    assert!(d.join("a/b").is_dir(), "the output folder is created");
    assert_eq!(out.path_for(42), d.join("a/b/f_00042.png"));
    assert_eq!(out.dir(), d.join("a/b/").as_path());
    assert!(!out.exists(42));
    touch(&out.path_for(42));
    assert!(out.exists(42));
    assert!(!out.exists(43));

    let out = open_output(&format!("{}/frames/", s(d))).unwrap();
    assert!(d.join("frames").is_dir());
    assert_eq!(out.path_for(7), d.join("frames/000007.png"));
    assert_eq!(out.path_for(1234567), d.join("frames/1234567.png"));

    let out = OutputPattern::in_dir(&d.join("exr"), "exr").unwrap();
    assert_eq!(out.path_for(3), d.join("exr/000003.exr"));

    // Existing folder given without a trailing slash.
    let out = open_output(&s(&d.join("exr"))).unwrap();
    assert_eq!(out.path_for(3), d.join("exr/000003.png"));

    let e = open_output(&format!("{}/x/%04d.xyz", s(d))).unwrap_err();
    assert!(
        e.is_input_error() && e.to_string().contains("extension"),
        "{e}"
    );
    let e = open_output("single.png").unwrap_err();
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
