//! Executor overhead on a 10-pass graph: CPU time to record and submit a frame
//! (engine overhead) against the GPU time of its passes, on whatever adapter
//! `GpuContext::new` picks (lavapipe in CI). Skips without an adapter.

use criterion::{criterion_group, criterion_main, Criterion};
use fxgraph::gpu::context::{AdapterChoice, GpuContext};
use fxgraph::gpu::executor::{Engine, FrameInputs};
use fxgraph::gpu::runner::{create_output, Effect};
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
        let mut gpu_total = Duration::ZERO;
        let mut cpu_total = Duration::ZERO;
        let mut frames = 0u32;
        c.bench_function(&format!("executor/10 passes {w}x{h} ({adapter})"), |b| {
            b.iter(|| {
                let t = Instant::now();
                let timings = prepared
                    .run(&mut engine, &FrameInputs::single(&tex), &out, true)
                    .unwrap();
                cpu_total += timings
                    .iter()
                    .map(|p| Duration::from_secs_f64(p.cpu_ms / 1e3))
                    .sum::<Duration>();
                gpu_total += timings
                    .iter()
                    .filter_map(|p| p.gpu_ms)
                    .map(|g| Duration::from_secs_f64(g / 1e3))
                    .sum::<Duration>();
                frames += 1;
                ctx.wait_idle().unwrap();
                t.elapsed()
            })
        });
        if frames > 0 {
            eprintln!(
                "{w}x{h}: per frame, CPU record+submit {:.3} ms, GPU passes {:.3} ms (mean of {frames} frames)",
                cpu_total.as_secs_f64() * 1e3 / frames as f64,
                gpu_total.as_secs_f64() * 1e3 / frames as f64
            );
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
