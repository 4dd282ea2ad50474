//! The sources and sinks of file and stream jobs: numbered image files, y4m streams
//! (files, pipes, ffmpeg's: see [`super::streams`]). `fxrun` adds its own (e.g. named
//! outputs for `-o DIR`).

use super::frames::{
    FrameSink, FrameSource, OutputFrame, Picture, PlaneFrame, SideLimit, SourceFrame,
};
use super::planes::{gpu_refusal, PlaneRoute};
use crate::io::{self, Image, IoError, Pixels};
use std::sync::Arc;

/// Image files read in order (numbered frames, or the images of a batch), each
/// checked against the device's size limit from its header before it is decoded.
pub struct FilesSource {
    pub frames: Vec<(u64, std::path::PathBuf)>,
    pub load: io::LoadOptions,
    limit: SideLimit,
    pos: usize,
}

impl FilesSource {
    pub fn new(frames: Vec<(u64, std::path::PathBuf)>, load: io::LoadOptions) -> Self {
        FilesSource {
            frames,
            load,
            limit: SideLimit::known(io::MAX_SIDE),
            pos: 0,
        }
    }
}

/// Read an image file, refuse a size over the device's limit from its header, decode.
pub(crate) fn load_checked(
    path: &std::path::Path,
    limit: &SideLimit,
    load: &io::LoadOptions,
) -> Result<Image, IoError> {
    let bytes = io::read_image_file(path)?;
    let (w, h) = io::image_dimensions(&bytes, path)?;
    if let Err(max) = limit.check(w, h) {
        return Err(IoError::Decode {
            path: path.to_path_buf(),
            message: format!(
                "the image is {w}x{h}, larger than the GPU's limit of {max} pixels per side"
            ),
        });
    }
    io::decode_image(&bytes, path, load)
}

impl FrameSource for FilesSource {
    fn frame_count(&self) -> Option<u64> {
        Some(self.frames.len() as u64)
    }
    fn next_frame(&mut self) -> Option<SourceFrame> {
        let (n, path) = self.frames.get(self.pos)?;
        self.pos += 1;
        Some(SourceFrame {
            number: *n,
            name: path.display().to_string(),
            image: load_checked(path, &self.limit, &self.load).map(Picture::from),
            aux: Vec::new(),
        })
    }
    fn set_limit(&mut self, limit: SideLimit) {
        self.limit = limit;
    }
}

/// Where each output frame's file goes.
pub enum OutputNames {
    /// A numbered pattern (`out/%04d.png`).
    Pattern(io::sequence::OutputPattern),
    /// A name per frame number (a batch's outputs, one image's output, a sequence's
    /// `-o DIR` names).
    Named(std::collections::HashMap<u64, std::path::PathBuf>),
}

/// Image files written atomically, named by [`OutputNames`].
pub struct FilesSink {
    pub names: OutputNames,
    pub save: io::SaveOptions,
}

impl FrameSink for FilesSink {
    fn write(&mut self, frame: OutputFrame) -> Result<String, IoError> {
        let path = match &self.names {
            OutputNames::Pattern(p) => p.path_for(frame.number),
            OutputNames::Named(names) => {
                names
                    .get(&frame.number)
                    .cloned()
                    .ok_or_else(|| IoError::Unsupported {
                        path: format!("frame {}", frame.number).into(),
                        message: "no output file name for this frame".into(),
                    })?
            }
        };
        io::save_image(&path, frame.width, frame.height, &frame.pixels, &self.save)?;
        Ok(path.display().to_string())
    }
}

fn y4m_error(e: io::y4m::Y4mError) -> IoError {
    IoError::from(e)
}

/// A YUV4MPEG2 stream (stdin, a file, ffmpeg's output): its frames' planes as they
/// are read when the GPU converts them ([`Y4mSource::set_plane_route`]), else
/// decoded to RGBA frames here: 8-bit streams to 8-bit sRGB pixels (decoded by the
/// GPU), deeper ones to linear floats (no precision lost before the GPU).
pub struct Y4mSource<R: std::io::Read + Send> {
    pub reader: io::y4m::Y4mReader<R>,
    pub conversion: io::y4m::YuvConversion,
    /// Frames to skip before the first one produced (a shard's start).
    pub skip: u64,
    /// Last frame number to read (a shard's end plus its context), if any.
    pub last: Option<u64>,
    /// A frame failed: the stream cannot go on.
    pub failed: bool,
    /// Frames in the stream, when known (for the progress bar and the report).
    pub frames: Option<u64>,
    /// Whether the frames go to the GPU as planes (decided by the run's device).
    route: PlaneRoute,
    /// The header shared by the planes sent, and whether planes are sent (known
    /// from the first frame on).
    shared: Option<(Arc<io::y4m::Y4mHeader>, bool)>,
}

impl<R: std::io::Read + Send> Y4mSource<R> {
    /// All the frames of `reader`, converted with `conversion`.
    pub fn new(reader: io::y4m::Y4mReader<R>, conversion: io::y4m::YuvConversion) -> Self {
        Y4mSource {
            reader,
            conversion,
            skip: 0,
            last: None,
            failed: false,
            frames: None,
            route: PlaneRoute::known(false),
            shared: None,
        }
    }

    /// The header the frames share, and whether they go to the GPU as planes (else
    /// they are converted here): the run's device decides (frames read before it
    /// exists are converted here), and signals other than sRGB are converted on the
    /// CPU (logged once).
    fn shared(&mut self) -> (Arc<io::y4m::Y4mHeader>, bool) {
        if self.shared.is_none() {
            if let Some(mut planes) = self.route.decided() {
                if let (true, Some(why)) = (planes, gpu_refusal(&self.conversion)) {
                    let name = self.reader.name();
                    log::info!("{name}: Y'CbCr conversion on the CPU: {why}");
                    planes = false;
                }
                self.shared = Some((Arc::new(self.reader.header().clone()), planes));
            }
        }
        match &self.shared {
            Some((header, planes)) => (header.clone(), *planes),
            None => (Arc::new(self.reader.header().clone()), false),
        }
    }

    /// Whether the frames up to [`Y4mSource::last`] have all been read (the stream may
    /// go on).
    pub fn past_last(&self) -> bool {
        self.last.is_some_and(|l| self.reader.frames_read() > l)
    }

    fn read(&mut self) -> Result<Option<(u64, Picture)>, IoError> {
        loop {
            let n = self.reader.frames_read();
            if self.past_last() {
                return Ok(None);
            }
            let Some(frame) = self.reader.next_frame().map_err(y4m_error)? else {
                return Ok(None);
            };
            if n < self.skip {
                continue;
            }
            let (header, to_gpu) = self.shared();
            let planes = PlaneFrame {
                frame,
                header,
                conversion: self.conversion,
            };
            if to_gpu {
                return Ok(Some((n, Picture::Planes(planes))));
            }
            let img = planes.to_image().map_err(|m| IoError::Decode {
                path: self.reader.name().into(),
                message: format!("y4m frame {n}: {m}"),
            })?;
            return Ok(Some((n, img.into())));
        }
    }
}

impl<R: std::io::Read + Send> FrameSource for Y4mSource<R> {
    fn frame_count(&self) -> Option<u64> {
        let n = self.frames?;
        let end = self.last.map_or(n, |l| n.min(l.saturating_add(1)));
        Some(end.saturating_sub(self.skip))
    }
    fn next_frame(&mut self) -> Option<SourceFrame> {
        if self.failed {
            return None;
        }
        let n = self.reader.frames_read();
        let (number, image) = match self.read() {
            Ok(None) => return None,
            Ok(Some((n, img))) => (n, Ok(img)),
            Err(e) => {
                self.failed = true;
                (n, Err(e))
            }
        };
        Some(SourceFrame {
            number,
            name: format!("{} frame {number}", self.reader.name()),
            image,
            aux: Vec::new(),
        })
    }
    fn set_plane_route(&mut self, route: PlaneRoute) {
        self.route = route;
    }
}

/// A YUV4MPEG2 stream written from the output frames into an [`io::OutputTarget`]
/// (stdout, a file written atomically, a video encoder); the header is written with the
/// first frame (its size is the output's). The output is made final
/// ([`io::OutputTarget::commit`]) only when the run completes, and discarded otherwise.
pub struct Y4mSink<W: io::OutputTarget> {
    pub inner: Option<W>,
    pub writer: Option<io::y4m::Y4mWriter<W>>,
    /// Header fields to pass on (frame rate, interlacing, aspect, chroma, depth).
    pub template: io::y4m::Y4mHeader,
    pub conversion: io::y4m::YuvConversion,
    pub name: String,
    /// Non-finite samples were reported already (once per output).
    pub warned_non_finite: bool,
}

impl<W: io::OutputTarget> Y4mSink<W> {
    /// A sink writing into `inner`, named `name` in messages.
    pub fn new(
        inner: W,
        template: io::y4m::Y4mHeader,
        conversion: io::y4m::YuvConversion,
        name: impl Into<String>,
    ) -> Self {
        Y4mSink {
            inner: Some(inner),
            writer: None,
            template,
            conversion,
            name: name.into(),
            warned_non_finite: false,
        }
    }

    /// NaN or ±Inf samples in a frame for an HDR signal: say once what they become.
    fn check_non_finite(&mut self, number: u64, pixels: &Pixels) {
        let Pixels::F32(v) = pixels else { return };
        if self.warned_non_finite || !self.conversion.color.transfer.is_hdr() {
            return;
        }
        let bad = v.iter().filter(|x| !x.is_finite()).count();
        if bad > 0 {
            self.warned_non_finite = true;
            log::warn!(
                "{}: frame {number} has {bad} NaN or infinite samples: NaN is written as 0 (black), +Inf as the {} peak, -Inf as 0 (reported once)",
                self.name,
                self.conversion.color.transfer.name()
            );
        }
    }

    /// The target back (flushed when frames were written), if it has not been handed
    /// back already.
    fn take_target(&mut self) -> Result<Option<W>, IoError> {
        match self.writer.take() {
            Some(w) => w.into_inner().map(Some).map_err(y4m_error),
            None => Ok(self.inner.take()),
        }
    }
}

impl<W: io::OutputTarget> Y4mSink<W> {
    /// The writer, made with the first frame (its size is the output's).
    fn writer_for(
        &mut self,
        width: u32,
        height: u32,
    ) -> Result<&mut io::y4m::Y4mWriter<W>, IoError> {
        if self.writer.is_none() {
            let mut header = self.template.clone();
            header.width = width;
            header.height = height;
            let inner = self.inner.take().ok_or_else(|| IoError::Io {
                path: self.name.clone().into(),
                source: std::io::Error::other("the stream is already finished"),
            })?;
            let w = io::y4m::Y4mWriter::new(inner, header, self.name.clone()).map_err(y4m_error)?;
            self.writer = Some(w);
        }
        Ok(self.writer.as_mut().expect("writer created"))
    }
}

impl<W: io::OutputTarget> FrameSink for Y4mSink<W> {
    fn write(&mut self, frame: OutputFrame) -> Result<String, IoError> {
        use io::y4m::image_to_yuv;
        self.writer_for(frame.width, frame.height)?;
        self.check_non_finite(frame.number, &frame.pixels);
        let w = self.writer.as_mut().expect("writer created");
        let header = w.header().clone();
        let img = Image {
            width: frame.width,
            height: frame.height,
            pixels: frame.pixels,
            source: io::SourceInfo {
                format: io::FileFormat::Png,
                bit_depth: header.depth,
                has_alpha: false,
                float: false,
            },
        };
        let yuv = image_to_yuv(&img, &header, &self.conversion).map_err(|m| IoError::Decode {
            path: self.name.clone().into(),
            message: m,
        })?;
        w.write_frame(&yuv).map_err(y4m_error)?;
        Ok(format!("{} frame {}", self.name, frame.number))
    }
    fn plane_output(&self) -> Option<(io::y4m::Y4mHeader, io::y4m::YuvConversion)> {
        Some((self.template.clone(), self.conversion))
    }
    fn write_planes(
        &mut self,
        number: u64,
        width: u32,
        height: u32,
        planes: Vec<u8>,
    ) -> Result<String, IoError> {
        let w = self.writer_for(width, height)?;
        w.write_planes(&planes).map_err(y4m_error)?;
        Ok(format!("{} frame {number}", self.name))
    }
    fn finish(&mut self) -> Result<(), IoError> {
        let wrote = self.writer.is_some();
        match self.take_target() {
            Ok(Some(mut t)) if wrote => t.commit(),
            // No frame: nothing to make final (the run reports that it had no frames).
            Ok(Some(mut t)) => {
                t.abandon();
                Ok(())
            }
            Ok(None) => Ok(()),
            Err(e) => Err(e),
        }
    }
    fn abort(&mut self) {
        // Not flushed here: the target decides (stdout keeps what was written, a
        // file's temporary is removed, an encoder is killed first).
        let target = match self.writer.take() {
            Some(w) => Some(w.into_unflushed()),
            None => self.inner.take(),
        };
        if let Some(mut t) = target {
            t.abandon();
        }
    }
}

/// Frames from the caller's memory, numbered from 0 in order.
pub struct MemorySource {
    frames: std::vec::IntoIter<Image>,
    aux: Vec<(String, Image)>,
    count: u64,
    next: u64,
}

impl MemorySource {
    pub fn new(frames: Vec<Image>) -> Self {
        MemorySource {
            count: frames.len() as u64,
            frames: frames.into_iter(),
            aux: Vec::new(),
            next: 0,
        }
    }

    /// Auxiliary images (`AUX.NAME`) given with every frame.
    pub fn with_aux(mut self, aux: Vec<(String, Image)>) -> Self {
        self.aux = aux;
        self
    }
}

impl FrameSource for MemorySource {
    fn frame_count(&self) -> Option<u64> {
        Some(self.count)
    }
    fn next_frame(&mut self) -> Option<SourceFrame> {
        let img = self.frames.next()?;
        let number = self.next;
        self.next += 1;
        Some(SourceFrame {
            number,
            name: format!("frame {number}"),
            image: Ok(img.into()),
            aux: self.aux.clone(),
        })
    }
}

/// One output frame kept in memory: its number, size and pixels.
pub type MemoryFrame = (u64, u32, u32, Pixels);

/// Output frames collected in memory; [`MemorySink::frames`] is a handle that stays
/// with the caller when the sink is moved into a run.
#[derive(Default)]
pub struct MemorySink {
    frames: std::sync::Arc<std::sync::Mutex<Vec<MemoryFrame>>>,
}

impl MemorySink {
    /// The frames written so far (all of them once the run returned).
    pub fn frames(&self) -> std::sync::Arc<std::sync::Mutex<Vec<MemoryFrame>>> {
        self.frames.clone()
    }
}

impl FrameSink for MemorySink {
    fn write(&mut self, frame: OutputFrame) -> Result<String, IoError> {
        let number = frame.number;
        self.frames.lock().unwrap_or_else(|e| e.into_inner()).push((
            number,
            frame.width,
            frame.height,
            frame.pixels,
        ));
        Ok(format!("memory frame {number}"))
    }
}

/// Output frames dropped: for a run kept for what it writes besides its frames (a
/// rendered frame's G-buffer with `--time` and `--gbuffer` alone).
pub struct DiscardSink;

impl FrameSink for DiscardSink {
    fn write(&mut self, frame: OutputFrame) -> Result<String, IoError> {
        Ok(format!("frame {} (not written)", frame.number))
    }
}

/// The auxiliary images of `--aux NAME=FILE` (and a slang preset's LUTs),
/// decoded once for a whole batch or sequence.
pub(crate) fn load_aux(
    paths: &[(String, std::path::PathBuf)],
    load: &io::LoadOptions,
) -> Result<Vec<(String, Image)>, IoError> {
    let limit = SideLimit::known(io::MAX_SIDE);
    paths
        .iter()
        .map(|(name, path)| Ok((name.clone(), load_checked(path, &limit, load)?)))
        .collect()
}

/// A source whose frames all come with the same auxiliary images (`AUX.NAME`):
/// the images of `--aux` for a batch or a sequence.
pub(crate) struct WithAux {
    inner: Box<dyn FrameSource>,
    aux: Vec<(String, Image)>,
}

/// `source`, its frames given `aux` (`source` itself when `aux` is empty).
pub(crate) fn with_aux(
    source: Box<dyn FrameSource>,
    aux: Vec<(String, Image)>,
) -> Box<dyn FrameSource> {
    if aux.is_empty() {
        return source;
    }
    Box::new(WithAux { inner: source, aux })
}

impl FrameSource for WithAux {
    fn frame_count(&self) -> Option<u64> {
        self.inner.frame_count()
    }
    fn next_frame(&mut self) -> Option<SourceFrame> {
        let mut f = self.inner.next_frame()?;
        f.aux.extend(self.aux.iter().cloned());
        Some(f)
    }
    fn set_limit(&mut self, limit: SideLimit) {
        self.inner.set_limit(limit);
    }
    fn set_plane_route(&mut self, route: PlaneRoute) {
        self.inner.set_plane_route(route);
    }
}
