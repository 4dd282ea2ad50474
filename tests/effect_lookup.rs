//! How `fxrun NAME` finds an effect: `--` search folders, then `./NAME.fx`, then
//! `./effects/NAME.fx`, then the built-in library; a file on disk overrides the
//! built-in of the same name, and `./shaders/NAME.wgsl` overrides a built-in
//! shader (README, "Using fxrun").

use crate::common;

use common::cli::{fxrun_in, stdout};

use std::path::Path;

const SEPIA: &str = r#"EFFECT.sepia_film = {
    DESCRIPTION = "a user's sepia"
    PASS = {
        tone = SHADER.sepia_tone { img = IN }
    }
    OUT = tone
}
"#;

const SEPIA_SHADER: &str = r#"@group(0) @binding(0) var img: texture_2d<f32>;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let y = dot(c.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
    return vec4<f32>(y * vec3<f32>(1.0, 0.9, 0.7), c.a);
}
"#;

#[test]
fn a_name_finds_the_file_in_the_current_folder() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("sepia_film.fx"), SEPIA).unwrap();
    std::fs::write(dir.path().join("sepia_tone.wgsl"), SEPIA_SHADER).unwrap();
    let o = fxrun_in(dir.path(), &["sepia_film", "--check"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = fxrun_in(dir.path(), &["sepia_film", "--describe"]);
    assert!(stdout(&o).contains("a user's sepia"), "{}", stdout(&o));
}

#[test]
fn effects_on_disk_override_the_built_ins() {
    let dir = tempfile::tempdir().unwrap();
    let builtin = fxrun_in(dir.path(), &["vignette", "--describe"]);
    assert!(builtin.status.success());
    assert!(!stdout(&builtin).contains("my own vignette"));
    std::fs::create_dir(dir.path().join("effects")).unwrap();
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("effects/vignette.fx"))
            .unwrap()
            .replace(
                "DESCRIPTION = \"Vignette:",
                "DESCRIPTION = \"my own vignette. Vignette:",
            );
    std::fs::write(dir.path().join("effects/vignette.fx"), &text).unwrap();
    let o = fxrun_in(dir.path(), &["vignette", "--describe"]);
    assert!(stdout(&o).contains("my own vignette"), "{}", stdout(&o));
    // ./vignette.fx comes before ./effects/vignette.fx
    std::fs::write(
        dir.path().join("vignette.fx"),
        text.replace("my own vignette", "the top one"),
    )
    .unwrap();
    let o = fxrun_in(dir.path(), &["vignette", "--describe"]);
    assert!(stdout(&o).contains("the top one"), "{}", stdout(&o));
}

#[test]
fn shaders_on_disk_override_built_in_shaders() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("shaders")).unwrap();
    // a vignette shader that does not compile: the run must read it
    std::fs::write(
        dir.path().join("shaders/vignette.wgsl"),
        "fn fs_main() -> f32 { return oops; }\n",
    )
    .unwrap();
    let o = fxrun_in(dir.path(), &["vignette", "--check"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("shaders/vignette.wgsl"), "{err}");
}
