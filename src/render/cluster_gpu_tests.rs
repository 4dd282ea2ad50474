//! The GPU-built cluster lists against the CPU reference (`clusters::build`,
//! the same tests written on the CPU) and against the lights themselves (every
//! visible point inside a light's sphere finds the light in its cluster).

use super::*;
use crate::gpu::context::{require_gpu, AdapterChoice};
use crate::render::clusters::{build, ClusterGrid, LocalLight, SLICES, TILE_PX};
use crate::render::gpu_types::GpuLight;
use crate::render::light_view_gpu::ViewFrame;
use crate::render::lights::frustum_planes;
use crate::render::world_lights::WorldLights;
use crate::scene::camera::{look_to_rh, perspective_rh};
use glam::Vec3;

fn context() -> Option<GpuContext> {
    match GpuContext::new(&AdapterChoice::Auto) {
        Ok(ctx) => Some(ctx),
        Err(e) if require_gpu() => panic!("GPU tests need an adapter: {e}"),
        Err(e) => {
            eprintln!("skipped: no GPU ({e})");
            None
        }
    }
}

/// The light view and cluster passes of one test.
struct Passes {
    view: LightView,
    clusters: GpuClusters,
}

impl Passes {
    fn new(ctx: &GpuContext) -> Passes {
        let view = LightView::new(ctx).unwrap();
        let clusters = GpuClusters::new(ctx, &view).unwrap();
        Passes { view, clusters }
    }
}

/// One test frame: the grid, the camera and the global lights.
#[derive(Clone, Copy)]
struct TestFrame<'a> {
    grid: ClusterGrid,
    view: Mat4,
    proj: &'a Mat4,
    width: u32,
    height: u32,
    globals: &'a [u32],
}

/// Moves the uploaded lights into view space, culls and bins them on the GPU
/// (the reservation read back first, as the renderer does when the lights or
/// the grid change, when `size` is set) and reads the lists back.
fn gpu_lists(ctx: &GpuContext, p: &mut Passes, f: &TestFrame<'_>, size: bool) -> ClusterLists {
    p.view.prepare(
        ctx,
        &ViewFrame {
            grid: f.grid,
            view: &f.view,
            proj: f.proj,
            width: f.width,
            height: f.height,
        },
    );
    let encoder = |label| {
        ctx.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
    };
    if size {
        let mut e = encoder("cluster test sizing");
        p.view.encode(&mut e, &mut Vec::new(), None);
        ctx.queue.submit([e.finish()]);
        let summary = p.view.summary(ctx).unwrap();
        p.clusters.reserve(u64::from(summary.footprint_clusters));
    }
    let frame = ClusterFrame {
        grid: f.grid,
        proj: f.proj,
        width: f.width,
        height: f.height,
        globals: f.globals,
        view: &p.view,
    };
    p.clusters.prepare(ctx, &frame).expect("lists fit");
    let mut e = encoder("cluster test");
    p.clusters.encode(&mut e, &mut Vec::new(), (&p.view, None));
    ctx.queue.submit([e.finish()]);
    p.clusters.after_submit();
    let lists = p.clusters.read_lists(ctx, f.grid).expect("read back");
    let errors = ctx.take_uncaptured_errors();
    assert!(errors.is_empty(), "{errors:?}");
    lists
}

/// Uploads `locals` (view-space spheres, the view the identity) and builds
/// their lists on the GPU.
fn lists_of(
    ctx: &GpuContext,
    p: &mut Passes,
    f: &TestFrame<'_>,
    locals: &[LocalLight],
) -> ClusterLists {
    let lights = locals.iter().map(|l| l.index + 1).max().unwrap_or(0);
    let lights = lights.max(f.globals.iter().map(|g| g + 1).max().unwrap_or(0));
    p.view
        .set_lights(ctx, &WorldLights::for_tests(lights, f.globals, locals));
    gpu_lists(ctx, p, f, true)
}

/// The CPU reference of a frame: the spheres moved by `view`, culled against
/// the frustum as the CPU classification culls them, binned by `build`.
fn cpu_lists(f: &TestFrame<'_>, world: &[LocalLight]) -> (ClusterLists, Vec<LocalLight>) {
    let planes = frustum_planes(f.proj);
    let visible: Vec<LocalLight> = world
        .iter()
        .map(|l| LocalLight {
            center: f.view.transform_point3(l.center),
            ..*l
        })
        .filter(|l| {
            !planes
                .iter()
                .any(|p| p.truncate().dot(l.center) + p.w < -l.radius)
        })
        .collect();
    let lists = build(f.grid, f.proj, f.width, f.height, f.globals, &visible).unwrap();
    (lists, visible)
}

/// The cluster a view-space point falls in, as the lighting shaders compute it
/// (`fx_cluster_range` in engine.wgsl).
fn cluster_of(grid: &ClusterGrid, proj: &Mat4, w: u32, h: u32, p: Vec3) -> Option<u32> {
    let clip = *proj * p.extend(1.0);
    let (nx, ny) = (clip.x / clip.w, clip.y / clip.w);
    if nx.abs() >= 1.0 || ny.abs() >= 1.0 || -p.z < grid.near || -p.z > grid.far {
        return None;
    }
    let px = (nx + 1.0) * 0.5 * w as f32;
    let py = (1.0 - ny) * 0.5 * h as f32;
    let tx = (px as u32 / grid.tile_px).min(grid.tiles_x - 1);
    let ty = (py as u32 / grid.tile_px).min(grid.tiles_y - 1);
    let s = ((-p.z / grid.near).ln() * grid.log_scale).floor();
    let s = (s.max(0.0) as u32).min(grid.slices - 1);
    Some((s * grid.tiles_y + ty) * grid.tiles_x + tx)
}

struct Rng(u64);

impl Rng {
    /// xorshift64, uniform in [0, 1).
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f32 / (1u64 << 53) as f32
    }
}

/// Samples `per_light` points inside each light's sphere and checks that each
/// visible one finds its light in its cluster's GPU list. Returns the samples
/// checked.
fn every_point_finds_its_light(
    lists: &ClusterLists,
    proj: &Mat4,
    (w, h): (u32, u32),
    locals: &[LocalLight],
    per_light: usize,
) -> usize {
    let mut rng = Rng(12345);
    let mut checked = 0;
    for l in locals {
        for _ in 0..per_light {
            let dir =
                Vec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize_or_zero();
            let p = l.center + dir * l.radius * rng.next().cbrt() * 0.999;
            let Some(c) = cluster_of(&lists.grid, proj, w, h, p) else {
                continue;
            };
            let [o, n] = lists.ranges[c as usize];
            let list = &lists.indices[o as usize..(o + n) as usize];
            assert!(list.contains(&l.index), "light {} missing at {p}", l.index);
            checked += 1;
        }
    }
    checked
}

/// The GPU lists equal the CPU reference's, list for list and in the same
/// order.
fn assert_same_lists(gpu: &ClusterLists, cpu: &ClusterLists) {
    assert_eq!(gpu.globals, cpu.globals);
    assert_eq!(gpu.ranges.len(), cpu.ranges.len());
    let differ = (0..cpu.ranges.len())
        .filter(|&c| {
            let list = |l: &ClusterLists| {
                let [o, n] = l.ranges[c];
                l.indices[o as usize..(o + n) as usize].to_vec()
            };
            list(gpu) != list(cpu)
        })
        .count();
    assert_eq!(
        differ,
        0,
        "{differ} of {} cluster lists differ",
        cpu.ranges.len()
    );
    assert_eq!(gpu.indices, cpu.indices);
    assert_eq!(gpu.ranges, cpu.ranges);
    assert_eq!(gpu.max_per_cluster, cpu.max_per_cluster);
}

/// Lights in front of, around and behind the camera: every visible point inside
/// a sphere finds its light in the GPU lists, which equal the CPU reference.
#[test]
fn every_lit_point_finds_its_light_in_the_gpu_lists() {
    let Some(ctx) = context() else { return };
    let (w, h) = (200, 120);
    let proj = perspective_rh(1.0, w as f32 / h as f32, 0.1, 50.0);
    let grid = ClusterGrid::new(w, h, 0.1, 50.0, 16, 12);
    let sphere = |index, center, radius| LocalLight {
        index,
        center,
        radius,
    };
    let locals = [
        sphere(0, Vec3::new(0.5, -0.3, -4.0), 1.0),
        sphere(1, Vec3::new(0.0, 0.0, 0.2), 2.0),
        sphere(2, Vec3::new(-3.0, 1.0, -20.0), 0.3),
        sphere(3, Vec3::new(0.0, 0.0, 5.0), 1.0),
    ];
    let frame = TestFrame {
        grid,
        view: Mat4::IDENTITY,
        proj: &proj,
        width: w,
        height: h,
        globals: &[7],
    };
    let mut passes = Passes::new(&ctx);
    let lists = lists_of(&ctx, &mut passes, &frame, &locals);
    assert_eq!(lists.indices[0], 7);
    let checked = every_point_finds_its_light(&lists, &proj, (w, h), &locals, 4000);
    assert!(checked > 3000, "too few visible samples: {checked}");
    // the light behind the camera is listed nowhere
    assert!(!lists.indices[1..].contains(&3));
    let (cpu, _) = cpu_lists(&frame, &locals);
    assert_same_lists(&lists, &cpu);
}

/// 16,384 random lights at 1920×1080 with the renderer's grid: the GPU lists
/// equal the CPU reference, and sampled points find their lights.
#[test]
fn sixteen_thousand_lights_on_the_gpu() {
    let Some(ctx) = context() else { return };
    let (w, h) = (1920, 1080);
    let proj = perspective_rh(0.9, w as f32 / h as f32, 0.1, 60.0);
    let grid = ClusterGrid::new(w, h, 0.5, 40.0, TILE_PX, SLICES);
    let mut rng = Rng(99);
    let locals: Vec<LocalLight> = (0..16_384)
        .map(|i| LocalLight {
            index: i + 2,
            center: Vec3::new(
                (rng.next() - 0.5) * 30.0,
                (rng.next() - 0.5) * 16.0,
                -rng.next() * 42.0 + 2.0,
            ),
            radius: 0.2 + rng.next() * rng.next() * 3.0,
        })
        .collect();
    let frame = TestFrame {
        grid,
        view: Mat4::IDENTITY,
        proj: &proj,
        width: w,
        height: h,
        globals: &[0, 1],
    };
    let mut passes = Passes::new(&ctx);
    let lists = lists_of(&ctx, &mut passes, &frame, &locals);
    let (cpu, _) = cpu_lists(&frame, &locals);
    eprintln!(
        "16,384 lights: {} entries, longest list {}",
        cpu.indices.len() - 2,
        cpu.max_per_cluster
    );
    assert!(cpu.indices.len() > 100_000, "the lights overlap clusters");
    assert_same_lists(&lists, &cpu);
    let checked = every_point_finds_its_light(&lists, &proj, (w, h), &locals, 20);
    assert!(checked > 100_000 / 10, "too few visible samples: {checked}");
}

/// One cluster (`--light-culling none`) lists every light in the view in light
/// order (those behind the camera are culled); a second, smaller frame reuses
/// the buffers.
#[test]
fn one_cluster_lists_every_light_and_buffers_are_reused() {
    let Some(ctx) = context() else { return };
    let proj = perspective_rh(1.0, 1.0, 0.1, 10.0);
    let grid = ClusterGrid::new(64, 64, 0.1, 10.0, 0, 1);
    let locals: Vec<LocalLight> = (0..300)
        .map(|i| LocalLight {
            index: i,
            center: Vec3::new(0.0, 0.0, if i % 2 == 0 { 100.0 } else { -3.0 }),
            radius: 1.0,
        })
        .collect();
    let mut passes = Passes::new(&ctx);
    let frame = TestFrame {
        grid,
        view: Mat4::IDENTITY,
        proj: &proj,
        width: 64,
        height: 64,
        globals: &[300],
    };
    let lists = lists_of(&ctx, &mut passes, &frame, &locals);
    let mut expected = vec![300];
    expected.extend((0..300).filter(|i| i % 2 == 1));
    assert_eq!(lists.ranges, vec![[1, 150]]);
    assert_eq!(lists.indices, expected);
    let frame = TestFrame {
        globals: &[],
        ..frame
    };
    let lists = lists_of(&ctx, &mut passes, &frame, &locals[..5]);
    assert_eq!(lists.ranges, vec![[0, 2]]);
    assert_eq!(lists.indices, vec![1, 3]);
}

/// A room's few large lights at 1920×1080 with the renderer's grid, the camera
/// inside some: footprints of thousands of clusters (many workgroups each)
/// between small ones of a single chunk. The GPU lists equal the CPU reference.
#[test]
fn large_lights_spread_over_many_workgroups() {
    let Some(ctx) = context() else { return };
    let (w, h) = (1920, 1080);
    let proj = perspective_rh(0.9, w as f32 / h as f32, 0.1, 60.0);
    let grid = ClusterGrid::new(w, h, 0.1, 60.0, TILE_PX, SLICES);
    let mut rng = Rng(7);
    let locals: Vec<LocalLight> = (0..26)
        .map(|i| {
            let big = i % 3 != 1;
            LocalLight {
                index: i,
                center: Vec3::new(
                    (rng.next() - 0.5) * 8.0,
                    (rng.next() - 0.5) * 4.0,
                    -rng.next() * 12.0 + 1.0,
                ),
                radius: if big { 4.0 + rng.next() * 12.0 } else { 0.1 },
            }
        })
        .collect();
    let frame = TestFrame {
        grid,
        view: Mat4::IDENTITY,
        proj: &proj,
        width: w,
        height: h,
        globals: &[26],
    };
    let most = locals
        .iter()
        .filter_map(|l| grid.footprint(&proj, w, h, l))
        .map(|f| f.clusters())
        .max();
    assert!(
        most > Some(16 * CHUNK),
        "a light spans many chunks: {most:?}"
    );
    let mut passes = Passes::new(&ctx);
    let lists = lists_of(&ctx, &mut passes, &frame, &locals);
    let (cpu, _) = cpu_lists(&frame, &locals);
    assert!(cpu.indices.len() > 50_000, "the lights fill the view");
    assert_same_lists(&lists, &cpu);
    let checked = every_point_finds_its_light(&lists, &proj, (w, h), &locals, 200);
    assert!(checked > 1000, "too few visible samples: {checked}");
}

/// Still lights, uploaded once, under a camera that orbits them for six
/// frames: each frame the GPU moves them into view space, culls them and bins
/// them, and the lists equal the CPU reference's (the spheres moved and culled
/// on the CPU, then `build`) exactly; the view-space light array matches the
/// CPU's transform (1e-4 relative), and the visible count the CPU's. No frame
/// uploads the lights again. A reservation too small for a frame's entries
/// gives every light in every cluster (exact, never fewer lights).
#[test]
fn a_moving_camera_over_still_lights_uploads_nothing() {
    let Some(ctx) = context() else { return };
    let (w, h) = (640, 360);
    let proj = perspective_rh(0.9, w as f32 / h as f32, 0.1, 60.0);
    let grid = ClusterGrid::new(w, h, 0.3, 40.0, TILE_PX, SLICES);
    let mut rng = Rng(31);
    let world: Vec<LocalLight> = (0..4096)
        .map(|i| LocalLight {
            index: i + 1,
            center: Vec3::new(
                (rng.next() - 0.5) * 30.0,
                (rng.next() - 0.5) * 10.0,
                (rng.next() - 0.5) * 30.0,
            ),
            radius: 0.2 + rng.next() * rng.next() * 3.0,
        })
        .collect();
    let globals = [0];
    let mut passes = Passes::new(&ctx);
    passes
        .view
        .set_lights(&ctx, &WorldLights::for_tests(4097, &globals, &world));
    assert_eq!(passes.view.uploads(), 1);
    for k in 0..6 {
        let angle = k as f32 * 0.7;
        let eye = Vec3::new(angle.cos() * 12.0, 2.0 + k as f32 * 0.5, angle.sin() * 12.0);
        let frame = TestFrame {
            grid,
            view: look_to_rh(eye, -eye.normalize(), Vec3::Y),
            proj: &proj,
            width: w,
            height: h,
            globals: &globals,
        };
        let lists = gpu_lists(&ctx, &mut passes, &frame, k == 0);
        let (cpu, visible) = cpu_lists(&frame, &world);
        assert!(
            cpu.indices.len() > 2000,
            "frame {k}: the lights fill the view"
        );
        assert_same_lists(&lists, &cpu);
        let summary = passes.view.summary(&ctx).unwrap();
        assert_eq!(summary.visible as usize, visible.len(), "frame {k}");
        let bytes = ctx.read_buffer(passes.view.lights(), 0, 4098 * 96).unwrap();
        let gpu: &[GpuLight] = bytemuck::cast_slice(&bytes);
        for l in &world {
            let cpu = frame.view.transform_point3(l.center);
            let got = Vec3::from(gpu[l.index as usize].position);
            assert!(
                (got - cpu).length() <= 1e-4 * (1.0 + cpu.length()),
                "frame {k}: light {} at {got}, not {cpu}",
                l.index
            );
        }
        let checked = every_point_finds_its_light(&lists, &proj, (w, h), &visible, 4);
        assert!(checked > 1000, "too few visible samples: {checked}");
    }
    assert_eq!(
        passes.view.uploads(),
        1,
        "a moving camera re-uploaded the lights"
    );
    // a reservation too small (for lights four times as large): every
    // cluster lists every light, in order
    let large: Vec<LocalLight> = world
        .iter()
        .map(|l| LocalLight {
            radius: l.radius * 4.0,
            ..*l
        })
        .collect();
    let mut small = Passes::new(&ctx);
    small
        .view
        .set_lights(&ctx, &WorldLights::for_tests(4097, &globals, &large));
    let frame = TestFrame {
        grid,
        view: look_to_rh(
            Vec3::new(12.0, 2.0, 0.0),
            Vec3::new(-12.0, -2.0, 0.0).normalize(),
            Vec3::Y,
        ),
        proj: &proj,
        width: w,
        height: h,
        globals: &globals,
    };
    let lists = gpu_lists(&ctx, &mut small, &frame, false);
    assert!(small.clusters.summary(&ctx).unwrap().overflowed);
    assert!(lists.ranges.iter().all(|r| *r == [1, 4096]));
    let mut all = vec![0];
    all.extend(1..=4096);
    assert_eq!(lists.indices, all);
}
