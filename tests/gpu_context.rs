//! Device layer tests. They skip (printing "skipping: no adapter") when no adapter
//! works, unless `FX_REQUIRE_GPU=1`, which turns that into a failure. The GL case runs
//! in a child process with `WGPU_BACKEND=gl` and skips unless `FX_REQUIRE_GL=1`.
//!
//! Run with `XDG_RUNTIME_DIR=/tmp cargo test --test engine gpu_context:: -- --nocapture` to see
//! the adapter list, format support and timings.
#![cfg(feature = "gpu")]

use std::process::Command;
use std::sync::OnceLock;
use std::time::Instant;

use fxgraph::gpu::context::{
    list_adapters, require_gpu, AdapterChoice, GpuContext, GpuError, GpuTimer,
};
use fxgraph::gpu::transfer::texture_2d;

fn init_logging() {
    let _ = env_logger::builder().is_test(true).try_init();
}

/// The shared Auto context, or `None` (after printing why) when tests should skip.
fn shared_context() -> Option<&'static GpuContext> {
    shared_context_and_creation_ms().map(|(ctx, _)| ctx)
}

/// The shared context and how long creating it took (the first instance and device
/// of the process, so it includes loading the drivers).
fn shared_context_and_creation_ms() -> Option<(&'static GpuContext, f64)> {
    static CTX: OnceLock<(Result<GpuContext, String>, f64)> = OnceLock::new();
    let (ctx, ms) = CTX.get_or_init(|| {
        init_logging();
        let start = Instant::now();
        let ctx = GpuContext::new(&AdapterChoice::Auto).map_err(|e| e.to_string());
        (ctx, start.elapsed().as_secs_f64() * 1e3)
    });
    match ctx {
        Ok(ctx) => Some((ctx, *ms)),
        Err(e) if require_gpu() => panic!("FX_REQUIRE_GPU=1 but no GPU context: {e}"),
        Err(e) => {
            eprintln!("skipping: no adapter ({e})");
            None
        }
    }
}

macro_rules! context_or_skip {
    () => {
        match shared_context() {
            Some(ctx) => ctx,
            None => return,
        }
    };
}

/// The formats whose support the tests print: the engine's texture formats.
const REPORTED_FORMATS: [wgpu::TextureFormat; 5] = [
    wgpu::TextureFormat::Rgba8Unorm,
    wgpu::TextureFormat::Rgba8UnormSrgb,
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::Rgba32Float,
    wgpu::TextureFormat::R32Float,
];

/// `ctx.upload_texture` of a `w` x `h` texture with no extra usage.
fn upload(
    ctx: &GpuContext,
    label: &str,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    data: &[u8],
) -> Result<wgpu::Texture, GpuError> {
    ctx.upload_texture(label, w, h, format, data, wgpu::TextureUsages::empty())
}

/// A 256-byte buffer `label` with `usage`, made on `device`.
fn buffer(device: &wgpu::Device, label: &str, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: 256,
        usage,
        mapped_at_creation: false,
    })
}

/// A `size` RGBA8 texture `label` (one mip level, one sample) with `usage`,
/// made on `device` with no data.
fn rgba8_texture(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    let format = wgpu::TextureFormat::Rgba8Unorm;
    device.create_texture(&texture_2d(label, size, format, usage, &[]))
}

fn rgba8_pattern(width: u32, height: u32) -> Vec<u8> {
    (0..width * height * 4)
        .map(|i| (i.wrapping_mul(37) ^ (i >> 7)) as u8)
        .collect()
}

fn rgba16f_pattern(width: u32, height: u32) -> Vec<u8> {
    let values: Vec<half::f16> = (0..width * height * 4)
        .map(|i| half::f16::from_f32((i % 4001) as f32 * 0.25 - 500.0))
        .collect();
    bytemuck::cast_slice(&values).to_vec()
}

fn rgba32f_pattern(width: u32, height: u32) -> Vec<u8> {
    let values: Vec<f32> = (0..width * height * 4)
        .map(|i| i as f32 * 1.5 - 1000.0 + 1.0 / 3.0)
        .collect();
    bytemuck::cast_slice(&values).to_vec()
}

fn pattern(format: wgpu::TextureFormat, width: u32, height: u32) -> Vec<u8> {
    match format {
        wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Rgba8UnormSrgb => {
            rgba8_pattern(width, height)
        }
        wgpu::TextureFormat::Rgba16Float => rgba16f_pattern(width, height),
        wgpu::TextureFormat::Rgba32Float => rgba32f_pattern(width, height),
        other => panic!("no test pattern for {other:?}"),
    }
}

#[test]
fn list_adapters_contains_the_auto_choice_and_respects_preference() {
    let ctx = context_or_skip!();
    let adapters = list_adapters();
    for a in &adapters {
        eprintln!("adapter {a}");
    }
    eprintln!(
        "auto choice: {} ({}, {:?}), timestamps {}",
        ctx.info.name, ctx.info.backend, ctx.info.device_type, ctx.timestamps
    );
    assert!(!adapters.is_empty());
    for (i, a) in adapters.iter().enumerate() {
        assert_eq!(a.index, i);
    }
    let chosen_backend = ctx.info.backend.to_str();
    assert!(
        adapters
            .iter()
            .any(|a| a.name == ctx.info.name && a.backend == chosen_backend),
        "the Auto adapter is not in list_adapters()"
    );

    let real_gpu = |t: &str| t == "DiscreteGpu" || t == "IntegratedGpu";
    let chosen_type = format!("{:?}", ctx.info.device_type);
    if adapters.iter().any(|a| real_gpu(&a.device_type)) {
        assert!(real_gpu(&chosen_type), "Auto skipped a real GPU");
    } else if adapters
        .iter()
        .any(|a| a.device_type == "Cpu" && a.backend == "vulkan")
    {
        // No real GPU: lavapipe (Vulkan on the CPU) must win over GL.
        assert_eq!(chosen_type, "Cpu");
        assert_eq!(ctx.info.backend, wgpu::Backend::Vulkan);
    }
}

#[test]
fn adapter_choice_by_name_and_index() {
    let ctx = context_or_skip!();
    let by_name = GpuContext::new(&AdapterChoice::NameContains(ctx.info.name.to_uppercase()))
        .expect("adapter by name");
    assert_eq!(by_name.info.name, ctx.info.name);

    let summary = list_adapters()
        .into_iter()
        .find(|a| a.name == ctx.info.name && a.backend == ctx.info.backend.to_str())
        .expect("auto adapter listed");
    let by_index = GpuContext::new(&AdapterChoice::Index(summary.index)).expect("adapter by index");
    assert_eq!(by_index.info.name, ctx.info.name);
    assert_eq!(by_index.info.backend, ctx.info.backend);

    match GpuContext::new(&AdapterChoice::NameContains("no-such-adapter-xyz".into())) {
        Err(GpuError::AdapterNotFound { wanted, available }) => {
            assert!(wanted.contains("no-such-adapter-xyz"));
            assert!(!available.is_empty());
        }
        other => panic!("expected AdapterNotFound, got {other:?}"),
    }
    assert!(matches!(
        GpuContext::new(&AdapterChoice::Index(10_000)),
        Err(GpuError::AdapterNotFound { .. })
    ));
}

#[test]
fn upload_readback_round_trip_is_exact() {
    let ctx = context_or_skip!();
    let formats = [
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureFormat::Rgba16Float,
        wgpu::TextureFormat::Rgba32Float,
    ];
    for format in formats {
        for (width, height) in [(67, 41), (1, 1), (64, 3), (1, 5)] {
            let data = pattern(format, width, height);
            let texture = upload(ctx, "round trip", (width, height), format, &data)
                .unwrap_or_else(|e| panic!("upload {format:?} {width}x{height}: {e}"));
            let back = ctx
                .read_texture(&texture)
                .unwrap_or_else(|e| panic!("read {format:?} {width}x{height}: {e}"));
            assert_eq!(back.len(), data.len(), "{format:?} {width}x{height}");
            assert!(back == data, "{format:?} {width}x{height}: bytes differ");
        }
    }
    assert!(ctx.take_uncaptured_errors().is_empty());
}

#[test]
fn srgb_texture_reads_back_stored_bytes_and_has_a_linear_view() {
    let ctx = context_or_skip!();
    let data = rgba8_pattern(67, 41);
    let texture = ctx
        .upload_texture(
            "srgb",
            67,
            41,
            wgpu::TextureFormat::Rgba8UnormSrgb,
            &data,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .expect("upload srgb");
    assert_eq!(ctx.read_texture(&texture).expect("read srgb"), data);

    let downlevel = ctx.adapter.get_downlevel_capabilities().flags;
    if downlevel.contains(wgpu::DownlevelFlags::VIEW_FORMATS) {
        // The texture lists its linear twin, so a reinterpreting view is valid.
        ctx.scoped("linear view of srgb texture", |_| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("linear view"),
                format: Some(wgpu::TextureFormat::Rgba8Unorm),
                ..Default::default()
            })
        })
        .expect("linear view");
    }
}

#[test]
fn scoped_turns_validation_errors_into_err() {
    let ctx = context_or_skip!();
    let zero = ctx.scoped("zero-size texture", |device| {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING;
        rgba8_texture(device, "zero-size texture", (0, 0), usage)
    });
    match zero {
        Err(GpuError::Validation { what, message }) => {
            assert_eq!(what, "zero-size texture");
            assert!(!message.is_empty());
        }
        other => panic!("expected a validation error, got {other:?}"),
    }

    let bad_buffer = ctx.scoped("map-read storage buffer", |device| {
        let usage = wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE;
        buffer(device, "map-read storage buffer", usage)
    });
    assert!(
        matches!(bad_buffer, Err(GpuError::Validation { .. })),
        "{bad_buffer:?}"
    );

    // Nested scopes are LIFO and the outer one stays clean.
    let nested = ctx.scoped("outer", |_| {
        ctx.scoped("inner", |device| {
            let usage = wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::MAP_WRITE;
            buffer(device, "bad inner buffer", usage)
        })
        .is_err()
    });
    assert!(matches!(nested, Ok(true)), "{nested:?}");

    let fine = ctx.scoped("valid buffer", |device| {
        let usage = wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST;
        buffer(device, "valid buffer", usage)
    });
    assert!(fine.is_ok());
    assert!(ctx.take_uncaptured_errors().is_empty());
}

#[test]
fn upload_and_readback_report_bad_input() {
    let ctx = context_or_skip!();
    use wgpu::TextureFormat::{Depth32Float, Rgba8Unorm};
    let short = upload(ctx, "short data", (4, 4), Rgba8Unorm, &[0; 10]);
    assert!(
        matches!(short, Err(GpuError::Validation { .. })),
        "{short:?}"
    );
    let depth = upload(ctx, "depth", (4, 4), Depth32Float, &[0; 64]);
    let unsupported = matches!(depth, Err(GpuError::UnsupportedFormat { .. }));
    assert!(unsupported, "{depth:?}");

    let usage = wgpu::TextureUsages::TEXTURE_BINDING;
    let no_copy_src = rgba8_texture(&ctx.device, "no copy src", (4, 4), usage);
    let read = ctx.read_texture(&no_copy_src);
    assert!(matches!(read, Err(GpuError::Validation { .. })), "{read:?}");
    assert!(ctx.take_uncaptured_errors().is_empty());
}

#[test]
fn check_size_rejects_one_more_than_the_limit() {
    let ctx = context_or_skip!();
    let max = ctx.device.limits().max_texture_dimension_2d;
    assert!(ctx.check_size(max, 1, "big").is_ok());
    match ctx.check_size(max + 1, 16, "huge intermediate") {
        Err(err @ GpuError::TooLarge { .. }) => {
            let message = err.to_string();
            assert!(message.contains("huge intermediate"), "{message}");
            assert!(message.contains(&max.to_string()), "{message}");
        }
        other => panic!("expected TooLarge, got {other:?}"),
    }
    assert!(matches!(
        ctx.check_size(16, max + 1, "tall"),
        Err(GpuError::TooLarge { .. })
    ));
    assert!(ctx.check_size(0, 16, "empty").is_err());
}

#[test]
fn format_support_matches_webgpu_basics() {
    let ctx = context_or_skip!();
    for format in REPORTED_FORMATS {
        eprintln!("{format:?}: {:?}", ctx.format_support(format));
    }
    let rgba8 = ctx.format_support(wgpu::TextureFormat::Rgba8Unorm);
    assert!(rgba8.render && rgba8.blend && rgba8.filter);
    let rgba16f = ctx.format_support(wgpu::TextureFormat::Rgba16Float);
    assert!(rgba16f.render && rgba16f.filter);
    let depth = ctx.format_support(wgpu::TextureFormat::Depth32Float);
    assert!(!depth.render && !depth.blend);
    let rgba32f = ctx.format_support(wgpu::TextureFormat::Rgba32Float);
    if !ctx
        .device
        .features()
        .contains(wgpu::Features::FLOAT32_FILTERABLE)
    {
        assert!(!rgba32f.filter);
    }
}

#[test]
fn encode_readback_pipelines_several_copies() {
    let ctx = context_or_skip!();
    let a_data = rgba8_pattern(67, 41);
    let b_data = rgba32f_pattern(3, 2);
    let a = upload(ctx, "a", (67, 41), wgpu::TextureFormat::Rgba8Unorm, &a_data).unwrap();
    let b = upload(ctx, "b", (3, 2), wgpu::TextureFormat::Rgba32Float, &b_data).unwrap();
    let mut encoder = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("pipelined readback"),
        });
    let pa = ctx.encode_readback(&mut encoder, &a).unwrap();
    let pb = ctx.encode_readback(&mut encoder, &b).unwrap();
    assert_eq!((pa.width(), pa.height()), (67, 41));
    ctx.queue.submit([encoder.finish()]);
    assert_eq!(pb.finish().unwrap(), b_data);
    assert_eq!(pa.finish().unwrap(), a_data);
    ctx.wait_idle().unwrap();
}

#[test]
fn timer_measures_clear_passes() {
    let ctx = context_or_skip!();
    check_timer(ctx);
}

/// Times three clear passes; skips (printing why) without timestamp queries.
fn check_timer(ctx: &GpuContext) {
    let Some(timer) = GpuTimer::new(ctx, 4) else {
        assert!(!ctx.timestamps, "timestamps supported but no timer");
        eprintln!("skipping: adapter has no timestamp queries");
        return;
    };
    assert!(GpuTimer::new(ctx, 0).is_none());
    assert!(timer.pass_writes(4).is_none());
    let target = ctx
        .upload_texture(
            "timer target",
            256,
            256,
            wgpu::TextureFormat::Rgba8Unorm,
            &rgba8_pattern(256, 256),
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .unwrap();
    let view = target.create_view(&wgpu::TextureViewDescriptor {
        label: Some("timer target view"),
        ..Default::default()
    });
    let used = 3;
    let mut encoder = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("timed clears"),
        });
    for i in 0..used {
        let _pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("timed clear"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLUE),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timer.pass_writes(i),
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }
    timer.resolve(&mut encoder, used);
    ctx.scoped("timed submit", |_| ctx.queue.submit([encoder.finish()]))
        .unwrap();
    let ms = timer.read_ms(ctx, used).unwrap();
    eprintln!(
        "clear pass times (ms): {ms:?}, period {} ns",
        ctx.queue.get_timestamp_period()
    );
    assert_eq!(ms.len(), used as usize);
    assert!(ms.iter().all(|t| t.is_finite() && *t >= 0.0), "{ms:?}");
    // Reading twice works (the buffer was unmapped).
    assert_eq!(timer.read_ms(ctx, used).unwrap().len(), used as usize);
    let back = ctx.read_texture(&target).unwrap();
    assert_eq!(&back[..4], &[0, 0, 255, 255]);
}

#[test]
fn timings_context_creation_and_1080p_readback() {
    let Some((ctx, first_ms)) = shared_context_and_creation_ms() else {
        return;
    };
    let start = Instant::now();
    let fresh = GpuContext::new(&AdapterChoice::Auto).expect("second context");
    let again_ms = start.elapsed().as_secs_f64() * 1e3;
    drop(fresh);

    let (w, h) = (1920, 1080);
    let data = rgba8_pattern(w, h);
    let texture = upload(ctx, "1080p", (w, h), wgpu::TextureFormat::Rgba8Unorm, &data).unwrap();
    ctx.wait_idle().unwrap();
    let mut times = Vec::new();
    for _ in 0..5 {
        let start = Instant::now();
        let back = ctx.read_texture(&texture).unwrap();
        times.push(start.elapsed().as_secs_f64() * 1e3);
        assert!(back == data);
    }
    eprintln!(
        "TIMING {}: context creation {first_ms:.1} ms (first), {again_ms:.1} ms (again); \
         1920x1080 rgba8 readback ms {:?}",
        ctx.info.name,
        times.iter().map(|t| format!("{t:.2}")).collect::<Vec<_>>()
    );
}

/// Runs `gl_child_probe` in a child process with `WGPU_BACKEND=gl`: the instance
/// reads the variable when it is created, and changing the environment of this
/// multi-threaded test process would race with the other tests.
#[test]
fn gl_backend_works_headless() {
    let exe = std::env::current_exe().expect("test executable");
    let output = Command::new(exe)
        .args([
            &crate::common::test_name(module_path!(), "gl_child_probe"),
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("WGPU_BACKEND", "gl")
        .env("FXGRAPH_GL_CHILD", "1")
        .output()
        .expect("run child test");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("--- GL child stdout ---\n{stdout}\n--- GL child stderr ---\n{stderr}");
    let require_gl = std::env::var("FX_REQUIRE_GL").is_ok_and(|v| v == "1");
    if stderr.contains("GL_PROBE_SKIP") && !require_gl {
        eprintln!("skipping: no GL adapter");
        return;
    }
    assert!(output.status.success(), "GL child failed");
    assert!(stderr.contains("GL_PROBE_OK"), "GL child did not run");
}

#[test]
fn gl_child_probe() {
    if std::env::var_os("FXGRAPH_GL_CHILD").is_none() {
        return; // only meaningful inside gl_backend_works_headless
    }
    init_logging();
    let adapters = list_adapters();
    for a in &adapters {
        eprintln!("GL adapter {a}");
    }
    assert!(adapters.iter().all(|a| a.backend == "gl"), "{adapters:?}");
    let ctx = match GpuContext::new(&AdapterChoice::Auto) {
        Ok(ctx) => ctx,
        Err(e) => {
            eprintln!("GL_PROBE_SKIP: {e}");
            return;
        }
    };
    assert_eq!(ctx.info.backend, wgpu::Backend::Gl);
    eprintln!(
        "GL context: {} / {} {}; timestamps {}; max texture {}",
        ctx.info.name,
        ctx.info.driver,
        ctx.info.driver_info,
        ctx.timestamps,
        ctx.device.limits().max_texture_dimension_2d
    );
    for format in REPORTED_FORMATS {
        eprintln!("GL {format:?}: {:?}", ctx.format_support(format));
    }
    for format in [
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureFormat::Rgba16Float,
        wgpu::TextureFormat::Rgba32Float,
    ] {
        for (w, h) in [(67, 41), (1, 1)] {
            let data = pattern(format, w, h);
            let texture = upload(&ctx, "gl round trip", (w, h), format, &data)
                .unwrap_or_else(|e| panic!("GL upload {format:?} {w}x{h}: {e}"));
            let back = ctx
                .read_texture(&texture)
                .unwrap_or_else(|e| panic!("GL read {format:?} {w}x{h}: {e}"));
            assert!(back == data, "GL {format:?} {w}x{h}: bytes differ");
        }
    }
    check_timer(&ctx);
    assert!(ctx.take_uncaptured_errors().is_empty());
    eprintln!("GL_PROBE_OK");
}
