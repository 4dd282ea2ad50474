//! The Y'CbCr <-> RGB conversions: known values, round trips (4:4:4 within two
//! codes, subsampled on smooth content, mono), interlaced chroma per field, unclipped
//! floats, size checks, and the speed of a 1080p frame.

use super::*;

/// Y'CbCr of one RGB byte triple through a 1x1... 2x2 4:4:4 frame.
fn yuv_of(rgb: [u8; 3], c: &YuvConversion) -> [u8; 3] {
    let hd = header(2, 2, Chroma::C444);
    let rgba: Vec<u8> = (0..4).flat_map(|_| [rgb[0], rgb[1], rgb[2], 255]).collect();
    let mut f = YuvFrame::default();
    rgba_u8_to_yuv(&rgba, &hd, c, &mut f).unwrap();
    [f.y[0], f.u[0], f.v[0]]
}

fn rgb_of(yuv: [u8; 3], c: &YuvConversion) -> [u8; 3] {
    let hd = header(2, 2, Chroma::C444);
    let f = YuvFrame {
        y: vec![yuv[0]; 4],
        u: vec![yuv[1]; 4],
        v: vec![yuv[2]; 4],
        params: vec![],
    };
    let mut out = vec![0u8; 16];
    yuv_to_rgba_u8(&f, &hd, c, &mut out).unwrap();
    assert_eq!(out[3], 255);
    [out[0], out[1], out[2]]
}

#[test]
fn known_values() {
    let bt709 = conv(Matrix::Bt709, Range::Limited);
    let bt601 = conv(Matrix::Bt601, Range::Limited);
    let full601 = conv(Matrix::Bt601, Range::Full);
    assert_eq!(yuv_of([255, 255, 255], &bt709), [235, 128, 128]);
    assert_eq!(yuv_of([0, 0, 0], &bt709), [16, 128, 128]);
    assert_eq!(yuv_of([255, 0, 0], &bt601), [81, 90, 240]);
    assert_eq!(yuv_of([0, 255, 0], &bt601), [145, 54, 34]);
    assert_eq!(yuv_of([0, 0, 255], &bt601), [41, 240, 110]);
    assert_eq!(yuv_of([255, 0, 0], &bt709), [63, 102, 240]);
    assert_eq!(yuv_of([255, 255, 255], &full601), [255, 128, 128]);
    assert_eq!(yuv_of([0, 0, 0], &full601), [0, 128, 128]);

    assert_eq!(rgb_of([235, 128, 128], &bt709), [255, 255, 255]);
    assert_eq!(rgb_of([16, 128, 128], &bt709), [0, 0, 0]);
    assert_eq!(rgb_of([126, 128, 128], &bt601), [128, 128, 128]);
    let red = rgb_of([81, 90, 240], &bt601);
    assert!(red[0] >= 254 && red[1] <= 1 && red[2] <= 1, "{red:?}");
    // Out of range codes clip.
    assert_eq!(rgb_of([255, 128, 128], &bt709), [255, 255, 255]);
    assert_eq!(rgb_of([0, 128, 128], &bt709), [0, 0, 0]);

    // The float path: linear white and black, and the sRGB decode of grey.
    let hd = header(2, 2, Chroma::C444);
    let f = YuvFrame {
        y: vec![235, 16, 126, 235],
        u: vec![128; 4],
        v: vec![128; 4],
        params: vec![],
    };
    let mut out = vec![0f32; 16];
    yuv_to_rgba_f32(&f, &hd, &bt709, &mut out).unwrap();
    // The sRGB curve is a polynomial fit within 3e-6 of the formula.
    let close = |got: &[f32], want: &[f32]| {
        assert!(
            got.iter().zip(want).all(|(a, b)| (a - b).abs() < 3e-6),
            "{got:?} vs {want:?}"
        )
    };
    close(&out[0..4], &[1.0, 1.0, 1.0, 1.0]);
    close(&out[4..8], &[0.0, 0.0, 0.0, 1.0]);
    assert_eq!((out[3], out[7]), (1.0, 1.0));
    let grey = srgb::srgb_to_linear(110.0 / 219.0);
    close(&out[8..11], &[grey; 3]);
    let mut back = YuvFrame::default();
    rgba_f32_to_yuv(&out, &hd, &bt709, &mut back).unwrap();
    assert_eq!(back.y, f.y);
    assert_eq!(back.u, f.u);
}

/// Every grey level plus random colours, `n` pixels, as a `w x h` RGBA image.
fn test_colours(w: usize, h: usize, seed: u64) -> Vec<u8> {
    let mut rng = Rng(seed);
    let mut v = Vec::with_capacity(w * h * 4);
    for i in 0..w * h {
        if i < 256 {
            v.extend_from_slice(&[i as u8, i as u8, i as u8, 255]);
        } else {
            v.extend_from_slice(&[rng.byte(), rng.byte(), rng.byte(), 255]);
        }
    }
    v
}

#[test]
fn rgb_round_trip_444_is_within_two_codes() {
    let (w, h) = (128usize, 128usize);
    let rgba = test_colours(w, h, 5);
    let hd = header(w as u32, h as u32, Chroma::C444);
    let mut report = Vec::new();
    for matrix in [Matrix::Bt601, Matrix::Bt709] {
        for range in [Range::Limited, Range::Full] {
            let c = conv(matrix, range);
            // 8-bit sRGB in and out.
            let mut f = YuvFrame::default();
            rgba_u8_to_yuv(&rgba, &hd, &c, &mut f).unwrap();
            let mut back = vec![0u8; rgba.len()];
            yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
            let (max, mean) = rgb_diff(&rgba, &back);
            // Grey stays grey.
            for p in back[..256 * 4].chunks_exact(4) {
                assert!(
                    p[0].abs_diff(p[1]) <= 1 && p[1].abs_diff(p[2]) <= 1,
                    "{p:?}"
                );
            }
            // Linear f32 in and out, compared after sRGB encoding.
            let lin: Vec<f32> = Pixels::U8(rgba.clone()).to_f32_linear(false);
            let mut f2 = YuvFrame::default();
            rgba_f32_to_yuv(&lin, &hd, &c, &mut f2).unwrap();
            // The same Y'CbCr within one code (the f32 path's sRGB tables move values
            // that sit on a rounding boundary).
            let planes = |f: &YuvFrame| [f.y.clone(), f.u.clone(), f.v.clone()].concat();
            let code_diff = planes(&f2)
                .iter()
                .zip(planes(&f))
                .map(|(a, b)| a.abs_diff(b))
                .max();
            assert_eq!(
                code_diff,
                Some(1).min(code_diff),
                "u8 and f32 inputs differ"
            );
            let mut backf = vec![0f32; lin.len()];
            yuv_to_rgba_f32(&f2, &hd, &c, &mut backf).unwrap();
            let back8 = Pixels::F32(backf).to_u8_srgb(false);
            let (max_f, mean_f) = rgb_diff(&rgba, &back8);
            report.push(format!(
                "{matrix:?}/{range:?}: u8 max {max} mean {mean:.3}, f32 max {max_f} mean {mean_f:.3}"
            ));
            // Limited range has 219 luma and 225 chroma levels for 256 RGB levels.
            assert!(max <= 2 && max_f <= 2, "{}", report.last().unwrap());
            assert!(mean < 0.75 && mean_f < 0.75, "{}", report.last().unwrap());
        }
    }
    eprintln!(
        "4:4:4 round trip (8-bit sRGB units):\n  {}",
        report.join("\n  ")
    );
}

/// A smooth colour image: slow sinusoids, about 20 % to 80 % of full scale.
fn smooth_image(w: usize, h: usize) -> Vec<u8> {
    let mut v = Vec::with_capacity(w * h * 4);
    for y in 0..h {
        for x in 0..w {
            let (xf, yf) = (x as f32, y as f32);
            let r = 128.0 + 70.0 * (xf / 23.0).sin() * (yf / 31.0).cos();
            let g = 128.0 + 60.0 * ((xf + yf) / 37.0).sin();
            let b = 128.0 + 75.0 * (yf / 19.0).cos() * (xf / 41.0).cos();
            v.extend_from_slice(&[r.round() as u8, g.round() as u8, b.round() as u8, 255]);
        }
    }
    v
}

#[test]
fn rgb_round_trip_subsampled_on_smooth_content() {
    let (w, h) = (160usize, 120usize);
    let rgba = smooth_image(w, h);
    let mut report = Vec::new();
    for chroma in [
        Chroma::C420Jpeg,
        Chroma::C420Mpeg2,
        Chroma::C420Paldv,
        Chroma::C420,
        Chroma::C422,
    ] {
        for interlace in [Interlace::Progressive, Interlace::TopFieldFirst] {
            let mut hd = header(w as u32, h as u32, chroma);
            hd.interlace = interlace;
            let c = conv(Matrix::Bt601, Range::Limited);
            let mut f = YuvFrame::default();
            rgba_u8_to_yuv(&rgba, &hd, &c, &mut f).unwrap();
            let mut back = vec![0u8; rgba.len()];
            yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
            let (max, mean) = rgb_diff(&rgba, &back);
            // Inside a two-pixel border (where the last chroma sample of co-sited layouts,
            // and of each field, is clamped instead of interpolated).
            let inner = |img: &[u8]| -> Vec<u8> {
                (2..h - 2)
                    .flat_map(|y| img[(y * w + 2) * 4..(y * w + w - 2) * 4].to_vec())
                    .collect()
            };
            let (max_in, _) = rgb_diff(&inner(&rgba), &inner(&back));
            report.push(format!(
                "C{chroma} I{}: max {max} (inside the border {max_in}) mean {mean:.3}",
                interlace.code()
            ));
            assert!(
                max <= 4 && max_in <= 3 && mean < 0.5,
                "{}",
                report.last().unwrap()
            );
        }
    }
    eprintln!(
        "4:2:0 / 4:2:2 round trip on smooth content (8-bit sRGB units):\n  {}",
        report.join("\n  ")
    );
}

#[test]
fn mono_round_trip() {
    let (w, h) = (16u32, 16u32);
    let grey: Vec<u8> = (0..256)
        .flat_map(|i| [i as u8, i as u8, i as u8, 255])
        .collect();
    let hd = header(w, h, Chroma::Mono);
    let c = conv(Matrix::Bt709, Range::Limited);
    let mut f = YuvFrame::default();
    rgba_u8_to_yuv(&grey, &hd, &c, &mut f).unwrap();
    assert!(f.u.is_empty() && f.v.is_empty());
    assert_eq!((f.y[0], f.y[255]), (16, 235));
    let mut back = vec![0u8; grey.len()];
    yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
    let (max, _) = rgb_diff(&grey, &back);
    assert!(max <= 1, "max {max}");
    // Full range mono is lossless.
    let c = conv(Matrix::Bt709, Range::Full);
    rgba_u8_to_yuv(&grey, &hd, &c, &mut f).unwrap();
    yuv_to_rgba_u8(&f, &hd, &c, &mut back).unwrap();
    assert_eq!(back, grey);
}

#[test]
fn interlaced_chroma_is_resampled_per_field() {
    // 4:2:0, 4x8: chroma rows 0, 2 (top field) carry one colour, rows 1, 3 (bottom field)
    // another. Per field, every even luma row sees only the top colour.
    let mut hd = header(4, 8, Chroma::C420Mpeg2);
    hd.interlace = Interlace::BottomFieldFirst;
    let f = YuvFrame {
        y: vec![126; 32],
        u: [[100u8; 2], [160; 2], [100; 2], [160; 2]].concat(),
        v: [[200u8; 2], [60; 2], [200; 2], [60; 2]].concat(),
        params: vec![],
    };
    let c = conv(Matrix::Bt601, Range::Limited);
    let mut out = vec![0u8; 4 * 8 * 4];
    yuv_to_rgba_u8(&f, &hd, &c, &mut out).unwrap();
    let top = rgb_of([126, 100, 200], &c);
    let bottom = rgb_of([126, 160, 60], &c);
    for y in 0..8 {
        let want = if y % 2 == 0 { top } else { bottom };
        for x in 0..4 {
            let p = &out[(y * 4 + x) * 4..][..3];
            assert_eq!(p, want, "row {y} col {x}");
        }
    }
    // Read as progressive, the fields' colours mix.
    let progressive = YuvConversion {
        chroma_fields: ChromaFields::Progressive,
        ..c
    };
    yuv_to_rgba_u8(&f, &hd, &progressive, &mut out).unwrap();
    assert_ne!(&out[4 * 4 * 2..][..3], top);
    // And downsampling keeps the fields apart too.
    let mut back = YuvFrame::default();
    let mut rgba = vec![0u8; 4 * 8 * 4];
    yuv_to_rgba_u8(&f, &hd, &c, &mut rgba).unwrap();
    rgba_u8_to_yuv(&rgba, &hd, &c, &mut back).unwrap();
    for (a, b) in back.u.iter().zip(&f.u).chain(back.v.iter().zip(&f.v)) {
        assert!(a.abs_diff(*b) <= 1, "{:?} vs {:?}", back.u, f.u);
    }
    // Mixed streams follow each frame's `I` parameter.
    hd.interlace = Interlace::Mixed;
    let mut fm = f.clone();
    fm.params = vec!["Itii".into()];
    assert!(fm.field_chroma(&hd, &c));
    fm.params = vec!["I1pp".into()];
    assert!(!fm.field_chroma(&hd, &c));
    fm.params = vec![];
    assert!(!fm.field_chroma(&hd, &c));
}

#[test]
fn unclipped_floats_keep_colours_outside_the_rgb_cube() {
    let hd = header(2, 2, Chroma::C444);
    let f = YuvFrame {
        y: vec![240, 30, 200, 128],
        u: vec![20, 230, 128, 16],
        v: vec![230, 40, 128, 240],
        params: vec![],
    };
    let c = YuvConversion {
        clip: false,
        ..conv(Matrix::Bt709, Range::Limited)
    };
    let mut lin = vec![0f32; 16];
    yuv_to_rgba_f32(&f, &hd, &c, &mut lin).unwrap();
    assert!(
        lin.iter().any(|&v| v < 0.0) && lin.iter().any(|&v| v > 1.0),
        "{lin:?}"
    );
    let mut back = YuvFrame::default();
    rgba_f32_to_yuv(&lin, &hd, &c, &mut back).unwrap();
    assert_eq!(back, f);
    // Clipped, they change.
    let clipped = YuvConversion { clip: true, ..c };
    yuv_to_rgba_f32(&f, &hd, &clipped, &mut lin).unwrap();
    assert!(lin.iter().all(|&v| (0.0..=1.0).contains(&v)));
    rgba_f32_to_yuv(&lin, &hd, &clipped, &mut back).unwrap();
    assert_ne!(back, f);
}

#[test]
fn image_conversion_checks_sizes() {
    let hd = header(8, 6, Chroma::C420Jpeg);
    let c = YuvConversion::for_header(&hd);
    let f = YuvFrame::black(&hd, Range::Limited);
    let img = yuv_to_image(&f, &hd, &c, RgbKind::LinearF32).unwrap();
    assert_eq!((img.width, img.height), (8, 6));
    assert!(
        matches!(&img.pixels, Pixels::F32(v) if v.len() == 8 * 6 * 4 && v[0] == 0.0 && v[3] == 1.0)
    );
    let img8 = yuv_to_image(&f, &hd, &c, RgbKind::SrgbU8).unwrap();
    assert!(matches!(&img8.pixels, Pixels::U8(v) if v[..4] == [0, 0, 0, 255]));
    assert_eq!(image_to_yuv(&img, &hd, &c).unwrap(), f);
    assert_eq!(image_to_yuv(&img8, &hd, &c).unwrap(), f);
    let other = header(8, 4, Chroma::C420Jpeg);
    let e = image_to_yuv(&img, &other, &c).unwrap_err();
    assert_eq!(e, "the image is 8x6 but the y4m stream is 8x4");
    let mut short = f.clone();
    short.y.pop();
    assert!(yuv_to_image(&short, &hd, &c, RgbKind::SrgbU8).is_err());
}

/// Conversion speed of one 1920x1080 4:2:0 frame (meaningful in release builds:
/// `cargo test --release --test io conversion_speed -- --nocapture`).
#[test]
fn conversion_speed_1080p() {
    let mut hd = header(1920, 1080, Chroma::C420Mpeg2);
    hd.interlace = Interlace::TopFieldFirst;
    let c = YuvConversion::for_header(&hd);
    let rgba = smooth_image(1920, 1080);
    let mut f = YuvFrame::default();
    rgba_u8_to_yuv(&rgba, &hd, &c, &mut f).unwrap();
    let mut out8 = vec![0u8; rgba.len()];
    let mut outf = vec![0f32; rgba.len()];
    let lin = Pixels::U8(rgba.clone()).to_f32_linear(false);
    let reps = if cfg!(debug_assertions) { 1 } else { 20 };
    let time = |name: &str, run: &mut dyn FnMut()| {
        run();
        let mut best = f64::MAX;
        let mut total = 0.0;
        for _ in 0..reps {
            let t = Instant::now();
            run();
            let ms = t.elapsed().as_secs_f64() * 1e3;
            best = best.min(ms);
            total += ms;
        }
        eprintln!(
            "1080p {name}: best {best:.2} ms, mean {:.2} ms ({reps} runs)",
            total / reps as f64
        );
    };
    time("Y'CbCr 4:2:0 -> RGBA u8", &mut || {
        yuv_to_rgba_u8(&f, &hd, &c, &mut out8).unwrap()
    });
    time("Y'CbCr 4:2:0 -> RGBA f32 linear", &mut || {
        yuv_to_rgba_f32(&f, &hd, &c, &mut outf).unwrap()
    });
    let mut g = YuvFrame::default();
    time("RGBA u8 -> Y'CbCr 4:2:0", &mut || {
        rgba_u8_to_yuv(&rgba, &hd, &c, &mut g).unwrap()
    });
    time("RGBA f32 linear -> Y'CbCr 4:2:0", &mut || {
        rgba_f32_to_yuv(&lin, &hd, &c, &mut g).unwrap()
    });
    time("Y'CbCr -> Image f32 (allocating)", &mut || {
        let _ = yuv_to_image(&f, &hd, &c, RgbKind::LinearF32).unwrap();
    });
    // Reading and writing frames through memory.
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "mem").unwrap();
    for _ in 0..10 {
        w.write_frame(&f).unwrap();
    }
    let bytes = w.into_inner().unwrap();
    time("read 10 frames from memory", &mut || {
        let mut r = Y4mReader::new(Cursor::new(&bytes), "mem").unwrap();
        let mut buf = YuvFrame::default();
        while r.read_frame_into(&mut buf).unwrap() {}
    });
}

// ---------------------------------------------------------------------------------------
