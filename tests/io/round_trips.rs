//! JPEG (by PSNR) and the other formats: lossless, float and 16-bit round trips.

use super::*;

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

    // 16-bit files: the same sRGB-encoded codes.
    for name in ["s.tif", "s.ppm"] {
        let p = d.path().join(name);
        save(&p, w, h, &Pixels::F32(px.clone()), Some(16));
        let img = load(&p);
        assert_eq!(img.source.bit_depth, 16, "{name}");
        for (a, b) in px.iter().zip(f32s(&img)).step_by(4) {
            assert_eq!(srgb::encode_u16(*a), srgb::encode_u16(*b), "{name}");
        }
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
