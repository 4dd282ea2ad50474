//! Reading a stream frame by frame, with buffers that grow as bytes arrive.

use super::*;
use std::io::{self, BufRead, BufReader, Read};

/// Reads a YUV4MPEG2 stream: the header on construction, then frames one by one.
pub struct Y4mReader<R: Read> {
    inner: BufReader<R>,
    header: Y4mHeader,
    name: String,
    index: u64,
    line: Vec<u8>,
    failed: bool,
    header_bytes: usize,
}

impl<R: Read> Y4mReader<R> {
    /// Read and check the header. `name` names the stream in messages (`stdin`, a path).
    pub fn new(inner: R, name: impl Into<String>) -> Result<Y4mReader<R>, Y4mError> {
        let name = name.into();
        let mut inner = BufReader::with_capacity(1 << 16, inner);
        let mut line = Vec::new();
        let header_err = |message: String| Y4mError::Header {
            name: name.clone(),
            message,
        };
        (&mut inner)
            .take(MAX_HEADER_BYTES as u64)
            .read_until(b'\n', &mut line)
            .map_err(|source| Y4mError::Io {
                name: name.clone(),
                context: "reading the y4m header".into(),
                source,
            })?;
        if line.is_empty() {
            return Err(header_err(
                "the stream is empty (no YUV4MPEG2 header)".into(),
            ));
        }
        let magic_ok =
            line.starts_with(MAGIC) && matches!(line.get(MAGIC.len()), None | Some(b' ' | b'\n'));
        if !magic_ok || line.last() != Some(&b'\n') {
            let message = if !magic_ok {
                format!(
                    "not a YUV4MPEG2 stream (it starts with \"{}\")",
                    escape(&line[..line.len().min(16)])
                )
            } else if line.len() >= MAX_HEADER_BYTES {
                format!("the header line is longer than {MAX_HEADER_BYTES} bytes")
            } else {
                "the stream ends inside the header line".to_string()
            };
            return Err(header_err(message));
        }
        let header = Y4mHeader::parse(&line).map_err(header_err)?;
        Ok(Y4mReader {
            inner,
            header,
            name,
            index: 0,
            header_bytes: line.len(),
            line,
            failed: false,
        })
    }

    /// The stream's header.
    pub fn header(&self) -> &Y4mHeader {
        &self.header
    }

    /// The stream's name, as given to [`Y4mReader::new`].
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Bytes of the header line, `\n` included.
    pub fn header_bytes(&self) -> usize {
        self.header_bytes
    }

    /// The number of frames of a stream of `total` bytes whose `FRAME` lines have no
    /// parameters (each frame `FRAME\n` and its planes), or `None` when the bytes do
    /// not divide into such frames (a truncated stream, frame parameters).
    pub fn frames_in(&self, total: u64) -> Option<u64> {
        let frame = (FRAME_MAGIC.len() + 1 + self.header.frame_bytes()) as u64;
        let body = total.checked_sub(self.header_bytes as u64)?;
        (body % frame == 0).then_some(body / frame)
    }

    /// Frames read so far (the 0-based number of the next one).
    pub fn frames_read(&self) -> u64 {
        self.index
    }

    /// The next frame, or `None` at a clean end of the stream (right after a frame).
    /// Errors name the frame (0-based): a truncated frame, a malformed `FRAME` line.
    pub fn next_frame(&mut self) -> Result<Option<YuvFrame>, Y4mError> {
        let mut frame = YuvFrame::default();
        Ok(self.read_frame_into(&mut frame)?.then_some(frame))
    }

    /// [`Y4mReader::next_frame`] into an existing frame, reusing its buffers (no
    /// allocation when it already has the right sizes). Returns false at a clean end.
    pub fn read_frame_into(&mut self, frame: &mut YuvFrame) -> Result<bool, Y4mError> {
        let index = self.index;
        let frame_err = |name: &str, message: String| Y4mError::Frame {
            name: name.to_string(),
            frame: index,
            message,
        };
        self.line.clear();
        let n = (&mut self.inner)
            .take(MAX_FRAME_LINE_BYTES as u64)
            .read_until(b'\n', &mut self.line)
            .map_err(|source| self.io_err(source))?;
        if n == 0 {
            return Ok(false);
        }
        let line = &self.line;
        let magic_ok = line.starts_with(FRAME_MAGIC)
            && matches!(line.get(FRAME_MAGIC.len()), Some(b' ' | b'\n') | None);
        if line.last() != Some(&b'\n') || !magic_ok {
            let shown = escape(&line[..line.len().min(24)]);
            let message = if !magic_ok && !FRAME_MAGIC.starts_with(line) {
                format!("expected a `FRAME` line, found \"{shown}\"")
            } else if line.len() >= MAX_FRAME_LINE_BYTES {
                format!("the FRAME line is longer than {MAX_FRAME_LINE_BYTES} bytes")
            } else {
                format!("truncated: the stream ends inside the FRAME line (\"{shown}\")")
            };
            return Err(frame_err(&self.name, message));
        }
        let params = std::str::from_utf8(&line[FRAME_MAGIC.len()..line.len() - 1])
            .map_err(|_| frame_err(&self.name, "the FRAME line is not text".into()))?;
        frame.params.clear();
        frame.params.extend(
            params
                .split(' ')
                .filter(|p| !p.is_empty())
                .map(str::to_string),
        );
        let (yn, cn) = self.header.plane_bytes();
        let total = yn + 2 * cn;
        let mut got = 0;
        for (plane, want) in [(&mut frame.y, yn), (&mut frame.u, cn), (&mut frame.v, cn)] {
            let k = read_plane(&mut self.inner, plane, want).map_err(|source| Y4mError::Io {
                name: self.name.clone(),
                context: format!("reading y4m frame {index} (0-based)"),
                source,
            })?;
            got += k;
            if k < want {
                self.failed = true;
                return Err(frame_err(
                    &self.name,
                    format!("truncated (got {got} of {total} bytes)"),
                ));
            }
        }
        self.index += 1;
        Ok(true)
    }

    fn io_err(&self, source: io::Error) -> Y4mError {
        Y4mError::Io {
            name: self.name.clone(),
            context: format!("reading y4m frame {} (0-based)", self.index),
            source,
        }
    }
}

impl<R: Read> Iterator for Y4mReader<R> {
    type Item = Result<YuvFrame, Y4mError>;

    /// Frames until the end of the stream or the first error (which ends the iteration).
    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let r = self.next_frame().transpose();
        if matches!(r, Some(Err(_))) {
            self.failed = true;
        }
        r
    }
}

/// Fill `buf` with exactly `n` bytes when the stream has them; returns how many were
/// read (fewer at the end of the stream). A buffer that already has length `n` is
/// overwritten in place; otherwise it grows as the data arrives.
fn read_plane<R: Read>(r: &mut R, buf: &mut Vec<u8>, n: usize) -> io::Result<usize> {
    if buf.len() != n {
        buf.clear();
    }
    let mut filled = 0;
    while filled < n {
        if filled == buf.len() {
            let grow = (n - filled).min(READ_CHUNK.max(buf.len()));
            buf.resize(filled + grow, 0);
        }
        match r.read(&mut buf[filled..]) {
            Ok(0) => {
                buf.truncate(filled);
                return Ok(filled);
            }
            Ok(k) => filled += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}
