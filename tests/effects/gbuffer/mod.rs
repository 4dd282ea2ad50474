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
//! One module per effect (ssao, dof, fog, outline); this one holds the synthetic
//! scenes, the two ways of running an effect on them, and the test of all four on
//! degenerate G-buffer values.

mod dof;
mod fog;
mod outline;
mod ssao;

use crate::common::samples::*;
use crate::common::stream::effect_path;
use crate::common::*;
use fxgraph::app::{apply_in_memory, Effect};
use fxgraph::gpu::executor::{wgpu_format, CameraStd, Engine, FrameInputs};
use fxgraph::gpu::transfer::{create_output, input_format, read_pixels, upload_image};
use fxgraph::graph::plan::InputDesc;
use fxgraph::io::Image;
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

/// The G-buffer images `effect` reads.
fn aux_of(effect: &str) -> &'static [&'static str] {
    match effect {
        "ssao" | "outline" => &["depth", "normal"],
        "dof" | "fog" => &["depth"],
        other => panic!("{other} is not a G-buffer effect"),
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
) -> Vec<f32> {
    let aux = aux_of(effect);
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let mut e = Effect::compile(&[effect_path(effect)], &overrides).unwrap();
    let formats: HashMap<String, Format> = published_aux(true).into_iter().collect();
    let desc = InputDesc {
        width: scene.width,
        height: scene.height,
        format: Format::Rgba16f,
        colorspace: ColorSpace::Linear,
        aux: aux.iter().map(|n| (n.to_string(), formats[*n])).collect(),
        aux_sizes: Vec::new(),
        viewport: None,
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
) -> Vec<f32> {
    let aux = aux_of(effect);
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

/// A constant grey scene.
fn grey(w: u32, h: u32, v: f32) -> Image {
    image_f32(w, h, |_, _| [v, v, v, 1.0])
}

/// A colourful scene with values exactly representable in half floats.
fn colourful(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        [
            f16r32(0.1 + 0.8 * x as f32 / w as f32),
            f16r32(0.2 + 0.7 * y as f32 / h as f32),
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

// ---------------------------------------------------------------- the room

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

// ---------------------------------------------------------------- all four

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
    for (effect, o) in [
        ("ssao", &["radius=1"][..]),
        ("ssao", &["output=ao", "blur=false"][..]),
        ("dof", &["focus_distance=3"][..]),
        ("fog", &["height_falloff=0.5", "distance=radial"][..]),
        ("fog", &["mode=linear"][..]),
        ("outline", &[][..]),
        ("outline", &["mode=antialias"][..]),
    ] {
        let out = run_gbuffer(&mut eng, effect, o, &scene, &g, &cam);
        assert_finite(&out, &format!("{effect} {o:?}"));
    }
}
