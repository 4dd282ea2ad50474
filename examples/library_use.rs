//! Using fxgraph from a Rust program on its own wgpu device and textures.
//!
//! The program creates the device itself (as a renderer would), wraps it with
//! `GpuContext::from_existing`, compiles an effect chain, and each frame records
//! it into its own command encoder, reading its own input texture and writing its
//! own output texture, changing a parameter between frames without recompiling
//! (see docs/library.md).
//!
//! Run: `cargo run --release --example library_use [EFFECT...]` (default: glow).

use fxgraph::app::Effect;
use fxgraph::gpu::context::GpuContext;
use fxgraph::gpu::executor::{wgpu_format, Engine, FrameInputs};
use fxgraph::gpu::transfer::texture_2d;
use fxgraph::graph::plan::InputDesc;
use fxgraph::script::types::Format;
use std::time::Instant;

#[path = "shared/scene.rs"]
mod scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // Silences a harmless warning of the Vulkan loader on headless machines.
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let effects: Vec<String> = std::env::args().skip(1).collect();
    let effects = if effects.is_empty() {
        vec!["glow".to_string()]
    } else {
        effects
    };
    let (width, height) = (640u32, 360u32);

    // 1. The application's own device.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("application device"),
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        ..Default::default()
    }))?;
    println!("adapter: {}", adapter.get_info().name);

    // 2. The application's own input (a gradient with bright spots) and output textures.
    let input = device.create_texture(&texture_2d(
        "application scene",
        (width, height),
        wgpu::TextureFormat::Rgba16Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        &[],
    ));
    let texels = scene::gradient_with_spots(width, height);
    queue.write_texture(
        input.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * 8),
            rows_per_image: None,
        },
        input.size(),
    );
    let output = device.create_texture(&texture_2d(
        "application output",
        (width, height),
        wgpu_format(Format::Rgba8Srgb),
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        &[],
    ));

    // 3. Compile the effect and prepare it for this input, on the application's device.
    let mut engine = Engine::new(GpuContext::from_existing(
        adapter,
        device.clone(),
        queue.clone(),
    ));
    let mut effect = Effect::compile(&effects, &[])?;
    let desc = InputDesc {
        width,
        height,
        format: Format::Rgba16f,
        colorspace: fxgraph::script::types::ColorSpace::Linear,
        aux: Vec::new(),
        aux_sizes: Vec::new(),
        viewport: None,
    };
    let mut prepared = effect.prepare(&mut engine, &desc, Some(Format::Rgba8Srgb))?;
    println!(
        "passes: {:?}",
        prepared
            .plan
            .passes
            .iter()
            .map(|p| p.path.as_str())
            .collect::<Vec<_>>()
    );

    // 4. Frame after frame: one encoder, one submission per frame.
    let params = prepared.params();
    println!(
        "parameters: {:?}",
        params.iter().map(|p| p.name.as_str()).collect::<Vec<_>>()
    );
    let view = |t: &wgpu::Texture, label| {
        t.create_view(&wgpu::TextureViewDescriptor {
            label: Some(label),
            ..Default::default()
        })
    };
    let input_view = view(&input, "application scene view");
    let output_view = view(&output, "application output view");
    for frame in 0..5 {
        // Raise the glow threshold a little each frame (when the chain has one).
        if params
            .iter()
            .any(|p| p.name.ends_with("brightPass.threshold"))
        {
            prepared.set_param("brightPass.threshold", &[0.2 + 0.1 * frame as f64])?;
        }
        let t = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("application frame"),
        });
        prepared.record(
            &mut engine,
            &mut encoder,
            &FrameInputs::single(&input_view),
            &output_view,
        )?;
        let recorded = t.elapsed();
        queue.submit([encoder.finish()]);
        engine.ctx.wait_idle()?;
        println!(
            "frame {frame}: recorded in {:.3} ms, {:.2} ms wall with the GPU work",
            recorded.as_secs_f64() * 1e3,
            t.elapsed().as_secs_f64() * 1e3,
        );
    }
    println!("engine: {:?}", engine.stats());
    let pixels = engine.ctx.read_texture(&output)?;
    let centre = ((60 * width + 80) * 4) as usize;
    println!("output pixel at a light: {:?}", &pixels[centre..centre + 4]);
    Ok(())
}
