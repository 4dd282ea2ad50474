//! Mutation fuzzing of every parser a user's file reaches: EFFECT scripts (through
//! the loader, lowering and planning), WGSL pass shaders (preprocessing and
//! reflection), MATERIAL files (parsing, shader lookup, settings, textures) and
//! material WGSL (surface and lighting shaders: preprocessing, naga, interface
//! checks), image files (header probe, then decode, as the CLI does), y4m streams,
//! ffprobe's JSON, glTF scenes, and RetroArch slang presets (the `.slangp` file,
//! and a `.slang` shader through the whole lowering to WGSL). Seeds are the repository's own files and the shared
//! corpus (by path, never copied); each execution applies 1–4 mutations (bit flips,
//! interesting bytes, deleted, duplicated or spliced ranges, truncation, numbers
//! replaced by boundary values) and checks that the parser returns (no panic
//! escapes, no abort), that what it accepts is consistent (an image has
//! `width × height` pixels, a compiled graph has no errors, every diagnostic
//! renders) and that what it rejects says so in words: no message holds a
//! dependency's `Debug` dump or panic text ([`FORBIDDEN`]).
//!
//! In the test suite each target runs 120 executions from a fixed seed, so CI is
//! deterministic and takes seconds. The long run is the same code from a random
//! seed, each target stopping at `FX_FUZZ_RUNS` executions or after
//! `FX_FUZZ_SECONDS`, whichever comes first (either may be left out):
//!
//! ```text
//! FX_FUZZ_RUNS=100000 FX_FUZZ_SECONDS=3600 cargo test --release --test fuzz -- --nocapture --test-threads 1
//! ```
//!
//! The targets run on `FX_FUZZ_THREADS` threads (default: the machine's cores),
//! the slowest first; every target prints its executions per second
//! (docs/architecture.md, "Fuzzing", gives the measured rates).
//!
//! A finding (a panic, or an accepted input that breaks an invariant) is written to
//! `target/fuzz-findings/TARGET-SEED-N.bin` and fails the test, naming the file. No
//! GPU is needed; glTF scenes are loaded and converted but not drawn.
//! `FX_FUZZ_SEED=N` replays a run; `FX_FUZZ_TARGETS=material,gltf` runs only those
//! targets.

mod common;

use common::compile::compile_file;
use common::rng::Rng;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
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
type Check = Box<dyn Fn(&[u8], &Path) -> Result<bool, String> + Send + Sync>;

/// What no message to a user may hold: panic text, the png crate's `Debug` chunk
/// type, an `Option`'s or naga handle's `Debug` form, wgpu's validation chain.
const FORBIDDEN: &[&str] = &[
    "panicked at",
    "RUST_BACKTRACE",
    "ChunkType {",
    "Some(",
    "Handle(",
    "Caused by:",
    // naga's type dumps in a WGSL message (issue 29: `Struct { members:
    // [StructMember { name: Some("w"), ...` for a struct)
    "Struct { members",
    "StructMember {",
    "Vector { size",
    "Scalar { kind",
    "Matrix { columns",
];

/// `Ok(false)` (rejected) when `message` is clean, a finding otherwise.
fn rejected_with(message: &str) -> Result<bool, String> {
    match FORBIDDEN.iter().find(|f| message.contains(*f)) {
        Some(f) => Err(format!("`{f}` in a message: {message}")),
        None => Ok(false),
    }
}

/// How a target's check is given the mutated input: its bytes, or the file it
/// reads; under this file name either way (its extension picks the parser), and a
/// finding is replayed from a file of that name.
enum Input {
    Bytes(&'static str),
    File(&'static str),
}

struct Target {
    name: &'static str,
    seeds: Vec<Vec<u8>>,
    /// File name the mutated input is given as (its extension picks the parser).
    file: &'static str,
    /// Whether the check reads the file (otherwise it takes the bytes, and the
    /// file is written only for a finding to be replayed).
    reads_file: bool,
    check: Check,
}

impl Target {
    fn new(
        name: &'static str,
        input: Input,
        seeds: Vec<Vec<u8>>,
        check: impl Fn(&[u8], &Path) -> Result<bool, String> + Send + Sync + 'static,
    ) -> Target {
        let (file, reads_file) = match input {
            Input::Bytes(file) => (file, false),
            Input::File(file) => (file, true),
        };
        Target {
            name,
            seeds,
            file,
            reads_file,
            check: Box::new(check),
        }
    }
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

/// The repository's files with the extension `ext` in the folders `dirs`, of
/// 64 KiB at most: the seeds of a target.
fn repository_seeds(dirs: &[&str], ext: &str) -> Vec<Vec<u8>> {
    let paths: Vec<PathBuf> = dirs
        .iter()
        .flat_map(|d| files(&root().join(d), &[ext], 64 << 10))
        .collect();
    read_all(&paths)
}

/// Every diagnostic rendered; a finding when one holds a [`FORBIDDEN`] form.
fn render_all(d: &Diagnostics, s: &SourceMap) -> Result<(), String> {
    rejected_with(&d.render(s)).map(|_| ())
}

fn script_target() -> Target {
    let seeds = repository_seeds(&["effects", "tests/diagnostics"], "fx");
    Target::new("script", Input::File("fuzz.fx"), seeds, |_, path| {
        let (graph, diags, sources) = compile_file(path);
        render_all(&diags, &sources)?;
        let Some(g) = graph else { return Ok(false) };
        if diags.has_errors() {
            return Err("a graph came back with errors".into());
        }
        let input = InputDesc::rgba8_srgb(64, 48).with_aux(&fxgraph::render::published_aux(true));
        match plan(&g, &input, &PlanOptions::default()) {
            Ok((_, notes)) => render_all(&notes, &sources)?,
            Err(d) => {
                render_all(&d, &sources)?;
                return Ok(false);
            }
        }
        Ok(true)
    })
}

fn wgsl_target() -> Target {
    // The pass shaders: shaders/effects/<effect>/*.wgsl and shaders/engine/.
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root().join("shaders/effects"))
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    dirs.retain(|d| d.is_dir());
    dirs.sort();
    dirs.push(root().join("shaders/engine"));
    let paths: Vec<PathBuf> = dirs
        .iter()
        .flat_map(|d| files(d, &["wgsl"], 64 << 10))
        .collect();
    let seeds = read_all(&paths);
    Target::new("wgsl", Input::Bytes("fuzz.wgsl"), seeds, |bytes, _| {
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
                render_all(&d, &sources)?;
                Ok(false)
            }
        }
    })
}

/// MATERIAL files: the repository's and the docs' example, loaded next to the
/// docs' example shaders (`stripes.wgsl`, `wrap_lambert.wgsl`), as `--materials`.
fn material_target() -> Target {
    let seeds = repository_seeds(&["materials", "docs/examples"], "fx");
    Target::new("material", Input::Bytes("fuzz.fx"), seeds, |bytes, path| {
        let text = String::from_utf8_lossy(bytes);
        let dir = root().join("docs/examples");
        match fxgraph::scene::material_file::load_materials(
            &path.display().to_string(),
            &text,
            Some(&dir),
            0,
        ) {
            Ok(_) => Ok(true),
            Err(rendered) => rejected_with(&rendered),
        }
    })
}

/// Material shaders (surface and lighting), with their `#include`s of the
/// built-in library, checked as a user's file of that kind.
fn material_wgsl_target() -> Target {
    let seeds = repository_seeds(
        &["shaders/materials", "shaders/lib", "docs/examples"],
        "wgsl",
    );
    // A file: its `#include`s are looked up from the file's canonical path.
    let input = Input::File("fuzz_material.wgsl");
    Target::new("material-wgsl", input, seeds, |bytes, path| {
        use fxgraph::shader::{load_material_shader, MaterialShaderKind, ShaderFile};
        let text = String::from_utf8_lossy(bytes).into_owned();
        let kind = if text.contains("fn surface") {
            MaterialShaderKind::Surface
        } else {
            MaterialShaderKind::Lighting
        };
        let file = ShaderFile {
            shown: path.display().to_string(),
            text,
            path: Some(path.to_path_buf()),
        };
        let mut sources = SourceMap::new();
        match load_material_shader(kind, "fuzz_material", file, &mut sources) {
            Ok(_) => Ok(true),
            Err(list) => {
                render_all(&Diagnostics { list }, &sources)?;
                Ok(false)
            }
        }
    })
}

fn image_target(name: &'static str, file: &'static str, seeds: Vec<Vec<u8>>) -> Target {
    Target::new(name, Input::Bytes(file), seeds, |bytes, path| {
        // As the CLI: the header is probed (and its size checked) first.
        let (w, h) = match fxgraph::io::image_dimensions(bytes, path) {
            Ok(d) => d,
            Err(e) => return rejected_with(&e.to_string()),
        };
        let img = match fxgraph::io::decode_image(bytes, path, &Default::default()) {
            Ok(i) => i,
            Err(e) => return rejected_with(&e.to_string()),
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
    })
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
    Target::new("y4m", Input::Bytes("fuzz.y4m"), seeds, |bytes, _| {
        let mut r = match Y4mReader::new(bytes, "fuzz") {
            Ok(r) => r,
            Err(e) => return rejected_with(&e.to_string()),
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
                Err(e) => return rejected_with(&e.to_string()),
            }
        }
    })
}

/// ffprobe's JSON for a video: the stream tags and the HDR side data (mastering
/// display, content light level) that `--input-color` and the encoder read.
/// Seeds: an SDR BT.709 stream with audio, a PQ stream with its metadata on the
/// stream, an HLG one with it on the first frame.
fn video_probe_target() -> Target {
    let stream = |extra: &str| {
        format!(
            r#"{{"streams":[{{"index":0,"codec_name":"hevc","codec_type":"video","width":3840,"height":2160,"pix_fmt":"yuv420p10le","bits_per_raw_sample":"10","r_frame_rate":"24000/1001","avg_frame_rate":"24000/1001","field_order":"progressive","nb_frames":"48","duration":"2.002000","disposition":{{"attached_pic":0}}{extra}}},{{"index":1,"codec_name":"flac","codec_type":"audio","disposition":{{"attached_pic":0}}}}],"format":{{"duration":"2.002000"}}"#
        )
    };
    let mastering = r#"{"side_data_type":"Mastering display metadata","red_x":"34000/50000","red_y":"16000/50000","green_x":"13250/50000","green_y":"34500/50000","blue_x":"7500/50000","blue_y":"3000/50000","white_point_x":"15635/50000","white_point_y":"16450/50000","min_luminance":"50/10000","max_luminance":"10000000/10000"}"#;
    let light =
        r#"{"side_data_type":"Content light level metadata","max_content":1000,"max_average":400}"#;
    let seeds: Vec<Vec<u8>> = [
        stream(r#","color_range":"tv","color_space":"bt709","color_transfer":"bt709","color_primaries":"bt709""#)
            + "}",
        stream(&format!(
            r#","color_range":"tv","color_space":"bt2020nc","color_transfer":"smpte2084","color_primaries":"bt2020","side_data_list":[{mastering},{light}]"#
        )) + "}",
        stream(r#","color_range":"pc","color_space":"bt2020nc","color_transfer":"arib-std-b67","color_primaries":"bt2020""#)
            + format!(r#","frames":[{{"side_data_list":[{mastering},{light}]}}]}}"#).as_str(),
    ]
    .into_iter()
    .map(String::into_bytes)
    .collect();
    Target::new(
        "video-probe",
        Input::Bytes("fuzz.json"),
        seeds,
        |bytes, _| {
            use fxgraph::io::video::{parse_probe, video_color};
            let info = match parse_probe(Path::new("fuzz.mkv"), bytes) {
                Ok(info) => info,
                Err(e) => return rejected_with(&e.to_string()),
            };
            if info.width == 0 || info.height == 0 {
                return Err(format!("accepted a {}x{} stream", info.width, info.height));
            }
            let _ = info.hdr.peak_nits();
            let _ = info.hdr.encoder_params("libx265");
            match video_color(&info) {
                Ok(c) => {
                    for w in &c.warnings {
                        rejected_with(w)?;
                    }
                    Ok(true)
                }
                Err(e) => rejected_with(&e),
            }
        },
    )
}

/// The corpus's `.slangp` presets (librashader-presets' parser: keys, quoting,
/// `#reference`, wildcards), parsed as fxrun parses a preset argument.
fn slangp_target() -> Target {
    let mut paths = Vec::new();
    for dir in [
        "crt",
        "deinterlacing",
        "edge-smoothing/xbr/other presets",
        "handheld",
        "subframe-bfi",
        "presets/blurs",
        "stereoscopic-3d",
    ] {
        paths.extend(files(
            &corpus().join("slang").join(dir),
            &["slangp"],
            16 << 10,
        ));
    }
    // Paths made absolute, so that the mutated copy, parsed from the work
    // folder, still finds its shaders and LUTs.
    let seeds = paths
        .iter()
        .map(|p| absolute_preset_paths(&std::fs::read_to_string(p).unwrap(), p.parent().unwrap()))
        .collect();
    Target::new("slangp", Input::File("fuzz.slangp"), seeds, |_, path| {
        match fxgraph::slang::parse_preset(path) {
            Ok(_) => Ok(true),
            Err(e) => rejected_with(&e.to_string()),
        }
    })
}

/// A preset's text with each relative file value (`shader0 = x.slang`, LUTs,
/// `#reference`) made absolute against `dir`.
fn absolute_preset_paths(text: &str, dir: &Path) -> Vec<u8> {
    let file = |v: &str| [".slang", ".slangp", ".png"].iter().any(|e| v.ends_with(e));
    let mut out = String::new();
    for line in text.lines() {
        let (head, value) = match line.split_once('=') {
            Some((k, v)) => (format!("{k}= "), v.trim().trim_matches('"')),
            None => match line.strip_prefix("#reference") {
                Some(v) => ("#reference ".to_string(), v.trim().trim_matches('"')),
                None => (String::new(), ""),
            },
        };
        if file(value) && !Path::new(value).is_absolute() {
            out.push_str(&format!("{head}\"{}\"\n", dir.join(value).display()));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out.into_bytes()
}

/// A one-pass preset's `.slang` shader through the whole lowering: the
/// preprocessor (`#pragma`s; includes), glslang, librashader's reflection and
/// naga translation, fxgraph's rewrites (matrix varyings, built-ins, uniforms,
/// vertex stage) and the generated WGSL. Seeds: small single-file shaders of the
/// corpus. An accepted shader's generated folder is removed again.
fn slang_shader_target() -> Target {
    let mut paths = Vec::new();
    for dir in [
        "crt/shaders",
        "pixel-art-scaling/shaders",
        "scanlines/shaders",
        "handheld/shaders",
        "handheld/shaders/color",
        "subframe-bfi/shaders",
    ] {
        paths.extend(files(
            &corpus().join("slang").join(dir),
            &["slang"],
            8 << 10,
        ));
    }
    let seeds = read_all(&paths);
    Target::new(
        "slang-shader",
        Input::File("fuzz.slang"),
        seeds,
        |_, path| {
            let preset = path.with_file_name("fuzz.slangp");
            std::fs::write(&preset, "shaders = 1\nshader0 = fuzz.slang\n").unwrap();
            match fxgraph::slang::lower_preset(&preset) {
                Ok(lowered) => {
                    if let Some(dir) = lowered.fx.parent() {
                        let _ = std::fs::remove_dir_all(dir);
                    }
                    Ok(true)
                }
                Err(e) => rejected_with(&e.to_string()),
            }
        },
    )
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
    let seeds = read_all(&paths);
    Target::new("gltf", Input::File("fuzz.gltf"), seeds, |bytes, path| {
        // `.glb` when the bytes say so (the loader reads the magic).
        let path = if bytes.starts_with(b"glTF") {
            let glb = path.with_extension("glb");
            std::fs::write(&glb, bytes).unwrap();
            glb
        } else {
            path.to_path_buf()
        };
        match fxgraph::scene::gltf::load_gltf(&path) {
            Ok(_) => Ok(true),
            Err(e) => rejected_with(&e.to_string()),
        }
    })
}

struct Outcome {
    runs: u64,
    accepted: u64,
    findings: Vec<String>,
    elapsed: Duration,
}

fn run_target(t: &Target, seed: u64, budget: Budget, work: &Path) -> Outcome {
    let mut rng = Rng(seed | 1);
    let mut out = Outcome {
        runs: 0,
        accepted: 0,
        findings: Vec::new(),
        elapsed: Duration::ZERO,
    };
    assert!(!t.seeds.is_empty(), "{}: no seed files", t.name);
    // A folder per target: targets run in parallel, and some share a file name.
    let work = work.join(t.name.replace('/', "_"));
    std::fs::create_dir_all(&work).unwrap();
    let path = work.join(t.file);
    let start = Instant::now();
    loop {
        if budget.runs.is_some_and(|n| out.runs >= n)
            || budget.time.is_some_and(|d| start.elapsed() >= d)
        {
            break;
        }
        let s = &t.seeds[rng.below(t.seeds.len())];
        let o = &t.seeds[rng.below(t.seeds.len())];
        let input = mutate(&mut rng, s, o);
        if t.reads_file {
            std::fs::write(&path, &input).unwrap();
        }
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
            let f = dir.join(format!(
                "{}-{seed}-{}.bin",
                t.name.replace('/', "_"),
                out.runs
            ));
            std::fs::write(&f, &input).unwrap();
            out.findings.push(format!("{}: {p}", f.display()));
        }
    }
    out.elapsed = start.elapsed();
    out
}

/// Each target stops at the first limit reached.
#[derive(Clone, Copy)]
struct Budget {
    runs: Option<u64>,
    time: Option<Duration>,
}

#[test]
fn parsers_survive_mutated_inputs() {
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let (runs, seconds) = (env("FX_FUZZ_RUNS"), env("FX_FUZZ_SECONDS"));
    // The suite's run: 120 executions per target from a fixed seed. A run with
    // either variable set is a long run, from a random seed.
    let budget = Budget {
        runs: runs.or(if seconds.is_some() { None } else { Some(120) }),
        time: seconds.map(Duration::from_secs),
    };
    let seed = env("FX_FUZZ_SEED").unwrap_or(if runs.is_none() && seconds.is_none() {
        0x5eed
    } else {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(1, |d| d.as_nanos() as u64)
            ^ u64::from(std::process::id())
    });
    // The slowest target first, so that the threads end together.
    let mut targets = vec![
        material_target(),
        script_target(),
        wgsl_target(),
        material_wgsl_target(),
        slang_shader_target(),
        y4m_target(),
        video_probe_target(),
        slangp_target(),
    ];
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
    for t in &targets {
        assert!(!t.seeds.is_empty(), "{}: no seed files", t.name);
    }
    // `FX_FUZZ_TARGETS=material,gltf`: only those (a replay, a measurement).
    if let Ok(only) = std::env::var("FX_FUZZ_TARGETS") {
        let only: Vec<&str> = only.split(',').map(str::trim).collect();
        targets.retain(|t| only.contains(&t.name));
        assert!(
            !targets.is_empty(),
            "FX_FUZZ_TARGETS={only:?} names no target"
        );
    }
    // The targets on `FX_FUZZ_THREADS` threads, each taking the next target.
    let threads = env("FX_FUZZ_THREADS").map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |n| n.max(1) as usize,
    );
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                let Some(t) = targets.get(i) else { break };
                let o = run_target(t, seed, budget, dir.path());
                let secs = o.elapsed.as_secs_f64();
                eprintln!(
                    "fuzz {:26} seed {seed:#x}: {} executions in {secs:.1} s ({:.0}/s), {} mutated inputs accepted, {} findings",
                    t.name,
                    o.runs,
                    o.runs as f64 / secs.max(1e-9),
                    o.accepted,
                    o.findings.len()
                );
                failures.lock().unwrap().extend(o.findings);
            });
        }
    });
    let failures = failures.into_inner().unwrap();
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
    slang_stage_inputs_are_named_in_words();
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
        let r = catch_unwind(|| compile_file(&path));
        let (graph, diags, sources) = r.unwrap_or_else(|_| panic!("case {i} panicked"));
        assert!(graph.is_none(), "case {i} compiled");
        assert!(
            diags.render(&sources).contains("frame offset"),
            "case {i}: {}",
            diags.render(&sources)
        );
    }
}

/// A slang vertex stage reading `TexCoord` at location 5 (the `slang-shader`
/// target's finding, seed 0x18ebf040ca48573a): the message named naga's
/// `Some(Location { .. })`.
fn slang_stage_inputs_are_named_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let shader = common::slang::one_pass_shader("", "FragColor = texture(Source, vTexCoord);", "")
        .replace(
            "layout(location = 1) in vec2 TexCoord;",
            "layout(location = 5) in vec2 TexCoord;",
        );
    std::fs::write(dir.path().join("s.slang"), shader).unwrap();
    let preset = dir.path().join("s.slangp");
    std::fs::write(&preset, "shaders = 1\nshader0 = s.slang\n").unwrap();
    let message = match fxgraph::slang::lower_preset(&preset) {
        Ok(_) => panic!("a vertex input at location 5 was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        message.contains("the vertex input at location 5") && rejected_with(&message).is_ok(),
        "{message}"
    );
}
