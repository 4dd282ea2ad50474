//! Load and save timings (`cargo test --release --test io timing -- --ignored
//! --nocapture`).

use super::*;

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
