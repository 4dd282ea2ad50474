//! Mutation fuzzing of every parser a user's file reaches: EFFECT scripts (through
//! the loader, lowering and planning), WGSL pass shaders (preprocessing and
//! reflection), image files (header probe, then decode, as the CLI does), y4m
//! streams and glTF scenes. Seeds are the repository's own files and the shared
//! corpus (by path, never copied); each execution applies 1–4 mutations (bit flips,
//! interesting bytes, deleted, duplicated or spliced ranges, truncation, numbers
//! replaced by boundary values) and checks that the parser returns (no panic
//! escapes, no abort) and that what it accepts is consistent (an image has
//! `width × height` pixels, a compiled graph has no errors, every diagnostic
//! renders).
//!
//! In the test suite each target runs `FX_FUZZ_RUNS` executions (default 120) from a
//! fixed seed, so CI is deterministic and takes seconds. The long run is the same
//! code for a wall-clock budget per target, from a random seed:
//!
//! ```text
//! FX_FUZZ_SECONDS=1800 cargo test --release --test fuzz -- --nocapture --test-threads 1
//! ```
//!
//! A finding (a panic, or an accepted input that breaks an invariant) is written to
//! `target/fuzz-findings/TARGET-SEED-N.bin` and fails the test, naming the file. No
//! GPU is needed; glTF scenes are loaded and converted but not drawn.
//! `FX_FUZZ_SEED=N` replays a run.

mod common;

use common::rng::Rng;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use fxgraph::graph::{compile, CompileRequest};
use fxgraph::script::{Diagnostics, SourceMap};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "65535",
    "65536",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "2147483648",
    "-2147483649",
    "1e308",
    "1e-320",
    "0.5",
    "99999",
    "16385",
];

/// One mutated copy of `seed`; `other` supplies spliced chunks.
fn mutate(rng: &mut Rng, seed: &[u8], other: &[u8]) -> Vec<u8> {
    let mut d = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        let len = d.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                d[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                d[i] = [0u8, 0xff, 0x7f, 0x80, b'{', b'}', b'"', b'\n'][rng.below(8)];
            }
            2 if len > 1 => {
                let a = rng.below(len);
                let b = (a + 1 + rng.below(64)).min(len);
                d.drain(a..b);
            }
            3 if len > 1 => {
                let a = rng.below(len);
                let b = (a + 1 + rng.below(256)).min(len);
                let chunk = d[a..b].to_vec();
                let at = rng.below(len);
                d.splice(at..at, chunk);
            }
            4 if len > 1 => d.truncate(rng.below(len)),
            5 => {
                // A run of digits becomes a boundary value.
                let starts: Vec<usize> = (0..len)
                    .filter(|&i| d[i].is_ascii_digit() && (i == 0 || !d[i - 1].is_ascii_digit()))
                    .collect();
                if !starts.is_empty() {
                    let a = starts[rng.below(starts.len())];
                    let b = (a..len).find(|&i| !d[i].is_ascii_digit()).unwrap_or(len);
                    let n = NUMBERS[rng.below(NUMBERS.len())].as_bytes().to_vec();
                    d.splice(a..b, n);
                }
            }
            6 if !other.is_empty() => {
                let a = rng.below(other.len());
                let b = (a + 1 + rng.below(128)).min(other.len());
                let at = rng.below(len + 1);
                d.splice(at..at, other[a..b].iter().copied());
            }
            _ if len > 0 => {
                let i = rng.below(len);
                d[i] = rng.next() as u8;
            }
            _ => d.push(rng.next() as u8),
        }
    }
    d
}

/// One execution: `Ok(true)` the input was accepted, `Ok(false)` rejected with an
/// error, `Err(finding)` an accepted input that breaks an invariant.
type Check = Box<dyn Fn(&[u8], &Path) -> Result<bool, String>>;

struct Target {
    name: &'static str,
    seeds: Vec<Vec<u8>>,
    /// File name the mutated input is written as (its extension picks the parser).
    file: &'static str,
    check: Check,
}

fn files(dir: &Path, ext: &[&str], max_bytes: u64) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    // An empty `ext` takes every file.
    out.retain(|p| {
        (ext.is_empty()
            || p.extension()
                .is_some_and(|e| ext.iter().any(|x| e.eq_ignore_ascii_case(x))))
            && p.metadata()
                .is_ok_and(|m| m.is_file() && m.len() <= max_bytes)
    });
    out.sort();
    out
}

fn read_all(paths: &[PathBuf]) -> Vec<Vec<u8>> {
    paths.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn corpus() -> PathBuf {
    root().join("../shared/corpus")
}

fn render_all(d: &Diagnostics, s: &SourceMap) {
    let _ = d.render(s);
}

fn script_target() -> Target {
    let mut paths = files(&root().join("effects"), &["fx"], 64 << 10);
    paths.extend(files(&root().join("tests/diagnostics"), &["fx"], 64 << 10));
    Target {
        name: "script",
        seeds: read_all(&paths),
        file: "fuzz.fx",
        check: Box::new(|_, path| {
            let (graph, diags, sources) = compile(&CompileRequest {
                source: Some(std::sync::Arc::new(fxgraph::lookup::DiskEffects::default())),
                effects: vec![path.display().to_string()],
                ..Default::default()
            });
            render_all(&diags, &sources);
            let Some(g) = graph else { return Ok(false) };
            if diags.has_errors() {
                return Err("a graph came back with errors".into());
            }
            let input =
                InputDesc::rgba8_srgb(64, 48).with_aux(&fxgraph::render::published_aux(true));
            match plan(&g, &input, &PlanOptions::default()) {
                Ok((_, notes)) => render_all(&notes, &sources),
                Err(d) => {
                    render_all(&d, &sources);
                    return Ok(false);
                }
            }
            Ok(true)
        }),
    }
}

fn wgsl_target() -> Target {
    let paths = files(&root().join("shaders"), &["wgsl"], 64 << 10);
    Target {
        name: "wgsl",
        seeds: read_all(&paths),
        file: "fuzz.wgsl",
        check: Box::new(|bytes, _| {
            let text = String::from_utf8_lossy(bytes);
            let mut sources = SourceMap::new();
            let Ok((wgsl, _)) = fxgraph::shader::preprocess(&text, &[("N".into(), 3)]) else {
                return Ok(false);
            };
            // As the loader: spans point into the preprocessed text.
            let id = sources.add("fuzz.wgsl", wgsl.clone());
            match fxgraph::shader::reflect(&wgsl, id) {
                Ok(_) => Ok(true),
                Err(ds) => {
                    let mut d = Diagnostics::default();
                    ds.into_iter().for_each(|x| d.push(x));
                    render_all(&d, &sources);
                    Ok(false)
                }
            }
        }),
    }
}

fn image_target(name: &'static str, file: &'static str, seeds: Vec<Vec<u8>>) -> Target {
    Target {
        name,
        seeds,
        file,
        check: Box::new(|bytes, path| {
            // As the CLI: the header is probed (and its size checked) first.
            let Ok((w, h)) = fxgraph::io::image_dimensions(bytes, path) else {
                return Ok(false);
            };
            let Ok(img) = fxgraph::io::decode_image(bytes, path, &Default::default()) else {
                return Ok(false);
            };
            if (img.width, img.height) != (w, h) {
                return Err(format!(
                    "header says {w}x{h}, decoded {}x{}",
                    img.width, img.height
                ));
            }
            let want = img.width as usize * img.height as usize * 4;
            if img.pixels.len() != want {
                return Err(format!("{} samples for {w}x{h}", img.pixels.len()));
            }
            Ok(true)
        }),
    }
}

/// A small pattern saved in every format the library writes (seeds of the image
/// targets; the EXR is float).
fn generated_images(dir: &Path) -> Vec<(fxgraph::io::FileFormat, Vec<u8>)> {
    use fxgraph::io::{save_image, FileFormat, Pixels};
    let (w, h) = (23u32, 17u32);
    let mut out = Vec::new();
    for f in FileFormat::ALL {
        let path = dir.join(format!("seed.{}", f.extensions()[0]));
        let pixels = if f == FileFormat::Exr || f == FileFormat::Hdr {
            Pixels::F32((0..w * h * 4).map(|i| (i % 97) as f32 / 40.0).collect())
        } else {
            Pixels::U8((0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect())
        };
        if save_image(&path, w, h, &pixels, &Default::default()).is_ok() {
            out.push((f, std::fs::read(&path).unwrap()));
        }
    }
    out
}

fn y4m_target() -> Target {
    use fxgraph::io::y4m::{Chroma, Y4mHeader, Y4mReader, Y4mWriter, YuvFrame};
    let mut seeds = Vec::new();
    for chroma in [
        Chroma::from_tag("420jpeg").unwrap(),
        Chroma::from_tag("444").unwrap(),
    ] {
        let header = Y4mHeader::new(16, 8, chroma);
        let mut w = Y4mWriter::new(Vec::new(), header.clone(), "seed").unwrap();
        for _ in 0..3 {
            let frame = YuvFrame::black(&header, fxgraph::io::yuv::Range::Limited);
            w.write_frame(&frame).unwrap();
        }
        seeds.push(w.into_inner().unwrap());
    }
    Target {
        name: "y4m",
        seeds,
        file: "fuzz.y4m",
        check: Box::new(|bytes, _| {
            let Ok(mut r) = Y4mReader::new(bytes, "fuzz") else {
                return Ok(false);
            };
            let want = r.header().frame_bytes();
            let mut frames = 0;
            loop {
                match r.next_frame() {
                    Ok(Some(f)) => {
                        let got = f.y.len() + f.u.len() + f.v.len();
                        if got != want {
                            return Err(format!("frame of {got} bytes, header says {want}"));
                        }
                        frames += 1;
                        if frames * want > bytes.len() {
                            return Err("more frames than the bytes hold".into());
                        }
                    }
                    Ok(None) => return Ok(true),
                    Err(_) => return Ok(false),
                }
            }
        }),
    }
}

fn gltf_target() -> Target {
    let mut paths = vec![corpus().join("gltf/CornellBox.glb")];
    for dir in [
        "gltf/assimp/BoxTextured-glTF",
        "gltf/broken/IndexOutOfRange",
        "gltf/broken/RecursiveNodes",
        "gltf/broken/IncorrectVertexArrays",
        "gltf/animated/SimpleSkin",
        "gltf/animated/SimpleMorph",
        "gltf/animated/BoxAnimated",
        "gltf/animated/RiggedSimple",
    ] {
        paths.extend(files(&corpus().join(dir), &["gltf"], 64 << 10));
    }
    paths.retain(|p| p.exists());
    Target {
        name: "gltf",
        seeds: read_all(&paths),
        file: "fuzz.gltf",
        check: Box::new(|bytes, path| {
            // `.glb` when the bytes say so (the loader reads the magic).
            let path = if bytes.starts_with(b"glTF") {
                let glb = path.with_extension("glb");
                std::fs::write(&glb, bytes).unwrap();
                glb
            } else {
                path.to_path_buf()
            };
            Ok(fxgraph::scene::gltf::load_gltf(&path).is_ok())
        }),
    }
}

struct Outcome {
    runs: u64,
    accepted: u64,
    findings: Vec<String>,
}

fn run_target(t: &Target, seed: u64, budget: Budget, work: &Path) -> Outcome {
    let mut rng = Rng(seed | 1);
    let mut out = Outcome {
        runs: 0,
        accepted: 0,
        findings: Vec::new(),
    };
    assert!(!t.seeds.is_empty(), "{}: no seed files", t.name);
    let path = work.join(t.file);
    let start = Instant::now();
    loop {
        match budget {
            Budget::Runs(n) if out.runs >= n => break,
            Budget::Time(d) if start.elapsed() >= d => break,
            _ => {}
        }
        let s = &t.seeds[rng.below(t.seeds.len())];
        let o = &t.seeds[rng.below(t.seeds.len())];
        let input = mutate(&mut rng, s, o);
        std::fs::write(&path, &input).unwrap();
        let r = catch_unwind(AssertUnwindSafe(|| (t.check)(&input, &path)));
        out.runs += 1;
        let problem = match r {
            Ok(Ok(accepted)) => {
                out.accepted += u64::from(accepted && input != *s);
                None
            }
            Ok(Err(p)) => Some(p),
            Err(e) => Some(format!(
                "panic: {}",
                e.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default()
            )),
        };
        if let Some(p) = problem {
            let dir = root().join("target/fuzz-findings");
            std::fs::create_dir_all(&dir).unwrap();
            let f = dir.join(format!("{}-{seed}-{}.bin", t.name, out.runs));
            std::fs::write(&f, &input).unwrap();
            out.findings.push(format!("{}: {p}", f.display()));
        }
    }
    out
}

#[derive(Clone, Copy)]
enum Budget {
    Runs(u64),
    Time(Duration),
}

#[test]
fn parsers_survive_mutated_inputs() {
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let budget = match env("FX_FUZZ_SECONDS") {
        Some(s) => Budget::Time(Duration::from_secs(s)),
        None => Budget::Runs(env("FX_FUZZ_RUNS").unwrap_or(120)),
    };
    let seed = env("FX_FUZZ_SEED").unwrap_or(match budget {
        Budget::Runs(_) => 0x5eed,
        Budget::Time(_) => {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(1, |d| d.as_nanos() as u64)
                ^ u64::from(std::process::id())
        }
    });
    let mut targets = vec![script_target(), wgsl_target(), y4m_target()];
    let dir = tempfile::tempdir().unwrap();
    // Images: the README's photo, the corpus's small damaged EXRs, and a pattern in
    // every format. Each target writes its input under one extension (TGA has no
    // magic bytes, so the extension picks its decoder).
    let mut photos = read_all(&files(&root().join("examples/data"), &["jpg"], 512 << 10));
    // (The damaged EXRs are named `..._exr`, with no extension.)
    let mut exrs: Vec<Vec<u8>> = read_all(&files(&corpus().join("exr-damaged"), &[], 32 << 10))
        .into_iter()
        .filter(|b| b.starts_with(&[0x76, 0x2f, 0x31, 0x01]))
        .collect();
    let mut others = Vec::new();
    for (f, bytes) in generated_images(dir.path()) {
        use fxgraph::io::FileFormat;
        match f {
            FileFormat::Jpeg | FileFormat::Png => photos.push(bytes),
            FileFormat::Exr => exrs.push(bytes),
            FileFormat::Tga => targets.push(image_target("tga", "fuzz.tga", vec![bytes])),
            _ => others.push(bytes),
        }
    }
    targets.push(image_target("jpeg+png", "fuzz.img", photos));
    targets.push(image_target("exr", "fuzz.exr", exrs));
    targets.push(image_target(
        "tiff/bmp/hdr/webp/pnm/qoi",
        "fuzz.img",
        others,
    ));
    targets.push(gltf_target());
    let mut failures = Vec::new();
    for t in targets.iter().filter(|t| !t.seeds.is_empty()) {
        let o = run_target(t, seed, budget, dir.path());
        eprintln!(
            "fuzz {:10} seed {seed:#x}: {} executions, {} mutated inputs accepted, {} findings",
            t.name,
            o.runs,
            o.accepted,
            o.findings.len()
        );
        failures.extend(o.findings);
    }
    assert!(failures.is_empty(), "findings:\n{}", failures.join("\n"));
}

/// A file cut short is an error in every format, wherever the cut falls (a
/// truncated JPEG decoding to a grey bottom half was accepted once).
#[test]
fn truncated_images_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let mut seeds = generated_images(dir.path());
    for p in files(&root().join("examples/data"), &["jpg"], 512 << 10) {
        seeds.push((fxgraph::io::FileFormat::Jpeg, std::fs::read(p).unwrap()));
    }
    let mut accepted = Vec::new();
    for (f, bytes) in &seeds {
        let path = dir.path().join(format!("cut.{}", f.extensions()[0]));
        for pct in (5..100).step_by(5) {
            let cut = &bytes[..bytes.len() * pct / 100];
            let ok = fxgraph::io::image_dimensions(cut, &path).is_ok()
                && fxgraph::io::decode_image(cut, &path, &Default::default()).is_ok();
            if ok {
                accepted.push(format!("{} cut to {pct} %", f.name()));
            }
        }
    }
    assert!(accepted.is_empty(), "accepted: {accepted:?}");
}

/// Inputs the long run found, kept as regressions (each was a panic).
#[test]
fn findings_stay_fixed() {
    // A span ending inside a multi-byte character (naga on a damaged shader).
    let mut sources = SourceMap::new();
    let id = sources.add("x.wgsl", "let a = \u{FFFD}\u{FFFD};\nfn".to_string());
    let mut d = Diagnostics::default();
    d.push(
        fxgraph::script::Diagnostic::error("bad").at(fxgraph::script::Span::new(id, 9, 13), "here"),
    );
    assert!(d.render(&sources).contains("x.wgsl:1:9: error: bad"));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.fx");
    for (i, text) in [
        // `abs()` of i32::MIN when checking a frame offset (FX_FUZZ_SECONDS=40 run).
        "EFFECT.e = { PASS = { p = SHADER.copy { img = IN[-2147483648] } } OUT = p }",
        "EFFECT.e = { PASS = { p = SHADER.copy { img = IN[-99999999999999999999] } } OUT = p }",
        "EFFECT.e = { PASS = { p = SHADER.copy { img = PASS.p[-2147483648] } } OUT = p }",
    ]
    .into_iter()
    .enumerate()
    {
        std::fs::write(&path, text).unwrap();
        let r = catch_unwind(|| {
            compile(&CompileRequest {
                source: Some(std::sync::Arc::new(fxgraph::lookup::DiskEffects::default())),
                effects: vec![path.display().to_string()],
                ..Default::default()
            })
        });
        let (graph, diags, sources) = r.unwrap_or_else(|_| panic!("case {i} panicked"));
        assert!(graph.is_none(), "case {i} compiled");
        assert!(
            diags.render(&sources).contains("frame offset"),
            "case {i}: {}",
            diags.render(&sources)
        );
    }
}
