//! Batches of still images through the real `fxrun`: mixed sizes equal one-image runs
//! exactly, names and formats are kept, patterns number, failures stop the batch or
//! not (`--keep-going`), and temporal effects refuse frames of different sizes.

use crate::common::cli::{apply, arg as s, exits, exits_with, fxrun_line, names};
use crate::common::{self, gpu_scratch, image_u8, pattern_u8};

use std::path::{Path, PathBuf};

/// Writes a test pattern of `w`x`h` to `path` (format from the extension); the
/// `seed` shifts the pattern so the images differ.
fn write_image(path: &Path, w: u32, h: u32, seed: u32) {
    let base = pattern_u8(w + seed, h);
    let img = image_u8(w, h, |x, y| {
        let i = ((y * (w + seed) + x + seed) * 4) as usize;
        match &base.pixels {
            fxgraph::io::Pixels::U8(v) => [v[i], v[i + 1], v[i + 2], 255],
            _ => unreachable!(),
        }
    });
    fxgraph::io::save_image(path, w, h, &img.pixels, &Default::default()).unwrap();
}

/// A folder `dir/name` of test patterns: (file name, width, height, seed).
fn images(dir: &Path, name: &str, files: &[(&str, u32, u32, u32)]) -> PathBuf {
    let d = dir.join(name);
    std::fs::create_dir_all(&d).unwrap();
    for &(f, w, h, seed) in files {
        write_image(&d.join(f), w, h, seed);
    }
    d
}

/// The folder of the batch: three images of different sizes and formats, and a file
/// that is not an image.
fn photos(dir: &Path) -> PathBuf {
    let files = [
        ("a.png", 96, 64, 0),
        ("b.jpg", 64, 128, 3),
        ("c.png", 80, 80, 7),
    ];
    let d = images(dir, "photos", &files);
    std::fs::write(d.join("notes.txt"), "not an image").unwrap();
    d
}

fn pixels(p: &Path) -> fxgraph::io::Image {
    fxgraph::io::load_image(p, &Default::default())
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// `fxrun glow -i IN -o OUT` for one image.
fn single(input: &Path, output: &Path) {
    exits(&apply("glow", input, output, &[]), 0);
}

#[test]
fn mixed_size_folder_equals_one_image_runs_exactly() {
    let Some(dir) = gpu_scratch() else { return };
    let photos = photos(dir.path());
    let out = dir.path().join("out");
    let e = exits(&apply("glow", &photos, &out, &["-v"]), 0);
    assert!(e.contains("skipped") && e.contains("notes.txt"), "{e}");
    assert!(e.contains("3 images in"), "{e}");
    assert!(e.contains("per image (median)"), "{e}");
    // Names and formats kept.
    assert_eq!(names(&out), ["a.png", "b.jpg", "c.png"]);
    let one = dir.path().join("one");
    std::fs::create_dir_all(&one).unwrap();
    for (name, size) in [
        ("a.png", (96, 64)),
        ("b.jpg", (64, 128)),
        ("c.png", (80, 80)),
    ] {
        single(&photos.join(name), &one.join(name));
        let (batch, alone) = (pixels(&out.join(name)), pixels(&one.join(name)));
        assert_eq!((batch.width, batch.height), size, "{name}");
        assert_eq!(batch.source.format, alone.source.format, "{name}");
        assert!(
            batch.pixels == alone.pixels,
            "{name}: batch differs from a one-image run"
        );
    }
}

#[test]
fn wildcards_lists_and_patterns_name_the_outputs() {
    let Some(dir) = gpu_scratch() else { return };
    let photos = photos(dir.path());
    // A quoted wildcard, expanded by fxrun, numbered into a pattern (names without
    // numbers: by position in name order).
    let glob = format!("{}/*.png", s(&photos));
    let numbered = dir.path().join("numbered/%03d.png");
    exits(&apply("glow", &glob, &numbered, &[]), 0);
    let ndir = dir.path().join("numbered");
    assert_eq!(names(&ndir), ["000.png", "001.png"]);
    // Several inputs after one -i (as a shell expands photos/*), --format for all.
    let conv = dir.path().join("conv");
    let (a, b) = (photos.join("a.png"), photos.join("b.jpg"));
    let o = fxrun_line("glow -i {} {} -o {} --format png", &[&b, &a, &conv]);
    exits(&o, 0);
    assert_eq!(names(&conv), ["a.png", "b.png"]);
    assert!(pixels(&ndir.join("000.png")).pixels == pixels(&conv.join("a.png")).pixels);
    // Repeated -i gives the same.
    let rep = dir.path().join("rep");
    let o = fxrun_line("glow -i {} -i {} -o {}", &[&photos.join("c.png"), &a, &rep]);
    exits(&o, 0);
    assert_eq!(names(&rep), ["a.png", "c.png"]);
    assert!(pixels(&rep.join("c.png")).pixels == pixels(&ndir.join("001.png")).pixels);
}

#[test]
fn the_effect_is_planned_again_only_when_the_size_changes() {
    let Some(dir) = gpu_scratch() else { return };
    let d = images(
        dir.path(),
        "in",
        &[
            ("x1.png", 40, 30, 0),
            ("x2.png", 40, 30, 1),
            ("y.png", 30, 40, 2),
        ],
    );
    let json = dir.path().join("report.json");
    let o = fxrun_line(
        "glow -i {} -o {} --timings-json {}",
        &[&d, &dir.path().join("out"), &json],
    );
    exits(&o, 0);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(r["frames_total"], 3, "{r}");
    assert_eq!(r["job"], "batch", "{r}");
    assert_eq!(r["plans"], 2, "x1 and x2 share a plan: {r}");
    assert_eq!(r["done"].as_array().map(Vec::len), Some(3), "{r}");
    assert_eq!(r["done"][2]["width"], 30, "{r}");
}

#[test]
fn a_failed_image_stops_the_batch_or_not_and_never_leaves_a_partial_file() {
    let Some(dir) = gpu_scratch() else { return };
    let photos = photos(dir.path());
    // b.jpg cut in half: a truncated JPEG.
    let b = photos.join("b.jpg");
    let bytes = std::fs::read(&b).unwrap();
    std::fs::write(&b, &bytes[..bytes.len() / 2]).unwrap();
    // Outputs from an earlier run: the failed image's and the one after it.
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("b.jpg"), "earlier b").unwrap();
    std::fs::write(out.join("c.png"), "earlier c").unwrap();
    let e = exits(&apply("glow", &photos, &out, &[]), 1);
    assert!(
        e.contains(&format!("{}:", b.display())),
        "names the file: {e}"
    );
    for needle in ["truncated", "1 of 3 images failed", "1 not run"] {
        assert!(e.contains(needle), "{e}");
    }
    // a.png finished before the failure; b and c untouched; no temporaries.
    assert_eq!(names(&out), ["a.png", "b.jpg", "c.png"]);
    assert_eq!(std::fs::read(out.join("b.jpg")).unwrap(), b"earlier b");
    assert_eq!(std::fs::read(out.join("c.png")).unwrap(), b"earlier c");
    pixels(&out.join("a.png"));

    let out2 = dir.path().join("out2");
    let o = apply("glow", &photos, &out2, &["--keep-going"]);
    let e = exits_with(
        &o,
        1,
        &[&format!("{}:", b.display()), "1 of 3 images failed"],
    );
    assert!(!e.contains("not run"), "{e}");
    assert_eq!(names(&out2), ["a.png", "c.png"]);
    assert_eq!((pixels(&out2.join("c.png")).width), 80);
}

#[test]
fn a_temporal_effect_refuses_frames_of_different_sizes_before_writing() {
    let Some(dir) = gpu_scratch() else { return };
    let sizes = [
        ("f1.png", 64, 48, 0),
        ("f2.png", 64, 48, 1),
        ("f3.png", 48, 64, 2),
    ];
    let frames = images(dir.path(), "frames", &sizes);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("000001.png"), "earlier").unwrap();
    let o = apply("temporal_denoise", &frames, &out, &[]);
    let e = exits_with(&o, 1, &[&format!("{}:", frames.join("f3.png").display())]);
    assert!(e.contains("48x64") && e.contains("64x48"), "{e}");
    assert_eq!(names(&out), ["000001.png"]);
    assert_eq!(std::fs::read(out.join("000001.png")).unwrap(), b"earlier");
    // The same frames as several inputs: a temporal effect needs one sequence.
    let (f1, f2) = (frames.join("f1.png"), frames.join("f2.png"));
    let o = fxrun_line("temporal_denoise -i {} {} -o {}", &[&f1, &f2, &out]);
    exits_with(&o, 1, &["reads other frames"]);
    // Frames of one size run as a sequence; -o DIR keeps their names there too.
    write_image(&frames.join("f3.png"), 64, 48, 2);
    let seq = dir.path().join("seq");
    exits(&apply("temporal_denoise", &frames, &seq, &[]), 0);
    assert_eq!(names(&seq), ["f1.png", "f2.png", "f3.png"]);
}

#[test]
fn batches_that_would_lose_data_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let photos = photos(dir.path());
    write_image(&photos.join("a.bmp"), 16, 16, 0);
    // Two inputs, one output name.
    let out = dir.path().join("out");
    let o = apply("glow", &photos, &out, &["--format", "png"]);
    exits_with(&o, 1, &["would both be written"]);
    assert!(names(&out).is_empty(), "{:?}", names(&out));
    // Writing over the inputs.
    let before = std::fs::read(photos.join("a.png")).unwrap();
    exits_with(
        &apply("glow", &photos, &photos, &[]),
        1,
        &["would replace the input"],
    );
    assert_eq!(std::fs::read(photos.join("a.png")).unwrap(), before);
    // Several inputs into one file name.
    let (a, c) = (photos.join("a.png"), photos.join("c.png"));
    let o = fxrun_line(
        "glow -i {} {} -o {}",
        &[&a, &c, &dir.path().join("one.png")],
    );
    exits_with(&o, 1, &["need an output folder"]);
    // An effect given after -i is named as such.
    let o = fxrun_line("-i {} glow -o {}", &[&a, &out]);
    exits_with(&o, 1, &["effects go before -i"]);
}

#[test]
fn the_header_probe_reads_sizes_without_decoding() {
    use fxgraph::io::image_file_dimensions;
    let dir = tempfile::tempdir().unwrap();
    let photos = photos(dir.path());
    assert_eq!(
        image_file_dimensions(&photos.join("a.png")).unwrap(),
        (96, 64)
    );
    assert_eq!(
        image_file_dimensions(&photos.join("b.jpg")).unwrap(),
        (64, 128)
    );
    // A truncated image still has its header: the size is known, the decode fails later.
    let cut = dir.path().join("cut.png");
    let bytes = std::fs::read(photos.join("c.png")).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert_eq!(image_file_dimensions(&cut).unwrap(), (80, 80));
    let e = image_file_dimensions(&photos.join("notes.txt")).unwrap_err();
    assert!(e.to_string().contains("not a recognised image"), "{e}");
    let empty = dir.path().join("empty.png");
    std::fs::write(&empty, b"").unwrap();
    assert!(image_file_dimensions(&empty).unwrap_err().is_input_error());
    let e = image_file_dimensions(&photos).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
}

/// The library's pipeline on the caller's memory: frames of three sizes as stills
/// (`Mode::Stills`) equal one-image runs (`apply_in_memory`) exactly, in order; the
/// same frames as a sequence are refused at the first frame of another size.
#[test]
fn memory_frames_of_mixed_sizes_through_the_pipeline() {
    use fxgraph::app::{
        apply_in_memory, run_frames, Device, Effect, JobKind, MemorySink, MemorySource, Mode,
        PipelineOptions,
    };
    use fxgraph::script::types::Format;
    let Some(mut engine) = common::engine() else {
        return;
    };
    let frames: Vec<fxgraph::io::Image> = [(40, 24), (17, 33), (40, 24)]
        .iter()
        .enumerate()
        .map(|(i, &(w, h))| {
            image_u8(w, h, |x, y| {
                [
                    (x * 9 + i as u32 * 40) as u8,
                    (y * 7) as u8,
                    ((x ^ y) * 5) as u8,
                    255,
                ]
            })
        })
        .collect();
    let chain = ["glow".to_string()];
    let mut effect = Effect::compile(&chain, &[]).unwrap();
    let sink = MemorySink::default();
    let out = sink.frames();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let opts = PipelineOptions {
        mode: Mode::Stills,
        job: JobKind::Batch,
        output_format: Format::Rgba8Srgb,
        ..Default::default()
    };
    let report = run_frames(
        Device::Engine(&mut engine),
        &mut effect,
        Box::new(MemorySource::new(frames.clone())),
        Box::new(sink),
        &opts,
        stop.clone(),
        |_| {},
    )
    .unwrap();
    assert_eq!(report.done.len(), 3, "{:?}", report.failed);
    assert_eq!(report.plans, 3, "a new plan per change of size");
    let out = out.lock().unwrap();
    for (i, img) in frames.iter().enumerate() {
        let (n, w, h, px) = &out[i];
        assert_eq!(*n, i as u64);
        let (ew, eh, expected) =
            apply_in_memory(&mut engine, &chain, &[], img, &[], Format::Rgba8Srgb, false).unwrap();
        assert_eq!((*w, *h), (ew, eh));
        assert!(*px == expected, "frame {i} differs from a one-image run");
    }
    // As a sequence: one size only, the error names the frame.
    let opts = PipelineOptions {
        mode: Mode::Sequence,
        ..opts
    };
    let err = run_frames(
        Device::Engine(&mut engine),
        &mut effect,
        Box::new(MemorySource::new(frames)),
        Box::new(MemorySink::default()),
        &opts,
        stop,
        |_| {},
    )
    .unwrap_err();
    assert!(err.is_input_error(), "{err}");
    assert!(
        err.to_string().contains("frame 1") && err.to_string().contains("17x33"),
        "{err}"
    );
}
