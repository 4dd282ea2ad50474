//! The audio streams of an input video in an output container: what happens to each
//! one is decided before ffmpeg starts, from ffprobe's codec name and the container
//! ([`Container::copies_audio`]), so an encode never stops at the header of the
//! output (ffmpeg writes it only once the first frames came in) over an audio codec
//! the container cannot hold:
//!
//! - a codec the container holds is copied;
//! - any other is transcoded with the container's encoder (AAC for `.mp4`/`.mov`,
//!   Opus for `.webm`, ...: [`Container::audio_convert`]), or the next one this
//!   ffmpeg has ([`ALTERNATIVES`]); none at all stops the run before the first frame;
//! - a stream ffprobe names no codec for cannot be decoded by this ffmpeg either:
//!   it is dropped, with a note.

use super::container::Container;
use super::probe::OtherStream;

/// What happens to one audio stream of the input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AudioAction {
    /// Copied as it is (`-c:a:K copy`).
    Copy,
    /// Transcoded with `encoder` and its `options` (`-b:a 192k`, ...).
    Convert {
        encoder: &'static str,
        options: &'static [&'static str],
    },
    /// Left out: ffprobe knows no codec for it (nothing can decode it).
    Drop,
}

/// One audio stream of the input and what happens to it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AudioStream {
    /// The stream's index in the input file.
    pub index: usize,
    /// ffprobe's codec name (empty when it has none).
    pub codec: String,
    pub action: AudioAction,
}

/// Encoders (and their options) tried, in order, when this ffmpeg lacks the one of
/// [`Container::audio_convert`]: `.webm` also takes Vorbis.
pub const ALTERNATIVES: &[(&str, &[&[&str]])] = &[("libopus", &[&["libvorbis", "-q:a", "5"]])];

/// Why the audio cannot be written; the caller names the output file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NoEncoder {
    pub index: usize,
    pub codec: String,
    /// The encoders looked for.
    pub tried: Vec<&'static str>,
}

impl std::fmt::Display for NoEncoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "audio stream {} ({}) cannot be stored in this container, and this ffmpeg has no encoder to convert it ({}): write .mkv (it keeps every audio codec)",
            self.index,
            self.codec,
            self.tried.join(", ")
        )
    }
}

/// What happens to each audio stream of `streams` in `container`. `has_encoder`
/// says whether this ffmpeg has an encoder (asked only for streams that are
/// converted, once per encoder name).
pub fn plan_audio(
    container: &Container,
    streams: &[OtherStream],
    mut has_encoder: impl FnMut(&str) -> bool,
) -> Result<Vec<AudioStream>, NoEncoder> {
    let mut known: Vec<(&'static str, bool)> = Vec::new();
    let mut has = |name: &'static str| match known.iter().find(|(n, _)| *n == name) {
        Some((_, h)) => *h,
        None => {
            let h = has_encoder(name);
            known.push((name, h));
            h
        }
    };
    streams
        .iter()
        .map(|s| {
            let action = if s.codec.is_empty() {
                AudioAction::Drop
            } else if container.copies_audio(&s.codec) {
                AudioAction::Copy
            } else {
                let candidates = converters(container);
                match candidates.iter().find(|c| has(c[0])) {
                    Some(c) => AudioAction::Convert {
                        encoder: c[0],
                        options: &c[1..],
                    },
                    None => {
                        return Err(NoEncoder {
                            index: s.index,
                            codec: s.codec.clone(),
                            tried: candidates.iter().map(|c| c[0]).collect(),
                        })
                    }
                }
            };
            Ok(AudioStream {
                index: s.index,
                codec: s.codec.clone(),
                action,
            })
        })
        .collect()
}

/// The container's encoder, then its [`ALTERNATIVES`] (each: the encoder, then its
/// options in pairs).
fn converters(container: &Container) -> Vec<&'static [&'static str]> {
    let Some(first) = container.audio_convert.first() else {
        return Vec::new();
    };
    let mut v = vec![container.audio_convert];
    if let Some((_, more)) = ALTERNATIVES.iter().find(|(e, _)| e == first) {
        v.extend(more.iter().copied());
    }
    v
}

/// `-b:a` for the `k`-th audio output stream: `-b:a:k`; `-ar`: `-ar:a:k`.
pub(super) fn per_stream(opt: &str, kind: char, k: usize) -> String {
    if opt.contains(&format!(":{kind}")) {
        format!("{opt}:{k}")
    } else {
        format!("{opt}:{kind}:{k}")
    }
}

/// The ffmpeg arguments that map and encode `plan`'s streams from input 1, and a
/// note for each stream converted or dropped (`name`: the input file, `ext`: the
/// output's extension).
pub fn audio_args(plan: &[AudioStream], name: &str, ext: &str) -> (Vec<String>, Vec<String>) {
    let mut args = Vec::new();
    let mut notes = Vec::new();
    let mut k = 0;
    for s in plan {
        let (encoder, options) = match &s.action {
            AudioAction::Drop => {
                notes.push(format!(
                    "{name}: audio stream {} has a codec this ffmpeg does not know: dropped",
                    s.index
                ));
                continue;
            }
            AudioAction::Copy => ("copy", &[][..]),
            AudioAction::Convert { encoder, options } => {
                notes.push(format!(
                    "{name}: audio stream {} ({}) is converted to {encoder} for .{ext}",
                    s.index, s.codec
                ));
                (*encoder, *options)
            }
        };
        args.extend(["-map".to_string(), format!("1:{}", s.index)]);
        args.extend([per_stream("-c:a", 'a', k), encoder.to_string()]);
        for pair in options.chunks(2) {
            args.push(per_stream(pair[0], 'a', k));
            args.extend(pair.get(1).map(|v| v.to_string()));
        }
        k += 1;
    }
    (args, notes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn streams(codecs: &[&str]) -> Vec<OtherStream> {
        codecs
            .iter()
            .enumerate()
            .map(|(i, c)| OtherStream {
                index: i + 1,
                codec: c.to_string(),
            })
            .collect()
    }

    fn container(ext: &str) -> &'static Container {
        Container::of_path(Path::new(&format!("out.{ext}"))).unwrap()
    }

    /// The codec each of the six common codecs ends up as, per container (what the
    /// ffprobe matrix of tests/cli/video_audio.rs checks on real files).
    #[test]
    fn each_container_copies_what_it_holds_and_converts_the_rest() {
        let input = ["aac", "flac", "pcm_s16le", "opus", "mp3", "ac3"];
        let all = |_: &str| true;
        for (ext, expected) in [
            ("mp4", ["copy", "aac", "aac", "copy", "copy", "copy"]),
            ("mov", ["copy", "aac", "copy", "aac", "copy", "copy"]),
            ("mkv", ["copy"; 6]),
            (
                "webm",
                [
                    "libopus", "libopus", "libopus", "copy", "libopus", "libopus",
                ],
            ),
        ] {
            let plan = plan_audio(container(ext), &streams(&input), all).unwrap();
            let got: Vec<&str> = plan
                .iter()
                .map(|s| match &s.action {
                    AudioAction::Copy => "copy",
                    AudioAction::Convert { encoder, .. } => encoder,
                    AudioAction::Drop => "drop",
                })
                .collect();
            assert_eq!(got, expected, ".{ext}");
        }
    }

    #[test]
    fn a_missing_encoder_takes_the_next_or_stops_before_the_first_frame() {
        let webm = container("webm");
        let plan = plan_audio(webm, &streams(&["aac"]), |e| e != "libopus").unwrap();
        assert_eq!(
            plan[0].action,
            AudioAction::Convert {
                encoder: "libvorbis",
                options: &["-q:a", "5"]
            }
        );
        let e = plan_audio(webm, &streams(&["aac"]), |_| false).unwrap_err();
        assert_eq!(e.tried, ["libopus", "libvorbis"]);
        assert!(e.to_string().contains("audio stream 1 (aac)"), "{e}");
        // nothing converted: no encoder asked for
        let mut asked = 0;
        plan_audio(webm, &streams(&["opus"]), |_| {
            asked += 1;
            false
        })
        .unwrap();
        assert_eq!(asked, 0);
    }

    #[test]
    fn arguments_number_the_output_streams_and_skip_dropped_ones() {
        let plan = plan_audio(container("mp4"), &streams(&["", "flac", "aac"]), |_| true).unwrap();
        let (args, notes) = audio_args(&plan, "in.mkv", "mp4");
        assert_eq!(
            args.join(" "),
            "-map 1:2 -c:a:0 aac -b:a:0 192k -map 1:3 -c:a:1 copy"
        );
        assert_eq!(
            notes,
            [
                "in.mkv: audio stream 1 has a codec this ffmpeg does not know: dropped",
                "in.mkv: audio stream 2 (flac) is converted to aac for .mp4"
            ]
        );
        let mxf = plan_audio(container("mxf"), &streams(&["aac"]), |_| true).unwrap();
        assert_eq!(
            audio_args(&mxf, "a", "mxf").0.join(" "),
            "-map 1:1 -c:a:0 pcm_s24le -ar:a:0 48000"
        );
    }
}
