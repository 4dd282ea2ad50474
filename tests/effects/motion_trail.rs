//! `motion_trail` through the streaming runtime: the trail decays geometrically.

use crate::common::stream::run_stream;
use crate::common::*;
use fxgraph::io::Image;

/// A bright 1-px dot moving 5 px per frame over black: the trail it leaves holds
/// decay^k k frames later (both modes); a static grey stripe is unchanged by max and
/// brightened to grey * (1 - decay^(t+1)) / (1 - decay) by add.
#[test]
fn motion_trail_decays_geometrically() {
    let Some(mut engine) = engine() else {
        return;
    };
    let n = 10u32;
    let (w, h) = (64u32, 16u32);
    let dot_x = |t: u32| 4 + 5 * t;
    let frames: Vec<Image> = (0..n)
        .map(|t| {
            image_f32(w, h, |x, y| {
                let v = if y == 5 && x == dot_x(t) {
                    1.0
                } else if y >= 12 {
                    0.25
                } else {
                    0.0
                };
                [v, v, v, 1.0]
            })
        })
        .collect();
    let decay = 0.7f64;
    for mode in ["max", "add"] {
        let set_mode = format!("mode={mode}");
        let outs = run_stream(
            &mut engine,
            "motion_trail",
            &[&set_mode, "decay=0.7"],
            &frames,
            1,
        );
        let last = &outs[(n - 1) as usize];
        let trail: Vec<f64> = (0..n)
            .map(|k| at(last, w, dot_x(n - 1 - k), 5, 0) as f64)
            .collect();
        println!(
            "motion_trail {mode}: trail values at k = 0..9 frames back {:?}",
            trail.iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>()
        );
        for (k, v) in trail.iter().enumerate() {
            let want = decay.powi(k as i32);
            assert!(
                (v - want).abs() < 0.01 * want + 1e-3,
                "{mode} k={k}: {v} vs {want}"
            );
        }
        for k in 0..(n - 1) as usize {
            let ratio = trail[k + 1] / trail[k];
            assert!((ratio - decay).abs() < 0.01, "{mode}: ratio {ratio}");
        }
        // Nothing else on the dot's row lights up; alpha stays 1.
        for x in 0..w {
            if (x as i64 - 4) % 5 != 0 || x > dot_x(n - 1) {
                assert_eq!(at(last, w, x, 5, 0), 0.0, "{mode} x={x}");
            }
            assert!((at(last, w, x, 5, 3) - 1.0).abs() < 1e-6);
        }
        let grey = at(last, w, 10, 13, 0) as f64;
        let want = if mode == "max" {
            0.25
        } else {
            0.25 * (1.0 - decay.powi(n as i32)) / (1.0 - decay)
        };
        assert!(
            (grey - want).abs() < 0.005,
            "{mode}: static grey {grey} vs {want}"
        );
    }
}
