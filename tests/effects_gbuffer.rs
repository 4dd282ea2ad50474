//! GPU tests of the G-buffer effects ssao, dof, fog and outline, on synthetic
//! G-buffers ray-cast on the CPU (planes in view space).
//!
//! Two ways of feeding the G-buffer are exercised:
//! - `run_gbuffer`: what the deferred renderer will do: `Effect::prepare` with the
//!   G-buffer formats of `published_aux()` (depth r32f, normal rgba16f, ...), textures
//!   uploaded in those formats and a perspective camera in `FrameInputs::camera`;
//! - `run_aux`: `apply_in_memory` with float images (uploaded as rgba16f) and no
//!   camera (identity matrices: an orthographic view with x, y = ndc x, y).
//!
//! Run with `FX_REQUIRE_GPU=1 XDG_RUNTIME_DIR=/tmp cargo test --test effects_gbuffer`;
//! without an adapter (and without FX_REQUIRE_GPU) the GPU tests skip.

mod common;

use common::*;
use fxgraph::app::{apply_in_memory, Effect};
use fxgraph::gpu::executor::{wgpu_format, CameraStd, Engine, FrameInputs};
use fxgraph::gpu::transfer::{create_output, input_format, read_pixels, upload_image};
use fxgraph::graph::plan::InputDesc;
use fxgraph::io::{Image, Pixels};
use fxgraph::render::published_aux;
use fxgraph::script::types::{ColorSpace, Format};
use glam::{DMat4, DVec3, DVec4, Mat4};
use std::collections::HashMap;

// ---------------------------------------------------------------- cameras

/// A camera: the standard values the effects see and the matrix used to cast rays.
#[derive(Clone, Copy)]
struct Camera {
    std: Option<CameraStd>,
    inv_proj: DMat4,
}

/// A right-handed perspective (view along -z, y up, ndc depth 0..1: wgpu's
/// convention, glam's `camera::rh::proj::directx::perspective`).
fn perspective(fov_y_deg: f32, aspect: f32) -> Camera {
    let (near, far) = (0.1f32, 100.0f32);
    let f = 1.0 / (fov_y_deg.to_radians() * 0.5).tan();
    let r = far / (near - far);
    #[rustfmt::skip]
    let proj = Mat4::from_cols_array(&[
        f / aspect, 0.0, 0.0, 0.0,
        0.0, f, 0.0, 0.0,
        0.0, 0.0, r, -1.0,
        0.0, 0.0, r * near, 0.0,
    ]);
    let inv = proj.inverse();
    Camera {
        std: Some(CameraStd {
            near,
            far,
            proj: proj.to_cols_array(),
            inv_proj: inv.to_cols_array(),
        }),
        inv_proj: proj.as_dmat4().inverse(),
    }
}

/// No renderer: identity matrices (view x, y = ndc x, y; view axis +z).
fn identity_camera() -> Camera {
    Camera {
        std: None,
        inv_proj: DMat4::IDENTITY,
    }
}

fn unproject(inv: &DMat4, ndc: (f64, f64), z: f64) -> DVec3 {
    let h = *inv * DVec4::new(ndc.0, ndc.1, z, 1.0);
    h.truncate() / h.w
}

// ---------------------------------------------------------------- scenes

/// A plane in view space, visible where `keep(hit)` holds.
struct Plane {
    point: DVec3,
    normal: DVec3,
    keep: Box<dyn Fn(DVec3) -> bool>,
}

fn plane(point: [f64; 3], normal: [f64; 3]) -> Plane {
    Plane {
        point: DVec3::from(point),
        normal: DVec3::from(normal).normalize(),
        keep: Box::new(|_| true),
    }
}

fn plane_where(point: [f64; 3], normal: [f64; 3], keep: impl Fn(DVec3) -> bool + 'static) -> Plane {
    Plane {
        keep: Box::new(keep),
        ..plane(point, normal)
    }
}

/// A synthetic G-buffer: per pixel, linear depth, the view-space normal facing the
/// camera and the view-space position.
struct GBuffer {
    w: u32,
    h: u32,
    depth: Vec<f32>,
    normal: Vec<[f32; 3]>,
    position: Vec<[f32; 3]>,
}

impl GBuffer {
    fn depth_at(&self, x: u32, y: u32) -> f32 {
        self.depth[(y * self.w + x) as usize]
    }
}

/// Cast the ray of every pixel centre (as the effects reconstruct it: through the
/// unprojected points at ndc z 0.25 and 0.75) and keep the nearest plane hit.
/// Pixels that hit nothing get what the deferred renderer writes for its
/// background: depth = the far plane (0 without a camera), normal 0.
fn raycast(w: u32, h: u32, cam: &Camera, planes: &[Plane]) -> GBuffer {
    let n = (w * h) as usize;
    let miss = cam.std.map_or(0.0, |c| c.far);
    let mut g = GBuffer {
        w,
        h,
        depth: vec![miss; n],
        normal: vec![[0.0; 3]; n],
        position: vec![[0.0; 3]; n],
    };
    for y in 0..h {
        for x in 0..w {
            let ndc = (
                (x as f64 + 0.5) / w as f64 * 2.0 - 1.0,
                1.0 - (y as f64 + 0.5) / h as f64 * 2.0,
            );
            let a = unproject(&cam.inv_proj, ndc, 0.25);
            let b = unproject(&cam.inv_proj, ndc, 0.75);
            let s = if a.z >= 0.0 { 1.0 } else { -1.0 };
            let dir = b - a;
            let mut best: Option<(f64, DVec3, DVec3)> = None;
            for p in planes {
                let denom = dir.dot(p.normal);
                if denom.abs() < 1e-12 {
                    continue;
                }
                let t = (p.point - a).dot(p.normal) / denom;
                let hit = a + t * dir;
                let d = s * hit.z;
                if d <= 0.0 || !(p.keep)(hit) || best.is_some_and(|(bd, _, _)| bd <= d) {
                    continue;
                }
                let nrm = if p.normal.dot(dir) > 0.0 {
                    -p.normal
                } else {
                    p.normal
                };
                best = Some((d, nrm, hit));
            }
            if let Some((d, nrm, hit)) = best {
                let i = (y * w + x) as usize;
                g.depth[i] = d as f32;
                g.normal[i] = nrm.as_vec3().to_array();
                g.position[i] = hit.as_vec3().to_array();
            }
        }
    }
    g
}

/// A G-buffer of fronto-parallel pieces: linear depth `depth(x, y)`, normals facing
/// the camera (view axis -z) and positions on the view axis.
fn depth_map(w: u32, h: u32, depth: impl Fn(u32, u32) -> f32) -> GBuffer {
    let mut g = GBuffer {
        w,
        h,
        depth: Vec::new(),
        normal: vec![[0.0, 0.0, 1.0]; (w * h) as usize],
        position: Vec::new(),
    };
    for y in 0..h {
        for x in 0..w {
            let d = depth(x, y);
            g.depth.push(d);
            g.position.push([0.0, 0.0, -d]);
        }
    }
    g
}

// ---------------------------------------------------------------- running

fn effect_path(name: &str) -> String {
    format!("{}/effects/{name}.fx", env!("CARGO_MANIFEST_DIR"))
}

fn f32s(p: &Pixels) -> &[f32] {
    match p {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("expected float pixels"),
    }
}

fn f16_bytes(v: impl Iterator<Item = f32>) -> Vec<u8> {
    v.flat_map(|x| half::f16::from_f32(x).to_le_bytes())
        .collect()
}

/// The bytes of G-buffer image `name` in its renderer format (published_aux()).
fn gbuffer_bytes(g: &GBuffer, name: &str, format: Format) -> Vec<u8> {
    match (name, format) {
        ("depth", Format::R32f) => g.depth.iter().flat_map(|d| d.to_le_bytes()).collect(),
        ("normal", Format::Rgba16f) => {
            f16_bytes(g.normal.iter().flat_map(|n| [n[0], n[1], n[2], 0.0]))
        }
        ("position", Format::Rgba16f) => {
            f16_bytes(g.position.iter().flat_map(|p| [p[0], p[1], p[2], 1.0]))
        }
        other => panic!("no synthetic G-buffer image for {other:?}"),
    }
}

/// Run an effect as the deferred renderer will: G-buffer textures in the formats of
/// `published_aux()`, the camera in `FrameInputs`. The scene is uploaded as rgba16f;
/// the output is read back as rgba32f.
fn run_gbuffer(
    engine: &mut Engine,
    effect: &str,
    overrides: &[&str],
    scene: &Image,
    g: &GBuffer,
    cam: &Camera,
    aux: &[&str],
) -> Vec<f32> {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let mut e = Effect::compile(&[effect_path(effect)], &overrides).unwrap();
    let formats: HashMap<String, Format> = published_aux(true).into_iter().collect();
    let desc = InputDesc {
        width: scene.width,
        height: scene.height,
        format: Format::Rgba16f,
        colorspace: ColorSpace::Linear,
        aux: aux.iter().map(|n| (n.to_string(), formats[*n])).collect(),
    };
    let mut prepared = e
        .prepare(engine, &desc, Some(Format::Rgba32f))
        .unwrap_or_else(|err| panic!("{effect}: {err}"));
    let ctx = engine.ctx.clone();
    let input = upload_image(&ctx, "scene", scene, Format::Rgba16f).unwrap();
    let textures: Vec<(String, wgpu::Texture)> = aux
        .iter()
        .map(|n| {
            let f = formats[*n];
            let t = ctx
                .upload_texture(
                    n,
                    g.w,
                    g.h,
                    wgpu_format(f),
                    &gbuffer_bytes(g, n, f),
                    wgpu::TextureUsages::empty(),
                )
                .unwrap();
            (n.to_string(), t)
        })
        .collect();
    let mut inputs = FrameInputs::single(&input);
    for (n, t) in &textures {
        inputs.aux.insert(n.clone(), t.into());
    }
    inputs.camera = cam.std;
    let out = prepared.plan.output;
    let output = create_output(&ctx, out.width, out.height, out.format);
    prepared.run(engine, &inputs, &output, false).unwrap();
    let v = f32s(&read_pixels(&ctx, &output, out.format).unwrap()).to_vec();
    assert_eq!(v.len(), (scene.width * scene.height * 4) as usize);
    v
}

/// Run an effect through `apply_in_memory` with the G-buffer as float images (depth
/// in every channel), uploaded as rgba16f, without a camera (identity matrices).
fn run_aux(
    engine: &mut Engine,
    effect: &str,
    overrides: &[&str],
    scene: &Image,
    g: &GBuffer,
    aux: &[&str],
) -> Vec<f32> {
    let imgs: Vec<(String, Image)> = aux
        .iter()
        .map(|&n| {
            let img = image_f32(g.w, g.h, |x, y| {
                let i = (y * g.w + x) as usize;
                match n {
                    "depth" => [g.depth[i]; 4],
                    "normal" => {
                        let v = g.normal[i];
                        [v[0], v[1], v[2], 0.0]
                    }
                    "position" => {
                        let v = g.position[i];
                        [v[0], v[1], v[2], 1.0]
                    }
                    other => panic!("no synthetic G-buffer image {other}"),
                }
            });
            assert_eq!(input_format(&img, false).0, Format::Rgba16f);
            (n.to_string(), img)
        })
        .collect();
    let refs: Vec<(String, &Image)> = imgs.iter().map(|(n, i)| (n.clone(), i)).collect();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let (w, h, p) = apply_in_memory(
        engine,
        &[effect_path(effect)],
        &overrides,
        scene,
        &refs,
        Format::Rgba32f,
        false,
    )
    .unwrap_or_else(|err| panic!("{effect}: {err}"));
    assert_eq!((w, h), (scene.width, scene.height));
    f32s(&p).to_vec()
}

// ---------------------------------------------------------------- checks

fn f16r(x: f32) -> f32 {
    half::f16::from_f32(x).to_f32()
}

fn assert_finite(v: &[f32], what: &str) {
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        panic!("{what}: sample {i} is {}", v[i]);
    }
}

/// Channel `c` of every pixel.
fn channel(v: &[f32], c: usize) -> Vec<f32> {
    v.chunks_exact(4).map(|p| p[c]).collect()
}

/// Samples of `v` (one per pixel) over the rectangle [x0, x1) x [y0, y1).
fn region(v: &[f32], w: u32, x0: u32, x1: u32, y0: u32, y1: u32) -> Vec<f32> {
    let mut out = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            out.push(v[(y * w + x) as usize]);
        }
    }
    out
}

fn min_of(v: &[f32]) -> f32 {
    v.iter().copied().fold(f32::INFINITY, f32::min)
}

fn max_of(v: &[f32]) -> f32 {
    v.iter().copied().fold(f32::NEG_INFINITY, f32::max)
}

fn mean(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

fn variance(v: &[f32]) -> f64 {
    let m = mean(v);
    v.iter().map(|&x| (x as f64 - m).powi(2)).sum::<f64>() / v.len() as f64
}

/// A constant grey scene.
fn grey(w: u32, h: u32, v: f32) -> Image {
    image_f32(w, h, |_, _| [v, v, v, 1.0])
}

/// A colourful scene with values exactly representable in half floats.
fn colourful(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        [
            f16r(0.1 + 0.8 * x as f32 / w as f32),
            f16r(0.2 + 0.7 * y as f32 / h as f32),
            if (x / 3 + y / 5) % 2 == 0 { 0.25 } else { 0.75 },
            1.0,
        ]
    })
}

/// With FX_DUMP set, print a one-channel image as text (for looking at failures).
fn dump(what: &str, v: &[f32], w: u32, lo: f32, hi: f32) {
    if std::env::var_os("FX_DUMP").is_none() {
        return;
    }
    const RAMP: [char; 10] = [' ', '.', ':', '-', '=', '+', '*', '#', '%', '@'];
    eprintln!("{what} ({lo} -> ' ', {hi} -> '@'):");
    let h = v.len() as u32 / w;
    let step = w.div_ceil(64);
    for y in (0..h).step_by(step as usize) {
        let r: String = (0..w)
            .step_by(step as usize)
            .map(|x| {
                let t = (v[(y * w + x) as usize] - lo) / (hi - lo);
                RAMP[(t * 9.99).clamp(0.0, 9.0) as usize]
            })
            .collect();
        eprintln!("{y:4} |{r}|");
    }
}

// ================================================================ ssao

const SSAO_AUX: &[&str] = &["depth", "normal"];

/// A camera `height` above a floor (world y = 0), pitched down by `pitch_deg`:
/// world-to-view is a rotation about x by the pitch after moving the camera to the
/// origin (view: x right, y up, looking along -z).
struct Rig {
    height: f64,
    pitch: f64,
}

impl Rig {
    fn to_view(&self, p: DVec3) -> DVec3 {
        glam::DMat3::from_rotation_x(self.pitch) * (p - DVec3::new(0.0, self.height, 0.0))
    }

    fn to_world(&self, v: DVec3) -> DVec3 {
        glam::DMat3::from_rotation_x(-self.pitch) * v + DVec3::new(0.0, self.height, 0.0)
    }

    /// A world-space plane, visible where `keep(world point)` holds, in view space.
    fn plane(
        &'static self,
        point: [f64; 3],
        normal: [f64; 3],
        keep: impl Fn(DVec3) -> bool + 'static,
    ) -> Plane {
        let n = glam::DMat3::from_rotation_x(self.pitch) * DVec3::from(normal).normalize();
        Plane {
            point: self.to_view(DVec3::from(point)),
            normal: n,
            keep: Box::new(move |v| keep(self.to_world(v))),
        }
    }
}

/// The room of the SSAO tests: camera 2.5 above the floor, pitched down 30 degrees.
static ROOM: Rig = Rig {
    height: 2.5,
    pitch: std::f64::consts::PI / 6.0,
};

/// The floor (world y = 0) meeting a wall 6 units ahead (world z = -6): a concave
/// corner, seen with a 60-degree field of view. Returns the G-buffer, the camera
/// and the image row of the corner line.
fn corner_scene(n: u32, extra: Vec<Plane>) -> (GBuffer, Camera, u32) {
    let cam = perspective(60.0, 1.0);
    let mut planes = vec![
        ROOM.plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], |_| true),
        ROOM.plane([0.0, 0.0, -6.0], [0.0, 0.0, 1.0], |_| true),
    ];
    planes.extend(extra);
    let g = raycast(n, n, &cam, &planes);
    // The corner line's ndc y: its direction is 22.6 degrees below the horizon,
    // 7.4 above the view axis.
    let corner = ROOM.to_view(DVec3::new(0.0, 0.0, -6.0));
    let ndc_y = (corner.y / -corner.z) / (30f64.to_radians().tan());
    let row = ((1.0 - ndc_y) * 0.5 * n as f64) as u32;
    (g, cam, row)
}

#[test]
fn ssao_darkens_a_concave_corner_and_leaves_the_open_floor() {
    let Some(mut eng) = engine() else { return };
    let n = 96;
    let (g, cam, row) = corner_scene(n, Vec::new());
    // The ray-cast scene: the wall above the corner row, the floor below, both
    // reaching it (continuous depth across the corner).
    let (above, below) = (g.depth_at(48, row - 1), g.depth_at(48, row + 1));
    assert!(
        (above - below).abs() < 0.25 && above > 5.5,
        "{above} {below}"
    );
    let scene = grey(n, n, 0.5);
    let ao = run_gbuffer(
        &mut eng,
        "ssao",
        &["output=ao", "radius=1", "intensity=1"],
        &scene,
        &g,
        &cam,
        SSAO_AUX,
    );
    assert_finite(&ao, "ssao");
    let ao = channel(&ao, 0);
    dump("ssao corner", &ao, n, 1.0, 0.0);
    eprintln!("corner row {row}");
    // Along the corner (both sides, central columns): clearly darkened.
    let corner = region(&ao, n, 16, 80, row - 1, row + 2);
    let corner_mean = mean(&corner);
    let corner_max = max_of(&corner);
    eprintln!("corner: mean {corner_mean:.3}, max {corner_max:.3}");
    assert!(corner_max < 0.9, "corner AO max {corner_max}");
    assert!(corner_mean < 0.85, "corner AO mean {corner_mean}");
    let darkest = min_of(&region(&ao, n, 0, n, row - 4, row + 4));
    eprintln!("darkest near the corner: {darkest:.3}");
    assert!(darkest < 0.8, "darkest AO near the corner {darkest}");
    // Open floor near the camera (the bottom rows: 4 units or more from the wall).
    let floor = region(&ao, n, 0, n, n - 12, n);
    let floor_min = min_of(&floor);
    eprintln!("open floor: min {floor_min:.4}");
    assert!(floor_min > 0.95, "open floor AO min {floor_min}");
    // The wall high above the floor (> 3 units from it).
    let wall = region(&ao, n, 0, n, 0, 8);
    assert!(min_of(&wall) > 0.95, "open wall AO min {}", min_of(&wall));
    // AO darkens monotonically towards the corner from the open floor (coarsely).
    let band = |y0: u32| mean(&region(&ao, n, 16, 80, y0, y0 + 4));
    assert!(band(row + 1) < band(row + 8) && band(row + 8) <= band(n - 8) + 1e-6);

    // The intensity scales the occlusion (the blur is linear in the AO).
    let ao2 = run_gbuffer(
        &mut eng,
        "ssao",
        &["output=ao", "radius=1", "intensity=2"],
        &scene,
        &g,
        &cam,
        SSAO_AUX,
    );
    let ao2 = channel(&ao2, 0);
    let scaled = ao
        .iter()
        .zip(&ao2)
        .map(|(&a, &b)| ((1.0 - b) - 2.0 * (1.0 - a)).abs())
        .fold(0.0f32, f32::max);
    eprintln!("intensity 2 vs 2 x occlusion: max diff {scaled:.5}");
    assert!(
        scaled < 2e-3,
        "intensity 2: occlusion not doubled ({scaled})"
    );

    // The composite multiplies the scene by the same AO.
    let scene = colourful(n, n);
    let out = run_gbuffer(
        &mut eng,
        "ssao",
        &["radius=1", "intensity=1"],
        &scene,
        &g,
        &cam,
        SSAO_AUX,
    );
    let src = f32s(&scene.pixels);
    let mut worst = 0.0f32;
    for i in 0..(n * n) as usize {
        for c in 0..3 {
            worst = worst.max((out[i * 4 + c] - src[i * 4 + c] * ao[i]).abs());
        }
        assert_eq!(out[i * 4 + 3], 1.0);
    }
    assert!(worst < 2e-3, "composite differs from scene * ao by {worst}");
}

#[test]
fn ssao_defaults_give_visible_contact_shadows() {
    // Issue 10: at its defaults (radius 0.5, intensity 2) SSAO visibly darkens a
    // concave corner (intensity 1 left about 0.8 there: barely visible), and still
    // leaves the open floor and wall alone.
    let Some(mut eng) = engine() else { return };
    let n = 96;
    let (g, cam, row) = corner_scene(n, Vec::new());
    let ao = run_gbuffer(
        &mut eng,
        "ssao",
        &["output=ao"],
        &grey(n, n, 0.5),
        &g,
        &cam,
        SSAO_AUX,
    );
    assert_finite(&ao, "ssao");
    let ao = channel(&ao, 0);
    let darkest = min_of(&region(&ao, n, 0, n, row - 4, row + 4));
    let corner_mean = mean(&region(&ao, n, 16, 80, row - 1, row + 2));
    let floor_min = min_of(&region(&ao, n, 0, n, n - 12, n));
    let wall_min = min_of(&region(&ao, n, 0, n, 0, 8));
    eprintln!("defaults: corner mean {corner_mean:.3}, darkest {darkest:.3}, open floor min {floor_min:.3}, wall min {wall_min:.3}");
    assert!(darkest < 0.75, "darkest AO near the corner {darkest}");
    assert!(corner_mean < 0.82, "corner AO mean {corner_mean}");
    assert!(
        floor_min > 0.95 && wall_min > 0.95,
        "open floor {floor_min}, wall {wall_min}"
    );
}

#[test]
fn ssao_of_a_flat_plane_is_one_everywhere() {
    let Some(mut eng) = engine() else { return };
    // A plane filling the view, tilted in both axes, seen in perspective.
    let n = 64;
    let cam = perspective(70.0, 1.0);
    let g = raycast(n, n, &cam, &[plane([0.0, 0.0, -5.0], [0.4, 0.5, 0.75])]);
    assert!(g.depth.iter().all(|&d| d > 0.0));
    let ao = run_gbuffer(
        &mut eng,
        "ssao",
        &["output=ao", "samples=32"],
        &grey(n, n, 1.0),
        &g,
        &cam,
        SSAO_AUX,
    );
    assert_finite(&ao, "ssao");
    let lo = min_of(&channel(&ao, 0));
    eprintln!("tilted plane (perspective): min AO {lo:.5}");
    assert!(lo > 0.99, "flat plane AO min {lo}");

    // The floor alone under an empty sky (the renderer's background: depth = far,
    // normal 0), grazing far away.
    let g = raycast(
        n,
        n,
        &cam,
        &[plane_where([0.0, -1.0, 0.0], [0.0, 1.0, 0.0], |p| {
            p.z > -60.0
        })],
    );
    assert_eq!((g.depth_at(0, 0), g.normal[0]), (100.0, [0.0; 3]));
    let ao = run_gbuffer(
        &mut eng,
        "ssao",
        &["output=ao", "radius=1"],
        &grey(n, n, 1.0),
        &g,
        &cam,
        SSAO_AUX,
    );
    assert_finite(&ao, "ssao");
    let lo = min_of(&channel(&ao, 0));
    eprintln!("floor and sky: min AO {lo:.5}");
    assert!(lo > 0.99, "floor AO min {lo}");

    // Without a renderer (identity camera, rgba16f G-buffer images): a slanted plane.
    let cam = identity_camera();
    let g = raycast(n, n, &cam, &[plane([0.0, 0.0, 5.0], [0.3, -0.2, -1.0])]);
    let ao = run_aux(
        &mut eng,
        "ssao",
        &["output=ao", "radius=0.3"],
        &grey(n, n, 1.0),
        &g,
        SSAO_AUX,
    );
    assert_finite(&ao, "ssao");
    let lo = min_of(&channel(&ao, 0));
    eprintln!("slanted plane (identity camera): min AO {lo:.5}");
    assert!(lo > 0.99, "flat plane AO min {lo}");
}

#[test]
fn ssao_blur_does_not_cross_depth_discontinuities() {
    let Some(mut eng) = engine() else { return };
    // The corner scene with a board parallel to the wall, 3 units ahead, floating
    // 1 unit above the floor, covering the left half of the view: its AO is exactly
    // 1 before the blur; the corner beside it is dark.
    let n = 96;
    let board = ROOM.plane([0.0, 0.0, -3.0], [0.0, 0.0, 1.0], |p| {
        p.x < 0.0 && p.y > 1.0
    });
    let (g, cam, row) = corner_scene(n, vec![board]);
    let half = n / 2;
    assert!(g.depth_at(half - 1, row) < 4.0 && g.depth_at(half, row) > 5.0);
    let ao = |eng: &mut Engine, o: &[&str]| {
        let v = run_gbuffer(eng, "ssao", o, &grey(n, n, 1.0), &g, &cam, SSAO_AUX);
        assert_finite(&v, "ssao");
        channel(&v, 0)
    };
    let raw = ao(
        &mut eng,
        &["output=ao", "radius=1", "intensity=1", "blur=false"],
    );
    let blurred = ao(&mut eng, &["output=ao", "radius=1", "intensity=1"]);
    dump("ssao raw", &raw, n, 1.0, 0.0);
    dump("ssao blurred", &blurred, n, 1.0, 0.0);
    // The board, up to its edge, stays unoccluded: no dark AO of the corner behind
    // it leaks onto it.
    let on_board = |v: &[f32]| -> Vec<f32> {
        v.iter()
            .zip(&g.depth)
            .filter(|(_, &d)| d > 0.0 && d < 4.0)
            .map(|(&a, _)| a)
            .collect()
    };
    let board_raw = min_of(&on_board(&raw));
    let board = min_of(&on_board(&blurred));
    eprintln!("board: raw min {board_raw:.5}, blurred min {board:.5}");
    assert!(
        board_raw > 0.999 && board > 0.999,
        "board AO {board_raw} / {board}"
    );
    // Right beside it the corner stays dark: the board's AO of 1 does not leak
    // into it either.
    let beside_raw = mean(&region(&raw, n, half, half + 2, row - 1, row + 2));
    let beside = mean(&region(&blurred, n, half, half + 2, row - 1, row + 2));
    eprintln!("corner beside the board: mean raw {beside_raw:.4}, blurred {beside:.4}");
    assert!(
        beside < 0.9 && (beside - beside_raw).abs() < 0.06,
        "corner beside the board {beside_raw} -> {beside}"
    );
    // The blur smooths the rotation noise along the corner.
    let noisy = variance(&region(&raw, n, half + 8, n - 8, row - 2, row + 2));
    let smooth = variance(&region(&blurred, n, half + 8, n - 8, row - 2, row + 2));
    eprintln!("corner variance: raw {noisy:.6}, blurred {smooth:.6}");
    assert!(
        smooth < 0.5 * noisy,
        "blur did not reduce the noise: {noisy} -> {smooth}"
    );
}

// ================================================================ dof

const DOF_AUX: &[&str] = &["depth"];

/// A checker of 4-pixel squares in two colours with red = 0.
fn checker(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        if (x / 4 + y / 4) % 2 == 0 {
            [0.0, 0.875, 0.125, 1.0]
        } else {
            [0.0, 0.125, 0.75, 1.0]
        }
    })
}

#[test]
fn dof_in_focus_is_identity() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let scene = colourful(n, n);
    let src = f32s(&scene.pixels);
    let g = depth_map(n, n, |_, _| 5.0);
    let cam = perspective(60.0, 1.0);
    for o in [
        &["focus_distance=5"][..],
        &["focus_distance=5", "focal_range=0", "aperture=30"][..],
        &["focus_distance=4.5", "focal_range=1.5", "max_radius=64"][..],
    ] {
        let out = run_gbuffer(&mut eng, "dof", o, &scene, &g, &cam, DOF_AUX);
        let d = max_abs_diff(&out, src);
        eprintln!("dof {o:?}, depth = focus: max diff {d:e}");
        assert!(d < 1e-3, "{o:?}: in-focus scene changed by {d}");
    }
    // The same through apply_in_memory (depth as an rgba16f image).
    let out = run_aux(&mut eng, "dof", &["focus_distance=5"], &scene, &g, DOF_AUX);
    let d = max_abs_diff(&out, src);
    assert!(d < 1e-3, "in-focus scene changed by {d}");
}

#[test]
fn dof_blurs_a_far_checker() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let scene = checker(n, n);
    let g = depth_map(n, n, |_, _| 50.0);
    let cam = perspective(60.0, 1.0);
    // CoC radius 8 (1 - 3 / 50) = 7.52 px.
    let out = run_gbuffer(
        &mut eng,
        "dof",
        &["focus_distance=2"],
        &scene,
        &g,
        &cam,
        DOF_AUX,
    );
    assert_finite(&out, "dof");
    // Away from the border (clamped taps there).
    let inner = |v: &[f32]| region(&channel(v, 1), n, 12, n - 12, 12, n - 12);
    let (before, after) = (
        variance(&inner(f32s(&scene.pixels))),
        variance(&inner(&out)),
    );
    eprintln!(
        "far checker: green variance {before:.5} -> {after:.6} ({:.1}%)",
        100.0 * after / before
    );
    assert!(after < 0.05 * before, "variance {before} -> {after}");
    // The blur preserves the mean colour (the checker's mean is 0.5 in green).
    let m = mean(&inner(&out));
    assert!((m - 0.5).abs() < 0.02, "mean green {m}");
    // A smaller aperture blurs less.
    let out2 = run_gbuffer(
        &mut eng,
        "dof",
        &["focus_distance=2", "aperture=2"],
        &scene,
        &g,
        &cam,
        DOF_AUX,
    );
    let small = variance(&inner(&out2));
    eprintln!("aperture 2: variance {small:.5}");
    assert!(
        small > 3.0 * after && small < 0.8 * before,
        "aperture 2: {small}"
    );
}

#[test]
fn dof_sharp_foreground_keeps_its_edge_without_halo() {
    let Some(mut eng) = engine() else { return };
    // An in-focus red square (depth 5 = focus) in front of a far checker (depth 50).
    let n = 64;
    let fg = |x: u32, y: u32| (16..40).contains(&x) && (20..44).contains(&y);
    let g = depth_map(n, n, |x, y| if fg(x, y) { 5.0 } else { 50.0 });
    let bg = checker(n, n);
    let scene = image_f32(n, n, |x, y| {
        if fg(x, y) {
            [1.0, 0.25, 0.125, 1.0]
        } else {
            let i = ((y * n + x) * 4) as usize;
            let b = f32s(&bg.pixels);
            [b[i], b[i + 1], b[i + 2], 1.0]
        }
    });
    let src = f32s(&scene.pixels);
    let cam = perspective(60.0, 1.0);
    let out = run_gbuffer(
        &mut eng,
        "dof",
        &["focus_distance=5"],
        &scene,
        &g,
        &cam,
        DOF_AUX,
    );
    assert_finite(&out, "dof");
    let (mut fg_diff, mut halo) = (0.0f32, 0.0f32);
    for y in 0..n {
        for x in 0..n {
            let i = ((y * n + x) * 4) as usize;
            if fg(x, y) {
                // The sharp object, up to its edge, is unchanged.
                for c in 0..4 {
                    fg_diff = fg_diff.max((out[i + c] - src[i + c]).abs());
                }
            } else {
                // No red from the object spreads onto the blurred background.
                halo = halo.max(out[i]);
            }
        }
    }
    eprintln!("sharp foreground: max diff {fg_diff:e}; red on the background: max {halo:e}");
    assert!(fg_diff < 1e-3, "foreground changed by {fg_diff}");
    assert!(halo < 1e-3, "halo: red {halo} on the background");
    // The background itself is blurred, right up to the object.
    let strip = |v: &[f32]| region(&channel(v, 1), n, 44, 60, 4, 60);
    let (before, after) = (variance(&strip(src)), variance(&strip(&out)));
    eprintln!("background beside the object: green variance {before:.4} -> {after:.5}");
    assert!(
        after < 0.1 * before,
        "background variance {before} -> {after}"
    );
}

#[test]
fn dof_blurred_foreground_spreads_over_a_sharp_background() {
    let Some(mut eng) = engine() else { return };
    // A near red square (depth 1) in front of an in-focus checker (depth 5):
    // CoC of the square -2 (4.5 / 1 - 1) = -7 px.
    let n = 64;
    let fg = |x: u32, y: u32| (20..44).contains(&x) && (20..44).contains(&y);
    let g = depth_map(n, n, |x, y| if fg(x, y) { 1.0 } else { 5.0 });
    let bg = checker(n, n);
    let scene = image_f32(n, n, |x, y| {
        if fg(x, y) {
            [1.0, 0.0, 0.0, 1.0]
        } else {
            let b = f32s(&bg.pixels);
            let i = ((y * n + x) * 4) as usize;
            [b[i], b[i + 1], b[i + 2], 1.0]
        }
    });
    let src = f32s(&scene.pixels);
    let cam = perspective(60.0, 1.0);
    let out = run_gbuffer(
        &mut eng,
        "dof",
        &["focus_distance=5", "focal_range=1", "aperture=2"],
        &scene,
        &g,
        &cam,
        DOF_AUX,
    );
    assert_finite(&out, "dof");
    let red = channel(&out, 0);
    dump("dof near field (red)", &red, n, 0.0, 1.0);
    // Distance (Chebyshev) of a background pixel from the square.
    let dist = |x: u32, y: u32| {
        let dx = (20i32 - x as i32).max(x as i32 - 43).max(0);
        let dy = (20i32 - y as i32).max(y as i32 - 43).max(0);
        dx.max(dy)
    };
    // The square's middle stays red; its blur reaches over the background next to
    // it (about half at the silhouette); beyond its CoC the background is sharp.
    let middle = min_of(&region(&red, n, 28, 36, 28, 36));
    let edge = mean(&region(&red, n, 43, 44, 28, 36));
    let next = mean(&region(&red, n, 44, 45, 28, 36));
    let mut far_diff = 0.0f32;
    for y in 0..n {
        for x in 0..n {
            if !fg(x, y) && dist(x, y) > 8 {
                let i = ((y * n + x) * 4) as usize;
                for c in 0..4 {
                    far_diff = far_diff.max((out[i + c] - src[i + c]).abs());
                }
            }
        }
    }
    let beyond = mean(&region(&red, n, 49, 50, 28, 36));
    eprintln!("near field: middle red min {middle:.3}, its edge {edge:.3}, next to it {next:.3}, 5 px out {beyond:.3}, >8 px max diff {far_diff:e}");
    assert!(middle > 0.99, "middle of the blurred square {middle}");
    assert!(
        edge > 0.4 && edge < 0.8,
        "red on the edge of the square {edge}"
    );
    assert!(next > 0.25 && next < edge, "red next to the square {next}");
    assert!(
        beyond > 0.01 && beyond < next,
        "red 5 px from the square {beyond}"
    );
    assert!(
        far_diff < 1e-3,
        "background beyond the CoC changed by {far_diff}"
    );
}

// ================================================================ fog

const FOG_AUX: &[&str] = &["depth"];
const FOG_COLOR: [f32; 3] = [0.5, 0.6, 0.7];

/// The transmittance f(D) of fog mode `mode` (as documented in effects/fog.fx).
fn fog_transmittance(mode: &str, d: f64, density: f64, start: f64, end: f64) -> f64 {
    match mode {
        "linear" => ((end - d) / (end - start)).clamp(0.0, 1.0),
        "exponential" => (-density * d).exp(),
        "exponential_squared" => (-(density * d).powi(2)).exp(),
        other => panic!("unknown fog mode {other}"),
    }
}

/// Largest difference of `out` from mix(scene, FOG_COLOR, 1 - f(pixel)), alpha kept.
fn fog_error(out: &[f32], scene: &Image, f: impl Fn(usize) -> f64) -> f64 {
    let src = f32s(&scene.pixels);
    let mut worst = 0.0f64;
    for (i, (o, s)) in out.chunks_exact(4).zip(src.chunks_exact(4)).enumerate() {
        let t = f(i);
        for c in 0..3 {
            let want = s[c] as f64 * t + FOG_COLOR[c] as f64 * (1.0 - t);
            worst = worst.max((o[c] as f64 - want).abs());
        }
        worst = worst.max((o[3] - s[3]).abs() as f64);
    }
    worst
}

#[test]
fn fog_matches_the_analytic_blend_at_constant_depth() {
    let Some(mut eng) = engine() else { return };
    let n = 32;
    let scene = colourful(n, n);
    let cam = perspective(60.0, 1.0);
    let (density, start, end) = (0.12, 2.0, 20.0);
    for mode in ["linear", "exponential", "exponential_squared"] {
        for d in [0.5f32, 3.0, 8.0, 19.0, 40.0] {
            let g = depth_map(n, n, |_, _| d);
            let o = [
                format!("mode={mode}"),
                format!("density={density}"),
                format!("start={start}"),
                format!("end={end}"),
            ];
            let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
            let f = fog_transmittance(mode, d as f64, density, start, end);
            let out = run_gbuffer(&mut eng, "fog", &o, &scene, &g, &cam, FOG_AUX);
            let err = fog_error(&out, &scene, |_| f);
            eprintln!("fog {mode} at depth {d}: f = {f:.4}, max error {err:.2e}");
            assert!(err < 1e-3, "{mode} at depth {d}: error {err}");
        }
    }
    // The defaults (exponential, density 0.05) through apply_in_memory.
    let g = depth_map(n, n, |_, _| 10.0);
    let out = run_aux(&mut eng, "fog", &[], &scene, &g, FOG_AUX);
    let err = fog_error(&out, &scene, |_| (-0.5f64).exp());
    eprintln!("fog defaults at depth 10 (apply_in_memory): max error {err:.2e}");
    assert!(err < 1e-3, "defaults: error {err}");
}

#[test]
fn fog_leaves_depth_zero_unchanged() {
    let Some(mut eng) = engine() else { return };
    let n = 32;
    let scene = colourful(n, n);
    let src = f32s(&scene.pixels);
    let cam = perspective(60.0, 1.0);
    // Depth 0 everywhere but one column at depth 30 (which is fogged).
    let g = depth_map(n, n, |x, _| if x == 5 { 30.0 } else { 0.0 });
    for mode in ["linear", "exponential", "exponential_squared"] {
        for extra in [
            &[][..],
            &["height_falloff=0.3", "camera_height=2", "distance=radial"][..],
        ] {
            let mut o = vec![
                format!("mode={mode}"),
                "density=0.2".to_string(),
                "end=10".to_string(),
            ];
            o.extend(extra.iter().map(|s| s.to_string()));
            let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
            let out = run_gbuffer(&mut eng, "fog", &o, &scene, &g, &cam, FOG_AUX);
            let mut worst = 0.0f32;
            for (i, (a, b)) in out.iter().zip(src).enumerate() {
                if (i / 4) as u32 % n != 5 {
                    worst = worst.max((a - b).abs());
                }
            }
            let fogged = (out[5 * 4] - src[5 * 4]).abs();
            eprintln!("fog {o:?}: depth 0 max diff {worst:e}, depth 30 diff {fogged:.3}");
            assert_eq!(worst, 0.0, "{o:?}: depth 0 changed");
            assert!(fogged > 0.01, "{o:?}: depth 30 not fogged");
        }
    }
}

#[test]
fn fog_radial_distance_and_height_falloff() {
    let Some(mut eng) = engine() else { return };
    let n = 48;
    let scene = colourful(n, n);
    let density = 0.15;
    // A wall facing a level camera: the radial distance grows off-centre.
    let cam = perspective(70.0, 1.0);
    let g = raycast(n, n, &cam, &[plane([0.0, 0.0, -8.0], [0.0, 0.0, 1.0])]);
    let dist = |i: usize| DVec3::from(g.position[i].map(|v| v as f64)).length();
    let out = run_gbuffer(
        &mut eng,
        "fog",
        &["distance=radial", "density=0.15"],
        &scene,
        &g,
        &cam,
        FOG_AUX,
    );
    let err = fog_error(&out, &scene, |i| (-density * dist(i)).exp());
    eprintln!(
        "radial exponential fog: max error {err:.2e} (distance {:.3} .. {:.3})",
        dist(((n / 2) * n + n / 2) as usize),
        dist(0)
    );
    assert!(err < 1e-3, "radial: error {err}");

    // Height fog seen by the pitched camera of the room (2.5 above the floor): the
    // floor and the wall, world heights from the rig, up = the world's up in view space.
    let cam = perspective(60.0, 1.0);
    let g = raycast(
        n,
        n,
        &cam,
        &[
            ROOM.plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], |_| true),
            ROOM.plane([0.0, 0.0, -6.0], [0.0, 0.0, 1.0], |_| true),
        ],
    );
    let up = glam::DMat3::from_rotation_x(ROOM.pitch) * DVec3::Y;
    let (k, h0) = (0.8, 0.5);
    for (mode, distance) in [
        ("exponential", "radial"),
        ("exponential_squared", "depth"),
        ("linear", "radial"),
    ] {
        let o = [
            format!("mode={mode}"),
            format!("distance={distance}"),
            format!("density={density}"),
            "start=1".to_string(),
            "end=12".to_string(),
            format!("height_falloff={k}"),
            format!("fog_height={h0}"),
            format!("camera_height={}", ROOM.height),
            format!("up=({},{},{})", up.x, up.y, up.z),
        ];
        let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
        let out = run_gbuffer(&mut eng, "fog", &o, &scene, &g, &cam, FOG_AUX);
        assert_finite(&out, "fog");
        let f = |i: usize| {
            let p = DVec3::from(g.position[i].map(|v| v as f64));
            let l = if distance == "radial" {
                p.length()
            } else {
                g.depth[i] as f64
            };
            // The mean density along the segment, from world heights.
            let (hc, hp) = (ROOM.height, ROOM.to_world(p).y);
            let x = k * (hp - hc);
            let mean_exp = if x.abs() < 1e-9 {
                1.0
            } else {
                (1.0 - (-x).exp()) / x
            };
            let d = l * (-k * (hc - h0)).exp() * mean_exp;
            fog_transmittance(mode, d, density, 1.0, 12.0)
        };
        let err = fog_error(&out, &scene, f);
        eprintln!("height fog {mode}/{distance}: max error {err:.2e}");
        assert!(err < 1e-3, "height fog {mode}/{distance}: error {err}");
    }
    // Denser low fog: the floor near the camera (low) gets more fog than uniform fog
    // of the density at the camera's height would give.
    let o = [
        format!("density={density}"),
        format!("height_falloff={k}"),
        format!("camera_height={}", ROOM.height),
        format!("up=({},{},{})", up.x, up.y, up.z),
    ];
    let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
    let low = run_gbuffer(&mut eng, "fog", &o, &grey(n, n, 0.0), &g, &cam, FOG_AUX);
    let i = (((n - 1) * n + n / 2) * 4) as usize;
    let at_camera = 1.0 - (-density * (-k * ROOM.height).exp() * g.depth[i / 4] as f64).exp();
    eprintln!(
        "floor below the camera: fog {:.4} vs {at_camera:.4} at the camera's density",
        low[i] / FOG_COLOR[0]
    );
    assert!((low[i] / FOG_COLOR[0]) as f64 > at_camera * 1.5);
}

// ================================================================ outline

const OUTLINE_AUX: &[&str] = &["depth", "normal"];

/// The columns (x) where `mask` is above 0.5, row by row.
fn marked_columns(mask: &[f32], w: u32) -> Vec<Vec<u32>> {
    mask.chunks_exact(w as usize)
        .map(|row| (0..w).filter(|&x| row[x as usize] > 0.5).collect())
        .collect()
}

fn outline_mask(eng: &mut Engine, o: &[&str], g: &GBuffer, cam: &Camera) -> Vec<f32> {
    let mut o = o.to_vec();
    o.push("mode=mask");
    let out = run_gbuffer(
        eng,
        "outline",
        &o,
        &grey(g.w, g.h, 0.5),
        g,
        cam,
        OUTLINE_AUX,
    );
    assert_finite(&out, "outline");
    // The mask is binary at width 1 and grey.
    channel(&out, 0)
}

#[test]
fn outline_marks_a_depth_step_exactly() {
    let Some(mut eng) = engine() else { return };
    // A board at depth 4 on the left, a wall at depth 6 on the right (x >= 32).
    let n = 64;
    let g = depth_map(n, n, |x, _| if x < 32 { 4.0 } else { 6.0 });
    let cam = perspective(60.0, 1.0);
    let mask = outline_mask(&mut eng, &[], &g, &cam);
    assert!(
        mask.iter().all(|&v| v == 0.0 || v == 1.0),
        "mask not binary"
    );
    let cols = marked_columns(&mask, n);
    assert!(
        cols.iter().all(|c| c == &vec![31]),
        "outline columns {:?}",
        &cols[..4]
    );
    eprintln!(
        "depth step: outline exactly on column 31 (the near side), {} pixels",
        mask.iter().filter(|&&v| v > 0.5).count()
    );

    // Thresholds: the step is 2 / 4 = 0.5 of the near depth.
    for (t, expect) in [(0.4, true), (0.6, false)] {
        let o = format!("depth_threshold={t}");
        let m = outline_mask(&mut eng, &[&o], &g, &cam);
        let count = m.iter().filter(|&&v| v > 0.5).count();
        eprintln!("depth_threshold {t}: {count} outline pixels");
        assert_eq!(
            count,
            if expect { n as usize } else { 0 },
            "depth_threshold {t}"
        );
    }

    // Width 2: the columns beside the line too; overlay draws the colour there.
    let m = outline_mask(&mut eng, &["width=2"], &g, &cam);
    assert!(marked_columns(&m, n).iter().all(|c| c == &vec![30, 31, 32]));
    let scene = colourful(n, n);
    let src = f32s(&scene.pixels);
    let out = run_gbuffer(
        &mut eng,
        "outline",
        &["color=(1,0,1)", "opacity=0.5"],
        &scene,
        &g,
        &cam,
        OUTLINE_AUX,
    );
    let mut worst = 0.0f32;
    for y in 0..n {
        for x in 0..n {
            let i = ((y * n + x) * 4) as usize;
            for c in 0..4 {
                let want = if x == 31 && c < 3 {
                    0.5 * src[i + c] + 0.5 * [1.0, 0.0, 1.0][c]
                } else {
                    src[i + c]
                };
                worst = worst.max((out[i + c] - want).abs());
            }
        }
    }
    eprintln!("overlay: max diff from the expected image {worst:e}");
    assert!(worst < 1e-6, "overlay differs by {worst}");

    // The same through apply_in_memory (rgba16f G-buffer images, no camera).
    let out = run_aux(
        &mut eng,
        "outline",
        &["mode=mask"],
        &grey(n, n, 0.5),
        &g,
        OUTLINE_AUX,
    );
    assert!(marked_columns(&channel(&out, 0), n)
        .iter()
        .all(|c| c == &vec![31]));
}

#[test]
fn outline_finds_nothing_on_flat_or_slanted_planes() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let cam = perspective(60.0, 1.0);
    // A plane slanted by 41 degrees filling the view, and the floor grazing to the
    // horizon under a sky.
    let slanted = raycast(n, n, &cam, &[plane([0.0, 0.0, -5.0], [0.55, 0.35, 0.75])]);
    assert!(slanted.depth.iter().all(|&d| d > 0.0));
    let floor = raycast(
        n,
        n,
        &cam,
        &[plane_where([0.0, -1.0, 0.0], [0.0, 1.0, 0.0], |p| {
            p.z > -80.0
        })],
    );
    for (what, g) in [("slanted plane", &slanted), ("floor", &floor)] {
        let mask = outline_mask(&mut eng, &["depth_threshold=0.02"], g, &cam);
        let cols = marked_columns(&mask, n);
        // The floor's far edge against the sky (the renderer's background: depth =
        // far, normal 0) is a silhouette: the last floor row, nothing else.
        let rows: Vec<usize> = (0..n as usize).filter(|&y| !cols[y].is_empty()).collect();
        eprintln!("{what}: outline rows {rows:?}");
        if what == "floor" {
            let last = (0..n).rev().find(|&y| g.depth_at(0, y) == 100.0).unwrap() + 1;
            assert_eq!(rows, vec![last as usize], "floor outline rows");
            assert_eq!(cols[last as usize].len(), n as usize);
        } else {
            assert!(rows.is_empty(), "outline on a plane: rows {rows:?}");
        }
    }
}

#[test]
fn outline_detects_a_normal_crease() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    // A valley seen without a renderer (identity camera: view x = ndc x): two planes
    // meeting at x = 0 at 53.13 degrees, depth continuous (5 + |x| / 2).
    let cam = identity_camera();
    let valley = raycast(
        n,
        n,
        &cam,
        &[
            plane_where([0.0, 0.0, 5.0], [0.5, 0.0, 1.0], |p| p.x < 0.0),
            plane_where([0.0, 0.0, 5.0], [-0.5, 0.0, 1.0], |p| p.x >= 0.0),
        ],
    );
    let step = (valley.depth_at(32, 0) - valley.depth_at(31, 0)).abs();
    assert!(
        step < 1e-4,
        "depth not continuous across the crease: {step}"
    );
    for (t, want) in [(30.0, vec![31, 32]), (50.0, vec![31, 32]), (55.0, vec![])] {
        let o = format!("normal_threshold={t}");
        let out = run_aux(
            &mut eng,
            "outline",
            &["mode=mask", &o],
            &grey(n, n, 0.5),
            &valley,
            OUTLINE_AUX,
        );
        let cols = marked_columns(&channel(&out, 0), n);
        eprintln!("valley, normal_threshold {t}: columns {:?}", cols[0]);
        assert!(
            cols.iter().all(|c| c == &want),
            "normal_threshold {t}: {:?}",
            cols[0]
        );
    }

    // The concave corner of the room in perspective: floor meeting the wall at 90
    // degrees. The outline follows the corner line, one pixel per column.
    let (g, cam, row) = corner_scene(n, Vec::new());
    let mask = outline_mask(&mut eng, &[], &g, &cam);
    let mut rows_per_col = Vec::new();
    for x in 0..n {
        let rows: Vec<u32> = (0..n)
            .filter(|&y| mask[(y * n + x) as usize] > 0.5)
            .collect();
        assert!(
            !rows.is_empty() && rows.iter().all(|&y| y.abs_diff(row) <= 1),
            "column {x}: rows {rows:?} (corner row {row})"
        );
        rows_per_col.push(rows.len());
    }
    eprintln!(
        "room corner (row {row}): outline rows per column {:?}",
        &rows_per_col[..8]
    );
    assert!(
        rows_per_col.iter().all(|&k| k == 1),
        "more than one outline row in a column"
    );
    let o = outline_mask(&mut eng, &["normal_threshold=95"], &g, &cam);
    assert!(o.iter().all(|&v| v == 0.0), "corner found above its angle");
}

#[test]
fn outline_antialias_blends_across_edges_only() {
    let Some(mut eng) = engine() else { return };
    let n = 32;
    let g = depth_map(n, n, |x, _| if x < 16 { 4.0 } else { 6.0 });
    let cam = perspective(60.0, 1.0);
    let (red, blue) = ([1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]);
    let scene = image_f32(n, n, |x, y| {
        if x < 16 {
            red
        } else if y % 2 == 0 {
            blue
        } else {
            [0.0, 0.5, 1.0, 1.0]
        }
    });
    let src = f32s(&scene.pixels);
    for strength in [1.0f32, 0.5] {
        let o = format!("strength={strength}");
        let out = run_gbuffer(
            &mut eng,
            "outline",
            &["mode=antialias", &o],
            &scene,
            &g,
            &cam,
            OUTLINE_AUX,
        );
        let mut worst = 0.0f32;
        for y in 0..n {
            for x in 0..n {
                let i = ((y * n + x) * 4) as usize;
                let across = match x {
                    15 => Some(i + 4),
                    16 => Some(i - 4),
                    _ => None,
                };
                for c in 0..4 {
                    let want = match across {
                        Some(j) => src[i + c] + 0.5 * strength * (src[j + c] - src[i + c]),
                        None => src[i + c],
                    };
                    worst = worst.max((out[i + c] - want).abs());
                }
            }
        }
        eprintln!("antialias strength {strength}: max diff from the expected blend {worst:e}");
        assert!(worst < 1e-6, "antialias strength {strength}: {worst}");
    }
}

// ================================================================ all four

#[test]
fn degenerate_gbuffer_values_give_finite_output() {
    let Some(mut eng) = engine() else { return };
    // The room, with holes: depth 0 (no geometry), infinite and NaN depths, and
    // zero normals, in blocks.
    let n = 48;
    let (mut g, cam, _) = corner_scene(n, Vec::new());
    for y in 0..n {
        for x in 0..n {
            let i = (y * n + x) as usize;
            match (x / 8 + y / 8) % 5 {
                1 => g.depth[i] = 0.0,
                2 => g.depth[i] = f32::INFINITY,
                3 => g.depth[i] = f32::NAN,
                4 => g.normal[i] = [0.0; 3],
                _ => {}
            }
        }
    }
    let scene = colourful(n, n);
    for (effect, o, aux) in [
        ("ssao", &["radius=1"][..], SSAO_AUX),
        ("ssao", &["output=ao", "blur=false"][..], SSAO_AUX),
        ("dof", &["focus_distance=3"][..], DOF_AUX),
        (
            "fog",
            &["height_falloff=0.5", "distance=radial"][..],
            FOG_AUX,
        ),
        ("fog", &["mode=linear"][..], FOG_AUX),
        ("outline", &[][..], OUTLINE_AUX),
        ("outline", &["mode=antialias"][..], OUTLINE_AUX),
    ] {
        let out = run_gbuffer(&mut eng, effect, o, &scene, &g, &cam, aux);
        assert_finite(&out, &format!("{effect} {o:?}"));
    }
}
