//! Motion vectors (`AUX.motion`, src/render/motion.rs) against the projected
//! displacement of known geometry, computed here by ray casting: the box over a
//! plane of `common/shadow_scene.rs`, a translating box, a camera turning about
//! its target, and a jittered frame (whose vectors must not contain the jitter).
//! Convention (docs/renderer.md): pixels, current minus previous position, x
//! right, y down. Interior pixels (whose 3×3 neighbourhood sees one surface)
//! agree within 0.05 px in all three techniques.

use crate::common;
use crate::common::shadow_scene;

use common::brdf::OracleCamera;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{FrameMotion, Renderer, RendererOptions, Technique};
use fxgraph::scene::Camera;
use glam::{Mat3, Mat4, Vec2, Vec3};
use shadow_scene::*;

const TOLERANCE_PX: f32 = 0.05;

fn oracle(c: &Camera) -> OracleCamera {
    OracleCamera::of(c, W, H)
}

/// What a ray sees: 0 nothing, 1 the ground, 2 the box; and the hit point.
fn trace(origin: Vec3, dir: Vec3, box_transform: &Mat4) -> (u8, Vec3) {
    let mut best = (0u8, f32::INFINITY);
    if dir.y.abs() > 1e-9 {
        let t = -origin.y / dir.y;
        let p = origin + dir * t;
        if t > 0.0 && p.x.abs() <= GROUND && p.z.abs() <= GROUND {
            best = (1, t);
        }
    }
    // the box in its local frame (an affine transform keeps ray parameters)
    let inv = box_transform.inverse();
    let (o, d) = (inv.transform_point3(origin), inv.transform_vector3(dir));
    let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
    for a in 0..3 {
        let (lo, hi) = (-BOX_HALF[a], BOX_HALF[a]);
        if d[a].abs() < 1e-12 {
            if o[a] < lo || o[a] > hi {
                t0 = f32::INFINITY;
            }
            continue;
        }
        let (ta, tb) = ((lo - o[a]) / d[a], (hi - o[a]) / d[a]);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    if t0 <= t1 && t0 > 0.0 && t0 < best.1 {
        best = (2, t0);
    }
    (best.0, origin + dir * best.1)
}

/// Pixel position (x right, y down, centres at .5) of world point `x`, or of
/// direction `x` when `w` is 0.
fn project(c: &OracleCamera, x: Vec3, w: f32) -> Vec2 {
    let f = (c.target - c.eye).normalize();
    let s = f.cross(c.up).normalize();
    let u = s.cross(f);
    let d = x - c.eye * w;
    let t = (c.fov_y * 0.5).tan();
    let (xv, yv, zv) = (d.dot(s), d.dot(u), d.dot(f));
    let ndc = Vec2::new(xv / (zv * c.aspect * t), yv / (zv * t));
    Vec2::new(
        (ndc.x + 1.0) * 0.5 * c.width as f32,
        (1.0 - ndc.y) * 0.5 * c.height as f32,
    )
}

/// The ray through the image point `p` (pixels, y down) of camera `c`.
fn ray_at(c: &OracleCamera, p: Vec2) -> Vec3 {
    let f = (c.target - c.eye).normalize();
    let s = f.cross(c.up).normalize();
    let u = s.cross(f);
    let t = (c.fov_y * 0.5).tan();
    let ndc_x = p.x / c.width as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - p.y / c.height as f32 * 2.0;
    (s * (ndc_x * c.aspect * t) + u * (ndc_y * t) + f).normalize()
}

struct Case {
    name: &'static str,
    camera: Camera,
    prev_camera: Camera,
    box_now: Mat4,
    box_prev: Mat4,
    jitter: [f32; 2],
}

/// Expected motion per pixel (`None` where the 3×3 neighbourhood sees more
/// than one surface).
fn expected(case: &Case) -> Vec<Option<Vec2>> {
    let (cam, prev) = (oracle(&case.camera), oracle(&case.prev_camera));
    let j = Vec2::from(case.jitter);
    let mut ids = vec![0u8; (W * H) as usize];
    let mut hits = vec![Vec3::ZERO; (W * H) as usize];
    for y in 0..H {
        for x in 0..W {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + j;
            let (id, hit) = trace(cam.eye, ray_at(&cam, p), &case.box_now);
            ids[(y * W + x) as usize] = id;
            hits[(y * W + x) as usize] = hit;
        }
    }
    let mut out = vec![None; (W * H) as usize];
    for y in 1..H - 1 {
        for x in 1..W - 1 {
            let i = (y * W + x) as usize;
            let id = ids[i];
            let uniform = (-1i32..=1).all(|dy| {
                (-1i32..=1).all(|dx| {
                    ids[((y as i32 + dy) as u32 * W + (x as i32 + dx) as u32) as usize] == id
                })
            });
            if !uniform {
                continue;
            }
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + j;
            let was = match id {
                0 => project(&prev, ray_at(&cam, p), 0.0),
                1 => project(&prev, hits[i], 1.0),
                _ => project(
                    &prev,
                    (case.box_prev * case.box_now.inverse()).transform_point3(hits[i]),
                    1.0,
                ),
            };
            // the unjittered position of what the pixel shows, minus where it was
            out[i] = Some(p - was);
        }
    }
    out
}

fn check(case: &Case) {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let scene = scene(directional());
    let rest: Vec<Mat4> = scene.instances.iter().map(|i| i.transform).collect();
    let expect = expected(case);
    let interior = expect.iter().filter(|e| e.is_some()).count();
    assert!(
        interior > (W * H / 2) as usize,
        "{}: too few interior pixels",
        case.name
    );
    for technique in Technique::ALL {
        let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
        let motion = FrameMotion {
            transforms: vec![rest[0], case.box_now],
            prev_transforms: vec![rest[0], case.box_prev],
            prev_camera: Some(case.prev_camera),
            jitter: case.jitter,
            ..Default::default()
        };
        let (out, _) = r
            .render_frame(ctx, &case.camera, &motion, W, H, technique, None)
            .unwrap_or_else(|e| panic!("{}: {technique}: {e}", case.name));
        let got = read_rgba_f32(ctx, out.aux("motion").expect("AUX.motion")).unwrap();
        let (mut worst, mut at) = (0f32, (0, 0));
        let mut largest = 0f32;
        for (i, e) in expect.iter().enumerate() {
            let Some(e) = e else { continue };
            let g = Vec2::new(got[i][0], got[i][1]);
            largest = largest.max(e.length());
            let err = (g - *e).length();
            if err > worst {
                worst = err;
                at = (i as u32 % W, i as u32 / W);
            }
        }
        eprintln!(
            "{} ({technique}): {interior} interior pixels, largest motion {largest:.2} px, worst error {worst:.4} px at {at:?}",
            case.name
        );
        assert!(
            worst <= TOLERANCE_PX,
            "{} ({technique}): motion off by {worst} px at {at:?} (expected {:?}, got {:?})",
            case.name,
            expect[(at.1 * W + at.0) as usize],
            got[(at.1 * W + at.0) as usize]
        );
    }
}

fn turned(c: Camera, degrees: f32) -> Camera {
    let r = Mat3::from_rotation_y(degrees.to_radians());
    Camera {
        eye: c.target + r * (c.eye - c.target),
        ..c
    }
}

#[test]
fn a_translating_box_moves_its_pixels_and_nothing_else() {
    let box_now = Mat4::from_translation(BOX_CENTER);
    check(&Case {
        name: "translating box",
        camera: camera(),
        prev_camera: camera(),
        box_now,
        box_prev: Mat4::from_translation(BOX_CENTER - Vec3::new(0.35, 0.1, -0.2)),
        jitter: [0.0, 0.0],
    });
}

#[test]
fn a_rotating_box_under_a_turning_camera() {
    let box_now = Mat4::from_translation(BOX_CENTER) * Mat4::from_rotation_y(0.3);
    check(&Case {
        name: "rotating box, turning camera",
        camera: camera(),
        prev_camera: turned(camera(), -4.0),
        box_now,
        box_prev: Mat4::from_translation(BOX_CENTER) * Mat4::from_rotation_y(0.22),
        jitter: [0.0, 0.0],
    });
}

#[test]
fn a_turning_camera_moves_the_background_too() {
    let mut cam = camera();
    // look up a little so that the sky (no geometry) shows at the top
    cam.target = Vec3::new(0.0, 2.5, 0.5);
    let case = Case {
        name: "turning camera, background",
        camera: cam,
        prev_camera: turned(cam, 3.0),
        box_now: Mat4::from_translation(BOX_CENTER),
        box_prev: Mat4::from_translation(BOX_CENTER),
        jitter: [0.0, 0.0],
    };
    let sky = expected(&case)
        .iter()
        .enumerate()
        .filter(|(i, e)| {
            e.is_some() && {
                let (x, y) = (*i as u32 % W, *i as u32 / W);
                let c = oracle(&case.camera);
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                trace(c.eye, ray_at(&c, p), &case.box_now).0 == 0
            }
        })
        .count();
    assert!(sky > 500, "the case must show the background ({sky} px)");
    check(&case);
}

#[test]
fn jitter_never_shows_in_the_motion_vectors() {
    check(&Case {
        name: "jittered frame",
        camera: camera(),
        prev_camera: turned(camera(), 2.0),
        box_now: Mat4::from_translation(BOX_CENTER + Vec3::X * 0.2),
        box_prev: Mat4::from_translation(BOX_CENTER),
        jitter: [0.37, -0.21],
    });
}

#[test]
fn a_still_frame_has_no_motion() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let scene = scene(directional());
    let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
    let (out, _) = r
        .render(ctx, &camera(), W, H, Technique::Deferred, None)
        .unwrap();
    let got = read_rgba_f32(ctx, out.aux("motion").unwrap()).unwrap();
    assert!(got.iter().all(|m| m[0] == 0.0 && m[1] == 0.0));
}

/// The skinned, animated corpus model `SimpleSkin` (Khronos, see the corpus
/// README) between two times: each pixel's expected motion comes from ray
/// casting the CPU-skinned triangles (`Pose::skinned_mesh`, the spec's oracle) of
/// the current time and carrying the hit's barycentric coordinates to the same
/// triangle at the previous time.
#[test]
fn a_skinned_mesh_moves_its_pixels_with_its_joints() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/corpus/gltf/animated/SimpleSkin/SimpleSkin.gltf");
    assert!(
        path.exists(),
        "the corpus model {} is missing",
        path.display()
    );
    let scene = fxgraph::scene::Scene::load(path.to_str().unwrap()).unwrap();
    let playback = fxgraph::scene::Playback::default();
    let (t, dt) = (0.8, 1.0 / 30.0);
    let (now, prev) = (scene.pose(t, &playback), scene.pose(t - dt, &playback));
    let camera = Camera {
        eye: Vec3::new(0.5, 1.0, 3.2),
        target: Vec3::new(0.5, 1.0, 0.0),
        up: Vec3::Y,
        fov_y: 50f32.to_radians(),
        near: 0.1,
        far: 20.0,
    };
    let deformed: Vec<usize> = (0..scene.instances.len())
        .filter(|&i| scene.is_deformed(i))
        .collect();
    assert!(!deformed.is_empty(), "SimpleSkin is skinned");
    // CPU: world triangles now and before
    let mut tris: Vec<([Vec3; 3], [Vec3; 3])> = Vec::new();
    for i in 0..scene.instances.len() {
        let (a, b) = (now.skinned_mesh(&scene, i), prev.skinned_mesh(&scene, i));
        let mesh = &scene.meshes[scene.instances[i].mesh];
        for f in mesh.indices.chunks_exact(3) {
            let g = |m: &fxgraph::scene::PosedMesh| [0, 1, 2].map(|k| m.positions[f[k] as usize]);
            tris.push((g(&a), g(&b)));
        }
    }
    let cam = oracle(&camera);
    let hit = |x: u32, y: u32| -> Option<Vec3> {
        let d = ray_at(&cam, Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
        let mut best: Option<(f32, Vec3)> = None;
        for (p, q) in &tris {
            // Möller-Trumbore
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let h = d.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-12 {
                continue;
            }
            let s = cam.eye - p[0];
            let u = s.dot(h) / det;
            let qv = s.cross(e1);
            let v = d.dot(qv) / det;
            let dist = e2.dot(qv) / det;
            if u < 0.0 || v < 0.0 || u + v > 1.0 || dist <= 0.0 {
                continue;
            }
            if best.is_none_or(|(bd, _)| dist < bd) {
                best = Some((dist, q[0] * (1.0 - u - v) + q[1] * u + q[2] * v));
            }
        }
        best.map(|(_, was)| was)
    };
    let prev_cam = oracle(&camera);
    let covered: Vec<Option<Vec3>> = (0..W * H).map(|i| hit(i % W, i / W)).collect();
    let motion = FrameMotion::posed(&scene, &now, &prev);
    for technique in Technique::ALL {
        let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
        let (out, _) = r
            .render_frame(ctx, &camera, &motion, W, H, technique, None)
            .unwrap();
        let got = read_rgba_f32(ctx, out.aux("motion").unwrap()).unwrap();
        let (mut n, mut worst, mut largest) = (0, 0f32, 0f32);
        for y in 1..H - 1 {
            for x in 1..W - 1 {
                let inside = (-1i32..=1).all(|dy| {
                    (-1i32..=1).all(|dx| {
                        covered[((y as i32 + dy) as u32 * W + (x as i32 + dx) as u32) as usize]
                            .is_some()
                    })
                });
                let Some(was) = covered[(y * W + x) as usize].filter(|_| inside) else {
                    continue;
                };
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let want = p - project(&prev_cam, was, 1.0);
                let g = got[(y * W + x) as usize];
                worst = worst.max((Vec2::new(g[0], g[1]) - want).length());
                largest = largest.max(want.length());
                n += 1;
            }
        }
        eprintln!("skinned ({technique}): {n} interior pixels, largest motion {largest:.2} px, worst error {worst:.4} px");
        assert!(
            n > 200,
            "{technique}: the model must cover the view ({n} px)"
        );
        assert!(
            largest > 0.5,
            "{technique}: the joints must move ({largest} px)"
        );
        assert!(worst <= TOLERANCE_PX, "{technique}: off by {worst} px");
    }
}
