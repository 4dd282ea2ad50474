//! The renderer's environment settings: [`Renderer::set_environment`],
//! [`Renderer::set_background`] and what the prefiltering did. (Methods of
//! [`Renderer`]; the renderer itself does not import this file, nor does the
//! environment module.)

use super::environment::EnvironmentTexture;
use super::error::RenderError;
use super::renderer::Renderer;
use crate::gpu::context::GpuContext;

impl Renderer {
    /// Lights the scene with `env` from now on (`None`: punctual lights only),
    /// loading its map; the prefiltered maps are cached by (map content, size),
    /// so setting a map again costs its loading only.
    pub fn set_environment(
        &mut self,
        ctx: &GpuContext,
        env: Option<&crate::scene::Environment>,
    ) -> Result<(), RenderError> {
        let map = env.map(|e| e.load()).transpose()?;
        self.environment.set(ctx, env.zip(map.as_ref()))?;
        self.rebuild_group0(ctx);
        Ok(())
    }

    /// What pixels without geometry show (the scene's colour by default).
    /// [`Background::Environment`](crate::scene::Background) without an
    /// environment shows the colour.
    pub fn set_background(&mut self, background: crate::scene::Background) {
        if let crate::scene::Background::Color(c) = background {
            self.background = c;
        }
        self.environment.background = background;
    }

    /// Milliseconds the last environment set spent prefiltering (0: cached or
    /// none), and how many maps this renderer has prefiltered.
    pub fn environment_prefiltering(&self) -> (f64, usize) {
        (
            self.environment.last_prefilter_ms,
            self.environment.prefiltered,
        )
    }

    /// Reads back a prefiltered environment texture (tests, inspection): its
    /// side and RGBA f32 texels, rows top first.
    pub fn read_environment(
        &self,
        ctx: &GpuContext,
        which: EnvironmentTexture,
    ) -> Result<(u32, Vec<f32>), RenderError> {
        Ok(self.environment.read(ctx, which)?)
    }

    /// (levels, level-0 side) of the specular environment map, if any.
    pub fn environment_shape(&self) -> Option<(u32, u32)> {
        self.environment.specular_shape()
    }
}
