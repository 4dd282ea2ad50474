//! What the pipeline ([`super::pipeline`]) joins: frames from a [`FrameSource`]
//! (decode thread), outputs to a [`FrameSink`] (encode thread), and the device's size
//! limit the sources check headers against ([`SideLimit`]).

use super::planes::PlaneRoute;
use crate::io::y4m::{yuv_to_image, RgbKind, Y4mHeader, YuvConversion, YuvFrame};
use crate::io::{Image, IoError, Pixels};
use std::sync::{Arc, Condvar, Mutex};

/// A frame from a source: its number, a name for messages (a file name, `stdin frame
/// N`), the decoded picture or why it could not be, and auxiliary images (`AUX.NAME`).
pub struct SourceFrame {
    pub number: u64,
    pub name: String,
    pub image: Result<Picture, IoError>,
    pub aux: Vec<(String, Image)>,
}

/// A frame's pixels on their way to the GPU: RGBA, or the Y'CbCr planes of a y4m
/// or video stream, converted on the GPU ([`super::planes`]).
pub enum Picture {
    Rgba(Image),
    Planes(PlaneFrame),
}

/// A y4m frame as it was read, with what says how to convert it.
pub struct PlaneFrame {
    pub frame: YuvFrame,
    pub header: Arc<Y4mHeader>,
    pub conversion: YuvConversion,
}

impl From<Image> for Picture {
    fn from(img: Image) -> Picture {
        Picture::Rgba(img)
    }
}

impl PlaneFrame {
    /// The RGBA image the CPU conversion makes of the frame (what a y4m source
    /// sends when the GPU does not convert): 8-bit sRGB for 8-bit sRGB streams,
    /// linear floats otherwise.
    pub fn to_image(&self) -> Result<Image, String> {
        let h = &*self.header;
        let kind = if h.depth > 8 || !self.conversion.color.is_srgb() {
            RgbKind::LinearF32
        } else {
            RgbKind::SrgbU8
        };
        yuv_to_image(&self.frame, h, &self.conversion, kind)
    }
}

impl Picture {
    /// The picture as RGBA, converted on the CPU if it is planes (`name` names the
    /// frame in an error).
    pub fn into_image(self, name: &str) -> Result<Image, IoError> {
        match self {
            Picture::Rgba(img) => Ok(img),
            Picture::Planes(p) => p.to_image().map_err(|message| IoError::Decode {
                path: name.into(),
                message,
            }),
        }
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        match self {
            Picture::Rgba(img) => (img.width, img.height),
            Picture::Planes(p) => (p.header.width, p.header.height),
        }
    }
}

/// Where frames come from (runs on the decode thread).
pub trait FrameSource: Send {
    /// Number of frames, if known (for the progress bar and the report).
    fn frame_count(&self) -> Option<u64>;
    /// The next frame, or `None` at the end. A source that cannot go on after a failed
    /// frame (a broken stream) returns `None` after it.
    fn next_frame(&mut self) -> Option<SourceFrame>;
    /// The device's size limit, for sources that read sizes from headers.
    fn set_limit(&mut self, _limit: SideLimit) {}
    /// Whether the GPU converts Y'CbCr frames, for sources that read them: such a
    /// source sends [`Picture::Planes`] when the route says so.
    fn set_plane_route(&mut self, _route: PlaneRoute) {}
}

/// An output frame handed to a [`FrameSink`]: its number, size and pixels.
pub struct OutputFrame {
    pub number: u64,
    pub width: u32,
    pub height: u32,
    pub pixels: Pixels,
}

/// Where output frames go (runs on the encode thread).
pub trait FrameSink: Send {
    /// Write an output frame; returns where it went (a file name, `stdout`).
    fn write(&mut self, frame: OutputFrame) -> Result<String, IoError>;
    /// Called once after the last frame of a complete run (every frame read was
    /// written, no failure, not interrupted): make the output final.
    fn finish(&mut self) -> Result<(), IoError> {
        Ok(())
    }
    /// Called once instead of [`FrameSink::finish`] when the run failed or was
    /// interrupted: a sink writing one file (a y4m or video file) discards it, so that
    /// no partial output is left and an existing one is kept. Sinks of one file per
    /// frame keep the frames written (the default does nothing).
    fn abort(&mut self) {}
    /// A sink of y4m frames that takes their planes as the stream stores them
    /// ([`FrameSink::write_planes`]): the header of its frames (the size is set to
    /// the output's) and their conversion. `None` (the default): RGBA only.
    fn plane_output(&self) -> Option<(Y4mHeader, YuvConversion)> {
        None
    }
    /// Write an output frame given as the planes of [`FrameSink::plane_output`]'s
    /// layout (Y, Cb, Cr); only called on sinks that offer it.
    fn write_planes(
        &mut self,
        number: u64,
        width: u32,
        height: u32,
        _planes: Vec<u8>,
    ) -> Result<String, IoError> {
        Err(IoError::Unsupported {
            path: format!("frame {number}").into(),
            message: format!("this output takes RGBA frames, not {width}x{height} Y'CbCr planes"),
        })
    }
}

/// The largest width or height the device takes, known once the device exists.
/// [`SideLimit::check`] answers sizes every device takes at once and waits for the
/// device only for larger ones, so decoding overlaps device creation.
#[derive(Clone, Default)]
pub struct SideLimit(Arc<(Mutex<Option<u32>>, Condvar)>);

impl SideLimit {
    /// A limit already known.
    pub fn known(max: u32) -> Self {
        let l = SideLimit::default();
        l.set(max);
        l
    }

    /// Set the limit (once the device exists, or when it failed: then any value).
    pub fn set(&self, max: u32) {
        let (m, cv) = &*self.0;
        *m.lock().unwrap_or_else(|e| e.into_inner()) = Some(max.min(crate::io::MAX_SIDE));
        cv.notify_all();
    }

    /// Ok when an image of `width` × `height` fits the device; Err with the limit.
    pub fn check(&self, width: u32, height: u32) -> Result<(), u32> {
        let side = width.max(height);
        if side <= wgpu::Limits::default().max_texture_dimension_2d {
            return Ok(());
        }
        let (m, cv) = &*self.0;
        let mut v = m.lock().unwrap_or_else(|e| e.into_inner());
        while v.is_none() {
            v = cv.wait(v).unwrap_or_else(|e| e.into_inner());
        }
        let max = v.expect("set");
        if side <= max {
            Ok(())
        } else {
            Err(max)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SideLimit;

    #[test]
    fn side_limit_waits_for_the_device_only_above_what_every_device_takes() {
        let limit = SideLimit::default();
        // Every device takes 8192 px per side: answered before the device exists.
        assert_eq!(limit.check(8192, 100), Ok(()));
        let l = limit.clone();
        let waiter = std::thread::spawn(move || (l.check(10000, 10), l.check(20000, 10)));
        std::thread::sleep(std::time::Duration::from_millis(20));
        limit.set(16384);
        assert_eq!(waiter.join().unwrap(), (Ok(()), Err(16384)));
        // The io layer's cap bounds any device's limit.
        assert_eq!(SideLimit::known(1 << 20).check(40000, 1), Err(32768));
    }
}
