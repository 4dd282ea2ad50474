//! What `fxrun` refuses to read: devices as inputs, scripts, includes and glTF
//! URIs, and includes outside the including script's folder (`..`, absolute paths,
//! symlinks out); no byte of a refused file shows in a message.

use crate::common::cli::{apply, exits, exits_with, fxrun};
use std::path::Path;

#[test]
fn devices_are_refused_as_inputs_includes_and_gltf_uris() {
    if !Path::new("/dev/zero").exists() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let t = std::time::Instant::now();
    let o = apply("tonemap", "/dev/zero", &out, &[]);
    exits_with(&o, 1, &["/dev/zero: not a regular file"]);
    let o = fxrun(&["/dev/zero", "--check"]);
    exits_with(&o, 1, &["not a regular file"]);
    let fx = dir.path().join("inc.fx");
    std::fs::write(&fx, "INCLUDE \"/dev/zero\"\n").unwrap();
    let o = fxrun(&[fx.to_str().unwrap(), "--check"]);
    exits_with(&o, 1, &["absolute include paths are not allowed"]);
    if crate::gpu() {
        let gltf = dir.path().join("zero.gltf");
        std::fs::write(
            &gltf,
            r#"{"asset":{"version":"2.0"},"images":[{"uri":"/dev/zero"}],"buffers":[{"uri":"/dev/zero","byteLength":4}]}"#,
        )
        .unwrap();
        let o = fxrun(&[
            "--scene",
            gltf.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let e = exits(&o, 1);
        assert!(
            e.contains("zero.gltf: ")
                && e.contains("/dev/zero")
                && e.contains("not a regular file"),
            "{e}"
        );
    }
    assert!(t.elapsed().as_secs() < 30);
}

#[test]
fn include_is_confined_to_the_script_folder() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("a/b");
    std::fs::create_dir_all(&sub).unwrap();
    let secret = dir.path().join("secret.fx");
    std::fs::write(&secret, "SECRET-FIRST-LINE\n").unwrap();
    let check = |text: &str| {
        let fx = sub.join("x.fx");
        std::fs::write(&fx, text).unwrap();
        fxrun(&[fx.to_str().unwrap(), "--check"])
    };
    for (inc, why) in [
        ("../../secret.fx", "`..` is not allowed"),
        ("../../../../../../../etc/passwd", "`..` is not allowed"),
        (
            secret.to_str().unwrap(),
            "absolute include paths are not allowed",
        ),
    ] {
        let o = check(&format!("INCLUDE \"{inc}\"\n"));
        let e = exits_with(&o, 1, &[why]);
        assert!(
            !e.contains("SECRET-FIRST-LINE") && !e.contains("root:"),
            "{e}"
        );
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&secret, sub.join("link.fx")).unwrap();
        let o = check("INCLUDE \"link.fx\"\n");
        let e = exits_with(&o, 1, &["outside the including file's folder"]);
        assert!(!e.contains("SECRET-FIRST-LINE"), "{e}");
    }
    // A file in the folder (and the built-in library) still works.
    std::fs::write(sub.join("lib.fx"), "").unwrap();
    let o = check("INCLUDE \"lib.fx\"\nINCLUDE \"glow.fx\"\nEFFECT.x = { PASS = { p = SHADER.copy { img = IN } } OUT = p }\n");
    let e = crate::common::cli::stderr(&o);
    assert!(!e.contains("cannot include"), "{e}");
}
