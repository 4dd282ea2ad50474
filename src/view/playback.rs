//! Sequences in the viewer: numbered frames, a folder, a `.y4m` or video file
//! (`app::OpenedInput`: ffmpeg decodes videos) or a y4m stream on stdin, played
//! through a `gpu::stream::Stream` (the history, future frames and feedback of
//! temporal effects, as in a normal run).
//!
//! Frames decode on a thread of their own. Playing or stepping forward runs the
//! stream one output further. Going back, and planning again (a reload, an effect
//! parameter that changes the passes), starts a new stream at the frame that the
//! shown one's history needs: `history` frames earlier for effects that read
//! earlier input frames, the first frame for feedback effects, so the frame shown
//! is the one a whole normal run writes. A pipe cannot be rewound beyond the frames
//! kept in memory.

use super::fx::Fx;
use crate::app::{FilesSource, FrameSource, OpenedInput, RunError, SourceFrame, StreamInput};
use crate::gpu::executor::{Engine, Prepared};
use crate::gpu::stream::Stream;
use crate::gpu::transfer::{input_format, upload_image};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::io::{Image, IoError, LoadOptions};
use crate::script::types::Format;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Decoded frames kept beyond what the effect's history needs (going back in a pipe).
const EXTRA_KEPT: usize = 8;

/// Where the frames come from.
pub enum SeqInput {
    /// Image files in order.
    Files(Vec<(u64, PathBuf)>),
    /// A `.y4m` file or a video file (decoded by ffmpeg), reopened to go back.
    Stream(StreamInput),
    /// A YUV4MPEG2 stream on stdin.
    Stdin,
}

/// Frames from a decode thread, after those taken from memory (a rewound pipe).
struct Decoder {
    front: VecDeque<(u64, Image)>,
    rx: Receiver<SourceFrame>,
    /// Position of the next frame `rx` gives.
    next: u64,
    stop: Arc<AtomicBool>,
}

impl Drop for Decoder {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn spawn_decoder(mut source: Box<dyn FrameSource>, from: u64) -> Decoder {
    let (tx, rx): (SyncSender<SourceFrame>, _) = std::sync::mpsc::sync_channel(4);
    let stop = Arc::new(AtomicBool::new(false));
    let halt = Arc::clone(&stop);
    std::thread::spawn(move || {
        while let Some(f) = source.next_frame() {
            if halt.load(Ordering::Relaxed) || tx.send(f).is_err() {
                break;
            }
        }
    });
    Decoder {
        front: VecDeque::new(),
        rx,
        next: from,
        stop,
    }
}

impl Decoder {
    /// The next frame and its position; `None` at the end.
    fn next(&mut self) -> Option<Result<(u64, Image), IoError>> {
        if let Some(f) = self.front.pop_front() {
            return Some(Ok(f));
        }
        let f = self.rx.recv().ok()?;
        let n = self.next;
        self.next += 1;
        let name = f.name;
        Some(
            f.image
                .and_then(|p| p.into_image(&name))
                .map(|img| (n, img)),
        )
    }
}

/// A sequence played through the effect.
pub struct Playback {
    input: SeqInput,
    load: LoadOptions,
    pub fps: f64,
    rate: u32,
    output_format: Option<Format>,
    decoder: Option<Decoder>,
    /// The stdin stream's decoder, kept across rewinds (a pipe is read once).
    stdin: Option<Decoder>,
    stream: Option<Stream>,
    /// Position of the first frame pushed into the stream.
    stream_from: u64,
    input_ended: bool,
    stream_ended: bool,
    /// Recent frames by position (rewinding a pipe, the "before" image).
    recent: VecDeque<(u64, Image)>,
    /// Output index shown (input position × rate + subframe).
    shown: Option<u64>,
    /// The size and format of the sequence (from its first frame).
    desc: Option<InputDesc>,
    pub playing: bool,
    last_step: Instant,
    before: Option<(u64, wgpu::Texture, Format)>,
    /// The last output index of the sequence, once the end was reached.
    last: Option<u64>,
}

impl Playback {
    pub fn new(
        input: SeqInput,
        load: LoadOptions,
        fps: f64,
        rate: u32,
        output_format: Option<Format>,
    ) -> Self {
        Playback {
            input,
            load,
            fps,
            rate: rate.max(1),
            output_format,
            decoder: None,
            stdin: None,
            stream: None,
            stream_from: 0,
            input_ended: false,
            stream_ended: false,
            recent: VecDeque::new(),
            shown: None,
            desc: None,
            playing: true,
            last_step: Instant::now(),
            before: None,
            last: None,
        }
    }

    /// The output format: the screenshot's (or `-o`'s), else a file of the input's type.
    pub fn output_format(&self) -> Format {
        self.output_format
            .unwrap_or(match self.desc.as_ref().map(|d| d.format) {
                Some(Format::Rgba16f) => Format::Rgba16f,
                Some(Format::Rgba8) => Format::Rgba8,
                _ => Format::Rgba8Srgb,
            })
    }

    /// A decoder whose first frame is at position `from`.
    fn decoder_from(&mut self, from: u64) -> Result<Decoder, RunError> {
        let load = self.load;
        let source: Box<dyn FrameSource> = match &self.input {
            SeqInput::Files(frames) => {
                let from = (from as usize).min(frames.len());
                Box::new(FilesSource::new(frames[from..].to_vec(), load))
            }
            SeqInput::Stream(input) => OpenedInput::open(input)?.into_source(from, None),
            SeqInput::Stdin => {
                let mut d = match self.stdin.take() {
                    Some(d) => d,
                    None => spawn_decoder(
                        OpenedInput::open(&StreamInput::Stdin)?.into_source(0, None),
                        0,
                    ),
                };
                // Rewind into the frames kept; the live stream continues after them.
                let oldest = self.recent.front().map_or(d.next, |(n, _)| *n);
                if from < oldest && d.next > from {
                    self.stdin = Some(d);
                    return Err(RunError::Other(format!(
                        "stdin is a pipe: frame {from} is gone (frames {oldest} on are kept)"
                    )));
                }
                d.front = self
                    .recent
                    .iter()
                    .filter(|(n, _)| *n >= from)
                    .cloned()
                    .collect();
                return Ok(d);
            }
        };
        Ok(spawn_decoder(source, from))
    }

    /// Give a finished decoder of stdin back (it is reused after a rewind).
    fn keep_stdin(&mut self) {
        if let (SeqInput::Stdin, Some(mut d)) = (&self.input, self.decoder.take()) {
            d.front.clear();
            self.stdin = Some(d);
        }
    }

    /// Start a new stream of `fx`'s effect that shows output `target`: from the frame
    /// its history needs (the first frame for feedback effects).
    pub fn seek(&mut self, engine: &mut Engine, fx: &mut Fx, target: u64) -> Result<(), RunError> {
        let frame = target / self.rate as u64;
        let history = fx.graph().map_or(0, |g| g.history as u64);
        let from = if fx.has_feedback() {
            0
        } else {
            frame.saturating_sub(history)
        };
        self.keep_stdin();
        let mut decoder = self.decoder_from(from)?;
        // The plan needs the sequence's size: its first frame.
        if self.desc.is_none() {
            match decoder.next() {
                Some(Ok((n, img))) => {
                    self.set_desc(&img);
                    decoder.front.push_front((n, img));
                }
                Some(Err(e)) => return Err(e.into()),
                None => return Err(RunError::Other("the sequence has no frames".into())),
            }
        }
        let desc = self.desc.clone().expect("set above");
        let opts = PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(self.output_format()),
        };
        let mut prepared = fx.effect_mut()?.prepare_with(engine, &desc, &opts)?;
        if let Some(old) = self.prepared_ref() {
            let inspect = old.inspected_pass();
            if inspect.is_some_and(|i| i < prepared.plan.passes.len()) {
                let _ = prepared.inspect(inspect);
            }
        }
        prepared.set_gpu_timings(engine, true);
        prepared.fps = self.fps;
        let mut stream = Stream::new(engine, prepared, desc.format);
        stream.rate = self.rate;
        stream.frame_offset = from;
        self.stream = Some(stream);
        self.decoder = Some(decoder);
        self.stream_from = from;
        self.input_ended = false;
        self.stream_ended = false;
        self.shown = None;
        while self.shown.is_none_or(|s| s < target) {
            if !self.advance(engine)? {
                break;
            }
        }
        Ok(())
    }

    fn set_desc(&mut self, img: &Image) {
        let (format, colorspace) = input_format(img, self.load.assume_linear);
        self.desc = Some(InputDesc {
            width: img.width,
            height: img.height,
            format,
            colorspace,
            aux: Vec::new(),
            aux_sizes: Vec::new(),
            viewport: None,
        });
    }

    /// Run the stream one output further; false at the end of the sequence.
    pub fn advance(&mut self, engine: &mut Engine) -> Result<bool, RunError> {
        let rate = self.rate as u64;
        loop {
            let stream = self
                .stream
                .as_mut()
                .ok_or(RunError::Other("no stream".into()))?;
            if let Some(rel) = stream.next(engine)? {
                self.shown = Some(self.stream_from * rate + rel);
                self.last_step = Instant::now();
                return Ok(true);
            }
            if self.input_ended {
                if self.stream_ended {
                    self.last = self.shown;
                    self.playing = false;
                    return Ok(false);
                }
                stream.end();
                self.stream_ended = true;
                continue;
            }
            let decoder = self.decoder.as_mut().expect("made with the stream");
            match decoder.next() {
                None => self.input_ended = true,
                Some(Err(e)) => {
                    self.playing = false;
                    return Err(e.into());
                }
                Some(Ok((n, img))) => {
                    let want = self.desc.as_ref().expect("set by seek");
                    if (img.width, img.height) != (want.width, want.height) {
                        self.playing = false;
                        return Err(RunError::BadInput(IoError::Decode {
                            path: format!("frame {n}").into(),
                            message: format!(
                                "the frame is {}x{}, the sequence started at {}x{}: the frames of a sequence must have one size",
                                img.width, img.height, want.width, want.height
                            ),
                        }));
                    }
                    stream.push_image(engine, &img)?;
                    let keep = stream.ring_len() + EXTRA_KEPT;
                    if self.recent.back().is_none_or(|(m, _)| *m < n) {
                        self.recent.push_back((n, img));
                    }
                    while self.recent.len() > keep {
                        self.recent.pop_front();
                    }
                }
            }
        }
    }

    /// Is the next frame due (playing at `fps` × rate outputs per second)?
    pub fn due(&self) -> bool {
        let period = 1.0 / (self.fps * self.rate as f64);
        self.playing && self.last_step.elapsed() >= Duration::from_secs_f64(period)
    }

    /// Time until the next frame is due, when playing.
    pub fn until_due(&self) -> Option<Duration> {
        let period = Duration::from_secs_f64(1.0 / (self.fps * self.rate as f64));
        self.playing
            .then(|| period.saturating_sub(self.last_step.elapsed()))
    }

    /// Step by `delta` outputs (back: a new stream, see the module's documentation).
    pub fn step(&mut self, engine: &mut Engine, fx: &mut Fx, delta: i64) -> Result<bool, RunError> {
        let shown = self.shown.unwrap_or(0);
        if delta > 0 {
            let mut moved = false;
            for _ in 0..delta {
                moved |= self.advance(engine)?;
            }
            return Ok(moved);
        }
        let target = shown.saturating_sub(delta.unsigned_abs());
        if target == shown {
            return Ok(false);
        }
        self.seek(engine, fx, target)?;
        Ok(true)
    }

    /// The output shown, if any.
    pub fn shown(&self) -> Option<u64> {
        self.shown
    }

    pub fn prepared(&mut self) -> Option<&mut Prepared> {
        self.stream.as_mut().map(|s| &mut s.prepared)
    }

    pub fn prepared_ref(&self) -> Option<&Prepared> {
        self.stream.as_ref().map(|s| &s.prepared)
    }

    /// The output of the frame shown.
    pub fn output(&self) -> Option<(&wgpu::Texture, Format)> {
        let s = self.stream.as_ref()?;
        self.shown?;
        Some((s.output(), s.prepared.plan.output.format))
    }

    /// The input frame of the output shown (uploaded when asked for).
    pub fn before(&mut self, engine: &Engine) -> Option<(&wgpu::Texture, Format)> {
        let pos = self.shown? / self.rate as u64;
        if self.before.as_ref().is_none_or(|(n, _, _)| *n != pos) {
            let (_, img) = self.recent.iter().find(|(n, _)| *n == pos)?;
            let (f, _) = input_format(img, self.load.assume_linear);
            let tex = upload_image(&engine.ctx, "viewer before", img, f).ok()?;
            self.before = Some((pos, tex, f));
        }
        self.before.as_ref().map(|(_, t, f)| (t, *f))
    }

    /// `frame N of M` (and the field with `--rate`).
    pub fn caption(&self) -> String {
        let total = match &self.input {
            SeqInput::Files(f) => Some(f.len() as u64),
            _ => self.last.map(|l| l / self.rate as u64 + 1),
        };
        let name = match &self.input {
            SeqInput::Files(f) => f
                .first()
                .map(|(_, p)| p.parent().unwrap_or(p).display().to_string())
                .unwrap_or_default(),
            SeqInput::Stream(StreamInput::Y4mFile(p) | StreamInput::Video(p)) => {
                p.display().to_string()
            }
            SeqInput::Stream(StreamInput::Stdin) => "stdin".into(),
            SeqInput::Stdin => "stdin".into(),
        };
        let Some(shown) = self.shown else {
            return name;
        };
        let frame = shown / self.rate as u64;
        let of = total.map(|t| format!(" of {t}")).unwrap_or_default();
        let field = if self.rate > 1 {
            format!(", output {} of the frame", shown % self.rate as u64 + 1)
        } else {
            String::new()
        };
        let state = if self.playing { "playing" } else { "paused" };
        format!("{name}: frame {}{of}{field} ({state})", frame + 1)
    }
}
