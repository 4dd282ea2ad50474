//! Decoding a video file to a y4m stream: `ffmpeg -i IN -map 0:V -f yuv4mpegpipe -`
//! as a child process, its stdout read by [`crate::io::y4m::Y4mReader`].

use super::pix_fmt;
use super::probe::VideoInfo;
use super::process::{file_arg, require, shell_line, status_text, Child};
use super::VideoError;
use std::process::{ChildStdout, Stdio};

/// An ffmpeg child decoding the video stream of a file to y4m on its stdout.
pub struct Decoder {
    child: Child,
    info: VideoInfo,
    line: String,
}

/// The ffmpeg arguments [`Decoder::spawn`] uses: the video stream `info.index`,
/// converted to the planar format of its layout and depth (`yuv420p10le`), at a
/// constant frame rate; `-strict -1` lets ffmpeg write the y4m formats above 8 bits.
pub fn decode_args(info: &VideoInfo) -> Vec<String> {
    let depth = pix_fmt::y4m_depth(info.layout, info.depth);
    // `-copyts`: ffmpeg's constant-rate output then starts at the first frame instead
    // of padding from the file's start with copies of it (a video stream starting
    // after the audio), and still fills gaps of variable-rate video.
    let mut a: Vec<String> = [
        "-hide_banner",
        "-nostdin",
        "-loglevel",
        "error",
        "-copyts",
        "-i",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.push(file_arg(&info.path));
    for s in [
        "-map".to_string(),
        format!("0:{}", info.index),
        "-an".into(),
        "-sn".into(),
        "-dn".into(),
        "-pix_fmt".into(),
        pix_fmt::name(info.layout, depth),
        "-strict".into(),
        "-1".into(),
        "-f".into(),
        "yuv4mpegpipe".into(),
        "-".into(),
    ] {
        a.push(s);
    }
    a
}

impl Decoder {
    /// Start ffmpeg on the file `info` describes (from [`super::probe`]).
    pub fn spawn(info: &VideoInfo) -> Result<Decoder, VideoError> {
        let ffmpeg = require("ffmpeg", &info.path)?;
        let args = decode_args(info);
        let line = shell_line("ffmpeg", &args);
        let child = Child::spawn("ffmpeg", &ffmpeg, &args, Stdio::null(), Stdio::piped()).map_err(
            |source| VideoError::Io {
                path: info.path.clone(),
                program: "ffmpeg",
                source,
            },
        )?;
        Ok(Decoder {
            child,
            info: info.clone(),
            line,
        })
    }

    /// The command line run (for `-v`).
    pub fn command_line(&self) -> &str {
        &self.line
    }

    /// The file's streams.
    pub fn info(&self) -> &VideoInfo {
        &self.info
    }

    /// The y4m stream (once: later calls give `None`).
    pub fn take_stdout(&mut self) -> Option<ChildStdout> {
        self.child.child.stdout.take()
    }

    /// Wait for ffmpeg after its stream ended (or was found broken). An exit status
    /// other than 0 is the file's fault ([`VideoError::Input`], with ffmpeg's last
    /// stderr lines); on success its stderr lines (warnings) are logged.
    pub fn finish(&mut self) -> Result<(), VideoError> {
        let status = self.child.wait().map_err(|source| VideoError::Io {
            path: self.info.path.clone(),
            program: "ffmpeg",
            source,
        })?;
        if !status.success() {
            return Err(self.failure(status));
        }
        self.child.log_stderr("decoding");
        Ok(())
    }

    /// The y4m stream was found broken (a truncated or malformed frame): if ffmpeg
    /// ends with an error within a short while, that error (the stream broke because
    /// ffmpeg failed); otherwise ffmpeg is ended and `None` (the stream's own error
    /// stands).
    pub fn failure_after_broken_stream(&mut self) -> Option<VideoError> {
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
        while std::time::Instant::now() < deadline {
            if let Some(status) = self.child.try_status() {
                return (!status.success()).then(|| self.failure(status));
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        self.child.kill();
        None
    }

    /// The error of an ffmpeg that ended with `status`, with its last stderr lines.
    fn failure(&self, status: std::process::ExitStatus) -> VideoError {
        VideoError::Input {
            path: self.info.path.clone(),
            message: format!(
                "ffmpeg could not decode the video ({}):\n{}",
                status_text(status),
                self.child.tail()
            ),
        }
    }

    /// End ffmpeg now (the run stopped before the end of the video).
    pub fn stop(&mut self) {
        self.child.kill();
    }
}
