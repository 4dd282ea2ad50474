//! Writing a stream.

use super::*;
use std::io::Write;

/// Writes a YUV4MPEG2 stream: the header on construction, then frames. Does not buffer:
/// give it a `BufWriter` (or a locked stdout in one) for small writes to coalesce.
pub struct Y4mWriter<W: Write> {
    inner: W,
    header: Y4mHeader,
    name: String,
    frames: u64,
}

impl<W: Write> Y4mWriter<W> {
    /// Check `header` ([`Y4mHeader::validate`]) and write it. `name` names the stream in
    /// messages (`stdout`, a path). Logs a warning when the line is longer than the 96
    /// bytes ffmpeg's demuxer accepts.
    pub fn new(
        mut inner: W,
        header: Y4mHeader,
        name: impl Into<String>,
    ) -> Result<Y4mWriter<W>, Y4mError> {
        let name = name.into();
        header.validate().map_err(|message| Y4mError::Header {
            name: name.clone(),
            message,
        })?;
        let line = header.to_line();
        if line.len() > FFMPEG_MAX_HEADER {
            log::warn!(
                "{name}: the y4m header is {} bytes long; ffmpeg reads at most {FFMPEG_MAX_HEADER}",
                line.len()
            );
        }
        inner
            .write_all(line.as_bytes())
            .map_err(|source| Y4mError::Io {
                name: name.clone(),
                context: "writing the y4m header".into(),
                source,
            })?;
        Ok(Y4mWriter {
            inner,
            header,
            name,
            frames: 0,
        })
    }

    /// The header written.
    pub fn header(&self) -> &Y4mHeader {
        &self.header
    }

    /// Frames written so far.
    pub fn frames_written(&self) -> u64 {
        self.frames
    }

    /// Write one frame: `FRAME`, its parameters, `\n`, then the planes (Y only for mono).
    /// The planes must match the header ([`YuvFrame::check_size`]) and the parameters be
    /// non-empty without spaces or newlines.
    pub fn write_frame(&mut self, frame: &YuvFrame) -> Result<(), Y4mError> {
        frame
            .check_size(&self.header)
            .map_err(|m| self.frame_error(m))?;
        self.write_parts(&frame.params, [&frame.y, &frame.u, &frame.v])
    }

    /// Write one frame from its planes as one block of bytes (Y, Cb, Cr, as the
    /// stream stores them: [`Y4mHeader::frame_bytes`] of them), without `FRAME`
    /// parameters.
    pub fn write_planes(&mut self, planes: &[u8]) -> Result<(), Y4mError> {
        let want = self.header.frame_bytes();
        if planes.len() != want {
            let m = format!("{} bytes of planes, the header needs {want}", planes.len());
            return Err(self.frame_error(m));
        }
        self.write_parts(&[], [planes, &[], &[]])
    }

    fn frame_error(&self, message: String) -> Y4mError {
        Y4mError::Frame {
            name: self.name.clone(),
            frame: self.frames,
            message,
        }
    }

    /// `FRAME`, its parameters, `\n`, the planes' bytes.
    fn write_parts(&mut self, params: &[String], parts: [&[u8]; 3]) -> Result<(), Y4mError> {
        let index = self.frames;
        let mut line = Vec::with_capacity(16);
        line.extend_from_slice(FRAME_MAGIC);
        for p in params {
            if p.is_empty() || p.contains([' ', '\n', '\r']) {
                return Err(self.frame_error(format!("invalid FRAME parameter `{p}`")));
            }
            line.push(b' ');
            line.extend_from_slice(p.as_bytes());
        }
        line.push(b'\n');
        for b in [&line[..], parts[0], parts[1], parts[2]] {
            self.inner.write_all(b).map_err(|source| Y4mError::Io {
                name: self.name.clone(),
                context: format!("writing y4m frame {index} (0-based)"),
                source,
            })?;
        }
        self.frames += 1;
        Ok(())
    }

    /// Flush the underlying writer.
    pub fn flush(&mut self) -> Result<(), Y4mError> {
        self.inner.flush().map_err(|source| Y4mError::Io {
            name: self.name.clone(),
            context: "flushing the y4m stream".into(),
            source,
        })
    }

    /// Return the underlying writer without flushing it (a run that is abandoned).
    pub fn into_unflushed(self) -> W {
        self.inner
    }

    /// Flush and return the underlying writer.
    pub fn into_inner(mut self) -> Result<W, Y4mError> {
        self.flush()?;
        Ok(self.inner)
    }
}
