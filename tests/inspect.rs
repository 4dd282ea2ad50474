//! The library's tools API (what `fxrun --view` uses): `Prepared::inspect` keeps a
//! copy of a chosen intermediate that equals a run of the effect up to that pass,
//! without changing the output or the textures the plan takes from the pool;
//! `Prepared::set_gpu_timings` reads per-pass GPU times of frames recorded into
//! the caller's encoder, without stalling; an 8-bit output recorded into its BGRA
//! twin (a window surface's format) holds the same values.

use crate::common;

use fxgraph::app::Effect;
use fxgraph::gpu::context::GpuContext;
use fxgraph::gpu::executor::{Engine, Execution, FrameInputs, Prepared};
use fxgraph::gpu::transfer::{create_output, read_pixels, upload_image};
use fxgraph::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use fxgraph::io::Pixels;
use fxgraph::script::types::Format;
use std::sync::MutexGuard;

fn prepare(engine: &mut Engine, effect: &str, input: &InputDesc, out: Format) -> Prepared {
    let mut e = Effect::compile(&[effect.to_string()], &[]).unwrap();
    let opts = PlanOptions {
        policy: ReusePolicy::Pool,
        output_format: Some(out),
    };
    e.prepare_with(engine, input, &opts).unwrap()
}

/// What each test starts from: the test engine, its context, and a `w` x `h` test
/// pattern uploaded as an 8-bit sRGB input with its description; `None` (test
/// skipped) without a GPU.
fn setup(
    w: u32,
    h: u32,
) -> Option<(
    MutexGuard<'static, Engine>,
    GpuContext,
    wgpu::Texture,
    InputDesc,
)> {
    let engine = common::engine()?;
    let ctx = engine.ctx.clone();
    let img = common::pattern_u8(w, h);
    let input = upload_image(&ctx, "test input", &img, Format::Rgba8Srgb).unwrap();
    Some((engine, ctx, input, InputDesc::rgba8_srgb(w, h)))
}

/// `glow` prepared for `desc` (pooled) and an 8-bit sRGB output of its size.
fn prepared_glow(
    engine: &mut Engine,
    ctx: &GpuContext,
    desc: &InputDesc,
) -> (Prepared, wgpu::Texture) {
    let glow = prepare(engine, "glow", desc, Format::Rgba8Srgb);
    let out = create_output(ctx, desc.width, desc.height, Format::Rgba8Srgb);
    (glow, out)
}

/// Record one frame into an encoder of our own and submit it.
fn frame(engine: &mut Engine, p: &mut Prepared, input: &wgpu::Texture, out: &wgpu::Texture) {
    let ctx = engine.ctx.clone();
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("test frame"),
        });
    p.frame = 0;
    let inputs = FrameInputs::still(input, &p.plan);
    p.record(engine, &mut enc, &inputs, out).unwrap();
    ctx.queue.submit([enc.finish()]);
}

#[test]
fn an_inspected_pass_equals_the_effect_up_to_it_and_changes_nothing_else() {
    let Some((mut engine, ctx, input, desc)) = setup(64, 48) else {
        return;
    };
    let (mut glow, out) = prepared_glow(&mut engine, &ctx, &desc);
    frame(&mut engine, &mut glow, &input, &out);
    let plain = read_pixels(&ctx, &out, Format::Rgba8Srgb).unwrap();
    let created = engine.stats().pool.created;
    let blur_x = glow
        .plan
        .passes
        .iter()
        .position(|p| p.path.ends_with("blurX"))
        .unwrap();
    assert!(glow.inspected().is_none());
    glow.inspect(Some(blur_x)).unwrap();
    assert!(glow.inspected().is_none(), "nothing before a frame");
    frame(&mut engine, &mut glow, &input, &out);
    assert_eq!(
        engine.stats().pool.created,
        created,
        "no texture more from the pool"
    );
    assert!(
        read_pixels(&ctx, &out, Format::Rgba8Srgb).unwrap() == plain,
        "the output is the same"
    );
    let copy = glow.inspected().expect("a copy after the frame").clone();
    let pass = &glow.plan.passes[blur_x];
    assert_eq!(
        (copy.width(), copy.height()),
        (pass.desc.width, pass.desc.height)
    );
    let seen = read_pixels(&ctx, &copy, pass.desc.format).unwrap();
    // The reference: the effect up to blurX, run on its own.
    let dir = tempfile::tempdir().unwrap();
    let fx = dir.path().join("upto.fx");
    std::fs::write(&fx, common::UPTO_BLUR_X).unwrap();
    let mut upto = prepare(&mut engine, fx.to_str().unwrap(), &desc, pass.desc.format);
    let o = upto.plan.output;
    let out2 = create_output(&ctx, o.width, o.height, o.format);
    frame(&mut engine, &mut upto, &input, &out2);
    let want = read_pixels(&ctx, &out2, o.format).unwrap();
    let (Pixels::F32(a), Pixels::F32(b)) = (&seen, &want) else {
        panic!("blurX is a float pass");
    };
    assert_eq!(a.len(), b.len());
    assert!(a == b, "largest difference {}", common::max_abs_diff(a, b));
    // Out of range is an error; None stops the copies.
    assert!(glow.inspect(Some(99)).is_err());
    glow.inspect(None).unwrap();
    assert!(glow.inspected().is_none());
}

#[test]
fn gpu_times_of_recorded_frames_come_back_without_a_stall() {
    let Some((mut engine, ctx, input, desc)) = setup(32, 32) else {
        return;
    };
    let (mut glow, out) = prepared_glow(&mut engine, &ctx, &desc);
    let on = glow.set_gpu_timings(&engine, true);
    assert_eq!(on, ctx.timestamps);
    // A frame is timed, mapped at the next `record` and read at a later one.
    for _ in 0..6 {
        frame(&mut engine, &mut glow, &input, &out);
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }
    let times = glow.gpu_timings();
    if !on {
        assert!(times.is_empty());
        return;
    }
    let paths: Vec<&str> = times.iter().map(|t| t.path.as_str()).collect();
    let want: Vec<&str> = glow.plan.passes.iter().map(|p| p.path.as_str()).collect();
    assert_eq!(paths, want);
    assert!(
        times.iter().all(|t| t.gpu_ms.is_some_and(|ms| ms >= 0.0)),
        "{times:?}"
    );
    glow.set_gpu_timings(&engine, false);
    assert!(glow.gpu_timings().is_empty());
}

#[test]
fn an_output_in_the_bgra_twin_format_holds_the_same_values() {
    let Some((mut engine, ctx, input, desc)) = setup(40, 24) else {
        return;
    };
    for (out, effect) in [(Format::Rgba8Srgb, "glow"), (Format::Rgba8, "edges")] {
        let mut p = prepare(&mut engine, effect, &desc, out);
        let rgba = create_output(&ctx, 40, 24, out);
        frame(&mut engine, &mut p, &input, &rgba);
        let twin = fxgraph::gpu::executor::bgra_twin(rgba.format()).unwrap();
        let bgra = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("test BGRA output"),
            size: rgba.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: twin,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[twin.remove_srgb_suffix()],
        });
        frame(&mut engine, &mut p, &input, &bgra);
        let a = ctx.read_texture(&rgba).unwrap();
        let mut b = ctx.read_texture(&bgra).unwrap();
        for px in b.chunks_exact_mut(4) {
            px.swap(0, 2);
        }
        assert!(a == b, "{effect}: the BGRA output differs");
    }
    // Another format is refused, naming the twin.
    let mut p = prepare(&mut engine, "glow", &desc, Format::Rgba8Srgb);
    let wrong = create_output(&ctx, 40, 24, Format::Rgba16f);
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("test"),
        });
    let inputs = FrameInputs::still(&input, &p.plan);
    let e = p
        .record(&mut engine, &mut enc, &inputs, &wrong)
        .unwrap_err();
    assert!(e.to_string().contains("BGRA twin"), "{e}");
}

/// Under compute execution gaussian_blur's last pass (compute-native, storing
/// rgba16float) writes an 8-bit sRGB output through a stand-in, converted and
/// copied in (gpu/executor/stand_in.rs): no pass is drawn, and inspecting that
/// pass copies the output itself, in the output's format.
#[test]
fn inspecting_an_output_written_through_a_stand_in_copies_the_output() {
    let Some((mut engine, ctx, input, desc)) = setup(64, 48) else {
        return;
    };
    let before = engine.execution();
    engine.set_execution(Execution::Compute);
    let mut blur = prepare(&mut engine, "gaussian_blur", &desc, Format::Rgba8Srgb);
    let out = create_output(&ctx, desc.width, desc.height, Format::Rgba8Srgb);
    let last = blur.plan.passes.len() - 1;
    blur.inspect(Some(last)).unwrap();
    frame(&mut engine, &mut blur, &input, &out);
    engine.set_execution(before);
    assert_eq!(blur.stats().fragment_passes, 0, "a pass was drawn");
    let copy = blur.inspected().expect("a copy after the frame").clone();
    let seen = read_pixels(&ctx, &copy, Format::Rgba8Srgb).unwrap();
    let written = read_pixels(&ctx, &out, Format::Rgba8Srgb).unwrap();
    assert!(seen == written, "the inspected copy is the output");
}
