//! The lights of a clustered (or unculled) frame moved into view space on the
//! GPU (`shaders/render/light_view.wgsl`), so that a frame's CPU work does not
//! grow with the light count: the world-space lights ([`WorldLights`]) are
//! uploaded when they change, and each frame writes only the view, the frustum
//! planes and the grid (a few hundred bytes). One compute pass ("light view")
//! then writes the view-space light array the shaders read, culls every point
//! and spot light's sphere against the frustum, computes the tiles and slices
//! it may touch (its cluster record, read by `cluster_gpu.rs`) and numbers the
//! chunks of the cluster count and fill dispatches, whose sizes it leaves in an
//! indirect buffer. The visible-light count and the footprints' clusters stay
//! on the GPU unless asked for ([`LightView::summary`]).

use super::clusters::ClusterGrid;
use super::gpu_types::GpuLight;
use super::world_lights::{GpuWorldLocal, WorldLights};
use crate::gpu::bindings;
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
use bytemuck::{Pod, Zeroable};
use glam::Mat4;

const SHADER: &str = include_str!("../../shaders/render/light_view.wgsl");
const COMPUTE: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;
const WORKGROUP: u32 = 64;
const ROW: u32 = 32768;

/// `Params` of light_view.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuViewParams {
    view: [f32; 16],
    planes: [[f32; 4]; 6],
    proj: [f32; 4],
    size: [f32; 4],
    grid: [u32; 4],
    counts: [u32; 4],
    scale: [f32; 4],
}

/// `ClusterLight` of clusters.wgsl and light_view.wgsl (written by the GPU;
/// the host only sizes its buffer).
#[allow(dead_code)]
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub(crate) struct GpuClusterLight {
    center: [f32; 3],
    radius: f32,
    index: u32,
    tiles_x: u32,
    tiles_y: u32,
    slices: u32,
    /// The light's first chunk (the chunks of the lights before it come first).
    first: u32,
    _pad: [u32; 3],
}

/// One frame's camera and grid.
pub(crate) struct ViewFrame<'a> {
    pub grid: ClusterGrid,
    pub view: &'a Mat4,
    pub proj: &'a Mat4,
    pub width: u32,
    pub height: u32,
}

/// What the GPU counted, read back ([`LightView::summary`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct ViewSummary {
    /// Point and spot lights inside the frustum.
    pub visible: u32,
    /// Clusters of their footprints: a bound on the cluster entries.
    pub footprint_clusters: u32,
}

/// The buffers of the pass.
struct Buffers {
    params: wgpu::Buffer,
    world: wgpu::Buffer,
    locals: wgpu::Buffer,
    lights: wgpu::Buffer,
    records: wgpu::Buffer,
    summary: wgpu::Buffer,
    /// The count and fill dispatches' sizes, copied from `summary` after the
    /// pass (it is bound as storage there).
    indirect: wgpu::Buffer,
}

const WORLD: &str = "light view world lights";
const LOCALS: &str = "light view culling spheres";
const LIGHTS: &str = "deferred lights (view space)";
const RECORDS: &str = "light clusters lights";

fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

impl Buffers {
    fn new(device: &wgpu::Device) -> Buffers {
        Buffers {
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light view parameters"),
                size: std::mem::size_of::<GpuViewParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            world: storage(device, WORLD, 1 << 12),
            locals: storage(device, LOCALS, 1 << 12),
            lights: storage(device, LIGHTS, 1 << 12),
            records: storage(device, RECORDS, 1 << 12),
            summary: storage(device, "light view summary", 32),
            indirect: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light clusters count dispatch"),
                size: 16,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        }
    }

    /// Grows the light buffers to `lights` lights and `locals` point and spot
    /// lights. Returns whether one was replaced.
    fn ensure(&mut self, device: &wgpu::Device, lights: u64, locals: u64) -> bool {
        let mut grown = false;
        let mut grow = |buffer: &mut wgpu::Buffer, label: &str, bytes: u64| {
            if bytes > buffer.size() {
                *buffer = storage(device, label, bytes.next_power_of_two());
                grown = true;
            }
        };
        let light = std::mem::size_of::<GpuLight>() as u64;
        grow(&mut self.world, WORLD, lights * light);
        grow(&mut self.lights, LIGHTS, lights * light);
        let local = std::mem::size_of::<GpuWorldLocal>() as u64;
        grow(&mut self.locals, LOCALS, locals * local);
        let record = std::mem::size_of::<GpuClusterLight>() as u64;
        grow(&mut self.records, RECORDS, locals * record);
        grown
    }
}

fn group(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, b: &Buffers) -> wgpu::BindGroup {
    let all = [
        &b.params, &b.world, &b.locals, &b.lights, &b.records, &b.summary,
    ];
    bindings::buffers_group(device, "light view group 0", layout, &all)
}

/// A 2D dispatch of `n` invocations (rows of [`ROW`] workgroups of
/// [`WORKGROUP`], as light_view.wgsl and clusters.wgsl number them).
pub(crate) fn dispatch_2d(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(WORKGROUP);
    (groups.min(ROW), groups.div_ceil(ROW).max(1))
}

/// The GPU view transform and culling of a renderer's lights.
pub(crate) struct LightView {
    layout: wgpu::BindGroupLayout,
    pipelines: [wgpu::ComputePipeline; 3],
    buffers: Buffers,
    group: wgpu::BindGroup,
    /// Lights and point and spot lights uploaded.
    counts: (u32, u32),
    /// Uploads of the world-space lights so far (tests: a moving camera
    /// uploads none).
    uploads: u64,
    /// Bumped when a buffer that other groups bind is replaced.
    generation: u64,
}

const ENTRY_POINTS: [&str; 3] = [
    "fx_cs_light_view",
    "fx_cs_light_records",
    "fx_cs_light_scan",
];

impl LightView {
    pub fn new(ctx: &GpuContext) -> Result<LightView, GpuError> {
        ctx.scoped("light view", |device| {
            let mut entries = vec![
                bindings::uniform_entry(0, COMPUTE),
                bindings::storage_entry(1, COMPUTE),
                bindings::storage_entry(2, COMPUTE),
            ];
            entries.extend((3..6).map(|i| bindings::storage_rw_entry(i, COMPUTE)));
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("light view group 0"),
                entries: &entries,
            });
            let pipelines = crate::gpu::compute_module::compute_pipelines(
                device,
                ctx.pipeline_cache.as_ref(),
                "light view",
                SHADER,
                &layout,
                ENTRY_POINTS,
            );
            let buffers = Buffers::new(device);
            let group = group(device, &layout, &buffers);
            LightView {
                layout,
                pipelines,
                buffers,
                group,
                counts: (0, 0),
                uploads: 0,
                generation: 0,
            }
        })
    }

    /// Uploads the world-space lights (when they changed: not per frame).
    pub fn set_lights(&mut self, ctx: &GpuContext, lights: &WorldLights) {
        let (n, locals) = (lights.gpu.len() as u32, lights.locals.len() as u32);
        if self
            .buffers
            .ensure(&ctx.device, u64::from(n), u64::from(locals))
        {
            self.group = group(&ctx.device, &self.layout, &self.buffers);
            self.generation += 1;
        }
        let q = &ctx.queue;
        q.write_buffer(&self.buffers.world, 0, bytemuck::cast_slice(&lights.gpu));
        if locals > 0 {
            q.write_buffer(
                &self.buffers.locals,
                0,
                bytemuck::cast_slice(&lights.locals),
            );
        }
        self.counts = (n, locals);
        self.uploads += 1;
    }

    /// Rewrites the world-space lights `indices` (their shadow layers changed).
    pub fn update_lights(&self, ctx: &GpuContext, lights: &WorldLights, indices: &[u32]) {
        let size = std::mem::size_of::<GpuLight>();
        for &i in indices {
            let light = &lights.gpu[i as usize];
            let at = (i as usize * size) as u64;
            ctx.queue
                .write_buffer(&self.buffers.world, at, bytemuck::bytes_of(light));
        }
    }

    /// Writes one frame's view, frustum and grid.
    pub fn prepare(&self, ctx: &GpuContext, frame: &ViewFrame<'_>) {
        let ViewFrame {
            grid,
            view,
            proj,
            width,
            height,
        } = *frame;
        let planes = super::lights::frustum_planes(proj).map(|p| p.to_array());
        let params = GpuViewParams {
            view: view.to_cols_array(),
            planes,
            proj: [proj.x_axis.x, proj.z_axis.x, proj.y_axis.y, proj.z_axis.y],
            size: [width as f32, height as f32, grid.near, grid.far],
            grid: [grid.tiles_x, grid.tiles_y, grid.slices, grid.tile_px],
            counts: [
                self.counts.0,
                self.counts.1,
                u32::from(grid.count() == 1),
                0,
            ],
            scale: [grid.log_scale, 0.0, 0.0, 0.0],
        };
        ctx.queue
            .write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(&params));
    }

    /// Encodes the pass ("light view" in `names`, timed with `timer`) and the
    /// copy of the count and fill dispatches' sizes.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        names: &mut Vec<String>,
        timer: Option<&GpuTimer>,
    ) {
        let b = &self.buffers;
        encoder.clear_buffer(&b.summary, 0, None);
        let index = names.len() as u32;
        names.push("light view".into());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("light view"),
                timestamp_writes: timer.and_then(|t| t.compute_pass_writes(index)),
            });
            pass.set_bind_group(0, &self.group, &[]);
            let [view, records, scan] = &self.pipelines;
            let (x, y) = dispatch_2d(self.counts.0);
            pass.set_pipeline(view);
            pass.dispatch_workgroups(x, y, 1);
            let (x, y) = dispatch_2d(self.counts.1);
            pass.set_pipeline(records);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(scan);
            pass.dispatch_workgroups(1, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&b.summary, 0, &b.indirect, 0, 12);
    }

    /// The view-space light array the shaders read.
    pub fn lights(&self) -> &wgpu::Buffer {
        &self.buffers.lights
    }

    /// The cluster records (`ClusterLight` of clusters.wgsl), the count and
    /// fill dispatches' sizes, and the summary the cluster pass reads its
    /// chunk count from.
    pub fn cluster_inputs(&self) -> (&wgpu::Buffer, &wgpu::Buffer, &wgpu::Buffer) {
        (
            &self.buffers.records,
            &self.buffers.indirect,
            &self.buffers.summary,
        )
    }

    /// The summary's buffer (its visible count at byte 16, its footprint
    /// clusters at 20).
    pub fn summary_buffer(&self) -> &wgpu::Buffer {
        &self.buffers.summary
    }

    /// Point and spot lights uploaded.
    pub fn locals(&self) -> u32 {
        self.counts.1
    }

    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Uploads of the world-space lights so far.
    pub fn uploads(&self) -> u64 {
        self.uploads
    }

    /// The visible lights and footprint clusters of the frame last encoded
    /// (waits for the GPU).
    pub fn summary(&self, ctx: &GpuContext) -> Result<ViewSummary, GpuError> {
        let bytes = ctx.read_buffer(&self.buffers.summary, 16, 8)?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        Ok(ViewSummary {
            visible: words[0],
            footprint_clusters: words[1],
        })
    }
}
