//! The visibility buffer (`RendererOptions::gbuffer_layout = Visibility`,
//! src/render/visibility.rs) against the fat G-buffer it replaces: the same
//! scene and camera rendered both ways give the same lit image and the same
//! AUX.albedo and AUX.normal (PSNR ≥ 45 dB each) on the built-in room, the
//! corpus Cornell box and FlightHelmet (textured: base colour, normal and
//! occlusion-roughness-metal maps, sampled with the resolve's own gradients).
//! Every opaque draw of the room and the Cornell box is resolved in compute.

use crate::common;

use common::ibl::corpus;
use common::renders::{rgb_psnr, save_rgb_review};
use fxgraph::gpu::context::GpuContext;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{GbufferLayout, Renderer, RendererOptions, Technique};
use fxgraph::scene::Scene;

const SIZE: (u32, u32) = (160, 120);
const MIN_DB: f64 = 45.0;

/// The lit scene, AUX.albedo and AUX.normal of `scene` with `layout`, and
/// the draws the visibility buffer left to the G-buffer pass.
fn images(
    ctx: &GpuContext,
    scene: &Scene,
    (layout, compute_lighting): (GbufferLayout, bool),
) -> ([Vec<[f32; 4]>; 3], Option<usize>) {
    let opts = RendererOptions {
        gbuffer_layout: layout,
        compute_lighting,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, scene, &opts).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    let camera = scene.default_camera();
    let (out, _) = r
        .render(ctx, &camera, SIZE.0, SIZE.1, Technique::Deferred, None)
        .unwrap_or_else(|e| panic!("{} {layout}: {e}", scene.name));
    let read = |t: &wgpu::Texture| read_rgba_f32(ctx, t).unwrap();
    let aux = |name: &str| read(out.aux(name).expect("an AUX image"));
    (
        [read(&out.scene), aux("albedo"), aux("normal")],
        r.visibility_fallback_batches(),
    )
}

/// Both layouts of `scene` agree (with the compute light pass, or the
/// fragment one: the resolve then starts the specular light buffer); returns
/// the visibility buffer's fallback draws.
fn layouts_agree(ctx: &GpuContext, scene: &Scene, what: &str, compute: bool) -> usize {
    let (fat, none) = images(ctx, scene, (GbufferLayout::Fat, compute));
    assert_eq!(none, None, "the fat layout has no visibility buffer");
    let (vis, fallback) = images(ctx, scene, (GbufferLayout::Visibility, compute));
    let fallback = fallback.expect("lavapipe has a visibility buffer");
    for (i, name) in ["scene", "albedo", "normal"].into_iter().enumerate() {
        let db = rgb_psnr(&fat[i], &vis[i], true);
        eprintln!("{what}: visibility vs fat G-buffer, {name}: {db:.1} dB");
        if db < MIN_DB {
            save_rgb_review(&format!("visbuf_{what}_{name}_fat"), SIZE, &fat[i]);
            save_rgb_review(&format!("visbuf_{what}_{name}_visibility"), SIZE, &vis[i]);
        }
        assert!(db >= MIN_DB, "{what} {name}: {db:.1} dB < {MIN_DB} dB");
    }
    fallback
}

#[test]
fn the_visibility_buffer_matches_the_fat_gbuffer() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let room = Scene::load("builtin:room").unwrap();
    assert_eq!(
        layouts_agree(ctx, &room, "room", true),
        0,
        "room: every draw resolved"
    );
    let cornell = Scene::load(corpus("gltf/CornellBox.glb").to_str().unwrap()).unwrap();
    assert_eq!(
        layouts_agree(ctx, &cornell, "cornell box", true),
        0,
        "Cornell box: every draw resolved"
    );
    let helmet = corpus("gltf/FlightHelmet/FlightHelmet.gltf");
    let helmet = Scene::load(helmet.to_str().unwrap()).unwrap();
    let fallback = layouts_agree(ctx, &helmet, "flight helmet", true);
    eprintln!("flight helmet: {fallback} draws in the G-buffer pass");
}

/// The draws the resolve leaves to the G-buffer pass (an alpha-tested
/// material), drawn over the visibility buffer's depth, and double-sided
/// materials (the resolve's front-facing test) agree too, lit by the
/// fragment light pass (the resolve writes the specular light buffer).
#[test]
fn fallback_draws_and_double_sided_materials_agree() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let mut room = Scene::load("builtin:room").unwrap();
    for m in &mut room.materials {
        m.double_sided = true;
    }
    room.materials[0].alpha_mode = fxgraph::scene::AlphaMode::Mask;
    room.materials[0].alpha_cutoff = 0.5;
    let fallback = layouts_agree(
        ctx,
        &room,
        "room, double-sided, one MASK material, fragment light pass",
        false,
    );
    assert!(
        fallback > 0,
        "the MASK material's draws stay in the G-buffer pass"
    );
}
