//! The GPU stage's Y'CbCr conversions ([`super::gpu_stage`]): a sequence's y4m or
//! video frames converted into the stream's input textures on the device, and its
//! outputs converted into the sink's planes there; each falls back to the CPU
//! conversion (logged) where the device cannot serve the stream.

use super::frames::{Picture, PlaneFrame};
use super::planes::{gpu_refusal, plane_layout};
use super::stage_messages::Readback;
use crate::gpu::executor::Engine;
use crate::gpu::stream::Stream;
use crate::gpu::yuv::{PlanesToRgb, RgbToPlanes, YuvGpuError};
use crate::io::y4m::{Y4mHeader, YuvConversion, YuvFrame};
use crate::script::types::{ColorSpace, Format};

/// The conversions of one sequence run.
#[derive(Default)]
pub(super) struct PlaneStage {
    /// What the sink writes, when the GPU may make its planes.
    offer: Option<(Y4mHeader, YuvConversion)>,
    input: Option<PlanesToRgb>,
    /// The stream's input format, once it exists; whether `input` was tried.
    input_format: Option<Format>,
    input_tried: bool,
    output: Option<RgbToPlanes>,
    /// A frame's planes were converted on the CPU here (logged once).
    warned: bool,
}

/// The texture format and colour space of a frame's picture: those the CPU
/// conversion's image would be uploaded as (`gpu::transfer::input_format`): 8-bit
/// sRGB streams as 8-bit textures, 9 and 10 bits as rgba16f, deeper as rgba32f.
pub(super) fn picture_format(pic: &Picture, assume_linear: bool) -> (Format, ColorSpace) {
    match pic {
        Picture::Rgba(img) => crate::gpu::transfer::input_format(img, assume_linear),
        Picture::Planes(p) => {
            let format = match p.header.depth {
                8 if !p.conversion.color.is_srgb() => Format::Rgba16f,
                8 if assume_linear => Format::Rgba8,
                8 => Format::Rgba8Srgb,
                9 | 10 => Format::Rgba16f,
                _ => Format::Rgba32f,
            };
            (format, ColorSpace::Linear)
        }
    }
}

impl PlaneStage {
    /// Whether the GPU converts the input's planes and makes the output's.
    pub(super) fn on_gpu(&self) -> [bool; 2] {
        [self.input.is_some(), self.output.is_some()]
    }

    /// The sink's offer of planes (the run's device converts on the GPU).
    pub(super) fn offer(&mut self, offer: Option<(Y4mHeader, YuvConversion)>) {
        self.offer = offer;
    }

    /// Make the output's conversion of a new stream whose input textures are in
    /// `input` (the input's is made with its first frame of planes).
    pub(super) fn prepare(&mut self, engine: &Engine, stream: &Stream, input: Format) {
        self.input_format = Some(input);
        let Some((template, conv)) = self.offer.take() else {
            return;
        };
        if let Some(why) = gpu_refusal(&conv) {
            log::info!("Y'CbCr output converted on the CPU: {why}");
            return;
        }
        let out = stream.prepared.plan.output;
        let mut header = template;
        (header.width, header.height) = (out.width, out.height);
        let fields = YuvFrame::default().field_chroma(&header, &conv);
        let layout = plane_layout(&header, &conv);
        let made = RgbToPlanes::new(&engine.ctx, &layout, out.format, fields);
        self.output = served(made, "output");
    }

    /// Push a frame into the stream: planes converted on the device, or an image
    /// (the CPU converts planes the device cannot).
    pub(super) fn push(
        &mut self,
        engine: &Engine,
        stream: &mut Stream,
        pic: Picture,
        name: &str,
    ) -> Result<(), super::error::RunError> {
        if let (Picture::Planes(p), false, Some(format)) =
            (&pic, self.input_tried, self.input_format)
        {
            self.input_tried = true;
            let layout = plane_layout(&p.header, &p.conversion);
            self.input = served(PlanesToRgb::new(&engine.ctx, &layout, format), "input");
        }
        match (pic, self.input.as_mut()) {
            (Picture::Planes(p), Some(conv)) => {
                let PlaneFrame {
                    frame,
                    header,
                    conversion,
                } = &p;
                let fields = frame.field_chroma(header, conversion);
                stream.push_planes(engine, conv, [&frame.y, &frame.u, &frame.v], fields)?;
            }
            (pic, _) => {
                if matches!(pic, Picture::Planes(_)) && !std::mem::replace(&mut self.warned, true) {
                    log::info!("{name}: Y'CbCr input converted on the CPU");
                }
                stream.push_image(engine, &pic.into_image(name)?)?;
            }
        }
        Ok(())
    }

    /// Run the stream's next ready output and start reading it back: as planes
    /// where the GPU makes the sink's, else as texels.
    pub(super) fn next(
        &mut self,
        engine: &mut Engine,
        stream: &mut Stream,
    ) -> Result<Option<(u64, Readback)>, crate::gpu::executor::ExecError> {
        let Some(conv) = self.output.as_mut() else {
            let next = stream.next_read_back(engine)?;
            return Ok(next.map(|(i, p)| (i, Readback::Texture(p))));
        };
        let ctx = engine.ctx.clone();
        let (w, h) = (conv.layout().width, conv.layout().height);
        let next = stream.next_then(engine, |enc, out| conv.encode(&ctx, enc, out))?;
        Ok(next.map(|(i, p)| (i, Readback::Planes(p, w, h))))
    }
}

/// A conversion made, or `None` (the CPU converts) with the reason logged; `what`:
/// input or output.
fn served<T>(made: Result<T, YuvGpuError>, what: &str) -> Option<T> {
    match made {
        Ok(c) => {
            log::info!("Y'CbCr {what} converted on the GPU");
            Some(c)
        }
        Err(e) => {
            log::warn!("Y'CbCr {what} converted on the CPU: {e}");
            None
        }
    }
}
