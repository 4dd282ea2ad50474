//! `frame_blend` through the streaming runtime: each output is the weighted mean of
//! the current and earlier frames (clamped at the first frame).

use crate::common::stream::run_stream;
use crate::common::*;
use fxgraph::io::Image;

/// Frame i has the value (i + 1) / 64 in every channel (exact in half floats).
fn index_frame(i: u64) -> Image {
    let v = (i + 1) as f32 / 64.0;
    image_f32(6, 4, |_, _| [v, v, v, 1.0])
}

fn index_value(i: i64) -> f64 {
    (i + 1) as f64 / 64.0
}

/// frame_blend against the analytic weighted mean, with IN[-i] clamped to frame 0:
/// every output of a 12-frame sequence (start, middle, end), for several settings.
#[test]
fn frame_blend_equals_the_weighted_mean() {
    let Some(mut engine) = engine() else {
        return;
    };
    let n = 12u64;
    let frames: Vec<Image> = (0..n).map(index_frame).collect();
    let cases: [(&[&str], &[f64], f64); 5] = [
        (&[], &[1.0, 1.0, 1.0], 0.0),
        (&["frames=1"], &[1.0], 0.0),
        (
            &[
                "frames=5",
                "weights=(5, 4, 3, 2)",
                "weights_more=(1, 0, 0, 0)",
            ],
            &[5.0, 4.0, 3.0, 2.0, 1.0],
            0.0,
        ),
        (
            &[
                "frames=8",
                "weights=(1, 2, 3, 4)",
                "weights_more=(5, 6, 7, 8)",
                "scale=0.01",
            ],
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0],
            0.01,
        ),
        // A temporal second difference (ffmpeg's example weights), scale 1.
        (
            &["weights=(-1, 2, -1, 0)", "scale=1"],
            &[-1.0, 2.0, -1.0],
            1.0,
        ),
    ];
    for (overrides, w, scale) in cases {
        let outs = run_stream(&mut engine, "frame_blend", overrides, &frames, 1);
        let k = if scale == 0.0 {
            1.0 / w.iter().sum::<f64>()
        } else {
            scale
        };
        let mut got = Vec::new();
        for (t, o) in outs.iter().enumerate() {
            let want: f64 = k * w
                .iter()
                .enumerate()
                .map(|(i, wi)| wi * index_value((t as i64 - i as i64).max(0)))
                .sum::<f64>();
            let alpha = k * w.iter().sum::<f64>();
            for px in o.chunks_exact(4) {
                for v in &px[..3] {
                    assert!(
                        (*v as f64 - want).abs() < 1e-5,
                        "{overrides:?} t={t}: {v} vs {want}"
                    );
                }
                assert!((px[3] as f64 - alpha).abs() < 1e-5);
            }
            got.push(o[0]);
        }
        println!(
            "frame_blend {overrides:?}: outputs x64 {:?}",
            got.iter()
                .map(|v| format!("{:.3}", v * 64.0))
                .collect::<Vec<_>>()
        );
    }
}
