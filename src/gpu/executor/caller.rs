//! The caller's images of a frame: its input frames, AUX images and output, each
//! in the view format the plan reads or writes (views of caller textures made
//! once and kept), and the output's format checked against the plan's (or its
//! BGRA twin).

use super::bgra::{bgra_twin, is_bgra};
use super::record::{CallerRef, Prepared};
use super::{wgpu_format, ExecError, FrameInputs, ImageRef};
use crate::graph::plan::Resource;

/// Views of caller textures kept.
const CALLER_VIEWS: usize = 32;

impl Prepared {
    /// The view of a caller image in `format`.
    pub(super) fn caller_view(
        &mut self,
        image: ImageRef,
        format: Option<wgpu::TextureFormat>,
        what: &str,
    ) -> Result<wgpu::TextureView, ExecError> {
        match image {
            ImageRef::View(v) => match format {
                None => Ok(v.clone()),
                Some(f) => Err(ExecError::Input(format!(
                    "{what} is read or written as {f:?}, a view of another format: pass the texture, not a view"
                ))),
            },
            ImageRef::Texture(t) => {
                // A BGRA output is viewed in the BGRA twin of the plan's view format.
                let format = match format {
                    Some(f) if is_bgra(t.format()) => bgra_twin(f).or(Some(f)),
                    other => other,
                };
                if let Some((_, _, v)) = self
                    .views
                    .iter()
                    .find(|(vt, vf, _)| vt == t && *vf == format)
                {
                    return Ok(v.clone());
                }
                let v = t.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("fxgraph {what} view")),
                    format,
                    ..Default::default()
                });
                if self.views.len() == CALLER_VIEWS {
                    self.views.remove(0);
                }
                self.views.push((t.clone(), format, v.clone()));
                self.stats.caller_views_created += 1;
                Ok(v)
            }
        }
    }

    /// The caller's images for this frame, in the order of `self.caller`.
    pub(super) fn resolve_caller(
        &mut self,
        inputs: &FrameInputs,
        output: ImageRef,
    ) -> Result<Vec<wgpu::TextureView>, ExecError> {
        if let ImageRef::Texture(t) = output {
            let want = wgpu_format(self.plan.output.format);
            let same = t.format().remove_srgb_suffix() == want.remove_srgb_suffix();
            let twin = bgra_twin(want).is_some_and(|b| b == t.format());
            if !same && !twin {
                return Err(ExecError::Input(format!(
                    "output texture is {:?}, the plan renders {want:?}{}",
                    t.format(),
                    bgra_twin(want)
                        .map(|b| format!(" (or its BGRA twin {b:?})"))
                        .unwrap_or_default()
                )));
            }
        }
        let mut views = Vec::with_capacity(self.caller.len());
        for i in 0..self.caller.len() {
            let CallerRef { resource, format } = self.caller[i].clone();
            let (image, what) = match &resource {
                Resource::Input { frame } => (
                    inputs.frames.get(frame).copied().ok_or_else(|| {
                        ExecError::Input(format!("input frame {frame:+} not provided"))
                    })?,
                    format!("input frame {frame:+}"),
                ),
                Resource::Aux(name) => (
                    inputs.aux.get(name).copied().ok_or_else(|| {
                        ExecError::Input(format!("auxiliary input `{name}` not provided"))
                    })?,
                    format!("auxiliary input `{name}`"),
                ),
                Resource::Output => (output, "output".to_string()),
                other => unreachable!("not a caller image: {other:?}"),
            };
            views.push(self.caller_view(image, format, &what)?);
        }
        Ok(views)
    }
}
