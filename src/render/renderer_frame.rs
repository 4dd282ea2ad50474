//! The steps of one frame, in the order [`Renderer::render_frame`] runs them:
//! the frame's cameras, the light lists and shadow maps, the uploads (cluster
//! lists, light buffers, frame uniforms), the pipelines, the recording, and
//! the statistics and images handed back. (Methods of [`Renderer`]; the
//! renderer itself does not import this file.)

use super::clusters::ClusterGrid;
use super::error::RenderError;
use super::frame::{self, FrameGpu, FramePipelines};
use super::frame_motion::{jittered, FrameMotion};
use super::gpu_types::{mat_array, GpuFrame};
use super::light_compute::ComputeLighting;
use super::lights::{FrameLists, LightLists};
use super::motion::MotionCameras;
use super::output::{GBufferTextures, RenderOutput, RenderStats};
use super::pipelines::Pipelines;
use super::renderer::Renderer;
use super::shadow_cache::CasterChange;
use super::shadows::ShadowFrame;
use super::targets::{Targets, GBUFFER_BYTES_COMPRESSED};
use super::technique::Technique;
use super::upload::Batch;
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
use crate::scene::{Aabb, Camera};
use glam::{Mat4, Vec3};
use std::collections::HashSet;
use std::time::Instant;

/// What a frame is asked for, and the cameras derived from it.
pub(super) struct FrameView<'a> {
    pub camera: &'a Camera,
    pub width: u32,
    pub height: u32,
    technique: Technique,
    pub aspect: f32,
    pub view: Mat4,
    /// The projection without the jitter (motion vectors, `proj_unjittered`).
    unjittered: Mat4,
    /// The projection the geometry passes use (jittered).
    pub proj: Mat4,
    /// The camera one frame earlier (this one after a cut).
    prev_camera: Camera,
    motion: MotionCameras,
}

impl<'a> FrameView<'a> {
    /// What the shadow planning needs of this frame: the camera, the lights'
    /// world positions and directions `world`, the casters' `bounds` and the
    /// renderer's shadow options.
    pub fn shadow_frame<'b>(
        &self,
        opts: &super::RendererOptions,
        world: &'b [(glam::Vec3, glam::Vec3)],
        bounds: Aabb,
    ) -> ShadowFrame<'b>
    where
        'a: 'b,
    {
        ShadowFrame {
            camera: self.camera,
            world,
            view: self.view,
            aspect: self.aspect,
            bounds,
            mode: opts.shadows,
            size: opts.shadow_size,
            budget: opts.shadow_budget,
            stable: opts.stable_cascades,
        }
    }
}

/// The frame's lights: the lists, their ranges in the visible-index buffer and
/// the cluster grid (none with light volumes). With cluster lists the light
/// array and the culling are the GPU's (`renderer_lights.rs`): `lists` holds
/// only the global lights, the ambient sum and the dark count.
pub(super) struct FrameLights {
    pub lists: LightLists,
    pub ranges: FrameLists,
    pub visible: Vec<u32>,
    pub grid: Option<ClusterGrid>,
    /// Lights in the frustum (before the forward loop's padding), when
    /// counted on the CPU (light volumes).
    pub visible_count: Option<u32>,
    /// The shadow-map array was replaced (group 0 binds it).
    pub shadows_grown: bool,
}

/// The renderer's parts the passes read, beside the pipeline caches they fill
/// (borrowed apart, so the caches can grow while the rest is read).
struct FrameParts<'a> {
    gpu: FrameGpu<'a>,
    pipelines: &'a mut Pipelines,
    light_compute: &'a mut ComputeLighting,
    ensured: &'a mut HashSet<(Technique, u32)>,
    targets: Option<&'a Targets>,
}

/// The CPU time of a frame's steps ([`RenderStats::cpu_split`]).
struct CpuSplit {
    last: Instant,
    parts: Vec<(String, f64)>,
}

impl CpuSplit {
    fn new() -> CpuSplit {
        CpuSplit {
            last: Instant::now(),
            parts: Vec::with_capacity(5),
        }
    }

    /// Removes step `name` from the split, and gives its time.
    fn take(&mut self, name: &str) -> f64 {
        let ms = self
            .parts
            .iter()
            .filter(|(n, _)| n == name)
            .map(|p| p.1)
            .sum();
        self.parts.retain(|(n, _)| n != name);
        ms
    }

    /// Ends step `name` (its time is added when it ran before).
    fn mark(&mut self, name: &str) {
        let now = Instant::now();
        let ms = (now - self.last).as_secs_f64() * 1e3;
        self.last = now;
        match self.parts.iter_mut().find(|(n, _)| n == name) {
            Some(p) => p.1 += ms,
            None => self.parts.push((name.to_string(), ms)),
        }
    }
}

/// A camera the projection can be built from: 0 < near < far and 0 < fov < 180°.
fn check_camera(camera: &Camera) -> Result<(), RenderError> {
    if !(camera.near > 0.0
        && camera.far > camera.near
        && camera.fov_y > 0.0
        && camera.fov_y < std::f32::consts::PI)
    {
        return Err(RenderError::Invalid(format!(
            "invalid camera ({camera}): need 0 < near < far and 0 < fov < 180°"
        )));
    }
    Ok(())
}

/// The first error the device reported while the frame was recorded, as the
/// frame's error.
fn check_device_errors(ctx: &GpuContext, label: String) -> Result<(), RenderError> {
    let errors = ctx.take_uncaptured_errors();
    if let Some(first) = errors.first() {
        return Err(RenderError::Gpu(GpuError::Validation {
            what: label,
            message: first.clone(),
        }));
    }
    Ok(())
}

impl Renderer {
    /// Renders one frame of a sequence: the instances where `motion` puts them,
    /// `AUX.motion` from where they and the camera were one frame earlier, the
    /// projection jittered by `motion.jitter`.
    ///
    /// With a `timer` (see [`GpuTimer::new`]; 16 passes are enough) the GPU time of
    /// every pass is measured and returned in [`RenderStats::pass_ms`].
    #[allow(clippy::too_many_arguments)]
    pub fn render_frame(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        motion: &FrameMotion,
        width: u32,
        height: u32,
        technique: Technique,
        timer: Option<&GpuTimer>,
    ) -> Result<(RenderOutput, RenderStats), RenderError> {
        let start = Instant::now();
        check_camera(camera)?;
        self.ensure_targets(ctx, width, height)?;
        let mut split = CpuSplit::new();
        let (bounds, moving) = self.pose(ctx, motion)?;
        let casters = self.caster_change(motion);
        split.mark("pose");
        let fv = self.frame_view(camera, motion, (width, height), technique);
        let fl = self.plan_lights(ctx, &fv, bounds, &casters)?;
        split.mark("lights");
        let cluster_bytes = self.upload_lights(ctx, &fv, &fl)?;
        self.write_frame_uniforms(ctx, &fv, &fl);
        split.mark("upload");
        self.ensure_frame_pipelines(ctx, technique, fl.ranges.forward_lights)?;
        split.mark("pipelines");
        let mut stats = self.frame_stats(&fv, &fl, cluster_bytes);
        let label = format!("deferred frame ({technique}, {width}x{height})");
        let (pass_names, draws) = self.record_frame(ctx, (&fv, &fl), &label, timer, &moving)?;
        self.clusters.after_submit();
        split.mark("record");
        stats.draw_calls = draws;
        stats.pipeline_ms = split.take("pipelines");
        stats.cpu_ms = start.elapsed().as_secs_f64() * 1e3 - stats.pipeline_ms;
        stats.cpu_split = split.parts;
        stats.pipelines = self.pipelines.pipelines_created;
        stats.shader_modules = self.pipelines.modules_created;
        self.read_gpu_stats(ctx, (timer, fl.grid.is_some()), pass_names, &mut stats)?;
        if timer.is_some() && fl.visible_count.is_none() {
            stats.lights_visible = self.read_visible_lights(ctx)?.unwrap_or(0);
        }
        check_device_errors(ctx, label)?;
        log::debug!(
            "{}: {technique} frame {width}x{height}: {} lights visible of {}, {} draws, cpu {:.2} ms",
            self.name,
            stats.lights_visible,
            stats.lights_total,
            stats.draw_calls,
            stats.cpu_ms
        );
        Ok((self.frame_output(&fv), stats))
    }

    /// The view, the jittered and unjittered projections, and the cameras of
    /// the motion vectors (the previous one is this one after a cut).
    fn frame_view<'a>(
        &self,
        camera: &'a Camera,
        motion: &FrameMotion,
        (width, height): (u32, u32),
        technique: Technique,
    ) -> FrameView<'a> {
        let aspect = width as f32 / height as f32;
        let view = camera.view();
        let unjittered = camera.proj(aspect);
        let proj = jittered(unjittered, motion.jitter, width, height);
        let prev_camera = motion
            .prev_camera
            .filter(|_| !motion.cut)
            .unwrap_or(*camera);
        let motion = MotionCameras {
            view,
            proj,
            curr_vp: unjittered * view,
            prev_vp: prev_camera.proj(aspect) * prev_camera.view(),
        };
        FrameView {
            camera,
            width,
            height,
            technique,
            aspect,
            view,
            unjittered,
            proj,
            prev_camera,
            motion,
        }
    }

    /// Culls and classifies the lights, gives shadow-map layers to those that
    /// get them (written into their GPU lights) and lays out the frame's light
    /// ranges and cluster grid over the geometry's depth range.
    fn plan_lights(
        &mut self,
        ctx: &GpuContext,
        fv: &FrameView<'_>,
        bounds: Aabb,
        casters: &CasterChange,
    ) -> Result<FrameLights, RenderError> {
        if self.opts.light_culling != super::clusters::LightCulling::Volumes {
            return self.plan_world_lights(ctx, fv, bounds, casters);
        }
        let camera = fv.camera;
        let mut lists = LightLists::classify(
            &self.lights,
            self.volumes.sphere_scale,
            self.volumes.cone_poly_scale,
            camera,
            &fv.view,
            &fv.proj,
            fv.aspect,
        );
        // Shadow maps: which lights get layers (written into their GpuLight).
        let shadows_grown = self.shadow_maps.prepare(
            ctx,
            &self.name,
            &mut lists.gpu,
            (&fv.shadow_frame(&self.opts, &lists.world, bounds), casters),
        )?;
        let visible_count = lists.forward.len() as u32;
        let (depth_near, depth_far) =
            super::clusters::depth_range(&bounds, &fv.view, camera.near, camera.far);
        let (ranges, visible, grid) = lists.frame_lists(
            self.opts.light_culling,
            fv.width,
            fv.height,
            depth_near,
            depth_far,
        );
        Ok(FrameLights {
            lists,
            ranges,
            visible,
            grid,
            visible_count: Some(visible_count),
            shadows_grown,
        })
    }

    /// Builds the cluster lists on the GPU (when there is a grid) and uploads
    /// the lights; group 0 again when a buffer it binds was replaced. Returns
    /// the cluster lists' size in bytes.
    fn upload_lights(
        &mut self,
        ctx: &GpuContext,
        fv: &FrameView<'_>,
        fl: &FrameLights,
    ) -> Result<u64, RenderError> {
        let (clusters_grown, cluster_bytes) = match fl.grid {
            Some(grid) => self.prepare_clusters(ctx, fv, fl, grid)?,
            None => (false, 0),
        };
        let grown = self.light_buffers.upload(ctx, &fl.lists.gpu, &fl.visible);
        if grown || fl.shadows_grown || clusters_grown {
            self.rebuild_group0(ctx);
        }
        Ok(cluster_bytes)
    }

    /// The frame's background (through the fog), its uniforms and the
    /// environment's, written to the GPU.
    fn write_frame_uniforms(&mut self, ctx: &GpuContext, fv: &FrameView<'_>, fl: &FrameLights) {
        let (camera, view) = (fv.camera, fv.view);
        let (cluster, cluster_z, global_lights) = match fl.grid {
            Some(g) => (
                [g.tiles_x, g.tiles_y, g.slices, g.tile_px],
                [g.log_scale, g.near, 0.0, 0.0],
                fl.lists.globals.len() as u32,
            ),
            None => ([0; 4], [0.0; 4], 0),
        };
        self.frame_background = match &self.fog {
            Some(f) => f.background(self.background, camera.far),
            None => self.background,
        };
        let gpu_frame = GpuFrame {
            view: mat_array(view),
            proj: mat_array(fv.proj),
            inv_proj: mat_array(fv.proj.inverse()),
            proj_unjittered: mat_array(fv.unjittered),
            // a camera that did not move reprojects exactly (motion 0, not noise)
            reproject: mat_array(if fv.prev_camera == *camera {
                fv.unjittered
            } else {
                fv.motion.prev_vp * view.inverse()
            }),
            viewport: [
                fv.width as f32,
                fv.height as f32,
                1.0 / fv.width as f32,
                1.0 / fv.height as f32,
            ],
            background: self.frame_background.extend(1.0).into(),
            ambient: fl.lists.ambient.extend(0.0).into(),
            near: camera.near,
            far: camera.far,
            light_count: fl.visible_count.unwrap_or(0),
            global_lights,
            cluster,
            cluster_z,
            fog: super::fog::Fog::gpu(self.fog.as_ref(), camera, &view),
        };
        ctx.queue
            .write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&gpu_frame));
        let background_fog = self.fog.as_ref().map_or((Vec3::ZERO, 1.0), |f| {
            (f.color, f.transmittance(camera.far))
        });
        self.environment.write_frame(ctx, &view, background_fog);
    }

    /// The renderer's parts the passes read, borrowed apart from the pipeline
    /// caches.
    fn frame_parts(&mut self) -> FrameParts<'_> {
        FrameParts {
            gpu: FrameGpu {
                opts: &self.opts,
                aux_formats: &self.aux_formats,
                materials: &self.materials,
                geometry: &self.geometry,
                material_gpu: &self.material_gpu,
                layouts: &self.layouts,
                environment: &self.environment,
                g0: &self.g0,
                shadow_maps: &self.shadow_maps,
                clusters: &self.clusters,
                light_view: &self.light_view,
                volumes: &self.volumes,
                motion: &self.motion,
                visibility: self.visibility.as_ref(),
                frame_background: self.frame_background,
            },
            pipelines: &mut self.pipelines,
            light_compute: &mut self.light_compute,
            ensured: &mut self.ensured,
            targets: self.targets.as_ref(),
        }
    }

    /// Creates the pipelines of `technique` with a forward loop of `loop_count`
    /// lights, once: they depend only on these (the batches are fixed when the
    /// renderer is made).
    fn ensure_frame_pipelines(
        &mut self,
        ctx: &GpuContext,
        technique: Technique,
        loop_count: u32,
    ) -> Result<(), RenderError> {
        let parts = self.frame_parts();
        if !parts.ensured.contains(&(technique, loop_count)) {
            let pipelines = (parts.pipelines, parts.light_compute);
            frame::ensure_pipelines(&parts.gpu, pipelines, ctx, technique, loop_count)
                .map_err(RenderError::Material)?;
            parts.ensured.insert((technique, loop_count));
        }
        Ok(())
    }

    /// The frame's statistics known before it is recorded: sizes, light
    /// counts, cluster and shadow-map memory.
    fn frame_stats(&self, fv: &FrameView<'_>, fl: &FrameLights, cluster_bytes: u64) -> RenderStats {
        let (technique, lists) = (fv.technique, &fl.lists);
        RenderStats {
            technique,
            width: fv.width,
            height: fv.height,
            triangles: self.triangles,
            lights_total: self.lights.len(),
            // with cluster lists: the global lights until the GPU's count is
            // read back (timed frames, `Renderer::read_visible_lights`)
            lights_visible: match fl.visible_count {
                Some(n) => n as usize,
                None => lists.globals.len(),
            },
            lights_fullscreen: lists.fullscreen.len(),
            volumes_outside: lists.sphere_out.len() + lists.cone_out.len(),
            volumes_inside: lists.sphere_in.len() + lists.cone_in.len(),
            lights_dark: lists.dark,
            light_culling: self.opts.light_culling,
            cluster_bytes,
            gbuffer_bytes_per_pixel: match technique {
                Technique::Deferred => GBUFFER_BYTES_COMPRESSED,
                Technique::LightPrepass => 13,
                // depth for shading + the three colour targets for the AUX images
                Technique::Forward => GBUFFER_BYTES_COMPRESSED,
            },
            shadow_layers: self.shadow_maps.used as usize,
            shadow_layers_rendered: self.shadow_maps.rendered() as usize,
            shadow_map_bytes: self.shadow_maps.bytes(),
            ..Default::default()
        }
    }

    /// Encodes and submits the frame's passes (`frame.rs`). Returns the timed
    /// pass names and the draw count.
    fn record_frame(
        &mut self,
        ctx: &GpuContext,
        (fv, fl): (&FrameView<'_>, &FrameLights),
        label: &str,
        timer: Option<&GpuTimer>,
        moving: &[Batch],
    ) -> Result<(Vec<String>, usize), RenderError> {
        let parts = self.frame_parts();
        let pipelines = FramePipelines {
            pipelines: parts.pipelines,
            light_compute: parts.light_compute,
        };
        let targets = parts.targets.expect("targets were just created");
        frame::encode(
            (&parts.gpu, &pipelines, targets),
            ctx,
            label,
            fv.technique,
            &fl.ranges,
            &fv.view,
            timer,
            (&fv.motion, moving),
        )
    }

    /// With a timer: the cluster lists' entries (when there were lists) and
    /// the GPU time of every pass, read back into `stats`.
    fn read_gpu_stats(
        &self,
        ctx: &GpuContext,
        (timer, clustered): (Option<&GpuTimer>, bool),
        pass_names: Vec<String>,
        stats: &mut RenderStats,
    ) -> Result<(), RenderError> {
        let Some(timer) = timer else {
            return Ok(());
        };
        if clustered {
            let summary = self.clusters.summary(ctx)?;
            stats.cluster_entries = summary.entries as usize;
            stats.cluster_max = summary.max_per_cluster as usize;
        }
        let ms = timer.read_ms(ctx, pass_names.len() as u32)?;
        log::debug!(
            "{}: frame GPU passes: {}",
            self.name,
            pass_names
                .iter()
                .zip(&ms)
                .map(|(n, t)| format!("{n}={t:.3}"))
                .collect::<Vec<_>>()
                .join("; ")
        );
        stats.gpu_ms = Some(ms.iter().sum());
        stats.pass_ms = pass_names.into_iter().zip(ms).collect();
        Ok(())
    }

    /// The frame's images: the HDR scene, the AUX images, the camera and the
    /// G-buffer textures.
    fn frame_output(&self, fv: &FrameView<'_>) -> RenderOutput {
        let t = self.targets.as_ref().expect("targets were just created");
        RenderOutput {
            width: fv.width,
            height: fv.height,
            scene: t.scene.texture.clone(),
            aux: t
                .aux
                .iter()
                .map(|(n, tex)| (n.clone(), tex.texture.clone()))
                .collect(),
            camera: super::camera_std(fv.camera, &fv.proj),
            gbuffer: GBufferTextures {
                depth: t.depth.texture.clone(),
                albedo: t.albedo.texture.clone(),
                normal: t.normal.texture.clone(),
                specular: t.specular.texture.clone(),
                light_diffuse: t.light_diffuse.texture.clone(),
                light_specular: t.light_specular.texture.clone(),
            },
        }
    }
}
