//! PNG: 8-bit RGBA and 16-bit round trips, opaque images written as RGB, floats
//! rounded through sRGB, grey and grey-alpha files expanded, `--assume-linear`.

use super::*;

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

#[test]
fn gray_and_gray_alpha_png_expand() {
    let d = tmp();
    let p = d.path().join("gray.png");
    write_raw_png(
        &p,
        3,
        1,
        ColorType::Grayscale,
        BitDepth::Eight,
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
        ColorType::GrayscaleAlpha,
        BitDepth::Eight,
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
        ColorType::Grayscale,
        BitDepth::Sixteen,
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
    write_raw_png(&p, 1, 1, ColorType::Rgba, BitDepth::Sixteen, &data);
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
