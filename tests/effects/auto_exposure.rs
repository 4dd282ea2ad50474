//! The `auto_exposure` effect (effects/auto_exposure.fx): metering (the
//! log-average of the luminance, EV relative to 0.18), adaptation over time at
//! speed_up / speed_down EV per second of the standard value `time`, compensation
//! and the EV limits. EVs are read back from the output: for an input pixel of
//! luminance L the output is L 2^(compensation - ev).

use crate::common::engine;
use crate::common::raster::constant;
use crate::common::stream::{run_stream_frames, SeqFrame};
use fxgraph::io::Image;
use fxgraph::script::types::Format;

const W: u32 = 40;
const H: u32 = 24;
/// Half floats in the output: 2^-11 relative, 0.0007 EV.
const EV_TOL: f64 = 0.005;

fn grey(l: f32) -> Image {
    constant(W, H, [l, l, l, 1.0])
}

fn seq(images: Vec<Image>) -> Vec<SeqFrame> {
    images
        .into_iter()
        .map(|image| SeqFrame {
            image,
            aux: vec![],
            jitter: [0.0, 0.0],
        })
        .collect()
}

/// The EV applied to pixel 0 of each output, given the input's value there.
fn evs(outs: &[Vec<f32>], inputs: &[f32], compensation: f64) -> Vec<f64> {
    outs.iter()
        .zip(inputs)
        .map(|(o, &l)| compensation - (o[0] as f64 / l as f64).log2())
        .collect()
}

#[test]
fn metering_is_the_log_average_and_the_result_averages_middle_grey() {
    let Some(mut engine) = engine() else { return };
    // A size the reductions do not divide evenly (67 x 41: 8 x 5 blocks of 8 or
    // 9 x 8 or 9 pixels at 1/8, then 1 x 1), columns 0..33 at 0.5 and the
    // rest at 8: the log-average is 2^((33 log2 0.5 + 34 log2 8) / 67).
    let two = crate::common::image_f32(67, 41, |x, _| {
        let l = if x < 33 { 0.5 } else { 8.0 };
        [l, l, l, 1.0]
    });
    let two_avg = ((33.0 * 0.5f64.log2() + 34.0 * 8.0f64.log2()) / 67.0).exp2();
    // A colour: Rec. 709 luminance 0.2126 r + 0.7152 g + 0.0722 b.
    let colour = constant(W, H, [0.9, 0.3, 0.1, 1.0]);
    let y709 = 0.2126 * 0.9 + 0.7152 * 0.3 + 0.0722 * 0.1;
    for (img, log_avg) in [(two, two_avg), (colour, y709)] {
        for comp in [0.0, 1.5, -2.0] {
            let set = format!("compensation={comp}");
            let out = run_stream_frames(
                &mut engine,
                "auto_exposure",
                &[&set],
                &seq(vec![img.clone()]),
                25.0,
            )
            .remove(0);
            let input = crate::common::samples::f32s(&img.pixels);
            // Every sample scaled by 2^(comp - ev), ev = log2(log-average / 0.18).
            let gain = (comp - (log_avg / 0.18).log2()).exp2();
            for (o, i) in out.chunks(4).zip(input.chunks(4)) {
                for c in 0..3 {
                    let want = i[c] as f64 * gain;
                    assert!(
                        ((o[c] as f64) / want).log2().abs() < EV_TOL,
                        "{o:?} vs {want}"
                    );
                }
                assert_eq!(o[3], i[3], "alpha kept");
            }
        }
    }
}

#[test]
fn adaptation_follows_at_speed_up_and_speed_down() {
    let Some(mut engine) = engine() else { return };
    let fps = 30.0;
    let dt = 1.0 / fps;
    let (l1, l2) = (0.18f32, 0.18f32 * 16.0); // EV 0 and EV 4
    let mut values = vec![l1; 6];
    values.extend(vec![l2; 44]);
    values.extend(vec![l1; 30]);
    let frames = seq(values.iter().map(|&l| grey(l)).collect());
    for (set, up, down) in [
        (vec![], 3.0, 1.0),
        (vec!["speed_up=1.5", "speed_down=4"], 1.5, 4.0),
    ] {
        let outs = run_stream_frames(&mut engine, "auto_exposure", &set, &frames, fps);
        let ev = evs(&outs, &values, 0.0);
        // Expected: the first frame takes its target; then each frame moves towards
        // the target by at most speed * dt.
        let mut want = 0.0f64;
        for (t, &l) in values.iter().enumerate() {
            let target = ((l as f64) / 0.18).log2();
            if t > 0 {
                let step = (target - want).clamp(-down * dt, up * dt);
                want += step;
            } else {
                want = target;
            }
            assert!(
                (ev[t] - want).abs() < EV_TOL,
                "{set:?} frame {t}: ev {} expected {want}",
                ev[t]
            );
            if t > 0 {
                let d = ev[t] - ev[t - 1];
                assert!(
                    d <= up * dt + EV_TOL && d >= -down * dt - EV_TOL,
                    "{set:?} frame {t}: step {d}"
                );
            }
        }
        // The rise (4 EV) is complete within the 44 bright frames at 3 EV/s: ev = 4.
        if up == 3.0 {
            assert!((ev[49] - 4.0).abs() < EV_TOL, "{}", ev[49]);
        }
    }
}

#[test]
fn ev_limits_clamp() {
    let Some(mut engine) = engine() else { return };
    for (set, l, ev) in [
        (vec![], 0.18f32 * 4096.0, 10.0f64), // EV 12, limited to max_ev = 10
        (vec![], 0.18 / 4096.0, -10.0),      // EV -12, limited to min_ev = -10
        (vec!["max_ev=2"], 0.18 * 16.0, 2.0),
        (vec!["min_ev=-1"], 0.18 / 16.0, -1.0),
        (vec!["max_ev=2"], 0.18 * 2.0, 1.0), // within the limits
    ] {
        let outs = run_stream_frames(
            &mut engine,
            "auto_exposure",
            &set,
            &seq(vec![grey(l); 3]),
            25.0,
        );
        for e in evs(&outs, &[l; 3], 0.0) {
            assert!(
                (e - ev).abs() < EV_TOL,
                "{set:?} L {l}: ev {e}, expected {ev}"
            );
        }
    }
    // A black frame is metered at min_ev (no infinite exposure).
    let outs = run_stream_frames(
        &mut engine,
        "auto_exposure",
        &[],
        &seq(vec![grey(0.0)]),
        25.0,
    );
    assert!(outs[0].chunks(4).all(|p| p[..3] == [0.0, 0.0, 0.0]));
}

/// `fxrun auto_exposure tonemap`: the exposed image feeds the tone curve; a flat
/// image of any level within the EV limits comes out as tonemap(0.18) (ACES fit: x (2.51 x + 0.03) /
/// (x (2.43 x + 0.59) + 0.14)).
#[test]
fn the_chain_with_tonemap_gives_middle_grey() {
    let Some(mut engine) = engine() else { return };
    let x = 0.18f64;
    let aces = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    for l in [0.02f32, 3.0, 100.0] {
        let (_, _, px) = crate::common::run(
            &mut engine,
            &["auto_exposure", "tonemap"],
            &[],
            &grey(l),
            Format::Rgba32f,
        )
        .unwrap();
        let v = crate::common::linear(&px);
        assert!(
            (v[0] as f64 - aces).abs() < 2e-3,
            "L {l}: {} vs {aces}",
            v[0]
        );
    }
}
