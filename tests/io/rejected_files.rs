//! Detection and rejection: content wins over the extension, format names and bit
//! depths, truncated PNG and JPEG files, empty, missing and text files, oversized
//! images refused before decoding, only regular files read, sizes from the header.

use super::*;

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
    for (path, format) in [
        ("a/B.PNG", Some(FileFormat::Png)),
        ("x.jpeg", Some(FileFormat::Jpeg)),
        ("x.exr", Some(FileFormat::Exr)),
        ("x.tiff", Some(FileFormat::Tiff)),
        ("x.txt", None),
        ("png", None),
    ] {
        assert_eq!(FileFormat::from_path(Path::new(path)), format, "{path}");
    }
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

    // Text: named as a PNG, or with an extension of no image format.
    for (name, why) in [
        ("notes.png", "not a valid PNG file"),
        ("notes.txt", "not a recognised image file"),
    ] {
        let text = d.path().join(name);
        std::fs::write(&text, "this is not an image\n").unwrap();
        let e = load_image(&text, &LoadOptions::default()).unwrap_err();
        assert!(matches!(e, IoError::Decode { .. }), "{e:?}");
        assert!(e.to_string().contains(why), "{e}");
    }

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
        ColorType::Grayscale,
        BitDepth::Eight,
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
