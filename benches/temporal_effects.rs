//! GPU time of `taa` and `motion_blur` against `fxaa` at 1920x1080 (or
//! FX_BENCH_SIZE=WxH) on a synthetic sequence: a checkerboard panning at
//! (5.3, 2.1) px per frame with a disc moving the other way, point-sampled at the
//! pixel centres plus each frame's Halton jitter, with its motion vectors and depth
//! as AUX.motion and AUX.depth (rgba16f). The three effects run frame by frame in
//! turn in one process on one engine (the same frames, same adapter state); each
//! frame is one submission whose passes are timed with timestamp queries. Printed:
//! per effect the median over the measured frames (FX_BENCH_FRAMES, default 8,
//! after 2 warm-up frames, which pay the software rasteriser's shader compilation)
//! of the GPU time of all its passes, and of each pass. Exits without figures
//! when there is no adapter or it has no timestamp queries.
//!
//!   cargo bench --bench temporal_effects      (bash bench/temporal_effects.sh)

use fxgraph::app::Effect;
use fxgraph::gpu::executor::{Engine, FrameInputs, Prepared};
use fxgraph::gpu::transfer::{create_output, upload_image};
use fxgraph::graph::plan::InputDesc;
use fxgraph::io::Image;
use fxgraph::script::halton23;
use fxgraph::script::types::{ColorSpace, Format};

mod bench_env;
use bench_env::{adapter, env_or, median, size};

// The tests' helpers (CPU-made images).
#[path = "../tests/common/mod.rs"]
mod common;

const PAN: [f32; 2] = [5.3, 2.1];
const DISC_VEL: [f32; 2] = [-9.0, 4.0];

/// Frame `t`: (colour, motion, depth), the scene sampled at the pixel centres
/// plus `jitter`.
fn frame(w: u32, h: u32, t: u32, jitter: [f32; 2]) -> (Image, Image, Image) {
    let (cx, cy) = (
        0.6 * w as f32 + DISC_VEL[0] * t as f32,
        0.4 * h as f32 + DISC_VEL[1] * t as f32,
    );
    let r = 0.15 * h as f32;
    let on_disc = |x: f32, y: f32| (x - cx).powi(2) + (y - cy).powi(2) < r * r;
    let colour = |x: f32, y: f32| -> [f32; 4] {
        if on_disc(x, y) {
            return [4.0, 1.5, 0.3, 1.0];
        }
        let (u, v) = (x - PAN[0] * t as f32, y - PAN[1] * t as f32);
        let k = ((u / 9.0).floor() + (v / 9.0).floor()).rem_euclid(2.0);
        [0.05 + 0.9 * k, 0.1 + 0.6 * k, 0.9 - 0.8 * k, 1.0]
    };
    let img = common::image_f32(w, h, |x, y| {
        colour(x as f32 + 0.5 + jitter[0], y as f32 + 0.5 + jitter[1])
    });
    let mut aux = common::raster::object_aux(w, h, on_disc, (DISC_VEL, 2.0), (PAN, 10.0));
    let (_, depth) = aux.pop().expect("depth");
    let (_, motion) = aux.pop().expect("motion");
    (img, motion, depth)
}

/// One frame of one effect: the GPU time of all its passes, and of each (ms).
type FrameTimes = (f64, Vec<(String, f64)>);

fn main() {
    let Some(ctx) = adapter("temporal effects") else {
        return;
    };
    let (w, h) = size((1920, 1080));
    let measured: u32 = env_or("FX_BENCH_FRAMES", 8);
    let warmup = 2;
    println!("adapter: {} ({:?})", ctx.info.name, ctx.info.backend);
    let mut engine = Engine::new(ctx.clone());
    let input = InputDesc {
        width: w,
        height: h,
        format: Format::Rgba16f,
        colorspace: ColorSpace::Linear,
        aux: vec![
            ("motion".into(), Format::Rgba16f),
            ("depth".into(), Format::Rgba16f),
        ],
        aux_sizes: Vec::new(),
        viewport: None,
    };
    let names = ["fxaa", "taa", "motion_blur"];
    let mut effects: Vec<(Prepared, wgpu::Texture)> = names
        .iter()
        .map(|name| {
            let mut e = Effect::compile(&[name.to_string()], &[]).unwrap();
            let p = e
                .prepare(&mut engine, &input, Some(Format::Rgba16f))
                .unwrap();
            (p, create_output(&ctx, w, h, Format::Rgba16f))
        })
        .collect();
    let mut times: Vec<Vec<FrameTimes>> = vec![Vec::new(); names.len()];
    for t in 0..warmup + measured {
        let jitter = halton23(t as u64);
        let (img, motion, depth) = frame(w, h, t, jitter);
        let up = |i: &Image, what: &str| upload_image(&ctx, what, i, Format::Rgba16f).unwrap();
        let (tex, mtex, dtex) = (
            up(&img, "bench frame"),
            up(&motion, "bench motion"),
            up(&depth, "bench depth"),
        );
        for (k, (prepared, out)) in effects.iter_mut().enumerate() {
            let inputs = FrameInputs::single(&tex)
                .with_aux("motion", &mtex)
                .with_aux("depth", &dtex)
                .with_jitter(if prepared.jitter().is_some() {
                    jitter
                } else {
                    [0.0, 0.0]
                });
            let timings = prepared.run(&mut engine, &inputs, &*out, true).unwrap();
            let passes: Option<Vec<(String, f64)>> = timings
                .iter()
                .map(|p| p.gpu_ms.map(|g| (p.path.clone(), g)))
                .collect();
            let Some(passes) = passes else {
                println!("the adapter has no timestamp queries: no GPU times");
                return;
            };
            if t >= warmup {
                times[k].push((passes.iter().map(|(_, g)| g).sum(), passes));
            }
        }
    }
    println!(
        "GPU time per frame at {w}x{h}, median of {measured} frames (after {warmup} warm-up frames), rgba16f in and out:"
    );
    for (k, name) in names.iter().enumerate() {
        let total = median(times[k].iter().map(|(t, _)| *t).collect());
        println!("  {name:<12} {total:>9.2} ms");
        for (i, (path, _)) in times[k][0].1.iter().enumerate() {
            let m = median(times[k].iter().map(|(_, p)| p[i].1).collect());
            println!("      {path:<28} {m:>9.2} ms");
        }
    }
}
