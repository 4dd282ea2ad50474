//! Clustered light lists built on the GPU each frame (`shaders/render/clusters.wgsl`).
//!
//! The host uploads the grid's plane slopes and slice depths ([`GridEdges`], a
//! few hundred floats); the lights' records (view-space bounding sphere, the
//! tiles and slices it may touch, its first chunk) come from the light view
//! pass (`light_view_gpu.rs`), on the GPU, so no per-light work is left on the
//! CPU. Four dispatches in one compute pass ("light clusters") then compute
//! the clusters' view-space boxes, count each cluster's lights, turn the counts
//! into ranges (one workgroup's prefix sum) and append the lights; a fifth
//! ("light clusters sort") sorts each list into light order. Counting and
//! appending take one workgroup per `CHUNK` clusters of a light's footprint
//! (slices × tiles), numbered by the light view pass, which also leaves their
//! number as the indirect dispatch size, so a light over the whole screen is
//! spread over many workgroups and a few large lights keep the GPU busy. The
//! lists are those of the CPU reference ([`super::clusters::build`]), test for
//! test, in the same order; `cluster_gpu_tests.rs` compares the two.
//!
//! Room for the lists: the footprints' clusters bound the entries; the light
//! view pass sums them on the GPU, and the reservation follows that sum (read
//! when the lights or the grid change, and in the background every frame:
//! `cluster_capacity.rs`), up to [`MAX_ENTRIES`]. A frame whose entries do not
//! fit lists every light in every cluster instead (exact, slower), never less.
//! The entry count and the longest list stay on the GPU unless asked for
//! ([`GpuClusters::summary`]: a blocking read, done for timed frames).

use super::cluster_capacity::CapacityFeedback;
#[cfg(test)]
use super::clusters::ClusterLists;
use super::clusters::{ClusterGrid, GridEdges, MAX_ENTRIES};
use super::light_view_gpu::{dispatch_2d, LightView};
use crate::gpu::bindings;
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
use bytemuck::{Pod, Zeroable};
use glam::Mat4;

const SHADER: &str = include_str!("../../shaders/render/clusters.wgsl");
const COMPUTE: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;
/// Invocations per workgroup of the per-cluster, per-light and per-entry
/// dispatches, and workgroups per row of a 2D dispatch (as in the shader).
const WORKGROUP: u32 = 64;
/// Clusters of a light's footprint per workgroup of the count and fill
/// dispatches (as in the shaders).
#[cfg(test)]
const CHUNK: usize = 256;
/// The most point and spot lights one frame can bin (their chunks, at least one
/// each, fit a 2D dispatch many times over).
pub(crate) const MAX_CLUSTER_LIGHTS: usize = 65535 * WORKGROUP as usize;

/// `Params` of clusters.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuClusterParams {
    grid: [u32; 4],
    counts: [u32; 4],
}

/// A frame's lists could not be built.
#[derive(Debug, thiserror::Error)]
pub(crate) enum ClusterError {
    #[error("{0} point and spot lights exceed the limit of {MAX_CLUSTER_LIGHTS}")]
    TooManyLights(usize),
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// One frame's request: the grid, the projection it is cut from, the global
/// lights (listed first, everywhere) and the light view pass that makes the
/// point and spot lights' records.
pub(crate) struct ClusterFrame<'a> {
    pub grid: ClusterGrid,
    pub proj: &'a Mat4,
    pub width: u32,
    pub height: u32,
    pub globals: &'a [u32],
    pub view: &'a LightView,
}

/// What the GPU built, read back ([`GpuClusters::summary`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct ClusterSummary {
    /// Light × cluster entries (without the global lights).
    pub entries: u32,
    /// The longest cluster list.
    pub max_per_cluster: u32,
    /// The entries did not fit the reservation: every cluster listed every
    /// light.
    pub overflowed: bool,
}

/// The buffers the five dispatches share, grown to a power of two when a frame
/// needs more.
struct Buffers {
    params: wgpu::Buffer,
    edges: wgpu::Buffer,
    bounds: wgpu::Buffer,
    counts: wgpu::Buffer,
    ranges: wgpu::Buffer,
    unsorted: wgpu::Buffer,
    owner: wgpu::Buffer,
    indices: wgpu::Buffer,
    summary: wgpu::Buffer,
    /// The sort's dispatch size, copied from `summary` between the two passes
    /// (a buffer cannot be written as storage and read as indirect arguments in
    /// one dispatch).
    indirect: wgpu::Buffer,
}

/// The dispatch sizes of the frame last prepared.
#[derive(Debug, Clone, Copy, Default)]
struct Plan {
    clusters: u32,
    /// Point and spot lights (records of the light view pass).
    locals: u32,
    /// (read back by the tests' [`GpuClusters::read_lists`])
    #[cfg_attr(not(test), allow(dead_code))]
    globals: u32,
    #[cfg_attr(not(test), allow(dead_code))]
    capacity: u32,
}

/// The GPU light clustering of a renderer.
pub(crate) struct GpuClusters {
    layout: wgpu::BindGroupLayout,
    pipelines: [wgpu::ComputePipeline; 5],
    buffers: Buffers,
    group: wgpu::BindGroup,
    /// The light view buffers `group` binds (their generation).
    view_generation: u64,
    plan: Option<Plan>,
    /// Entries to reserve room for (the footprints' clusters, as last read).
    wanted: u64,
    feedback: CapacityFeedback,
}

const ENTRY_POINTS: [&str; 5] = [
    "fx_cs_cluster_bounds",
    "fx_cs_cluster_count",
    "fx_cs_cluster_offsets",
    "fx_cs_cluster_fill",
    "fx_cs_cluster_sort",
];

fn storage(
    device: &wgpu::Device,
    label: &str,
    bytes: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
        mapped_at_creation: false,
    })
}

const EDGES: &str = "light clusters plane slopes and slice depths";
const BOUNDS: &str = "light clusters boxes";
const COUNTS: &str = "light clusters counters";
const RANGES: &str = "deferred cluster ranges";
const UNSORTED: &str = "light clusters entries (arrival order)";
const OWNER: &str = "light clusters entry owners";
const INDICES: &str = "deferred cluster lights";

const COPY_SRC: wgpu::BufferUsages = wgpu::BufferUsages::COPY_SRC;
const NONE: wgpu::BufferUsages = wgpu::BufferUsages::empty();

impl Buffers {
    fn new(device: &wgpu::Device) -> Buffers {
        Buffers {
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light clusters parameters"),
                size: std::mem::size_of::<GpuClusterParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            edges: storage(device, EDGES, 1 << 10, NONE),
            bounds: storage(device, BOUNDS, 1 << 16, NONE),
            counts: storage(device, COUNTS, 1 << 12, NONE),
            ranges: storage(device, RANGES, 1 << 13, COPY_SRC),
            unsorted: storage(device, UNSORTED, 1 << 12, NONE),
            owner: storage(device, OWNER, 1 << 12, NONE),
            indices: storage(device, INDICES, 1 << 12, COPY_SRC),
            summary: storage(device, "light clusters summary", 32, COPY_SRC),
            indirect: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light clusters sort dispatch"),
                size: 16,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        }
    }

    /// Grows every buffer to hold `clusters` clusters, `edges` floats and
    /// `capacity` entries. Returns whether one was replaced.
    fn ensure(&mut self, device: &wgpu::Device, clusters: u64, edges: u64, capacity: u64) -> bool {
        let mut grown = false;
        let mut grow = |buffer: &mut wgpu::Buffer, label: &str, bytes: u64, extra| {
            if bytes > buffer.size() {
                *buffer = storage(device, label, bytes.next_power_of_two(), extra);
                grown = true;
            }
        };
        grow(&mut self.edges, EDGES, edges * 4, NONE);
        grow(&mut self.bounds, BOUNDS, clusters * 32, NONE);
        grow(&mut self.counts, COUNTS, clusters * 4, NONE);
        grow(&mut self.ranges, RANGES, clusters * 8, COPY_SRC);
        grow(&mut self.unsorted, UNSORTED, capacity * 4, NONE);
        grow(&mut self.owner, OWNER, capacity * 4, NONE);
        grow(&mut self.indices, INDICES, capacity * 4, COPY_SRC);
        grown
    }
}

fn group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    b: &Buffers,
    view: &LightView,
) -> wgpu::BindGroup {
    let (records, _, view_summary) = view.cluster_inputs();
    let all = [
        &b.params,
        &b.edges,
        records,
        &b.bounds,
        &b.counts,
        &b.ranges,
        &b.unsorted,
        &b.owner,
        &b.indices,
        &b.summary,
        view_summary,
    ];
    bindings::buffers_group(device, "light clusters group 0", layout, &all)
}

impl GpuClusters {
    pub fn new(ctx: &GpuContext, view: &LightView) -> Result<GpuClusters, GpuError> {
        ctx.scoped("light clusters", |device| {
            let mut entries = vec![
                bindings::uniform_entry(0, COMPUTE),
                bindings::storage_entry(1, COMPUTE),
                bindings::storage_entry(2, COMPUTE),
            ];
            entries.extend((3..10).map(|i| bindings::storage_rw_entry(i, COMPUTE)));
            entries.push(bindings::storage_entry(10, COMPUTE));
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("light clusters group 0"),
                entries: &entries,
            });
            let pipelines = crate::gpu::compute_module::compute_pipelines(
                device,
                ctx.pipeline_cache.as_ref(),
                "light clusters",
                SHADER,
                &layout,
                ENTRY_POINTS,
            );
            let buffers = Buffers::new(device);
            let group = group(device, &layout, &buffers, view);
            GpuClusters {
                layout,
                pipelines,
                buffers,
                group,
                view_generation: view.generation(),
                plan: None,
                wanted: 0,
                feedback: CapacityFeedback::new(device),
            }
        })
    }

    /// The lists the lighting passes read: (offset, count) per cluster, and the
    /// global lights followed by every cluster's lights.
    pub fn lists(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.buffers.ranges, &self.buffers.indices)
    }

    /// Reserves room for `entries` cluster entries from the next frame on
    /// (the footprints' clusters, read back when the lights or the grid
    /// changed).
    pub fn reserve(&mut self, entries: u64) {
        self.wanted = self.wanted.max(entries);
    }

    /// Uploads one frame's grid. Returns whether the list buffers were
    /// replaced (the lighting passes' bind group must then be rebuilt) and the
    /// bytes reserved for the lists.
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        frame: &ClusterFrame<'_>,
    ) -> Result<(bool, u64), ClusterError> {
        let ClusterFrame {
            grid,
            proj,
            width,
            height,
            globals,
            view,
        } = *frame;
        let locals = view.locals();
        if locals as usize > MAX_CLUSTER_LIGHTS {
            return Err(ClusterError::TooManyLights(locals as usize));
        }
        if let Some(footprints) = self.feedback.poll(&ctx.device) {
            // room to spare, so that a moving camera seldom outgrows it
            self.wanted = self.wanted.max(u64::from(footprints) * 5 / 4);
        }
        // every light in every cluster fits: the fallback of a frame that
        // outgrows the reservation
        let least = (globals.len() + locals as usize + 1) as u64;
        let wanted = (self.wanted + globals.len() as u64).min(MAX_ENTRIES as u64);
        let GridEdges { ax, ay, depth } = grid.edges(proj, width, height);
        let mut edges = ax;
        edges.extend_from_slice(&ay);
        edges.extend_from_slice(&depth);
        let clusters = grid.count() as u32;
        let mut grown = self.buffers.ensure(
            &ctx.device,
            u64::from(clusters),
            edges.len() as u64,
            wanted.max(least),
        );
        if grown || self.view_generation != view.generation() {
            self.group = group(&ctx.device, &self.layout, &self.buffers, view);
            self.view_generation = view.generation();
            grown = true;
        }
        let capacity = (self.buffers.unsorted.size() / 4).min(u64::from(u32::MAX)) as u32;
        let params = GpuClusterParams {
            grid: [grid.tiles_x, grid.tiles_y, grid.slices, clusters],
            counts: [locals, globals.len() as u32, capacity, 0],
        };
        let b = &self.buffers;
        let q = &ctx.queue;
        q.write_buffer(&b.params, 0, bytemuck::bytes_of(&params));
        q.write_buffer(&b.edges, 0, bytemuck::cast_slice(&edges));
        if !globals.is_empty() {
            q.write_buffer(&b.unsorted, 0, bytemuck::cast_slice(globals));
        }
        self.plan = Some(Plan {
            clusters,
            locals,
            globals: globals.len() as u32,
            capacity,
        });
        let reserved = u64::from(clusters) * 8 + u64::from(capacity) * 4;
        Ok((grown, reserved))
    }

    /// Encodes the five dispatches of the frame last prepared: two compute
    /// passes, named "light clusters" and "light clusters sort" in `names` and
    /// timed with `timer`, with the copy of the sort's dispatch size between.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        names: &mut Vec<String>,
        (view, timer): (&LightView, Option<&GpuTimer>),
    ) {
        let Some(plan) = self.plan else {
            return;
        };
        view.encode(encoder, names, timer);
        self.feedback.encode(encoder, view.summary_buffer());
        self.encode_lists(encoder, names, (view, timer), plan);
        let b = &self.buffers;
        encoder.copy_buffer_to_buffer(&b.summary, 0, &b.indirect, 0, 12);
        let index = names.len() as u32;
        names.push("light clusters sort".into());
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("light clusters sort"),
            timestamp_writes: timer.and_then(|t| t.compute_pass_writes(index)),
        });
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_pipeline(&self.pipelines[4]);
        pass.dispatch_workgroups_indirect(&b.indirect, 0);
    }

    /// The boxes, the counts, the ranges and the unsorted lists.
    fn encode_lists(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        names: &mut Vec<String>,
        (view, timer): (&LightView, Option<&GpuTimer>),
        plan: Plan,
    ) {
        let index = names.len() as u32;
        names.push("light clusters".into());
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("light clusters"),
            timestamp_writes: timer.and_then(|t| t.compute_pass_writes(index)),
        });
        pass.set_bind_group(0, &self.group, &[]);
        let [bounds, count, offsets, fill, _] = &self.pipelines;
        let (x, y) = dispatch_2d(plan.clusters);
        pass.set_pipeline(bounds);
        pass.dispatch_workgroups(x, y, 1);
        // one workgroup per chunk of a light's footprint (as many as the
        // light view pass numbered)
        let (_, chunks, _) = view.cluster_inputs();
        if plan.locals > 0 {
            pass.set_pipeline(count);
            pass.dispatch_workgroups_indirect(chunks, 0);
        }
        pass.set_pipeline(offsets);
        pass.dispatch_workgroups(1, 1, 1);
        if plan.locals > 0 {
            pass.set_pipeline(fill);
            pass.dispatch_workgroups_indirect(chunks, 0);
        }
    }

    /// Maps the background readback of the frame just submitted.
    pub fn after_submit(&mut self) {
        self.feedback.after_submit();
    }

    /// The entry count and the longest list of the frame last rendered (waits
    /// for the GPU).
    pub fn summary(&self, ctx: &GpuContext) -> Result<ClusterSummary, GpuError> {
        let bytes = ctx.read_buffer(&self.buffers.summary, 12, 12)?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        Ok(ClusterSummary {
            entries: words[0],
            max_per_cluster: words[1],
            overflowed: words[2] != 0,
        })
    }

    /// The lists of the frame last rendered, read back as the CPU reference
    /// lays them out (waits for the GPU; tests).
    #[cfg(test)]
    pub fn read_lists(
        &self,
        ctx: &GpuContext,
        grid: ClusterGrid,
    ) -> Result<ClusterLists, GpuError> {
        let plan = self.plan.unwrap_or_default();
        let summary = self.summary(ctx)?;
        let ranges = ctx.read_buffer(&self.buffers.ranges, 0, u64::from(plan.clusters) * 8)?;
        let listed = if summary.overflowed {
            plan.locals
        } else {
            summary.entries
        };
        let entries = (plan.globals + listed).min(plan.capacity);
        let indices = ctx.read_buffer(&self.buffers.indices, 0, u64::from(entries) * 4)?;
        Ok(ClusterLists {
            grid,
            globals: plan.globals,
            ranges: bytemuck::cast_slice(&ranges).to_vec(),
            indices: bytemuck::cast_slice(&indices).to_vec(),
            max_per_cluster: summary.max_per_cluster,
        })
    }
}

#[cfg(test)]
#[path = "cluster_gpu_tests.rs"]
mod tests;
