//! Still images in the viewer: one image, or a batch stepped through with the arrow
//! keys. Every image is a still of its own, as in a normal run: uploaded in the
//! format a normal run uses, planned for its size (again only when the size or a
//! format changes), recorded as frame 0 into the viewer's encoder with
//! `Prepared::record`.

use crate::app::{Effect, RunError};
use crate::gpu::executor::{Engine, ExecError, FrameInputs, Prepared};
use crate::gpu::transfer::{input_format, upload_image};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::io::{self, Image, IoError, LoadOptions};
use crate::script::types::Format;
use crate::view::present::{window_output, window_output_format};
use std::path::PathBuf;

/// An image on the GPU with its auxiliary images.
struct Loaded {
    image: Image,
    input: wgpu::Texture,
    input_format: Format,
    aux: Vec<(String, wgpu::Texture, Format)>,
}

/// The images of the run and the one shown.
pub struct Stills {
    items: Vec<PathBuf>,
    index: usize,
    aux: Vec<(String, PathBuf)>,
    load: LoadOptions,
    /// The output format: what the screenshot file (or `-o`) takes; `None`: what a
    /// file of the input's own type takes.
    output_format: Option<Format>,
    loaded: Option<Loaded>,
    prepared: Option<Prepared>,
    output: Option<wgpu::Texture>,
    /// What the plan was made for.
    planned: Option<InputDesc>,
}

/// Read and decode an image, refusing a size over the device's limit first.
fn load_image(path: &std::path::Path, max: u32, load: &LoadOptions) -> Result<Image, IoError> {
    let bytes = io::read_image_file(path)?;
    let (w, h) = io::image_dimensions(&bytes, path)?;
    if w.max(h) > max {
        return Err(IoError::Decode {
            path: path.to_path_buf(),
            message: format!(
                "the image is {w}x{h}, larger than the GPU's limit of {max} pixels per side"
            ),
        });
    }
    io::decode_image(&bytes, path, load)
}

impl Stills {
    pub fn new(
        items: Vec<PathBuf>,
        aux: Vec<(String, PathBuf)>,
        load: LoadOptions,
        output_format: Option<Format>,
    ) -> Self {
        Stills {
            items,
            index: 0,
            aux,
            load,
            output_format,
            loaded: None,
            prepared: None,
            output: None,
            planned: None,
        }
    }

    /// Load (again) the image shown: after a step, or when its file changed.
    pub fn load(&mut self, engine: &Engine) -> Result<(), RunError> {
        let max = engine.ctx.device.limits().max_texture_dimension_2d;
        let path = &self.items[self.index];
        let image = load_image(path, max, &self.load)?;
        let assume_linear = self.load.assume_linear;
        let (fmt, _) = input_format(&image, assume_linear);
        let input = upload_image(&engine.ctx, "viewer input", &image, fmt)?;
        let mut aux = Vec::new();
        for (name, p) in &self.aux {
            let a = load_image(p, max, &self.load)?;
            let f = input_format(&a, assume_linear).0;
            aux.push((
                name.clone(),
                upload_image(&engine.ctx, &format!("viewer aux {name}"), &a, f)?,
                f,
            ));
        }
        self.loaded = Some(Loaded {
            image,
            input,
            input_format: fmt,
            aux,
        });
        Ok(())
    }

    /// What the effect is planned for: the image's size and formats.
    fn desc(&self) -> Option<InputDesc> {
        let l = self.loaded.as_ref()?;
        let (format, colorspace) = input_format(&l.image, self.load.assume_linear);
        Some(InputDesc {
            width: l.image.width,
            height: l.image.height,
            format,
            colorspace,
            aux: l.aux.iter().map(|(n, _, f)| (n.clone(), *f)).collect(),
            // Each auxiliary image keeps its own size (a LUT, a background).
            aux_sizes: l
                .aux
                .iter()
                .map(|(n, t, _)| (n.clone(), (t.width(), t.height())))
                .collect(),
            viewport: None,
        })
    }

    /// The output format: the screenshot's or `-o`'s, else a file of the input's type.
    pub fn output_format(&self) -> Format {
        self.output_format.unwrap_or(match &self.loaded {
            Some(l) if l.input_format == Format::Rgba16f => Format::Rgba16f,
            _ if self.load.assume_linear => Format::Rgba8,
            _ => Format::Rgba8Srgb,
        })
    }

    /// Does the shown image need a plan other than the current one?
    pub fn needs_plan(&self) -> bool {
        let key = |d: &InputDesc| {
            let aux = (d.aux.clone(), d.aux_sizes.clone());
            (d.width, d.height, d.format, d.colorspace, aux)
        };
        self.prepared.is_none() || self.desc().map(|d| key(&d)) != self.planned.as_ref().map(key)
    }

    /// Plan `effect` for the image shown, as a normal run does (the pool policy of
    /// stills and streams).
    pub fn prepare(&mut self, engine: &mut Engine, effect: &mut Effect) -> Result<(), RunError> {
        let desc = self
            .desc()
            .ok_or_else(|| RunError::Other("no image loaded".into()))?;
        let opts = PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(self.output_format()),
        };
        let mut prepared = effect.prepare_with(engine, &desc, &opts)?;
        let inspect = self.prepared.as_ref().and_then(|p| p.inspected_pass());
        if inspect.is_some_and(|i| i < prepared.plan.passes.len()) {
            let _ = prepared.inspect(inspect);
        }
        prepared.set_gpu_timings(engine, true);
        let o = prepared.plan.output;
        let want = window_output_format(&engine.ctx, o.format);
        let reuse = self
            .output
            .as_ref()
            .is_some_and(|t| (t.width(), t.height(), t.format()) == (o.width, o.height, want));
        if !reuse {
            self.output = Some(window_output(&engine.ctx, o.width, o.height, o.format));
        }
        self.prepared = Some(prepared);
        self.planned = Some(desc);
        Ok(())
    }

    pub fn prepared(&mut self) -> Option<&mut Prepared> {
        self.prepared.as_mut()
    }

    pub fn prepared_ref(&self) -> Option<&Prepared> {
        self.prepared.as_ref()
    }

    /// Record the image's frame into `encoder`: frame 0, as a one-image run.
    pub fn record(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), ExecError> {
        let (Some(l), Some(p), Some(out)) = (&self.loaded, &mut self.prepared, &self.output) else {
            return Ok(());
        };
        p.frame = 0;
        p.subframe = 0;
        let mut inputs = FrameInputs::still(&l.input, &p.plan);
        for (n, t, _) in &l.aux {
            inputs.aux.insert(n.clone(), t.into());
        }
        p.record(engine, encoder, &inputs, out)
    }

    /// The effect's output, in its format.
    pub fn output(&self) -> Option<(&wgpu::Texture, Format)> {
        Some((
            self.output.as_ref()?,
            self.prepared.as_ref()?.plan.output.format,
        ))
    }

    /// The effect's input (the "before" of the split view).
    pub fn before(&self) -> Option<(&wgpu::Texture, Format)> {
        let l = self.loaded.as_ref()?;
        Some((&l.input, l.input_format))
    }

    /// The auxiliary images (`--aux`).
    pub fn aux(&self) -> Vec<(String, &wgpu::Texture, Format)> {
        self.loaded
            .iter()
            .flat_map(|l| l.aux.iter().map(|(n, t, f)| (n.clone(), t, *f)))
            .collect()
    }

    /// Show image `index` (wrapping around); true when it is another one.
    pub fn step(&mut self, delta: i64) -> bool {
        let n = self.items.len() as i64;
        let next = (self.index as i64 + delta).rem_euclid(n) as usize;
        let moved = next != self.index;
        self.index = next;
        moved
    }

    /// Show the first image.
    pub fn first(&mut self) -> bool {
        std::mem::replace(&mut self.index, 0) != 0
    }

    /// The file shown and its place in the batch.
    pub fn caption(&self) -> String {
        let path = self.items[self.index].display();
        match (&self.loaded, self.items.len()) {
            (Some(l), 1) => format!("{path} ({}x{})", l.image.width, l.image.height),
            (Some(l), n) => format!(
                "{path} ({}x{}), image {} of {n}",
                l.image.width,
                l.image.height,
                self.index + 1
            ),
            (None, _) => path.to_string(),
        }
    }

    /// The shown image's path.
    pub fn current_path(&self) -> &std::path::Path {
        &self.items[self.index]
    }

    /// Number of images.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// No images (a batch always has one).
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}
