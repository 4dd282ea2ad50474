//! The GPU-built cluster lists against the CPU reference (`clusters::build`,
//! the same tests written on the CPU) and against the lights themselves (every
//! visible point inside a light's sphere finds the light in its cluster).

use super::*;
use crate::gpu::context::{require_gpu, AdapterChoice};
use crate::render::clusters::{build, ClusterGrid, LocalLight, SLICES, TILE_PX};
use crate::scene::camera::perspective_rh;
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

/// Builds the lists on the GPU and reads them back.
fn gpu_lists(
    ctx: &GpuContext,
    clusters: &mut GpuClusters,
    frame: &ClusterFrame<'_>,
) -> ClusterLists {
    clusters.prepare(ctx, frame).expect("lists fit");
    let mut encoder = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("cluster test"),
        });
    clusters.encode(&mut encoder, &mut Vec::new(), None);
    ctx.queue.submit([encoder.finish()]);
    let lists = clusters.read_lists(ctx, frame.grid).expect("read back");
    let errors = ctx.take_uncaptured_errors();
    assert!(errors.is_empty(), "{errors:?}");
    lists
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
    let frame = ClusterFrame {
        grid,
        proj: &proj,
        width: w,
        height: h,
        globals: &[7],
        locals: &locals,
    };
    let mut clusters = GpuClusters::new(&ctx).unwrap();
    let lists = gpu_lists(&ctx, &mut clusters, &frame);
    assert_eq!(lists.indices[0], 7);
    let checked = every_point_finds_its_light(&lists, &proj, (w, h), &locals, 4000);
    assert!(checked > 3000, "too few visible samples: {checked}");
    // the light behind the camera is listed nowhere
    assert!(!lists.indices[1..].contains(&3));
    let cpu = build(grid, &proj, w, h, &[7], &locals).unwrap();
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
    let frame = ClusterFrame {
        grid,
        proj: &proj,
        width: w,
        height: h,
        globals: &[0, 1],
        locals: &locals,
    };
    let mut clusters = GpuClusters::new(&ctx).unwrap();
    let lists = gpu_lists(&ctx, &mut clusters, &frame);
    let cpu = build(grid, &proj, w, h, &[0, 1], &locals).unwrap();
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

/// One cluster (`--light-culling none`) lists every light in light order, even
/// those outside the view; a second, smaller frame reuses the buffers.
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
    let mut clusters = GpuClusters::new(&ctx).unwrap();
    let frame = ClusterFrame {
        grid,
        proj: &proj,
        width: 64,
        height: 64,
        globals: &[300],
        locals: &locals,
    };
    let lists = gpu_lists(&ctx, &mut clusters, &frame);
    let mut expected = vec![300];
    expected.extend(0..300);
    assert_eq!(lists.ranges, vec![[1, 300]]);
    assert_eq!(lists.indices, expected);
    let frame = ClusterFrame {
        locals: &locals[..5],
        globals: &[],
        ..frame
    };
    let lists = gpu_lists(&ctx, &mut clusters, &frame);
    assert_eq!(lists.ranges, vec![[0, 5]]);
    assert_eq!(lists.indices, vec![0, 1, 2, 3, 4]);
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
    let frame = ClusterFrame {
        grid,
        proj: &proj,
        width: w,
        height: h,
        globals: &[26],
        locals: &locals,
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
    let mut clusters = GpuClusters::new(&ctx).unwrap();
    let lists = gpu_lists(&ctx, &mut clusters, &frame);
    let cpu = build(grid, &proj, w, h, &[26], &locals).unwrap();
    assert!(cpu.indices.len() > 50_000, "the lights fill the view");
    assert_same_lists(&lists, &cpu);
    let checked = every_point_finds_its_light(&lists, &proj, (w, h), &locals, 200);
    assert!(checked > 1000, "too few visible samples: {checked}");
}
