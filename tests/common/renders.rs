//! Images read back from the renderer (`[[f32; 4]]`, one RGBA value per pixel):
//! their PSNR against each other and files for review.
#![allow(dead_code)]

use fxgraph::io::Pixels;

/// PSNR (dB, peak 1) over the RGB values; with `clamp01` each value is clamped to
/// [0, 1] first (what a display shows), without it HDR values count as they are.
pub fn rgb_psnr(a: &[[f32; 4]], b: &[[f32; 4]], clamp01: bool) -> f64 {
    let v = |x: f32| if clamp01 { x.clamp(0.0, 1.0) } else { x };
    let mut mse = 0.0f64;
    for (p, q) in a.iter().zip(b) {
        for c in 0..3 {
            let d = f64::from(v(p[c]) - v(q[c]));
            mse += d * d;
        }
    }
    mse /= (a.len() * 3) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (1.0 / mse).log10()
    }
}

/// Asserts that `b` is within `min_db` dB PSNR of `a` ([`rgb_psnr`], values
/// clamped to [0, 1]), printing the PSNR as `what`.
#[track_caller]
pub fn assert_psnr(what: &str, a: &[[f32; 4]], b: &[[f32; 4]], min_db: f64) {
    let db = rgb_psnr(a, b, true);
    eprintln!("{what}: PSNR {db:.2} dB");
    assert!(db >= min_db, "{what}: PSNR {db:.2} dB < {min_db} dB");
}

/// Writes `pixels` (`w` x `h`, RGB with alpha 1) to tests/output/NAME.png for review.
pub fn save_rgb_review(name: &str, (w, h): (u32, u32), pixels: &[[f32; 4]]) {
    let data: Vec<f32> = pixels
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    super::save_for_review(name, w, h, &Pixels::F32(data));
}
