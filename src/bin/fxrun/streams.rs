//! `fxrun`: y4m and video streams as a sequence's input or output: `-i -`, `-i in.y4m`,
//! `-i in.mkv` (decoded by ffmpeg), `-o -`, `-o out.y4m`, `-o out.mp4` (encoded by
//! ffmpeg, with the input video's audio and subtitles).

use super::*;
use fxgraph::app::{
    open_output, OpenedInput, OpenedOutput, OutputSettings, StreamInput, StreamOutput,
};
use fxgraph::graph::Override;
use fxgraph::io::color_option::{ColorOverride, OutputColor};
use fxgraph::io::video::HdrMetadata;
use fxgraph::io::video::{MediaSource, VideoInfo};
use fxgraph::io::y4m::{Chroma, Interlace, Y4mHeader, YuvConversion};
use std::path::Path;

/// The stream an `-i` argument names, if it is one.
pub(crate) fn stream_input(spec: &SequenceSpec) -> Option<StreamInput> {
    match spec {
        SequenceSpec::Stdin => Some(StreamInput::Stdin),
        SequenceSpec::Y4m(p) => Some(StreamInput::Y4mFile(p.clone())),
        SequenceSpec::Video(p) => Some(StreamInput::Video(p.clone())),
        _ => None,
    }
}

/// The stream an `-o` argument names, if it is one.
pub(crate) fn stream_output(spec: &SequenceSpec) -> Option<StreamOutput> {
    match spec {
        SequenceSpec::Stdout => Some(StreamOutput::Stdout),
        SequenceSpec::Y4m(p) => Some(StreamOutput::Y4mFile(p.clone())),
        SequenceSpec::Video(p) => Some(StreamOutput::Video(p.clone())),
        _ => None,
    }
}

/// Open an input stream, printing the commands run with `-v`; `--input-color`
/// applied, and the doubts about its colour printed.
pub(crate) fn open_input(cli: &Cli, input: &StreamInput) -> Result<OpenedInput, Fail> {
    let mut opened = OpenedInput::open(input)?;
    if cli.verbose {
        for c in &opened.commands {
            eprintln!("fxrun: running: {c}");
        }
    }
    let name = match input {
        StreamInput::Stdin => "stdin".to_string(),
        StreamInput::Y4mFile(p) | StreamInput::Video(p) => p.display().to_string(),
    };
    match &cli.input_color {
        Some(spec) => {
            let o: ColorOverride = spec
                .parse()
                .map_err(|e| rejected(format!("--input-color {spec}: {e}")))?;
            o.apply(&mut opened.conversion);
        }
        None => {
            for w in &opened.color_warnings {
                eprintln!("fxrun: warning: {name}: {w}");
            }
            if opened.color_is_ambiguous() {
                eprintln!(
                    "fxrun: warning: {name}: a {}-bit y4m stream says nothing of its colour: read as SDR (sRGB curve, BT.709); if it is HDR, say so with --input-color transfer=pq (or hlg),primaries=bt2020",
                    opened.header.depth
                );
            }
        }
    }
    if opened.is_hdr() && opened.hdr_metadata().is_empty() && cli.verbose {
        eprintln!(
            "fxrun: note: {name}: no mastering-display or content-light metadata: tonemap measures each frame's peak"
        );
    }
    Ok(opened)
}

/// `--input-color` and `--output-color` are for streams (y4m, video): refused for
/// image inputs and outputs, where they would do nothing.
pub(crate) fn check_color_options(
    cli: &Cli,
    input_stream: bool,
    output_stream: bool,
) -> Result<(), Fail> {
    if cli.input_color.is_some() && !input_stream {
        return Err(rejected(
            "--input-color is for y4m and video inputs (image files say their own colour: EXR is linear, PNG sRGB or its cICP)",
        ));
    }
    if cli.output_color.is_some() && !output_stream {
        return Err(rejected(
            "--output-color is for y4m and video outputs (EXR outputs are linear working space; 8/16-bit images are sRGB)",
        ));
    }
    Ok(())
}

/// The HDR defaults of `tonemap` for an HDR input: the BT.2390 EETF unless an
/// operator was set, and the source peak from the metadata (else measured per
/// frame). Returns the `--set` list to compile the effects with.
pub(crate) fn hdr_tonemap_sets(cli: &Cli, peak: Option<f32>) -> Vec<Override> {
    let mut set = cli.set.clone();
    if !has_tonemap(cli) {
        return set;
    }
    let given = |key: &str| cli.set.iter().any(|o| o.name() == key);
    if !given("operator") {
        set.push(Override::parse("tonemap.operator=bt2390"));
    }
    if let (false, Some(p)) = (given("source_peak"), peak) {
        set.push(Override::parse(&format!("tonemap.source_peak={p}")));
    }
    set
}

/// Whether the effect chain has `tonemap` (or `tonemap_video`): its output, and
/// everything after it, is display-referred SDR.
pub(crate) fn has_tonemap(cli: &Cli) -> bool {
    cli.effects.iter().any(|e| {
        let stem = Path::new(e)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(e);
        stem == "tonemap" || stem == "tonemap_video"
    })
}

/// The effects for an HDR video: the built-in `tonemap` as `tonemap_video` (the
/// same effect, its measured peak smoothed over frames and reset at scene cuts).
pub(crate) fn video_tonemap(effects: &[String]) -> Vec<String> {
    effects
        .iter()
        .map(|e| {
            if e == "tonemap" {
                "tonemap_video".to_string()
            } else {
                e.clone()
            }
        })
        .collect()
}

/// A frame rate as a y4m ratio: 30 → 30:1; the NTSC rates n / 1.001, exact or as
/// typed (29.97, 59.94, 23.976) → 30000:1001, 60000:1001, 24000:1001; others in
/// thousandths (12.5 → 12500:1000).
pub(crate) fn fps_ratio(fps: f64) -> (u32, u32) {
    let whole = |x: f64, tol: f64| (x - x.round()).abs() < tol && x.round() <= 4e6;
    if whole(fps, 1e-6) {
        return (fps.round() as u32, 1);
    }
    let ntsc = fps * 1.001;
    if whole(ntsc, 1e-3) {
        return (ntsc.round() as u32 * 1000, 1001);
    }
    ((fps * 1000.0).round() as u32, 1000)
}

/// With `--skip-existing` and an existing `.y4m` or video output: says so and returns
/// true (the run is skipped; one file is written whole, never resumed).
pub(crate) fn skip_whole_file(cli: &Cli, ospec: &SequenceSpec) -> bool {
    if let (true, SequenceSpec::Y4m(p) | SequenceSpec::Video(p)) = (cli.skip_existing, ospec) {
        if std::fs::symlink_metadata(p).is_ok() {
            eprintln!(
                "fxrun: {} exists already; nothing to do (--skip-existing skips a whole y4m or video file: it cannot resume one)",
                p.display()
            );
            return true;
        }
    }
    false
}

/// A sequence run's end: an interrupted run fails (exit code 130) with a message
/// saying what it left of its output.
pub(crate) fn check_interrupted(
    report: &fxgraph::app::RunReport,
    ospec: &SequenceSpec,
) -> Result<(), Fail> {
    if !report.interrupted {
        return Ok(());
    }
    let hint = match ospec {
        SequenceSpec::Stdout => "the y4m stream on stdout ends after the last whole frame (--skip-existing does not apply to a stream)".to_string(),
        SequenceSpec::Y4m(p) | SequenceSpec::Video(p) => format!(
            "{} was not written (a partial file is not kept; an existing one is untouched)",
            p.display()
        ),
        _ => "completed frames are intact (rerun with --skip-existing to resume)".to_string(),
    };
    Err(Fail {
        code: 130,
        message: format!("interrupted after {} frames; {hint}", report.done.len()),
    })
}

/// What the output stream passes on from the input.
pub(crate) struct StreamPlan<'a> {
    /// The input stream's header and conversion (a y4m or video input).
    pub(crate) template: Option<(Y4mHeader, YuvConversion)>,
    /// The input video, for its audio, subtitles and colour tags.
    pub(crate) video: Option<&'a VideoInfo>,
    /// Frames per second of the input.
    pub(crate) fps: f64,
    /// The input frames written (`--frames`), as 0-based stream positions.
    pub(crate) emit: Option<(u64, u64)>,
    /// The effect deinterlaces (its output is progressive).
    pub(crate) deinterlaces: bool,
    /// The effect chain's output is display-referred (it has `tonemap`).
    pub(crate) display_referred: bool,
    /// The input's HDR metadata (video inputs).
    pub(crate) hdr: HdrMetadata,
}

/// The output's signal: `--output-color`, else SDR for a display-referred chain
/// from an HDR input, else the input's. Returns the conversion, the depth to write
/// (`--bit-depth` over the signal's default over the input's) and whether the tags
/// must be named after the signal (it is not the input's).
fn output_signal(
    cli: &Cli,
    plan: &StreamPlan,
    conversion: YuvConversion,
    input_depth: u8,
) -> Result<(YuvConversion, u8, bool), Fail> {
    let forced = match &cli.output_color {
        Some(s) => Some(
            s.parse::<OutputColor>()
                .map_err(|e| rejected(format!("--output-color {e}")))?,
        ),
        None => None,
    };
    let choice = forced.or_else(|| {
        (plan.display_referred && conversion.color.transfer.is_hdr()).then_some(OutputColor::Sdr)
    });
    Ok(match choice {
        Some(c) => {
            let (conv, depth) = c.conversion(&conversion);
            let same = conv.color == conversion.color && conv.matrix == conversion.matrix;
            let depth = if same { input_depth.max(depth) } else { depth };
            (conv, cli.bit_depth.unwrap_or(depth), !same)
        }
        None => (conversion, cli.bit_depth.unwrap_or(input_depth), false),
    })
}

/// Open an output stream: the input's header (rate times `--rate`, interlacing,
/// aspect, layout, `X` fields) or a 4:2:0 one at `--fps`; the depth from `--bit-depth`
/// or the input's; for a video, the encoder options and the input video's audio and
/// subtitles. Prints the encoder's command with `-v` and its notes.
pub(crate) fn open_stream_output(
    cli: &Cli,
    output: &StreamOutput,
    plan: &StreamPlan,
) -> Result<OpenedOutput, Fail> {
    let video_out = matches!(output, StreamOutput::Video(_));
    if !video_out {
        check_no_video_options(cli, output)?;
    }
    let (mut header, conversion) = match plan.template.clone() {
        Some(t) => t,
        None => {
            let mut h = Y4mHeader::new(1, 1, Chroma::C420Jpeg);
            h.fps = fps_ratio(plan.fps);
            let c = YuvConversion::for_header(&h);
            (h, c)
        }
    };
    header.fps = (header.fps.0.max(1) * cli.rate, header.fps.1.max(1));
    if cli.rate > 1 || plan.deinterlaces {
        header.interlace = Interlace::Progressive;
    }
    let (conversion, depth, retag) = output_signal(cli, plan, conversion, header.depth)?;
    header
        .set_depth(depth)
        .map_err(|m| rejected(format!("--bit-depth {depth}: {m}")))?;
    let mut settings = OutputSettings::new(header, conversion);
    if video_out {
        set_video_options(cli, plan, &mut settings, conversion, retag);
    } else if let Some(v) = plan.video {
        let n = v.audio.len() + v.subtitles.len();
        if n > 0 {
            eprintln!(
                "fxrun: note: {}: its audio and subtitles ({n} stream(s)) are not written to {} (a video file output keeps them)",
                v.path.display(),
                output.name()
            );
        }
    }
    let opened = open_output(output, &settings)?;
    if cli.verbose {
        for c in &opened.commands {
            eprintln!("fxrun: running: {c}");
        }
    }
    for n in &opened.notes {
        eprintln!("fxrun: note: {n}");
    }
    Ok(opened)
}

/// Refuses the video encoder options for an output that is not a video file.
fn check_no_video_options(cli: &Cli, output: &StreamOutput) -> Result<(), Fail> {
    let given = [
        ("--codec", cli.codec.is_some()),
        ("--crf", cli.crf.is_some()),
        ("--preset", cli.preset.is_some()),
        ("--pix-fmt", cli.pix_fmt.is_some()),
    ];
    if let Some((name, _)) = given.iter().find(|g| g.1) {
        return Err(rejected(format!(
            "{name} is for video file outputs (.mp4, .mkv, ...), not for {}",
            output.name()
        )));
    }
    Ok(())
}

/// The encoder options of a video file output, its colour tags and HDR metadata, and
/// the input video whose audio and subtitles it keeps (the slice written).
fn set_video_options(
    cli: &Cli,
    plan: &StreamPlan,
    settings: &mut OutputSettings,
    conversion: YuvConversion,
    retag: bool,
) {
    settings.codec = cli.codec.clone();
    settings.crf = cli.crf;
    settings.preset = cli.preset.clone();
    settings.pix_fmt = cli.pix_fmt.clone();
    if conversion.color.transfer.is_hdr() && !retag {
        settings.hdr = Some(plan.hdr).filter(|h| !h.is_empty());
    }
    // Tags say what the pixels are: named after the signal, except SDR video
    // read with the sRGB curve, whose own tags are kept.
    if retag || !conversion.color.is_srgb() {
        settings.tag_signal();
    } else if let Some(v) = plan.video {
        settings.primaries = v.color_primaries.clone();
        settings.transfer = v.color_transfer.clone();
    }
    if let Some(v) = plan.video {
        let fps = if v.fps.1 > 0 {
            v.fps.0 as f64 / v.fps.1 as f64
        } else {
            plan.fps
        };
        let (start, duration) = match plan.emit {
            Some((a, b)) => (
                a as f64 / fps,
                (b != u64::MAX).then(|| (b - a + 1) as f64 / fps),
            ),
            None => (0.0, None),
        };
        settings.media = Some(MediaSource {
            info: v.clone(),
            start,
            duration,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::fps_ratio;

    #[test]
    fn frame_rates_as_ratios() {
        assert_eq!(fps_ratio(25.0), (25, 1));
        assert_eq!(fps_ratio(29.97), (30000, 1001));
        assert_eq!(fps_ratio(30000.0 / 1001.0), (30000, 1001));
        assert_eq!(fps_ratio(23.976), (24000, 1001));
        assert_eq!(fps_ratio(59.94), (60000, 1001));
        assert_eq!(fps_ratio(12.5), (12500, 1000));
        assert_eq!(fps_ratio(1000.0), (1000, 1));
    }
}
