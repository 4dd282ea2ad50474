//! `taa` on frames the engine renders (issue 29, point 1): thin, high-contrast
//! bars drifting and turning over a dark wall, each frame jittered by the
//! renderer as `taa` asks (`halton23`), with the renderer's own AUX.motion and
//! AUX.depth, tone-mapped after `taa`.
//!
//! Reference: the same frame rendered 16 times with the projection offset to
//! the centres of a 4 x 4 grid of sub-pixel positions, averaged (a 4 x 4
//! box-supersampled render), then tone-mapped. The tone curve is the published
//! ACES fit of Narkowicz (2015), the `tonemap` effect's default, applied here on
//! the CPU to every image alike. The same reference resolved in display values
//! (the 16 samples tone-mapped, then averaged) is printed for the record.

use crate::common;

use common::stream::{run_stream_frames, SeqFrame};
use fxgraph::gpu::context::GpuContext;
use fxgraph::gpu::executor::Engine;
use fxgraph::io::Image;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{FrameMotion, Renderer, RendererOptions, Technique};
use fxgraph::scene::{Camera, Instance, Light, Material, Scene, ShaderBinding};
use fxgraph::script::halton23;
use fxgraph::script::types::Format;
use glam::{Mat4, Vec3};

const W: u32 = 128;
const H: u32 = 96;
/// Pixels this close to the edges are left out (content entering the frame).
const BORDER: u32 = 4;
type Px = [f32; 4];

/// Narkowicz's ACES fit, clamped to [0, 1] (effects/tonemap.fx, `aces`).
fn aces(x: f32) -> f32 {
    let x = x.max(0.0);
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

fn tonemapped(px: &[Px]) -> Vec<Px> {
    px.iter()
        .map(|p| [aces(p[0]), aces(p[1]), aces(p[2]), 1.0])
        .collect()
}

fn lambert(name: &str, c: [f64; 3]) -> Material {
    Material::new(
        name,
        ShaderBinding::new("standard").with("base_color", &[c[0], c[1], c[2], 1.0]),
        ShaderBinding::new("lambert"),
    )
}

/// The wall's transform: a 20-unit square at z = -2 facing the camera.
fn wall() -> Mat4 {
    Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0))
        * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(20.0))
}

/// A dark wall (instance 0, radiance 0.03) and in front of it, at z = 0, the
/// boxes `objects` at rest (instances 1..; white, radiance 3: a light from the
/// camera's side of 3π lux). The camera sees about 26 px per unit at z = 0.
fn scene(objects: &[Mat4]) -> Scene {
    let mut s = Scene {
        name: "taa scene".into(),
        ..Default::default()
    };
    s.meshes.push(fxgraph::scene::builtin::grid_plane(1));
    s.meshes.push(fxgraph::scene::builtin::box_mesh(Vec3::ONE));
    s.materials.push(lambert("wall", [0.01, 0.01, 0.012]));
    s.materials.push(lambert("white", [1.0, 0.95, 0.85]));
    let object = |i: usize, mesh: usize, material: usize, transform: Mat4| Instance {
        name: format!("object {i}"),
        mesh,
        material,
        transform,
        ..Default::default()
    };
    s.instances.push(object(0, 0, 0, wall()));
    for (i, t) in objects.iter().enumerate() {
        s.instances.push(object(i + 1, 1, 1, *t));
    }
    s.lights.push(Light::directional(
        Vec3::new(0.1, -0.1, -1.0),
        Vec3::ONE,
        3.0 * std::f32::consts::PI,
    ));
    s
}

/// The bars at rest: 0.01 to 0.05 units wide (0.3 to 1.3 px), 2.6 long, at
/// seven angles.
fn bars() -> Vec<Mat4> {
    [
        (0.012, 0.05, -1.4),
        (0.02, 0.45, -0.9),
        (0.035, 1.1, -0.4),
        (0.015, 1.52, 0.1),
        (0.05, 2.3, 0.6),
        (0.025, 2.75, 1.1),
        (0.01, 0.8, 1.5),
    ]
    .iter()
    .map(|&(w, angle, x)| {
        Mat4::from_translation(Vec3::new(x, 0.0, 0.0))
            * Mat4::from_rotation_z(angle)
            * Mat4::from_scale(Vec3::new(w, 2.6, w))
    })
    .collect()
}

/// The bars at frame `t`: drifting (0.61, 0.25) px per frame, each turning
/// 0.004 rad per frame about its centre, alternately either way.
fn bars_at(t: f32) -> Vec<Mat4> {
    let drift = Vec3::new(0.023, -0.0095, 0.0) * t;
    let mut out = vec![wall()];
    for (i, rest) in bars().iter().enumerate() {
        let spin = 0.004 * t * if i % 2 == 0 { 1.0 } else { -1.0 };
        let centre = rest.w_axis.truncate();
        out.push(
            Mat4::from_translation(drift + centre)
                * Mat4::from_rotation_z(spin)
                * Mat4::from_translation(-centre)
                * *rest,
        );
    }
    out
}

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 0.0, 5.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 40f32.to_radians(),
        near: 0.5,
        far: 20.0,
    }
}

/// A sequence: the instances' world transforms at frame `t`.
type Motion = fn(f32) -> Vec<Mat4>;

/// One rendered frame: the HDR image, AUX.motion and AUX.depth.
struct Rendered {
    hdr: Vec<Px>,
    motion: Vec<Px>,
    depth: Vec<Px>,
}

fn render(ctx: &GpuContext, r: &mut Renderer, at: Motion, t: f32, jitter: [f32; 2]) -> Rendered {
    let motion = FrameMotion {
        transforms: at(t),
        prev_transforms: at(t - 1.0),
        jitter,
        ..Default::default()
    };
    let (out, _) = r
        .render_frame(ctx, &camera(), &motion, W, H, Technique::Deferred, None)
        .unwrap_or_else(|e| panic!("frame {t}: {e}"));
    let read = |name: &str| read_rgba_f32(ctx, out.aux(name).expect(name)).unwrap();
    Rendered {
        hdr: read_rgba_f32(ctx, &out.scene).unwrap(),
        motion: read("motion"),
        depth: read("depth"),
    }
}

fn image(px: &[Px]) -> Image {
    common::image_f32(W, H, |x, y| px[(y * W + x) as usize])
}

fn rows(v: &[f32]) -> Vec<Px> {
    v.chunks_exact(4)
        .map(|p| [p[0], p[1], p[2], p[3]])
        .collect()
}

/// `frames` frames of `at` rendered with the Halton jitter, through `taa`: the
/// outputs (linear), tone-mapped.
fn taa_run(engine: &mut Engine, r: &mut Renderer, at: Motion, frames: u32) -> Vec<Vec<Px>> {
    let ctx = engine.ctx.clone();
    let seq: Vec<SeqFrame> = (0..frames)
        .map(|t| {
            let j = halton23(u64::from(t));
            let f = render(&ctx, r, at, t as f32, j);
            SeqFrame {
                image: image(&f.hdr),
                aux: vec![
                    ("motion".into(), image(&f.motion)),
                    ("depth".into(), image(&f.depth)),
                ],
                jitter: j,
            }
        })
        .collect();
    run_stream_frames(engine, "taa", &[], &seq, 30.0)
        .iter()
        .map(|o| tonemapped(&rows(o)))
        .collect()
}

/// The 4 x 4 supersampled reference of frame `t`, tone-mapped: the 16 HDR
/// renders averaged, then tone-mapped; and the 16 tone-mapped renders averaged.
fn supersampled(ctx: &GpuContext, r: &mut Renderer, at: Motion, t: f32) -> (Vec<Px>, Vec<Px>) {
    let n = (W * H) as usize;
    let (mut linear, mut display) = (vec![[0.0f32; 4]; n], vec![[0.0f32; 4]; n]);
    for b in 0..4 {
        for a in 0..4 {
            let j = [(a as f32 + 0.5) / 4.0 - 0.5, (b as f32 + 0.5) / 4.0 - 0.5];
            for (i, p) in render(ctx, r, at, t, j).hdr.iter().enumerate() {
                for c in 0..3 {
                    linear[i][c] += p[c] / 16.0;
                    display[i][c] += aces(p[c]) / 16.0;
                }
            }
        }
    }
    (tonemapped(&linear), display)
}

/// Mean absolute difference of r, g, b over the pixels at least [`BORDER`] from the edges.
fn mae(a: &[Px], b: &[Px]) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for y in BORDER..H - BORDER {
        for x in BORDER..W - BORDER {
            let i = (y * W + x) as usize;
            for c in 0..3 {
                s += f64::from((a[i][c] - b[i][c]).abs());
                n += 1;
            }
        }
    }
    s / n as f64
}

/// `fxaa` of a tone-mapped image (display values, as fxaa expects them).
fn fxaa(engine: &mut Engine, display: &[Px]) -> Vec<Px> {
    let (_, _, px) = common::run(engine, &["fxaa"], &[], &image(display), Format::Rgba32f)
        .unwrap_or_else(|e| panic!("fxaa: {e}"));
    rows(common::samples::f32s(&px))
}

/// Frames of the sequence; the last [`MEASURED`] are compared with the reference.
const FRAMES: u32 = 32;
const MEASURED: u32 = 6;

/// Issue 29 asks for taa / no AA <= 0.6 on such a scene. Measured here
/// (lavapipe): 0.583 (taa 0.0140, no AA 0.0240, fxaa 0.0310) with the history
/// at 3x the frame's resolution; before, at the frame's resolution, 0.796
/// (Keys' a = -1 cubic) and 0.837 (Catmull-Rom), near the 0.81. What
/// held it back: the history of sub-pixel motion is resampled every frame, and
/// the blur builds up over the frames it stands for (the same bars moving
/// exactly 1 px per frame gave 0.55, a longer history in motion 1.17). A
/// history texel a third of a pixel wide is blurred a ninth as much by each
/// resampling: 2x gave 0.62, 3x 0.583, 4x 0.56 (tuned each: the sample
/// Gaussian's sigma 0.13 px, Keys a = -0.75, `resample_limit` 1). The
/// resampling kernel matters less at that scale: a 6x6 Lanczos-3 gave 0.587.
/// Tone mapping before accumulation (x / (1 + max(x)), undone at the output)
/// gave 0.84 at 1x: it converges to the display-resolved average instead.
const RATIO_LIMIT: f64 = 0.6;

#[test]
fn taa_of_thin_moving_bars_against_the_supersampled_render() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let ctx = engine.ctx.clone();
    let mut r = Renderer::new(&ctx, &scene(&bars()), &RendererOptions::default()).unwrap();
    let outs = taa_run(&mut engine, &mut r, bars_at, FRAMES);
    let k = f64::from(MEASURED);
    let (mut taa, mut raw, mut fx) = (0.0, 0.0, 0.0);
    let (mut taa_d, mut raw_d, mut fx_d) = (0.0, 0.0, 0.0);
    for t in FRAMES - MEASURED..FRAMES {
        let (reference, reference_display) = supersampled(&ctx, &mut r, bars_at, t as f32);
        let plain = tonemapped(&render(&ctx, &mut r, bars_at, t as f32, [0.0, 0.0]).hdr);
        let smoothed = fxaa(&mut engine, &plain);
        let out = &outs[t as usize];
        taa += mae(out, &reference) / k;
        raw += mae(&plain, &reference) / k;
        fx += mae(&smoothed, &reference) / k;
        taa_d += mae(out, &reference_display) / k;
        raw_d += mae(&plain, &reference_display) / k;
        fx_d += mae(&smoothed, &reference_display) / k;
    }
    let ratio = taa / raw;
    eprintln!(
        "thin bars, mean absolute error against the 4x4 supersampled render (tone-mapped), last {MEASURED} of {FRAMES} frames: taa {taa:.4}, no anti-aliasing {raw:.4}, fxaa {fx:.4}; taa / no AA = {ratio:.3} (limit {RATIO_LIMIT}, issue 29), fxaa / no AA = {:.3}",
        fx / raw
    );
    eprintln!(
        "  against the 16 samples tone-mapped, then averaged: taa {taa_d:.4}, no anti-aliasing {raw_d:.4}, fxaa {fx_d:.4}"
    );
    assert!(
        ratio <= RATIO_LIMIT,
        "taa / no AA = {ratio:.3} > {RATIO_LIMIT}"
    );
    assert!(taa < fx, "taa {taa} is not closer than fxaa {fx}");
}

/// A 0.5-unit white square (13 px) crossing the wall at 2.5 px per frame.
fn square_at(t: f32) -> Vec<Mat4> {
    vec![
        wall(),
        Mat4::from_translation(Vec3::new(-1.2 + 0.0948 * t, 0.03 * t, 0.0))
            * Mat4::from_scale(Vec3::new(0.5, 0.5, 0.5)),
    ]
}

/// No trail where a moving object uncovered the background: the pixels the
/// square covered 4 frames ago or earlier that are now 2 px or more from it
/// (the pixels beside an edge are partly covered in the box reference too)
/// show the wall as the un-jittered render of the frame does, within 0.01 (1 %
/// of the display range).
#[test]
fn no_trail_four_frames_after_a_moving_object_uncovered_the_wall() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let ctx = engine.ctx.clone();
    let rest = square_at(0.0)[1..].to_vec();
    let mut r = Renderer::new(&ctx, &scene(&rest), &RendererOptions::default()).unwrap();
    let n = 14u32;
    let last = n - 1;
    let outs = taa_run(&mut engine, &mut r, square_at, n);
    // where the square is (depth nearer than the wall's 7) in un-jittered renders
    let covered = |r: &mut Renderer, t: u32| -> Vec<bool> {
        let d = render(&ctx, r, square_at, t as f32, [0.0, 0.0]).depth;
        d.iter().map(|p| p[0] < 6.0).collect()
    };
    let before: Vec<Vec<bool>> = (0..=last - 4).map(|t| covered(&mut r, t)).collect();
    let now = covered(&mut r, last);
    let plain = tonemapped(&render(&ctx, &mut r, square_at, last as f32, [0.0, 0.0]).hdr);
    let near_now = |x: u32, y: u32| {
        (-2i32..=2).any(|dy| {
            (-2i32..=2).any(|dx| {
                let (a, b) = (x as i32 + dx, y as i32 + dy);
                a >= 0
                    && b >= 0
                    && a < W as i32
                    && b < H as i32
                    && now[(b as u32 * W + a as u32) as usize]
            })
        })
    };
    let (mut checked, mut worst) = (0, 0.0f32);
    for y in BORDER..H - BORDER {
        for x in BORDER..W - BORDER {
            let i = (y * W + x) as usize;
            if near_now(x, y) || !before.iter().any(|c| c[i]) {
                continue;
            }
            checked += 1;
            for c in 0..3 {
                worst = worst.max((outs[last as usize][i][c] - plain[i][c]).abs());
            }
        }
    }
    eprintln!("{checked} pixels the square uncovered 4 or more frames ago, largest difference from the wall {worst:.5} (limit 0.01)");
    assert!(checked > 300, "{checked}");
    assert!(worst <= 0.01, "trail: {worst}");
}
