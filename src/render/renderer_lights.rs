//! The lights of a clustered or unculled frame (methods of [`Renderer`], called
//! by `renderer_frame.rs`): the world-space lights uploaded when they change,
//! the shadow casters planned on the CPU (a few lights), and the GPU's light
//! view and cluster passes prepared with per-frame data of a fixed size, so
//! that a frame's CPU time does not grow with the light count. (The volumes
//! path classifies every light on the CPU: `lights.rs`.)

use super::cluster_gpu::{ClusterError, ClusterFrame};
use super::clusters::{ClusterGrid, LocalLight};
use super::error::RenderError;
use super::light_view_gpu::ViewFrame;
use super::lights::{frame_grid, frustum_planes, FrameLists, LightLists, VolumeScales};
use super::renderer::Renderer;
use super::renderer_frame::{FrameLights, FrameView};
use super::shadow_cache::CasterChange;
use super::world_lights::WorldLights;
use crate::gpu::context::GpuContext;
use crate::scene::Aabb;

impl Renderer {
    /// The world-space lights, built and uploaded after a change of the
    /// lights; the shadow casters in view planned and their layers written;
    /// the frame's grid over the geometry's depth range.
    pub(super) fn plan_world_lights(
        &mut self,
        ctx: &GpuContext,
        fv: &FrameView<'_>,
        bounds: Aabb,
        casters: &CasterChange,
    ) -> Result<FrameLights, RenderError> {
        let world = match self.world_lights.take() {
            Some(world) => world,
            None => {
                let scales = VolumeScales {
                    sphere: self.volumes.sphere_scale,
                    cone_poly: self.volumes.cone_poly_scale,
                };
                let world = WorldLights::new(&self.lights, scales);
                self.light_view.set_lights(ctx, &world);
                world
            }
        };
        let world = self.world_lights.insert(world);
        let mut in_view = world.casters_in_view(&fv.view, &frustum_planes(&fv.proj));
        let shadows_grown = self.shadow_maps.prepare(
            ctx,
            &self.name,
            &mut in_view.gpu,
            (
                &fv.shadow_frame(&self.opts, &in_view.world, bounds),
                casters,
            ),
        )?;
        let changed = world.apply_shadows(&in_view);
        self.light_view.update_lights(ctx, world, &changed);
        let camera = fv.camera;
        let (depth_near, depth_far) =
            super::clusters::depth_range(&bounds, &fv.view, camera.near, camera.far);
        let culling = self.opts.light_culling;
        let grid = frame_grid(culling, fv.width, fv.height, depth_near, depth_far);
        let lists = LightLists {
            ambient: world.ambient,
            globals: world.globals.clone(),
            dark: world.dark,
            ..Default::default()
        };
        let ranges = FrameLists {
            fullscreen: 0..0,
            sphere_out: 0..0,
            sphere_in: 0..0,
            cone_out: 0..0,
            cone_in: 0..0,
            forward_lights: 1,
            clustered: true,
        };
        Ok(FrameLights {
            lists,
            ranges,
            // the forward loop's one (unread) entry: the black light
            visible: vec![world.black()],
            grid,
            visible_count: None,
            shadows_grown,
        })
    }

    /// Writes the light view and cluster passes' per-frame data; reads the
    /// reservation of the lists back first when the lights or the grid
    /// changed. Returns whether the list buffers were replaced and their size
    /// in bytes.
    pub(super) fn prepare_clusters(
        &mut self,
        ctx: &GpuContext,
        fv: &FrameView<'_>,
        fl: &FrameLights,
        grid: ClusterGrid,
    ) -> Result<(bool, u64), RenderError> {
        let frame = ViewFrame {
            grid,
            view: &fv.view,
            proj: &fv.proj,
            width: fv.width,
            height: fv.height,
        };
        self.light_view.prepare(ctx, &frame);
        let key = (self.light_view.uploads(), grid.tiles_x, grid.tiles_y);
        if self.cluster_sizing != Some(key) {
            self.size_clusters(fv, grid);
            self.cluster_sizing = Some(key);
        }
        self.clusters
            .prepare(
                ctx,
                &ClusterFrame {
                    grid,
                    proj: &fv.proj,
                    width: fv.width,
                    height: fv.height,
                    globals: &fl.lists.globals,
                    view: &self.light_view,
                },
            )
            .map_err(|e| match e {
                ClusterError::Gpu(e) => RenderError::Gpu(e),
                e => RenderError::Invalid(e.to_string()),
            })
    }

    /// Reserves room for the entries this frame's footprints may hold,
    /// computed on the CPU as the light view pass computes them: once per
    /// change of the lights or the grid (the lights were just uploaded, also
    /// O(lights)), so that the first frame neither waits for the GPU nor
    /// outgrows its lists; later frames follow the GPU's sums
    /// (`cluster_capacity.rs`).
    fn size_clusters(&mut self, fv: &FrameView<'_>, grid: ClusterGrid) {
        let Some(world) = &self.world_lights else {
            return;
        };
        let planes = frustum_planes(&fv.proj);
        let footprints: u64 = world
            .locals
            .iter()
            .filter_map(|l| {
                let center = fv.view.transform_point3(glam::Vec3::from(l.center));
                let outside = planes
                    .iter()
                    .any(|p| p.truncate().dot(center) + p.w < -l.radius);
                let light = LocalLight {
                    index: l.index,
                    center,
                    radius: l.radius,
                };
                let f = (!outside).then(|| grid.footprint(&fv.proj, fv.width, fv.height, &light));
                f.flatten().map(|f| f.clusters() as u64)
            })
            .sum();
        self.clusters.reserve(footprints * 5 / 4);
    }

    /// The point and spot lights inside the frustum of the frame last
    /// rendered with cluster lists, counted on the GPU, plus the global
    /// lights (waits for the GPU). `None` with light volumes (their count is
    /// [`super::RenderStats::lights_visible`] of every frame).
    pub fn read_visible_lights(&self, ctx: &GpuContext) -> Result<Option<usize>, RenderError> {
        if self.opts.light_culling == super::clusters::LightCulling::Volumes {
            return Ok(None);
        }
        let globals = self.world_lights.as_ref().map_or(0, |w| w.globals.len());
        let summary = self.light_view.summary(ctx)?;
        Ok(Some(globals + summary.visible as usize))
    }

    /// Uploads of the world-space lights so far (a moving camera over still
    /// lights uploads none: tests).
    pub fn light_uploads(&self) -> u64 {
        self.light_view.uploads()
    }
}
