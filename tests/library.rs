//! The library embedded in an application: its own device, its own encoder, its
//! own input and output textures; parameters changed between frames; the pool's
//! reuse; a temporal effect recorded frame by frame against the CLI stream path.

use crate::common;

use fxgraph::app::Effect;
use fxgraph::gpu::context::{require_gpu, GpuContext};
use fxgraph::gpu::executor::{Engine, FrameInputs, ParamError, Prepared};
use fxgraph::gpu::stream::Stream;
use fxgraph::gpu::transfer::{read_pixels, texture_2d};
use fxgraph::graph::plan::{InputDesc, PlanOptions};
use fxgraph::io::Pixels;
use fxgraph::script::types::{ColorSpace, Format};

/// out = IN * gain + bias, per channel (alpha kept).
const GAIN: &str = "@group(0) @binding(0) var img: texture_2d<f32>;
struct Params {
    gain: f32,       // @default(1) @range(0, 4) multiplier
    bias: vec2<f32>, // @default(0, 0) added to red and green
    taps: i32,       // @default(1) @range(1, 8) unused, an integer parameter
}
@group(0) @binding(1) var<uniform> params: Params;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    return vec4<f32>(c.r * params.gain + params.bias.x, c.g * params.gain + params.bias.y,
                     c.b * params.gain, c.a);
}
";

const TWO_GAINS: &str = "EFFECT.twogain = { PASS = {
    first = SHADER.gain { img = IN }
    second = SHADER.gain { img = PASS.first  OUT.FORMAT = rgba32f }
} OUT = second }";

/// r: IN, g: feedback + 1/64 (frames seen), b: the standard value `frame` / 64.
const ACCUM: &str = "@group(0) @binding(0) var c: texture_2d<f32>;
@group(0) @binding(1) var fb: texture_2d<f32>;
struct Params { frame: u32, }
@group(0) @binding(2) var<uniform> p: Params;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let q = vec2<i32>(pos.xy);
    let prev = textureLoad(fb, q, 0);
    return vec4<f32>(textureLoad(c, q, 0).r, prev.g + 1.0 / 64.0,
                     f32(p.frame) / 64.0 + 0.5 * prev.r, 1.0);
}
";

const FEEDBACK: &str = "EFFECT.accum = { PASS = {
    a = SHADER.accum { c = IN  fb = PASS.a[-1]  OUT.FORMAT = rgba32f }
} OUT = a }";

const W: u32 = 4;
const H: u32 = 3;

/// The application's device, made as an application would (not by fxgraph).
fn app_device() -> Option<(wgpu::Adapter, wgpu::Device, wgpu::Queue)> {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
        {
            Ok(a) => a,
            Err(e) => {
                assert!(!require_gpu(), "FX_REQUIRE_GPU=1 but no adapter: {e}");
                eprintln!("skipping: no adapter ({e})");
                return None;
            }
        };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("test application device"),
        ..Default::default()
    }))
    .expect("a device");
    Some((adapter, device, queue))
}

/// An engine on the application's device (`GpuContext::from_existing`), and the
/// application, which keeps the device and queue.
fn app_engine() -> Option<(Engine, App)> {
    let (adapter, device, queue) = app_device()?;
    let ctx = GpuContext::from_existing(adapter, device.clone(), queue.clone());
    Some((Engine::new(ctx), App { device, queue }))
}

/// The application: its device and queue, its own textures and encoders.
struct App {
    device: wgpu::Device,
    queue: wgpu::Queue,
}

impl App {
    /// A W x H rgba32f texture of the application's (sampled, copied, rendered to).
    fn texture(&self, label: &str) -> wgpu::Texture {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::RENDER_ATTACHMENT;
        let format = wgpu::TextureFormat::Rgba32Float;
        self.device
            .create_texture(&texture_2d(label, (W, H), format, usage, &[]))
    }

    /// Writes `texels` (W x H rgba32f) to `tex` through the application's queue.
    fn write(&self, tex: &wgpu::Texture, texels: &[f32]) {
        self.queue.write_texture(
            tex.as_image_copy(),
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(W * 16),
                rows_per_image: None,
            },
            tex.size(),
        );
    }

    /// One frame of `prepared` as the application runs it: recorded into its own
    /// encoder to `out_view` (a view of `output`), submitted on its queue; `output`
    /// read back.
    fn frame(
        &self,
        engine: &mut Engine,
        prepared: &mut Prepared,
        inputs: &FrameInputs,
        (out_view, output): (&wgpu::TextureView, &wgpu::Texture),
    ) -> Vec<f32> {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("app frame"),
            });
        let recorded = prepared.record(engine, &mut encoder, inputs, out_view);
        recorded.unwrap();
        self.queue.submit([encoder.finish()]);
        read_f32(&engine.ctx, output)
    }
}

/// The effect `fx` compiled from a folder with `shaders` (name, WGSL) in it; the
/// folder lives as long as the effect is used.
fn effect(shaders: &[(&str, &str)], fx: &str) -> (tempfile::TempDir, Effect) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in shaders {
        std::fs::write(dir.path().join(format!("{name}.wgsl")), text).unwrap();
    }
    let path = dir.path().join("effect.fx");
    std::fs::write(&path, fx).unwrap();
    let effect = Effect::compile(&[path.display().to_string()], &[]).unwrap();
    (dir, effect)
}

fn f32_input() -> InputDesc {
    InputDesc {
        width: W,
        height: H,
        format: Format::Rgba32f,
        colorspace: ColorSpace::Linear,
        aux: vec![],
        aux_sizes: Vec::new(),
        viewport: None,
    }
}

fn read_f32(ctx: &GpuContext, tex: &wgpu::Texture) -> Vec<f32> {
    match read_pixels(ctx, tex, Format::Rgba32f).unwrap() {
        Pixels::F32(v) => v,
        Pixels::U8(_) => unreachable!("rgba32f reads back as floats"),
    }
}

#[test]
fn caller_encoder_parameters_per_frame_against_a_cpu_oracle() {
    let Some((mut engine, app)) = app_engine() else {
        return;
    };
    let (_dir, mut effect) = effect(&[("gain", GAIN)], TWO_GAINS);
    let mut prepared = effect
        .prepare(&mut engine, &f32_input(), Some(Format::Rgba32f))
        .unwrap();
    let (input, output) = (app.texture("app input"), app.texture("app output"));
    let src: Vec<f32> = (0..W * H * 4).map(|i| (i % 7) as f32 / 8.0).collect();
    app.write(&input, &src);
    let in_view = input.create_view(&Default::default());
    let out_view = output.create_view(&Default::default());
    for frame in 0..6u32 {
        let gain = 0.5 + 0.25 * frame as f64;
        let bias = [0.125 * frame as f64, -0.0625];
        // `first.gain` and `second.gain` differ; `bias` is set on both passes.
        prepared.set_param("first.gain", &[gain]).unwrap();
        prepared.set_param("twogain/second.gain", &[2.0]).unwrap();
        prepared.set_param("bias", &bias).unwrap();
        let inputs = FrameInputs::single(&in_view);
        let got = app.frame(&mut engine, &mut prepared, &inputs, (&out_view, &output));
        for (i, (g, s)) in got.iter().zip(&src).enumerate() {
            let c = i % 4;
            let (b, k) = match c {
                0 => (bias[0], 1.0),
                1 => (bias[1], 1.0),
                2 => (0.0, 1.0),
                _ => (0.0, 0.0),
            };
            let first = if k == 0.0 {
                *s as f64
            } else {
                *s as f64 * gain + b
            };
            let want = if k == 0.0 { first } else { first * 2.0 + b };
            assert!(
                (*g as f64 - want).abs() < 1e-5,
                "frame {frame}, value {i}: {g} != {want}"
            );
        }
    }
    // Nothing was recompiled: the pipelines are the two of the prepare (one shader,
    // two target formats: rgba16f for `first`, rgba32f for `second`).
    assert_eq!(engine.stats().pipelines_created, 2);
}

#[test]
fn set_param_checks_like_set() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let (_dir, mut effect) = effect(&[("gain", GAIN)], TWO_GAINS);
    let mut prepared = effect
        .prepare(&mut engine, &f32_input(), Some(Format::Rgba32f))
        .unwrap();
    let writes = prepared.stats().uniform_writes;
    assert!(matches!(
        prepared.set_param("first.gain", &[5.0]),
        Err(ParamError::OutOfRange { lo, hi, .. }) if (lo, hi) == (0.0, 4.0)
    ));
    assert!(matches!(
        prepared.set_param("first.gain", &[1.0, 2.0]),
        Err(ParamError::WrongType { ref expected, .. }) if expected == "f32"
    ));
    assert!(matches!(
        prepared.set_param("taps", &[2.5]),
        Err(ParamError::WrongType { ref expected, .. }) if expected == "i32"
    ));
    let unknown = prepared.set_param("first.gian", &[1.0]).unwrap_err();
    assert!(
        matches!(&unknown, ParamError::Unknown { suggestion: Some(s), .. } if s.ends_with("first.gain")),
        "{unknown:?}"
    );
    assert!(matches!(
        prepared.set_param("third.gain", &[1.0]),
        Err(ParamError::Unknown { .. })
    ));
    // Rejected values write nothing; an accepted one writes each pass's buffer once.
    assert_eq!(prepared.stats().uniform_writes, writes);
    prepared.set_param("gain", &[3.0]).unwrap();
    assert_eq!(prepared.stats().uniform_writes, writes + 2);
    let gains: Vec<Vec<f64>> = prepared
        .params()
        .into_iter()
        .filter(|p| p.name.ends_with(".gain"))
        .map(|p| p.value)
        .collect();
    assert_eq!(gains, vec![vec![3.0], vec![3.0]]);
    // The same value again changes no bytes: no write.
    prepared.set_param("gain", &[3.0]).unwrap();
    assert_eq!(prepared.stats().uniform_writes, writes + 2);
}

/// A `w` x `h` sRGB texture, every byte 100, uploaded to `ctx`.
fn grey(ctx: &GpuContext, label: &str, w: u32, h: u32) -> wgpu::Texture {
    let data = vec![100u8; (w * h * 4) as usize];
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let usage = wgpu::TextureUsages::empty();
    ctx.upload_texture(label, w, h, format, &data, usage)
        .unwrap()
}

#[test]
fn pool_creates_nothing_after_the_first_frame() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    // Five passes with transient values between them.
    let fx = "EFFECT.chain = { PASS = {
        a = SHADER.blurX { img = IN  sigma = 1 }
        b = SHADER.blurY { img = PASS.a  sigma = 1 }
        c = SHADER.add { img1 = PASS.b  img2 = PASS.a }
        d = SHADER.blurX { img = PASS.c  sigma = 2 }
        e = SHADER.add { img1 = PASS.d  img2 = IN }
    } OUT = e }";
    let (_dir, mut effect) = effect(&[], fx);
    let input = InputDesc::rgba8_srgb(16, 8);
    let ctx = engine.ctx.clone();
    let tex = grey(&ctx, "pool input", 16, 8);
    for policy in [
        fxgraph::graph::plan::ReusePolicy::MinPeak,
        fxgraph::graph::plan::ReusePolicy::Pool,
    ] {
        let opts = PlanOptions {
            policy,
            output_format: Some(Format::Rgba8Srgb),
        };
        let mut prepared = effect.prepare_with(&mut engine, &input, &opts).unwrap();
        assert!(!prepared.plan.values.is_empty());
        let out = fxgraph::gpu::transfer::create_output(&ctx, 16, 8, Format::Rgba8Srgb);
        prepared
            .run(&mut engine, &FrameInputs::single(&tex), &out, false)
            .unwrap();
        let after_first = engine.stats();
        let bind_groups = prepared.stats().bind_groups_created;
        for _ in 0..5 {
            prepared
                .run(&mut engine, &FrameInputs::single(&tex), &out, false)
                .unwrap();
        }
        let steady = engine.stats();
        assert_eq!(
            steady.pool.created, after_first.pool.created,
            "{policy:?}: no texture created after the first frame"
        );
        assert_eq!(
            prepared.stats().bind_groups_created,
            bind_groups,
            "{policy:?}: no bind group created after the first frame"
        );
        assert_eq!(prepared.stats().frames, 6);
        assert!(steady.pool.held_bytes >= prepared.plan.peak_bytes.min(1));
    }
    // Another size: the first size's textures, unused, are destroyed once they
    // have been idle longer than the pool keeps them.
    engine.set_pool_keep_frames(1);
    let before = engine.stats().pool;
    let small = InputDesc::rgba8_srgb(8, 4);
    let mut prepared = effect
        .prepare(&mut engine, &small, Some(Format::Rgba8Srgb))
        .unwrap();
    let tex = grey(&ctx, "pool input 8x4", 8, 4);
    let out = fxgraph::gpu::transfer::create_output(&ctx, 8, 4, Format::Rgba8Srgb);
    for _ in 0..3 {
        prepared
            .run(&mut engine, &FrameInputs::single(&tex), &out, false)
            .unwrap();
    }
    let after = engine.stats().pool;
    engine.set_pool_keep_frames(8);
    assert!(after.created > before.created, "8x4 textures made");
    assert!(
        after.destroyed > before.destroyed,
        "16x8 textures destroyed"
    );
}

#[test]
fn feedback_through_the_caller_encoder_matches_the_stream() {
    let Some((mut engine, app)) = app_engine() else {
        return;
    };
    let (_dir, mut effect) = effect(&[("accum", ACCUM)], FEEDBACK);
    let opts = PlanOptions {
        output_format: Some(Format::Rgba32f),
        ..Default::default()
    };
    let frames = 5u32;
    let value = |i: u32| (i + 1) as f32 / 64.0;

    // The CLI path: a stream of uploaded images.
    let prepared = effect
        .prepare_with(&mut engine, &f32_input(), &opts)
        .unwrap();
    let mut stream = Stream::new(&engine, prepared, Format::Rgba32f);
    let mut from_stream = Vec::new();
    for i in 0..frames {
        let v = value(i);
        stream
            .push_image(&engine, &common::image_f32(W, H, |_, _| [v, v, v, 1.0]))
            .unwrap();
        while stream.next(&mut engine).unwrap().is_some() {
            from_stream.push(read_f32(&engine.ctx, stream.output()));
        }
    }
    stream.end();
    while stream.next(&mut engine).unwrap().is_some() {
        from_stream.push(read_f32(&engine.ctx, stream.output()));
    }

    // The application's path: its own textures and encoder, one frame each.
    let mut prepared = effect
        .prepare_with(&mut engine, &f32_input(), &opts)
        .unwrap();
    let (input, output) = (app.texture("app input"), app.texture("app output"));
    let out_view = output.create_view(&Default::default());
    let mut from_caller = Vec::new();
    for i in 0..frames {
        let v = value(i);
        app.write(&input, &[v, v, v, 1.0].repeat((W * H) as usize));
        let inputs = FrameInputs::single(&input);
        from_caller.push(app.frame(&mut engine, &mut prepared, &inputs, (&out_view, &output)));
    }
    assert_eq!(from_stream.len(), frames as usize);
    assert_eq!(from_caller, from_stream);
    // And both are what the effect means: g counts frames, b = frame/64 + IN[-1]/2.
    for (t, px) in from_caller.iter().enumerate() {
        let prev = if t == 0 { 0.0 } else { value(t as u32 - 1) };
        let want = [
            value(t as u32),
            (t + 1) as f32 / 64.0,
            t as f32 / 64.0 + 0.5 * prev,
        ];
        for c in 0..3 {
            assert!(
                (px[c] - want[c]).abs() < 1e-6,
                "frame {t} channel {c}: {px:?}"
            );
        }
    }
}
