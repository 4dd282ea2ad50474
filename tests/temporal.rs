//! Temporal references through the streaming runtime: frames whose pixels encode
//! their index prove which frame each reference reads at the start, middle and end.

use crate::common;

use common::cli::write_effect;
use common::stream::{output_f32, stream_of};
use fxgraph::app::Effect;
use fxgraph::gpu::executor::Engine;
use fxgraph::gpu::stream::Stream;
use fxgraph::gpu::transfer::read_pixels;
use fxgraph::script::types::{ColorSpace, Format};

const PICK: &str = "// r: IN[-2], g: IN, b: IN[+1], a: frames seen so far (feedback + 1/64).
@group(0) @binding(0) var p2: texture_2d<f32>;
@group(0) @binding(1) var c: texture_2d<f32>;
@group(0) @binding(2) var n: texture_2d<f32>;
@group(0) @binding(3) var fb: texture_2d<f32>;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let q = vec2<i32>(pos.xy);
    return vec4<f32>(textureLoad(p2, q, 0).r, textureLoad(c, q, 0).r, textureLoad(n, q, 0).r,
                     textureLoad(fb, q, 0).a + 1.0 / 64.0);
}
";

const PROBE: &str = "EFFECT.probe = { PASS = {
    a = SHADER.pick { p2 = IN[-2]  c = IN  n = IN[+1]  fb = PASS.a[-1] }
} OUT = a }";

/// Frame i has the value (i + 1) / 64 in every channel (exact in half floats).
fn frame(i: u64) -> fxgraph::io::Image {
    let v = (i + 1) as f32 / 64.0;
    common::image_f32(5, 3, |_, _| [v, v, v, 1.0])
}

fn index_of(v: f32) -> i64 {
    (v * 64.0).round() as i64 - 1
}

/// A stream of `effect` on 5x3 rgba16f frames.
fn stream(engine: &mut Engine, effect: &mut Effect) -> Stream {
    stream_of(engine, effect, (5, 3), Format::Rgba16f, ColorSpace::Linear)
}

/// The effect `NAME.fx` (`fx`) with its shader `SHADER.wgsl` in `dir`, compiled.
fn effect(dir: &std::path::Path, name: &str, fx: &str, shader: (&str, &str)) -> Effect {
    Effect::compile(&[write_effect(dir, name, fx, shader)], &[]).unwrap()
}

#[test]
fn history_future_and_feedback_read_the_right_frames() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut effect = effect(dir.path(), "probe", PROBE, ("pick", PICK));
    assert_eq!((effect.graph.history, effect.graph.latency), (2, 1));
    let mut stream = stream(&mut engine, &mut effect);
    assert_eq!(stream.ring_len(), 4);
    let n = 6u64;
    let mut seen = Vec::new();
    let mut check = |t: u64, engine: &mut Engine, stream: &Stream| {
        let px = output_f32(engine, stream);
        let got = [
            index_of(px[0]),
            index_of(px[1]),
            index_of(px[2]),
            index_of(px[3]),
        ];
        let last = n as i64 - 1;
        let t = t as i64;
        // r = IN[-2] clamped at the start, g = IN, b = IN[+1] clamped at the end,
        // a = frames seen so far - 1 (feedback starts from zero).
        assert_eq!(
            got,
            [(t - 2).max(0), t, (t + 1).min(last), t],
            "output frame {t}"
        );
        seen.push(t);
    };
    for i in 0..n {
        stream.push_image(&engine, &frame(i)).unwrap();
        // Latency 1: the first push makes nothing ready, then output i-1 per push.
        let out = stream.next(&mut engine).unwrap();
        assert_eq!(out, i.checked_sub(1));
        if let Some(t) = out {
            check(t, &mut engine, &stream);
        }
        assert_eq!(stream.next(&mut engine).unwrap(), None);
    }
    stream.end();
    while let Some(t) = stream.next(&mut engine).unwrap() {
        check(t, &mut engine, &stream);
    }
    assert_eq!(
        seen,
        (0..n as i64).collect::<Vec<_>>(),
        "one output per input, in order"
    );
}

/// With `rate = 2` every input frame gives two outputs; shaders see `subframe`.
#[test]
fn rate_two_gives_two_outputs_per_frame_with_subframe() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    const SUB: &str = "@group(0) @binding(0) var c: texture_2d<f32>;
struct P { subframe: f32, frame: f32 }
@group(0) @binding(1) var<uniform> p: P;
@fragment fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(textureLoad(c, vec2<i32>(pos.xy), 0).r, p.subframe, p.frame, 1.0);
}
";
    let fx = "EFFECT.s = { PASS = { a = SHADER.sub { c = IN } } OUT = a }";
    let mut effect = effect(dir.path(), "sub", fx, ("sub", SUB));
    let mut stream = stream(&mut engine, &mut effect);
    stream.rate = 2;
    let mut got = Vec::new();
    for i in 0..3 {
        stream.push_image(&engine, &frame(i)).unwrap();
        while let Some(o) = stream.next(&mut engine).unwrap() {
            let px = output_f32(&engine, &stream);
            got.push((o, index_of(px[0]), px[1] as u32, px[2] as u32));
        }
    }
    stream.end();
    assert_eq!(stream.next(&mut engine).unwrap(), None);
    assert_eq!(
        got,
        [
            (0, 0, 0, 0),
            (1, 0, 1, 0),
            (2, 1, 0, 1),
            (3, 1, 1, 1),
            (4, 2, 0, 2),
            (5, 2, 1, 2)
        ]
    );
}

/// A sequence processed in slices with the context frames each slice needs gives
/// the same outputs as one run (no feedback).
#[test]
fn slices_with_context_frames_equal_one_run() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    // Same shader, no feedback (fb reads the current input instead).
    let fx = "EFFECT.noback = { PASS = { a = SHADER.pick { p2 = IN[-2]  c = IN  n = IN[+1]  fb = IN } } OUT = a }";
    let mut effect = effect(dir.path(), "noback", fx, ("pick", PICK));
    let n = 9u64;
    let run = |engine: &mut Engine,
               effect: &mut Effect,
               frames: std::ops::Range<u64>,
               keep: std::ops::Range<u64>| {
        let mut s = stream(engine, effect);
        let mut outs = Vec::new();
        let base = frames.start;
        let mut take = |t: u64, engine: &mut Engine, s: &Stream| {
            let global = base + t;
            if keep.contains(&global) {
                outs.push((
                    global,
                    read_pixels(&engine.ctx, s.output(), Format::Rgba32f).unwrap(),
                ));
            }
        };
        for i in frames.clone() {
            s.push_image(engine, &frame(i)).unwrap();
            while let Some(t) = s.next(engine).unwrap() {
                take(t, engine, &s);
            }
        }
        s.end();
        while let Some(t) = s.next(engine).unwrap() {
            take(t, engine, &s);
        }
        outs
    };
    let whole = run(&mut engine, &mut effect, 0..n, 0..n);
    // Slices [0,3), [3,6), [6,9), each given 2 frames of history and 1 of future.
    let mut sliced = Vec::new();
    for (a, b) in [(0u64, 3u64), (3, 6), (6, 9)] {
        let frames = a.saturating_sub(2)..(b + 1).min(n);
        sliced.extend(run(&mut engine, &mut effect, frames, a..b));
    }
    assert_eq!(whole.len(), n as usize);
    assert_eq!(whole, sliced);
}
