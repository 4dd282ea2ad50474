//! Integration tests of the image file layer (`fxgraph::io`).
#![cfg(feature = "gpu")]

use std::path::{Path, PathBuf};
use std::time::Instant;

use fxgraph::io::{
    load_image, load_image_from_memory, save_image, srgb, write_atomic, FileFormat, Image, IoError,
    LoadOptions, Pixels, SaveOptions,
};

fn corpus() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/corpus"))
}

/// A corpus sub-folder, or `None` (with a message) when the corpus is not installed.
fn corpus_dir(sub: &str) -> Option<PathBuf> {
    let d = corpus().join(sub);
    if d.is_dir() {
        Some(d)
    } else {
        eprintln!("skipping: corpus folder {} is absent", d.display());
        None
    }
}

fn load(p: &Path) -> Image {
    load_image(p, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn save(p: &Path, w: u32, h: u32, px: &Pixels, bits: Option<u8>) {
    let opts = SaveOptions {
        bit_depth: bits,
        ..Default::default()
    };
    save_image(p, w, h, px, &opts).unwrap_or_else(|e| panic!("{e}"));
}

fn u8s(img: &Image) -> &[u8] {
    match &img.pixels {
        Pixels::U8(v) => v,
        Pixels::F32(_) => panic!("expected U8 pixels, got F32 ({:?})", img.source),
    }
}

fn f32s(img: &Image) -> &[f32] {
    match &img.pixels {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("expected F32 pixels, got U8 ({:?})", img.source),
    }
}

/// Deterministic RGBA bytes with every alpha value in use.
fn pattern_u8(w: u32, h: u32) -> Vec<u8> {
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            v.extend_from_slice(&[
                (x * 7 + y * 3) as u8,
                (i.wrapping_mul(2654435761) >> 24) as u8,
                (y * 11) as u8,
                (i * 13 + 5) as u8,
            ]);
        }
    }
    v
}

fn opaque(mut v: Vec<u8>) -> Vec<u8> {
    for p in v.chunks_exact_mut(4) {
        p[3] = 255;
    }
    v
}

/// Linear floats in [0, 1] covering dark and bright values, alpha varied.
fn pattern_f32(w: u32, h: u32) -> Vec<f32> {
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let fx = x as f32 / (w.max(2) - 1) as f32;
            let fy = y as f32 / (h.max(2) - 1) as f32;
            v.extend_from_slice(&[fx * fx * fx, fy, (fx + fy) * 0.5, 1.0 - fx * 0.75]);
        }
    }
    v
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn dir_names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

// ---------------------------------------------------------------------------------------
// sRGB

#[test]
fn srgb_reference_values() {
    assert_eq!(srgb::srgb_to_linear(0.0), 0.0);
    assert_eq!(srgb::srgb_to_linear(1.0), 1.0);
    assert!((srgb::srgb_to_linear(0.5) - 0.214_041_14).abs() < 1e-7);
    assert!((srgb::linear_to_srgb(0.214_041_14) - 0.5).abs() < 1e-6);
    assert!((srgb::srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-9);
    let lut = srgb::decode_lut_u8();
    assert_eq!(lut[0], 0.0);
    assert_eq!(lut[255], 1.0);
    assert!((lut[128] - 0.215_860_5).abs() < 1e-6);
    for v in 0..=255u8 {
        assert_eq!(srgb::encode_u8(lut[v as usize]), v);
    }
    assert_eq!(srgb::encode_u8(f32::NAN), 0);
    assert_eq!(srgb::encode_u8(-3.0), 0);
    assert_eq!(srgb::encode_u8(7.0), 255);
    assert_eq!(srgb::encode_u8(0.5), 188); // 255 * 0.735356 = 187.52
    assert_eq!(srgb::encode_u16(0.5), 48192); // 65535 * 0.735356 = 48191.6
    assert_eq!(srgb::encode_u16(f32::NAN), 0);
    assert_eq!(srgb::encode_u16(2.0), 65535);
}

#[test]
fn encode_u8_is_exact_at_every_decision_threshold() {
    // For each code k the exact threshold lies between two adjacent floats: find it by bisection
    // on the exact formula and check the fast encoder on both sides.
    for k in 1..=255u32 {
        let exact = |x: f32| (255.0 * srgb::linear_to_srgb_f64(x as f64)).round() as u32;
        let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if exact(f32::from_bits(mid)) >= k {
                hi = mid
            } else {
                lo = mid
            }
        }
        assert_eq!(
            srgb::encode_u8(f32::from_bits(lo)) as u32,
            k - 1,
            "below threshold {k}"
        );
        assert_eq!(
            srgb::encode_u8(f32::from_bits(hi)) as u32,
            k,
            "at threshold {k}"
        );
    }
}

proptest::proptest! {
    #[test]
    fn encode_u8_matches_exact_formula(x in 0.0f32..=1.0) {
        proptest::prop_assert_eq!(srgb::encode_u8(x), srgb::encode_u8_exact(x));
    }

    #[test]
    fn encode_u8_matches_exact_formula_dark(x in 0.0f32..0.01) {
        proptest::prop_assert_eq!(srgb::encode_u8(x), srgb::encode_u8_exact(x));
    }

    #[test]
    fn srgb_round_trip(x in 0.0f32..=1.0) {
        let back = srgb::srgb_to_linear(srgb::linear_to_srgb(x));
        proptest::prop_assert!((back - x).abs() <= 1e-6 * x.max(1e-3));
    }
}

// ---------------------------------------------------------------------------------------
// PNG

#[test]
fn png_8bit_rgba_round_trip_is_exact() {
    let d = tmp();
    for (w, h) in [(1, 1), (67, 41), (2, 3)] {
        let p = d.path().join(format!("rgba_{w}x{h}.png"));
        let px = pattern_u8(w, h);
        save(&p, w, h, &Pixels::U8(px.clone()), None);
        let img = load(&p);
        assert_eq!((img.width, img.height), (w, h));
        assert_eq!(u8s(&img), &px[..]);
        assert_eq!(img.source.format, FileFormat::Png);
        assert_eq!(img.source.bit_depth, 8);
        assert!(!img.source.float);
        if w * h > 1 {
            assert!(img.source.has_alpha, "alpha must be kept");
        }
    }
}

#[test]
fn png_opaque_is_written_as_rgb() {
    let d = tmp();
    let p = d.path().join("opaque.png");
    let px = opaque(pattern_u8(67, 41));
    save(&p, 67, 41, &Pixels::U8(px.clone()), None);
    let bytes = std::fs::read(&p).unwrap();
    assert_eq!(&bytes[12..16], b"IHDR");
    assert_eq!(bytes[24], 8, "bit depth");
    assert_eq!(bytes[25], 2, "colour type 2 = RGB");
    let img = load(&p);
    assert!(!img.source.has_alpha);
    assert_eq!(u8s(&img), &px[..]);

    // With one translucent pixel it is RGBA.
    let mut px2 = px;
    px2[4 * 100 + 3] = 254;
    save(&p, 67, 41, &Pixels::U8(px2.clone()), None);
    let bytes = std::fs::read(&p).unwrap();
    assert_eq!(bytes[25], 6, "colour type 6 = RGBA");
    assert_eq!(u8s(&load(&p)), &px2[..]);
}

#[test]
fn png_16bit_round_trip_within_one_code() {
    let d = tmp();
    let (w, h) = (67, 41);
    let p = d.path().join("deep.png");
    let px = pattern_f32(w, h);
    save(&p, w, h, &Pixels::F32(px.clone()), Some(16));
    assert_eq!(std::fs::read(&p).unwrap()[24], 16, "16-bit file");
    let img = load(&p);
    assert_eq!(img.source.bit_depth, 16);
    assert!(img.source.has_alpha);
    let got = f32s(&img);
    assert_eq!(got.len(), px.len());
    let tol = 0.5 / 65535.0 + 1e-6;
    for (i, (a, b)) in px.iter().zip(got).enumerate() {
        let (ea, eb) = if i % 4 == 3 {
            (*a, *b)
        } else {
            (srgb::linear_to_srgb(*a), srgb::linear_to_srgb(*b))
        };
        assert!((ea - eb).abs() <= tol, "sample {i}: wrote {a}, read {b}");
    }
    // Exact codes: what was written is encode_u16 of the input.
    for (a, b) in px.iter().zip(got).step_by(4).take(500) {
        assert_eq!(srgb::encode_u16(*a), srgb::encode_u16(*b));
    }
}

#[test]
fn png_16bit_from_u8_is_value_times_257() {
    let d = tmp();
    let p = d.path().join("u8to16.png");
    let px = pattern_u8(67, 41);
    save(&p, 67, 41, &Pixels::U8(px.clone()), Some(16));
    let lin = load_image(
        &p,
        &LoadOptions {
            assume_linear: true,
        },
    )
    .unwrap();
    for (a, b) in px.iter().zip(f32s(&lin)) {
        assert_eq!((*a as u32) * 257, (b * 65535.0).round() as u32);
    }
    // Default decoding goes through the sRGB curve and matches the 8-bit LUT.
    let img = load(&p);
    let lut = srgb::decode_lut_u8();
    for (i, (a, b)) in px.iter().zip(f32s(&img)).enumerate() {
        let want = if i % 4 == 3 {
            *a as f32 / 255.0
        } else {
            lut[*a as usize]
        };
        assert!((want - b).abs() < 1e-6, "sample {i}");
    }
}

#[test]
fn f32_to_png8_rounds_through_srgb() {
    let d = tmp();
    let p = d.path().join("f.png");
    let px = vec![
        0.5,
        0.0,
        1.0,
        1.0, //
        0.214_041_14,
        f32::NAN,
        2.0,
        0.5, //
        -1.0,
        0.001,
        0.18,
        0.0,
    ];
    save(&p, 3, 1, &Pixels::F32(px.clone()), None);
    let img = load(&p);
    assert_eq!(
        u8s(&img),
        &[188, 0, 255, 255, 128, 0, 255, 128, 0, 3, 118, 0]
    );
    // With assume_linear the values are scaled, not curved.
    let opts = SaveOptions {
        bit_depth: None,
        assume_linear: true,
    };
    save_image(&p, 3, 1, &Pixels::F32(px), &opts).unwrap();
    assert_eq!(u8s(&load(&p))[..4], [128, 0, 255, 255]);
}

fn write_raw_png(
    p: &Path,
    w: u32,
    h: u32,
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
) {
    let f = std::fs::File::create(p).unwrap();
    let mut e = png::Encoder::new(f, w, h);
    e.set_color(color);
    e.set_depth(depth);
    let mut wr = e.write_header().unwrap();
    wr.write_image_data(data).unwrap();
    wr.finish().unwrap();
}

#[test]
fn gray_and_gray_alpha_png_expand() {
    let d = tmp();
    let p = d.path().join("gray.png");
    write_raw_png(
        &p,
        3,
        1,
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        &[0, 77, 255],
    );
    let img = load(&p);
    assert_eq!(
        u8s(&img),
        &[0, 0, 0, 255, 77, 77, 77, 255, 255, 255, 255, 255]
    );
    assert!(!img.source.has_alpha);
    assert_eq!(img.source.bit_depth, 8);

    let p = d.path().join("gray_alpha.png");
    write_raw_png(
        &p,
        2,
        1,
        png::ColorType::GrayscaleAlpha,
        png::BitDepth::Eight,
        &[10, 20, 200, 0],
    );
    let img = load(&p);
    assert_eq!(u8s(&img), &[10, 10, 10, 20, 200, 200, 200, 0]);
    assert!(img.source.has_alpha);

    let p = d.path().join("gray16.png");
    // 0x8000 = 32768
    write_raw_png(
        &p,
        1,
        1,
        png::ColorType::Grayscale,
        png::BitDepth::Sixteen,
        &[0x80, 0x00],
    );
    let img = load(&p);
    let v = f32s(&img);
    let want = srgb::srgb_to_linear(32768.0 / 65535.0);
    assert!((v[0] - want).abs() < 1e-6 && v[0] == v[1] && v[1] == v[2]);
    assert_eq!(v[3], 1.0);
    assert_eq!(img.source.bit_depth, 16);
}

#[test]
fn assume_linear_changes_16bit_decoding() {
    let d = tmp();
    let p = d.path().join("mid.png");
    let data: Vec<u8> = [0x8000u16, 0x4000, 0xFFFF, 0x8000]
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    write_raw_png(
        &p,
        1,
        1,
        png::ColorType::Rgba,
        png::BitDepth::Sixteen,
        &data,
    );
    let srgb_img = load(&p);
    let lin_img = load_image(
        &p,
        &LoadOptions {
            assume_linear: true,
        },
    )
    .unwrap();
    let (a, b) = (f32s(&srgb_img), f32s(&lin_img));
    assert!((a[0] - 0.214_1).abs() < 1e-3, "{}", a[0]);
    assert!((b[0] - 32768.0 / 65535.0).abs() < 1e-7);
    assert!((b[1] - 16384.0 / 65535.0).abs() < 1e-7);
    assert_eq!(a[2], 1.0);
    assert_eq!(b[2], 1.0);
    // alpha is linear either way
    assert_eq!(a[3], b[3]);
    assert!((a[3] - 32768.0 / 65535.0).abs() < 1e-7);
}

// ---------------------------------------------------------------------------------------
// EXR

#[test]
fn exr_half_round_trip_keeps_hdr_values() {
    let d = tmp();
    let (w, h) = (67, 41);
    let p = d.path().join("half.exr");
    let mut px = pattern_f32(w, h);
    px[0] = 413.0;
    px[1] = 0.000_123;
    px[2] = 1234.5;
    px[3] = 0.25;
    px[4] = -0.5;
    save(&p, w, h, &Pixels::F32(px.clone()), None);
    let img = load(&p);
    assert_eq!((img.width, img.height), (w, h));
    assert_eq!(img.source.format, FileFormat::Exr);
    assert_eq!(img.source.bit_depth, 16);
    assert!(img.source.float && img.source.has_alpha);
    let got = f32s(&img);
    assert_eq!(got[0], 413.0);
    assert_eq!(got[4], -0.5);
    for (i, (a, b)) in px.iter().zip(got).enumerate() {
        // half: 11 significant bits; subnormals below 6.1e-5 have absolute steps of 6e-8
        let tol = a.abs() * (1.0 / 2048.0) + 6e-8;
        assert!((a - b).abs() <= tol, "sample {i}: wrote {a}, read {b}");
    }
}

#[test]
fn exr_float_round_trip_is_exact() {
    let d = tmp();
    let (w, h) = (67, 41);
    let p = d.path().join("float.exr");
    let mut px = pattern_f32(w, h);
    px[0] = 413.123_46;
    px[5] = 1e-9;
    px[6] = 70000.0;
    save(&p, w, h, &Pixels::F32(px.clone()), Some(32));
    let img = load(&p);
    assert_eq!(img.source.bit_depth, 32);
    assert_eq!(f32s(&img), &px[..]);

    // 1x1
    let p1 = d.path().join("one.exr");
    save(&p1, 1, 1, &Pixels::F32(vec![1.5, 2.5, 3.5, 1.0]), Some(32));
    assert_eq!(f32s(&load(&p1)), &[1.5, 2.5, 3.5, 1.0]);
}

#[test]
fn exr_from_u8_is_srgb_decoded() {
    let d = tmp();
    let p = d.path().join("from8.exr");
    let px = vec![0u8, 128, 255, 128];
    save(&p, 1, 1, &Pixels::U8(px), Some(32));
    let v = load(&p);
    let v = f32s(&v);
    assert_eq!(v[0], 0.0);
    assert!((v[1] - 0.215_860_5).abs() < 1e-6);
    assert_eq!(v[2], 1.0);
    assert!((v[3] - 128.0 / 255.0).abs() < 1e-7);
}

#[test]
fn exr_luminance_only_loads_as_gray() {
    use exr::prelude::Layer;
    use exr::prelude::{Encoding, LayerAttributes, SpecificChannels, Vec2, WritableImage};
    let d = tmp();
    let p = d.path().join("y.exr");
    let y = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|Vec2(x, _y): Vec2<usize>| (x as f32 * 2.0,));
    let layer = Layer::new(
        (3, 2),
        LayerAttributes::default(),
        Encoding::UNCOMPRESSED,
        y,
    );
    exr::prelude::Image::from_layer(layer)
        .write()
        .to_file(&p)
        .unwrap();
    let img = load(&p);
    assert_eq!((img.width, img.height), (3, 2));
    assert!(!img.source.has_alpha);
    let v = f32s(&img);
    assert_eq!(
        &v[..12],
        &[0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 1.0, 4.0, 4.0, 4.0, 1.0]
    );
}

#[test]
fn real_hdr_exr_files_load() {
    let Some(dir) = corpus_dir("exr") else { return };
    for name in ["CandleGlass.exr", "Desk.exr", "StillLife.exr"] {
        let t = Instant::now();
        let img = load(&dir.join(name));
        let v = f32s(&img);
        assert_eq!(v.len(), (img.width * img.height * 4) as usize);
        assert!(
            img.width >= 256 && img.height >= 256,
            "{name}: {}x{}",
            img.width,
            img.height
        );
        let max = v
            .chunks_exact(4)
            .flat_map(|p| &p[..3])
            .fold(0.0f32, |m, &x| m.max(x));
        assert!(max > 100.0, "{name}: max {max}");
        assert!(
            v.iter().all(|x| x.is_finite()),
            "{name}: non-finite samples"
        );
        eprintln!(
            "{name}: {}x{}, max {max}, {:?}, {:.0} ms",
            img.width,
            img.height,
            img.source,
            t.elapsed().as_secs_f64() * 1e3
        );
    }
}

#[test]
fn every_damaged_exr_is_rejected_without_panicking() {
    let Some(dir) = corpus_dir("exr-damaged") else {
        return;
    };
    let start = Instant::now();
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "rst") {
            continue;
        }
        let t = Instant::now();
        // The file names have no .exr extension: detection is by magic bytes.
        let r = load_image(&p, &LoadOptions::default());
        let ms = t.elapsed().as_secs_f64() * 1e3;
        match r {
            Err(e @ IoError::Decode { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(p.file_name().unwrap().to_str().unwrap()),
                    "{msg}"
                );
                assert!(e.is_input_error());
            }
            Err(e) => panic!("{}: expected a Decode error, got {e:?}", p.display()),
            Ok(img) => panic!(
                "{}: damaged file decoded as {}x{}",
                p.display(),
                img.width,
                img.height
            ),
        }
        assert!(ms < 5000.0, "{}: took {ms:.0} ms", p.display());
        n += 1;
    }
    assert!(n >= 50, "only {n} files in {}", dir.display());
    eprintln!(
        "{n} damaged EXR files rejected in {:.2} s",
        start.elapsed().as_secs_f64()
    );
}

// ---------------------------------------------------------------------------------------
// JPEG and other formats

fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    10.0 * (255.0f64 * 255.0 / mse).log10()
}

#[test]
fn jpeg_round_trip_psnr() {
    let d = tmp();
    let (w, h) = (160, 90);
    let mut px = Vec::new();
    for y in 0..h {
        for x in 0..w {
            px.extend_from_slice(&[
                (x * 255 / (w - 1)) as u8,
                (y * 255 / (h - 1)) as u8,
                ((x + y) * 255 / (w + h - 2)) as u8,
                100, // alpha is dropped
            ]);
        }
    }
    let p = d.path().join("grad.jpg");
    save(&p, w, h, &Pixels::U8(px.clone()), None);
    let img = load(&p);
    assert_eq!(img.source.format, FileFormat::Jpeg);
    assert!(!img.source.has_alpha);
    let got = u8s(&img);
    assert!(got.chunks_exact(4).all(|p| p[3] == 255));
    let rgb =
        |v: &[u8]| -> Vec<u8> { v.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let q = psnr(&rgb(&px), &rgb(got));
    assert!(q > 35.0, "PSNR {q:.1} dB");

    // odd and tiny sizes
    for (w, h) in [(1, 1), (67, 41)] {
        let p = d.path().join(format!("s{w}x{h}.jpeg"));
        save(&p, w, h, &Pixels::U8(opaque(pattern_u8(w, h))), None);
        let img = load(&p);
        assert_eq!((img.width, img.height), (w, h));
    }
}

#[test]
fn lossless_formats_round_trip() {
    let d = tmp();
    for (w, h) in [(1, 1), (67, 41)] {
        let rgba = pattern_u8(w, h);
        let rgb = opaque(rgba.clone());
        for (ext, keeps_alpha) in [
            ("tif", true),
            ("bmp", true),
            ("tga", true),
            ("webp", true),
            ("qoi", true),
            ("ppm", false),
            ("pam", true),
            ("png", true),
        ] {
            let p = d.path().join(format!("img_{w}x{h}.{ext}"));
            let src = if keeps_alpha { &rgba } else { &rgb };
            save(&p, w, h, &Pixels::U8(src.clone()), None);
            let img = load(&p);
            assert_eq!((img.width, img.height), (w, h), "{ext}");
            assert_eq!(Some(img.source.format), FileFormat::from_extension(ext));
            assert_eq!(u8s(&img), &src[..], "{ext} {w}x{h}");
            // opaque input written without alpha still reads back identical
            save(&p, w, h, &Pixels::U8(rgb.clone()), None);
            assert_eq!(u8s(&load(&p)), &rgb[..], "{ext} opaque");
        }
    }
}

#[test]
fn float_and_16bit_formats_round_trip() {
    let d = tmp();
    let (w, h) = (67, 41);
    let px = pattern_f32(w, h);

    let p = d.path().join("f.tif");
    save(&p, w, h, &Pixels::F32(px.clone()), Some(32));
    let img = load(&p);
    assert!(img.source.float);
    assert_eq!(f32s(&img), &px[..]);

    let p = d.path().join("s.tif");
    save(&p, w, h, &Pixels::F32(px.clone()), Some(16));
    let img = load(&p);
    assert_eq!(img.source.bit_depth, 16);
    for (a, b) in px.iter().zip(f32s(&img)).step_by(4) {
        assert_eq!(srgb::encode_u16(*a), srgb::encode_u16(*b));
    }

    let p = d.path().join("s.ppm");
    save(&p, w, h, &Pixels::F32(px.clone()), Some(16));
    let img = load(&p);
    assert_eq!(img.source.bit_depth, 16);
    for (a, b) in px.iter().zip(f32s(&img)).step_by(4) {
        assert_eq!(srgb::encode_u16(*a), srgb::encode_u16(*b));
    }

    let p = d.path().join("r.hdr");
    let bright: Vec<f32> = px.iter().map(|v| v * 300.0).collect();
    save(&p, w, h, &Pixels::F32(bright.clone()), None);
    let img = load(&p);
    assert_eq!(img.source.format, FileFormat::Hdr);
    for (i, (a, b)) in bright.iter().zip(f32s(&img)).enumerate() {
        if i % 4 == 3 {
            assert_eq!(*b, 1.0);
        } else {
            // RGBE: 8-bit mantissa shared by the pixel's largest channel
            let m = bright[i / 4 * 4..i / 4 * 4 + 3]
                .iter()
                .fold(0.0f32, |m, &x| m.max(x));
            assert!((a - b).abs() <= m / 128.0 + 1e-6, "sample {i}: {a} vs {b}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Detection, errors, limits

#[test]
fn content_wins_over_extension() {
    let d = tmp();
    let p = d.path().join("real.png");
    let px = pattern_u8(5, 4);
    save(&p, 5, 4, &Pixels::U8(px.clone()), None);
    let bytes = std::fs::read(&p).unwrap();
    let q = d.path().join("misnamed.tga");
    std::fs::write(&q, &bytes).unwrap();
    let img = load(&q);
    assert_eq!(img.source.format, FileFormat::Png);
    assert_eq!(u8s(&img), &px[..]);

    let img = load_image_from_memory(&bytes, None, &LoadOptions::default()).unwrap();
    assert_eq!(u8s(&img), &px[..]);

    // TGA has no magic: the hint decides.
    let t = d.path().join("x.tga");
    save(&t, 5, 4, &Pixels::U8(px.clone()), None);
    let tga = std::fs::read(&t).unwrap();
    let img = load_image_from_memory(&tga, Some(FileFormat::Tga), &LoadOptions::default()).unwrap();
    assert_eq!(u8s(&img), &px[..]);
    let e = load_image_from_memory(&tga, None, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e}");
}

#[test]
fn format_names_and_bit_depths() {
    assert_eq!(
        FileFormat::from_path(Path::new("a/B.PNG")),
        Some(FileFormat::Png)
    );
    assert_eq!(
        FileFormat::from_path(Path::new("x.jpeg")),
        Some(FileFormat::Jpeg)
    );
    assert_eq!(
        FileFormat::from_path(Path::new("x.exr")),
        Some(FileFormat::Exr)
    );
    assert_eq!(
        FileFormat::from_path(Path::new("x.tiff")),
        Some(FileFormat::Tiff)
    );
    assert_eq!(FileFormat::from_path(Path::new("x.txt")), None);
    assert_eq!(FileFormat::from_path(Path::new("png")), None);
    assert!(FileFormat::Png.supports_bit_depth(16));
    assert!(!FileFormat::Jpeg.supports_bit_depth(16));
    assert!(FileFormat::Exr.supports_bit_depth(32));
    assert!(!FileFormat::Exr.supports_bit_depth(8));
    assert!(!FileFormat::Png.supports_bit_depth(32));
}

#[test]
fn truncated_png_is_a_decode_error() {
    let d = tmp();
    let p = d.path().join("photo.png");
    save(&p, 67, 41, &Pixels::U8(pattern_u8(67, 41)), None);
    let bytes = std::fs::read(&p).unwrap();
    for cut in [bytes.len() / 2, 40, 8, 3] {
        std::fs::write(&p, &bytes[..cut]).unwrap();
        let e = load_image(&p, &LoadOptions::default()).unwrap_err();
        assert!(matches!(e, IoError::Decode { .. }), "cut {cut}: {e:?}");
        assert!(e.is_input_error());
        let msg = e.to_string();
        assert!(msg.contains("photo.png: "), "{msg}");
        if cut >= 8 {
            assert!(msg.contains("not a valid PNG file"), "{msg}");
        }
    }
    // corrupt data in the middle (bad CRC / deflate stream)
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    for b in &mut bad[mid..mid + 32] {
        *b ^= 0x5a;
    }
    std::fs::write(&p, &bad).unwrap();
    let e = load_image(&p, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
}

#[test]
fn empty_missing_and_text_files() {
    let d = tmp();
    let empty = d.path().join("empty.png");
    std::fs::write(&empty, b"").unwrap();
    let e = load_image(&empty, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        format!("{}: the file is empty", empty.display())
    );

    let missing = d.path().join("missing.png");
    let e = load_image(&missing, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
    assert!(!e.is_input_error());
    assert_eq!(e.path(), missing);
    assert!(e
        .to_string()
        .starts_with(&format!("{}: ", missing.display())));

    let text = d.path().join("notes.png");
    std::fs::write(&text, "this is not an image\n").unwrap();
    let e = load_image(&text, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
    assert!(e.to_string().contains("not a valid PNG file"), "{e}");

    let text = d.path().join("notes.txt");
    std::fs::write(&text, "this is not an image\n").unwrap();
    let e = load_image(&text, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
    assert!(e.to_string().contains("not a recognised image file"), "{e}");

    // a folder
    let e = load_image(d.path(), &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
}

#[test]
fn oversized_images_are_refused_before_decoding() {
    let d = tmp();
    // A real 40000x1 PNG: small file, but wider than the limit.
    let p = d.path().join("wide.png");
    write_raw_png(
        &p,
        40000,
        1,
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        &vec![9u8; 40000],
    );
    let e = load_image(&p, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
    assert!(e.to_string().contains("too large"), "{e}");

    // An EXR whose header claims 40000x1.
    use exr::prelude::{f16, Layer};
    use exr::prelude::{Encoding, LayerAttributes, SpecificChannels, Vec2, WritableImage};
    let p = d.path().join("wide.exr");
    let ch = SpecificChannels::rgb(|_: Vec2<usize>| (f16::ONE, f16::ONE, f16::ONE));
    let layer = Layer::new(
        (40000, 1),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        ch,
    );
    exr::prelude::Image::from_layer(layer)
        .write()
        .to_file(&p)
        .unwrap();
    let e = load_image(&p, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
    assert!(e.to_string().contains("too large"), "{e}");

    // Saving refuses too.
    let e = save_image(
        &d.path().join("big.png"),
        40000,
        1,
        &Pixels::U8(vec![0; 160000]),
        &SaveOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, IoError::Unsupported { .. }), "{e:?}");
}

#[test]
fn coffee_photo_loads_as_u8() {
    let Some(dir) = corpus_dir("photos") else {
        return;
    };
    let img = load(&dir.join("coffee.png"));
    assert_eq!((img.width, img.height), (600, 400));
    assert_eq!(img.source.format, FileFormat::Png);
    assert_eq!(img.source.bit_depth, 8);
    assert!(!img.source.has_alpha);
    let v = u8s(&img);
    assert_eq!(v.len(), 600 * 400 * 4);
    assert!(v.chunks_exact(4).all(|p| p[3] == 255));
    let mean: f64 = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    assert!(mean > 50.0 && mean < 250.0, "mean {mean}");
    // not a gray image
    assert!(v.chunks_exact(4).any(|p| p[0] != p[1] || p[1] != p[2]));

    let jpg = load(&dir.join("rocket.jpg"));
    assert_eq!(jpg.source.format, FileFormat::Jpeg);
    assert!(jpg.width > 100 && jpg.height > 100);
}

// ---------------------------------------------------------------------------------------
// Atomic writes

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

// ---------------------------------------------------------------------------------------
// Timings (run with `cargo test --release --test io -- --ignored --nocapture`)

#[test]
#[ignore]
fn timing_report() {
    let (w, h) = (1920u32, 1080u32);
    let n = (w * h) as usize;
    let lin: Vec<f32> = (0..n * 4)
        .map(|i| ((i * 7919) % 10007) as f32 / 10007.0)
        .collect();

    let t = Instant::now();
    let mut acc = 0u64;
    for &x in &lin[..2_000_000] {
        acc += srgb::encode_u8(x) as u64;
    }
    let fast = t.elapsed();
    let t = Instant::now();
    let mut acc2 = 0u64;
    for &x in &lin[..2_000_000] {
        acc2 += srgb::encode_u8_exact(x) as u64;
    }
    let exact = t.elapsed();
    assert_eq!(acc, acc2);
    eprintln!(
        "encode_u8: 2M values {:.2} ms (exact powf formula {:.2} ms)",
        fast.as_secs_f64() * 1e3,
        exact.as_secs_f64() * 1e3
    );
    let t = Instant::now();
    let px = Pixels::F32(lin.clone());
    let out = px.to_u8_srgb(false);
    eprintln!(
        "F32 -> U8 sRGB, 2M pixels (RGBA, threaded): {:.2} ms",
        t.elapsed().as_secs_f64() * 1e3
    );

    let d = tmp();
    // A smooth photo-like frame (gradients + mild noise) for realistic compression.
    let mut photo = vec![0u8; n * 4];
    for y in 0..h as usize {
        for x in 0..w as usize {
            let i = (y * w as usize + x) * 4;
            let noise = (((x * 31 + y * 17) * 2654435761usize) >> 28) as u8 & 3;
            photo[i] = (x * 255 / w as usize) as u8 + noise;
            photo[i + 1] = (y * 255 / h as usize) as u8;
            photo[i + 2] = ((x + y) % 256) as u8;
            photo[i + 3] = 255;
        }
    }
    for (name, px, bits) in [
        ("png8 from U8", Pixels::U8(photo.clone()), None),
        ("png8 from F32", Pixels::F32(lin.clone()), None),
        ("png16 from F32", Pixels::F32(lin.clone()), Some(16)),
        ("exr half from F32", Pixels::F32(lin.clone()), None),
    ] {
        let ext = if name.starts_with("exr") {
            "exr"
        } else {
            "png"
        };
        let p = d.path().join(format!("frame.{ext}"));
        let t = Instant::now();
        save(&p, w, h, &px, bits);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let size = std::fs::metadata(&p).unwrap().len();
        let t = Instant::now();
        let _ = load(&p);
        eprintln!(
            "{name}: save {ms:.1} ms, {:.1} MB, load {:.1} ms",
            size as f64 / 1e6,
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    if let Some(dir) = corpus_dir("photos") {
        let img = load(&dir.join("seeding_by_Clements_Engelhardt.jpg"));
        let p = d.path().join("photo.png");
        let t = Instant::now();
        save(&p, img.width, img.height, &img.pixels, None);
        eprintln!(
            "png8 {}x{} photo: save {:.1} ms, {:.1} MB",
            img.width,
            img.height,
            t.elapsed().as_secs_f64() * 1e3,
            std::fs::metadata(&p).unwrap().len() as f64 / 1e6
        );
    }
    std::hint::black_box(out);
}

#[test]
fn truncated_jpeg_is_a_decode_error() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/rocket.jpg");
    let bytes = std::fs::read(&src).unwrap();
    assert!(load_image(&src, &LoadOptions::default()).is_ok());
    let d = tmp();
    let p = d.path().join("cut.jpg");
    for pct in [20, 50, 90, 99] {
        std::fs::write(&p, &bytes[..bytes.len() * pct / 100]).unwrap();
        let e = load_image(&p, &LoadOptions::default()).unwrap_err();
        assert!(matches!(e, IoError::Decode { .. }), "{pct} %: {e:?}");
        let msg = e.to_string();
        assert!(msg.contains("cut.jpg: not a valid JPEG file"), "{msg}");
        assert!(msg.contains("truncated"), "{msg}");
    }
    // Our own JPEGs (and data after the end marker) still load.
    let own = d.path().join("own.jpg");
    save(&own, 33, 17, &Pixels::U8(pattern_u8(33, 17)), None);
    let mut b = std::fs::read(&own).unwrap();
    assert!(load_image(&own, &LoadOptions::default()).is_ok());
    b.extend_from_slice(b"trailing");
    std::fs::write(&own, &b).unwrap();
    assert!(load_image(&own, &LoadOptions::default()).is_ok());
}

#[test]
fn only_regular_files_are_read() {
    for dev in ["/dev/zero", "/dev/null"] {
        if !Path::new(dev).exists() {
            continue;
        }
        let t = Instant::now();
        let e = load_image(Path::new(dev), &LoadOptions::default()).unwrap_err();
        assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
        assert!(
            e.to_string()
                .starts_with(&format!("{dev}: not a regular file")),
            "{e}"
        );
        assert!(t.elapsed().as_secs_f64() < 1.0);
    }
    let d = tmp();
    let e = load_image(d.path(), &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
    // A file over the cap is refused before it is read.
    let p = d.path().join("small.png");
    save(&p, 4, 4, &Pixels::U8(pattern_u8(4, 4)), None);
    let e = fxgraph::io::read_regular_file(&p, 10).unwrap_err();
    assert!(e.to_string().contains("too large"), "{e}");
}

#[test]
fn image_dimensions_come_from_the_header_alone() {
    let d = tmp();
    // A PNM header announcing 20000x20000 followed by 4 bytes: no decode is attempted.
    let p = d.path().join("big.pgm");
    std::fs::write(&p, b"P5\n20000 20000\n255\n\0\0\0\0").unwrap();
    let bytes = fxgraph::io::read_image_file(&p).unwrap();
    assert_eq!(
        fxgraph::io::image_dimensions(&bytes, &p).unwrap(),
        (20000, 20000)
    );
    std::fs::write(&p, b"P5\n40000 20\n255\n\0\0\0\0").unwrap();
    let bytes = fxgraph::io::read_image_file(&p).unwrap();
    let e = fxgraph::io::image_dimensions(&bytes, &p).unwrap_err();
    assert!(
        e.to_string().contains("big.pgm: ") && e.to_string().contains("too large"),
        "{e}"
    );
}
