//! `fxrun` on frame sequences: patterns, sharding, resume, y4m pipes.

use crate::common::cli::{
    apply, arg as s, command, exits, exits_with, files, fxrun, fxrun_stdin, save, stderr, stdout,
    write, write_effect,
};
use crate::common::{gpu_scratch, image_u8};

use std::path::{Path, PathBuf};
use std::process::Stdio;

/// `n` frames `dir/f001.png`, ... of a moving pattern: frame i has a bright bar at
/// x = 3i.
fn write_frames(dir: &Path, n: u32) {
    std::fs::create_dir_all(dir).unwrap();
    for i in 0..n {
        let img = image_u8(40, 24, |x, y| {
            let bar = x / 3 == i;
            [
                if bar { 250 } else { (x * 5) as u8 },
                (y * 9) as u8,
                (i * 20) as u8,
                255,
            ]
        });
        save(&dir.join(format!("f{:03}.png", i + 1)), &img);
    }
}

/// A temporal effect without feedback, using history and future frames.
const TEMPORAL_FX: &str =
    "EFFECT.tmean = { PASS = { m = SHADER.tmean { a = IN[-1]  b = IN  c = IN[+1] } } OUT = m }";
const TEMPORAL_WGSL: &str = "@group(0) @binding(0) var a: texture_2d<f32>;
@group(0) @binding(1) var b: texture_2d<f32>;
@group(0) @binding(2) var c: texture_2d<f32>;
@fragment fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let q = vec2<i32>(pos.xy);
    return 0.25 * textureLoad(a, q, 0) + 0.5 * textureLoad(b, q, 0) + 0.25 * textureLoad(c, q, 0);
}
";

/// The effect `tmean.fx` in `dir` and the pattern of `n` frames written to `dir/in`:
/// (effect, input pattern).
fn setup(dir: &Path, n: u32) -> (String, PathBuf) {
    write_frames(&dir.join("in"), n);
    let fx = write_effect(dir, "tmean", TEMPORAL_FX, ("tmean", TEMPORAL_WGSL));
    (fx, dir.join("in/f%03d.png"))
}

/// `fxrun ID -i - -o OUTPUT` reading `stdin`, ID the identity effect.
fn identity_from_stdin(dir: &Path, output: &str, stdin: &[u8]) -> std::process::Output {
    let id = write(dir, "id.fx", "EFFECT.id = { OUT = IN }");
    fxrun_stdin(&[s(&id), "-i", "-", "-o", output], Some(stdin))
}

#[test]
fn three_slices_concatenate_to_one_run_byte_for_byte() {
    let Some(dir) = gpu_scratch() else { return };
    let (fx, input) = setup(dir.path(), 9);
    let whole = dir.path().join("whole/o%03d.png");
    let e = exits(&apply(&fx, &input, &whole, &[]), 0);
    assert!(e.is_empty(), "quiet when not a terminal: {e}");
    let sliced = dir.path().join("sliced/o%03d.png");
    for range in ["1..3", "4..6", "7..9"] {
        let o = apply(&fx, &input, &sliced, &["--frames", range]);
        assert_eq!(o.status.code(), Some(0), "{range}: {}", stderr(&o));
    }
    let (a, b) = (
        files(&dir.path().join("whole")),
        files(&dir.path().join("sliced")),
    );
    assert_eq!(a.len(), 9);
    assert_eq!(
        a.iter().map(|x| &x.0).collect::<Vec<_>>(),
        b.iter().map(|x| &x.0).collect::<Vec<_>>()
    );
    assert!(a == b, "sliced outputs differ from the single run");
    // Output numbering follows the input's (f001 -> o001).
    assert_eq!(a[0].0, "o001.png");
}

#[test]
fn skip_existing_resumes_and_feedback_slices_warn() {
    let Some(dir) = gpu_scratch() else { return };
    let (fx, input) = setup(dir.path(), 6);
    let out = dir.path().join("out/o%03d.png");
    exits(&apply(&fx, &input, &out, &["--frames", "1..3"]), 0);
    let before = files(&dir.path().join("out"));
    assert_eq!(before.len(), 3);
    // A stale temporary of a killed run is cleaned up.
    std::fs::write(dir.path().join("out/.o004.png.fxtmp-999999-0"), b"partial").unwrap();
    exits(&apply(&fx, &input, &out, &["--skip-existing"]), 0);
    let after = files(&dir.path().join("out"));
    assert_eq!(
        after.len(),
        6,
        "{:?}",
        after.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert_eq!(&after[..3], &before[..]);
    // Resuming again does nothing.
    let e = stderr(&apply(&fx, &input, &out, &["--skip-existing"]));
    assert!(e.contains("every output frame exists"), "{e}");
    // An effect with feedback warns when sliced.
    let fb =
        "EFFECT.fb = { PASS = { m = SHADER.tmean { a = PASS.m[-1]  b = IN  c = IN } } OUT = m }";
    let fb = write(dir.path(), "fb.fx", fb);
    let o = fxrun(&[s(&fb), "--describe"]);
    assert!(stdout(&o).contains("uses feedback"));
    let fbo = dir.path().join("fbo/%d.png");
    let o = apply(&fb, &input, fbo, &["--frames", "3..4"]);
    exits_with(&o, 0, &["uses feedback"]);
}

fn y4m_stream(w: u32, h: u32, frames: u32) -> Vec<u8> {
    let mut s = format!("YUV4MPEG2 W{w} H{h} F25:1 Ip A1:1 C444\n").into_bytes();
    for i in 0..frames {
        s.extend_from_slice(b"FRAME\n");
        for p in 0..3 {
            for y in 0..h {
                for x in 0..w {
                    // In gamut: mid luma, moderate chroma (no RGB clipping on the way).
                    let v = match p {
                        0 => 50 + ((x * 7 + y * 3 + i * 11) % 150),
                        1 => 122 + (x % 12),
                        _ => 134 - (y % 12),
                    };
                    s.push(v as u8);
                }
            }
        }
    }
    s
}

#[test]
fn y4m_round_trip_through_an_identity_effect() {
    let Some(dir) = gpu_scratch() else { return };
    let input = y4m_stream(32, 16, 3);
    let o = identity_from_stdin(dir.path(), "-", &input);
    exits(&o, 0);
    let out = o.stdout;
    let header_end = out.iter().position(|&b| b == b'\n').unwrap();
    assert_eq!(
        &out[..header_end],
        &input[..input.iter().position(|&b| b == b'\n').unwrap()],
        "header passed on"
    );
    assert_eq!(out.len(), input.len());
    // Within the YCbCr quantisation (8-bit RGB in between).
    let max = out
        .iter()
        .zip(&input)
        .map(|(a, b)| (*a as i32 - *b as i32).abs())
        .max()
        .unwrap();
    assert!(max <= 2, "max difference {max}");
}

#[test]
fn truncated_y4m_is_an_error_naming_the_frame() {
    let Some(dir) = gpu_scratch() else { return };
    let mut input = y4m_stream(32, 16, 3);
    input.truncate(input.len() - 100);
    let frames = dir.path().join("o%02d.png");
    let o = identity_from_stdin(dir.path(), s(&frames), &input);
    exits_with(&o, 1, &["frame 2"]);
    exits(&identity_from_stdin(dir.path(), "-", b"NOT A Y4M\n"), 1);
}

/// Ctrl-C (SIGINT) mid-sequence: exit 130, every written frame complete, no
/// temporary left, and `--skip-existing` finishes the rest.
#[cfg(unix)]
#[test]
fn interrupt_leaves_complete_frames_and_resumes() {
    let Some(dir) = gpu_scratch() else { return };
    let n = 120;
    let (fx, input) = setup(dir.path(), n);
    let out_dir = dir.path().join("out");
    let out = out_dir.join("o%03d.png");
    let mut child = command([&fx, "-i", s(&input), "-o", s(&out), "--queue", "1"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the first frames, then interrupt.
    let t0 = std::time::Instant::now();
    while std::fs::read_dir(&out_dir).map(|d| d.count()).unwrap_or(0) < 3 {
        assert!(t0.elapsed().as_secs() < 60, "no output appeared");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    let written: Vec<_> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(
        written
            .iter()
            .all(|p| !p.to_string_lossy().contains("fxtmp")),
        "temporary left: {written:?}"
    );
    for p in &written {
        fxgraph::io::load_image(p, &Default::default())
            .unwrap_or_else(|e| panic!("incomplete frame {}: {e}", p.display()));
    }
    eprintln!(
        "interrupted after {} of {n} frames, status {status:?}",
        written.len()
    );
    // The signal comes after 3 of 120 frames (here it stopped after about 8).
    assert!(written.len() < n as usize, "the run was not interrupted");
    assert_eq!(status.code(), Some(130), "an interrupted run exits 130");
    exits(&apply(&fx, &input, &out, &["--skip-existing"]), 0);
    assert_eq!(std::fs::read_dir(&out_dir).unwrap().count(), n as usize);
}
