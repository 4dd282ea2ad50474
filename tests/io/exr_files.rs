//! EXR: half and float round trips keep HDR values, 8-bit input is sRGB-decoded,
//! luminance-only files load as grey, real HDR files load, damaged files are rejected
//! without a panic.

use super::*;

/// The 67 x 41 float pattern with the samples `special` (index, value) put in,
/// written to an EXR file of `bits` bits (`None`: the default, half) and loaded
/// again: the samples written and the image read.
fn exr_round_trip(special: &[(usize, f32)], bits: Option<u8>) -> (Vec<f32>, Image) {
    let d = tmp();
    let p = d.path().join("round_trip.exr");
    let mut px = pattern_f32(67, 41);
    for &(i, v) in special {
        px[i] = v;
    }
    save(&p, 67, 41, &Pixels::F32(px.clone()), bits);
    (px, load(&p))
}

#[test]
fn exr_half_round_trip_keeps_hdr_values() {
    let special = [
        (0, 413.0),
        (1, 0.000_123),
        (2, 1234.5),
        (3, 0.25),
        (4, -0.5),
    ];
    let (px, img) = exr_round_trip(&special, None);
    assert_eq!((img.width, img.height), (67, 41));
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
    let (px, img) = exr_round_trip(&[(0, 413.123_46), (5, 1e-9), (6, 70000.0)], Some(32));
    assert_eq!(img.source.bit_depth, 32);
    assert_eq!(f32s(&img), &px[..]);

    // 1x1
    let d = tmp();
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
