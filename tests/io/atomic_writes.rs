//! Atomic writes: a failed save leaves the target untouched, and `write_atomic`
//! replaces existing files.

use super::*;

#[test]
fn failed_saves_leave_the_target_untouched() {
    let d = tmp();
    let target = d.path().join("out.png");
    std::fs::write(&target, b"original contents").unwrap();
    let px = Pixels::U8(pattern_u8(4, 4));

    // closure error after writing some bytes
    let e = write_atomic(&target, |w| {
        use std::io::Write;
        w.write_all(b"partial").unwrap();
        Err(IoError::Unsupported {
            path: target.clone(),
            message: "stop".into(),
        })
    })
    .unwrap_err();
    assert!(matches!(e, IoError::Unsupported { .. }));
    assert_eq!(std::fs::read(&target).unwrap(), b"original contents");
    assert_eq!(dir_names(d.path()), ["out.png"]);

    // panic inside the closure
    let r = std::panic::catch_unwind(|| {
        let _ = write_atomic(&target, |_| panic!("boom"));
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read(&target).unwrap(), b"original contents");
    assert_eq!(dir_names(d.path()), ["out.png"]);

    // unsupported bit depth for the format
    let jpg = d.path().join("out.jpg");
    std::fs::write(&jpg, b"old jpeg").unwrap();
    let e = save_image(
        &jpg,
        4,
        4,
        &px,
        &SaveOptions {
            bit_depth: Some(16),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, IoError::Unsupported { .. }), "{e:?}");
    assert!(
        e.to_string()
            .starts_with(&format!("{}: JPEG", jpg.display())),
        "{e}"
    );
    assert_eq!(std::fs::read(&jpg).unwrap(), b"old jpeg");

    // unknown extension
    let odd = d.path().join("out.xyz");
    std::fs::write(&odd, b"keep").unwrap();
    let e = save_image(&odd, 4, 4, &px, &SaveOptions::default()).unwrap_err();
    assert!(
        matches!(e, IoError::Unsupported { .. }) && e.is_input_error(),
        "{e:?}"
    );
    assert_eq!(std::fs::read(&odd).unwrap(), b"keep");

    // wrong buffer size
    let e = save_image(&target, 5, 4, &px, &SaveOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Unsupported { .. }), "{e:?}");
    assert_eq!(std::fs::read(&target).unwrap(), b"original contents");

    assert_eq!(dir_names(d.path()), ["out.jpg", "out.png", "out.xyz"]);

    // missing folder: an Io error
    let e = save_image(
        &d.path().join("nope/x.png"),
        4,
        4,
        &px,
        &SaveOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
    assert!(!e.is_input_error());

    // and a successful save replaces the file and leaves nothing else behind
    save(&target, 4, 4, &px, None);
    assert_eq!(
        u8s(&load(&target)),
        match &px {
            Pixels::U8(v) => &v[..],
            _ => unreachable!(),
        }
    );
    assert_eq!(dir_names(d.path()), ["out.jpg", "out.png", "out.xyz"]);
}

#[test]
fn write_atomic_replaces_existing_files() {
    let d = tmp();
    let target = d.path().join("data.bin");
    for content in [&b"first"[..], b"second, longer", b"3"] {
        write_atomic(&target, |w| {
            use std::io::Write;
            w.write_all(content).map_err(|e| IoError::Io {
                path: target.clone(),
                source: e,
            })
        })
        .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), content);
    }
    assert_eq!(dir_names(d.path()), ["data.bin"]);
}
