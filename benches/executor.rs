//! Executor overhead on a 10-pass graph: CPU time to record a frame into the
//! caller's encoder (`Prepared::record`) and to finish and submit it (engine
//! overhead), against the GPU time of its passes from timestamp queries, on
//! whatever adapter `GpuContext::new` picks (lavapipe in CI). Skips without an
//! adapter. The criterion figure is the CPU time (record+finish+submit) per frame.

use criterion::{criterion_group, criterion_main, Criterion};
use fxgraph::app::Effect;
use fxgraph::gpu::context::{AdapterChoice, GpuContext};
use fxgraph::gpu::executor::{Engine, FrameInputs};
use fxgraph::gpu::transfer::create_output;
use fxgraph::graph::plan::InputDesc;
use fxgraph::script::types::Format;
use std::time::{Duration, Instant};

const TEN_PASSES: &str = "EFFECT.ten = { PASS = {
    p0 = SHADER.brightPass { img = IN  threshold = 0.1  OUT.FORMAT = rgba8 }
    p1 = SHADER.blurX { img = PASS.p0  sigma = 1  OUT.FORMAT = rgba8 }
    p2 = SHADER.blurY { img = PASS.p1  sigma = 1  OUT.FORMAT = rgba8 }
    p3 = SHADER.add { img1 = PASS.p2  img2 = PASS.p0  OUT.FORMAT = rgba8 }
    p4 = SHADER.blurX { img = PASS.p3  sigma = 1  OUT.FORMAT = rgba8 }
    p5 = SHADER.blurY { img = PASS.p4  sigma = 1  OUT.FORMAT = rgba8 }
    p6 = SHADER.add { img1 = PASS.p5  img2 = PASS.p3  OUT.FORMAT = rgba8 }
    p7 = SHADER.blurX { img = PASS.p6  sigma = 1  OUT.FORMAT = rgba8 }
    p8 = SHADER.blurY { img = PASS.p7  sigma = 1  OUT.FORMAT = rgba8 }
    p9 = SHADER.add { img1 = PASS.p8  img2 = IN }
} OUT = p9 }";

fn bench(c: &mut Criterion) {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let Ok(ctx) = GpuContext::new(&AdapterChoice::Auto) else {
        eprintln!("no adapter: executor benchmark skipped");
        return;
    };
    let adapter = ctx.info.name.clone();
    let mut engine = Engine::new(ctx);
    let dir = std::env::temp_dir().join("fxgraph-bench");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ten.fx");
    std::fs::write(&path, TEN_PASSES).unwrap();
    let mut effect = Effect::compile(&[path.display().to_string()], &[]).unwrap();
    for (w, h) in [(64u32, 64u32), (640, 360)] {
        let input = InputDesc::rgba8_srgb(w, h);
        let mut prepared = effect
            .prepare(&mut engine, &input, Some(Format::Rgba8Srgb))
            .unwrap();
        let ctx = engine.ctx.clone();
        let data = vec![128u8; (w * h * 4) as usize];
        let tex = ctx
            .upload_texture(
                "bench input",
                w,
                h,
                wgpu::TextureFormat::Rgba8UnormSrgb,
                &data,
                wgpu::TextureUsages::empty(),
            )
            .unwrap();
        let out = create_output(&ctx, w, h, Format::Rgba8Srgb);
        // Warm up: the first frame pays the software rasteriser's shader compilation.
        prepared
            .run(&mut engine, &FrameInputs::single(&tex), &out, false)
            .unwrap();
        ctx.wait_idle().unwrap();
        // GPU time of the passes (timestamp queries), measured apart from the CPU
        // time so that reading the timestamps back does not count as overhead.
        let mut gpu_total = Duration::ZERO;
        let mut gpu_frames = 0u32;
        for _ in 0..20 {
            let timings = prepared
                .run(&mut engine, &FrameInputs::single(&tex), &out, true)
                .unwrap();
            let g: Vec<f64> = timings.iter().filter_map(|p| p.gpu_ms).collect();
            if g.len() == timings.len() {
                gpu_total += Duration::from_secs_f64(g.iter().sum::<f64>() / 1e3);
                gpu_frames += 1;
            }
        }
        let passes = prepared.plan.passes.len() as f64;
        let view = |t: &wgpu::Texture, label| {
            t.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                ..Default::default()
            })
        };
        let (out_view, in_view) = (
            view(&out, "bench output view"),
            view(&tex, "bench input view"),
        );
        // CPU side of a frame as an application pays it: record into its encoder
        // (`record`), then finish and submit.
        let mut record_total = Duration::ZERO;
        let mut frame_total = Duration::ZERO;
        let mut frames = 0u32;
        c.bench_function(&format!("executor/10 passes {w}x{h} ({adapter})"), |b| {
            b.iter(|| {
                let t = Instant::now();
                let mut encoder =
                    ctx.device
                        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                            label: Some("bench frame"),
                        });
                prepared
                    .record(
                        &mut engine,
                        &mut encoder,
                        &FrameInputs::single(&in_view),
                        &out_view,
                    )
                    .unwrap();
                let recorded = t.elapsed();
                ctx.queue.submit([encoder.finish()]);
                let cpu = t.elapsed();
                record_total += recorded;
                frame_total += cpu;
                frames += 1;
                ctx.wait_idle().unwrap();
                cpu
            })
        });
        if frames > 0 {
            let rec = record_total.as_secs_f64() * 1e3 / frames as f64;
            let frame = frame_total.as_secs_f64() * 1e3 / frames as f64;
            eprintln!(
                "{w}x{h}: CPU per frame: record {rec:.4} ms ({:.4} ms/pass), record+finish+submit {frame:.4} ms ({:.4} ms/pass); mean of {frames} frames",
                rec / passes,
                frame / passes
            );
        }
        if gpu_frames > 0 {
            let gpu = gpu_total.as_secs_f64() * 1e3 / gpu_frames as f64;
            let frame = frame_total.as_secs_f64() * 1e3 / frames.max(1) as f64;
            eprintln!(
                "{w}x{h}: GPU passes {gpu:.3} ms per frame (timestamps, mean of {gpu_frames}); engine overhead (record+finish+submit) {:.2} % of GPU time",
                100.0 * frame / gpu
            );
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
