//! `fxrun`: the command line: every option, under its `--help` heading.

use clap::Parser;
use std::path::PathBuf;

/// Largest `--queue`: frames held between the stages.
const MAX_QUEUE: u64 = 64;
/// Largest `--lights`: random point lights added to a scene.
const MAX_LIGHTS: u64 = 100_000;
/// Largest `--warmup`: frames run before the first written one.
const MAX_WARMUP: u64 = 1_000_000;

/// `--help` headings: every option is under one.
const IMAGES: &str = "Images and batches";
const SEQUENCES: &str = "Sequences";
const SCENES: &str = "Scenes (deferred renderer)";
const VIDEO: &str = "Video files (through ffmpeg)";
const ANALYSIS: &str = "Analysis";
const VIEWER: &str = "Viewer";
const OUTPUT: &str = "Output";
const COMMON: &str = "Common";

#[derive(Parser, Debug, Clone)]
#[command(
    name = "fxrun",
    version,
    disable_help_flag = true,
    disable_version_flag = true,
    about = "Apply declarative filter-graph effects (EFFECT scripts) to images on the GPU",
    after_help = "EFFECT is a path to an .fx file or a built-in effect name (see --list).\n\
Examples:\n  fxrun glow -i photo.png -o glow.png\n  fxrun glow -i photos/ -o out/            (a batch: every image, names kept)\n  fxrun gaussian_blur --set sigma=8 -i in.png -o out.png --timings\n  fxrun effects/glow.fx --check\n  fxrun glow --plan --size 1920x1080 --json\n\n\
Exit codes: 0 ok, 1 input rejected, 2 I/O, GPU or internal error."
)]
pub(crate) struct Cli {
    /// Effects to apply in order (paths to .fx files or built-in names).
    pub(crate) effects: Vec<String>,
    /// Print help (-h: short, --help: long).
    #[arg(short, long, action = clap::ArgAction::Help, help_heading = COMMON)]
    pub(crate) help: Option<bool>,
    /// Print the version.
    #[arg(short = 'V', long, action = clap::ArgAction::Version, help_heading = COMMON)]
    pub(crate) version: Option<bool>,
    /// Input image(s): a file, a folder of images, a wildcard pattern in quotes
    /// ('photos/*.jpg'), a numbered sequence (in/%04d.png), a .y4m file, a video file
    /// (.mp4, .mkv, ...: read with ffmpeg) or - (y4m on stdin). Takes
    /// every value up to the next option (-i a.jpg b.jpg, or a shell's photos/*.jpg),
    /// and may be repeated: so give the effects before -i.
    #[arg(help_heading = IMAGES, short, long, value_name = "INPUT", num_args = 1.., action = clap::ArgAction::Append)]
    pub(crate) input: Vec<PathBuf>,
    /// Output: an image file (format from the extension), a folder (a batch keeps each
    /// input's name and format), a numbered pattern (out/%04d.png), a .y4m file, a
    /// video file (.mp4, .mkv, ...: written with ffmpeg, with the input video's audio)
    /// or - (y4m on stdout).
    #[arg(help_heading = OUTPUT, short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Batches: the file format of -o DIR outputs (an extension: png, jpg, exr...)
    /// instead of each input's own.
    #[arg(help_heading = OUTPUT, long, value_name = "EXT")]
    pub(crate) format: Option<String>,
    /// Batches: go on after an image fails (exit 1 at the end if any failed); by
    /// default the batch stops at the first failed image.
    #[arg(help_heading = IMAGES, long)]
    pub(crate) keep_going: bool,
    /// Keep running after an image, batch or file-sequence run and re-run it when
    /// the effect, an INCLUDEd .fx, a shader (or its #include) or the input image
    /// changes; errors are printed and the watch goes on. An input folder is a hot
    /// folder: new and changed images in it are processed. Not for streams, --scene
    /// or the analysis modes. Ctrl-C ends it (status 0).
    #[arg(long, help_heading = COMMON)]
    pub(crate) watch: bool,
    /// Notes: files skipped in an input folder, each image written, automatic
    /// conversions.
    #[arg(help_heading = COMMON, short, long)]
    pub(crate) verbose: bool,
    /// Set a parameter: NAME=VALUE (effect), EFFECT.NAME=VALUE, or PASS.NAME=VALUE.
    #[arg(help_heading = COMMON, long = "set", value_name = "NAME=VALUE")]
    pub(crate) set: Vec<fxgraph::graph::Override>,
    /// An auxiliary input image: NAME=FILE (read by AUX.NAME).
    #[arg(help_heading = IMAGES, long = "aux", value_name = "NAME=FILE")]
    pub(crate) aux: Vec<String>,
    /// Bits per channel of the output file (8, 16, 32 where the format allows); of a
    /// y4m or video output, bits per sample (8, 9, 10, 12, 14, 16; default: the
    /// input stream's).
    #[arg(help_heading = OUTPUT, long)]
    pub(crate) bit_depth: Option<u8>,
    /// Treat 8/16-bit files as linear data (no sRGB decode on load or encode on save).
    #[arg(help_heading = IMAGES, long)]
    pub(crate) assume_linear: bool,
    /// Print one row per pass and the run's time split.
    #[arg(help_heading = OUTPUT, long)]
    pub(crate) timings: bool,
    /// Write the timings as JSON to FILE.
    #[arg(help_heading = OUTPUT, long, value_name = "FILE")]
    pub(crate) timings_json: Option<PathBuf>,
    /// Only check the effect: print diagnostics, exit 0 (warnings allowed) or 1.
    #[arg(help_heading = ANALYSIS, long)]
    pub(crate) check: bool,
    /// Write the graph as Graphviz DOT to FILE (`-` for stdout).
    #[arg(help_heading = ANALYSIS, long, value_name = "FILE", value_parser = clap::builder::NonEmptyStringValueParser::new())]
    pub(crate) dot: Option<String>,
    /// Print the schedule, the texture lifetime steps and the memory figures.
    #[arg(help_heading = ANALYSIS, long)]
    pub(crate) plan: bool,
    /// WxH: the size of a rendered --scene (1280x720); with -i INPUT, the
    /// viewport passes scale from (a slang preset's output size; the input's by
    /// default); or the input size --plan/--dot/--check assume (1920x1080).
    #[arg(help_heading = COMMON, long, value_name = "WxH")]
    pub(crate) size: Option<String>,
    /// With --plan: one JSON object on stdout.
    #[arg(help_heading = ANALYSIS, long)]
    pub(crate) json: bool,
    /// Texture reuse policy for --plan: min-peak (default) or pool.
    #[arg(help_heading = ANALYSIS, long, default_value = "min-peak")]
    pub(crate) policy: String,
    /// List the built-in effects.
    #[arg(help_heading = ANALYSIS, long)]
    pub(crate) list: bool,
    /// List the effect's passes and parameters.
    #[arg(help_heading = ANALYSIS, long)]
    pub(crate) describe: bool,
    /// List the GPU adapters.
    #[arg(help_heading = ANALYSIS, long)]
    pub(crate) adapters: bool,
    /// Pick an adapter by index (see --adapters) or by part of its name.
    #[arg(help_heading = COMMON, long)]
    pub(crate) adapter: Option<String>,
    /// How passes run: `fragment` (full-screen render passes), `compute`
    /// (compute dispatches of the same shaders), or `auto`: fragment on CPU
    /// adapters (lavapipe) and GL, compute on other GPUs.
    #[arg(help_heading = COMMON, long, value_name = "auto|fragment|compute", default_value = "auto")]
    pub(crate) execution: String,
    /// Where y4m and video frames are converted between Y'CbCr and RGB: `gpu`
    /// (compute passes on the device), `cpu`, or `auto`: the GPU except on CPU
    /// adapters (lavapipe), where the CPU conversion costs less.
    #[arg(help_heading = SEQUENCES, long, value_name = "auto|cpu|gpu", default_value = "auto")]
    pub(crate) ycbcr: String,
    /// Sequences: only write the outputs of input frames A to B (inclusive);
    /// history/future frames outside the range are still read.
    #[arg(help_heading = SEQUENCES, long, value_name = "A..B")]
    pub(crate) frames: Option<String>,
    /// Sequences: frames per second (the `time` shaders see; y4m input sets it).
    #[arg(help_heading = SEQUENCES, long)]
    pub(crate) fps: Option<f64>,
    /// Sequences: outputs per input frame (2 for field-rate deinterlacing).
    #[arg(help_heading = SEQUENCES, long, default_value_t = 1)]
    pub(crate) rate: u32,
    /// Sequences: frames before --frames to run without writing, so feedback
    /// effects warm up (at most 1000000).
    #[arg(help_heading = SEQUENCES, long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_WARMUP))]
    pub(crate) warmup: u64,
    /// Sequences and batches: skip frames (images) whose output file exists (resume an
    /// interrupted run).
    #[arg(help_heading = IMAGES, long)]
    pub(crate) skip_existing: bool,
    /// Sequences and batches: frames (images) queued between decode, GPU and encode
    /// (1 to 64).
    #[arg(help_heading = IMAGES, long, default_value_t = 3,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=MAX_QUEUE))]
    pub(crate) queue: usize,
    /// Video output: the ffmpeg encoder (default libx264, libvpx-vp9 for .webm).
    #[arg(help_heading = VIDEO, long, value_name = "NAME")]
    pub(crate) codec: Option<String>,
    /// Video output: constant-quality factor (libx264 18, libx265 20, VP9 24 by
    /// default; lower is better).
    #[arg(help_heading = VIDEO, long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=63))]
    pub(crate) crf: Option<u32>,
    /// Video output: the encoder's speed preset (libx264/libx265: ultrafast ...
    /// veryslow; default medium).
    #[arg(help_heading = VIDEO, long, value_name = "NAME")]
    pub(crate) preset: Option<String>,
    /// Video output: the pixel format (default yuv420p, yuv420p10le above 8 bits).
    #[arg(help_heading = VIDEO, long, value_name = "NAME")]
    pub(crate) pix_fmt: Option<String>,
    /// Streams: what the input's frames are, over its tags (y4m has none):
    /// transfer=pq|hlg|bt1886|srgb|linear, primaries=bt709|bt2020|p3,
    /// matrix=bt601|bt709|bt2020, range=limited|full, peak=CD/M2 (HLG display).
    /// An HDR transfer alone implies BT.2020 primaries and matrix.
    #[arg(help_heading = VIDEO, long, value_name = "KEY=VALUE,...")]
    pub(crate) input_color: Option<String>,
    /// Streams: write the output as hdr10 (PQ, BT.2020), hlg or sdr (BT.709,
    /// BT.1886). Default: SDR after `tonemap`, else the input's colour.
    #[arg(help_heading = VIDEO, long, value_name = "hdr10|hlg|sdr")]
    pub(crate) output_color: Option<String>,
    /// Render a scene with the deferred renderer as the effect input:
    /// builtin:room, builtin:bench, or a .gltf/.glb file (size from --size).
    #[arg(help_heading = SCENES, long, value_parser = clap::builder::NonEmptyStringValueParser::new())]
    pub(crate) scene: Option<String>,
    /// Scene camera: a glTF camera index or name (it moves with its animated
    /// node; name:NAME for any name, even `orbit`), eye=x,y,z;target=x,y,z;fov=deg,
    /// or orbit[:period=S,elevation=DEG,start=DEG,distance=D,fov=DEG] around the
    /// scene's bounds.
    #[arg(help_heading = SCENES, long)]
    pub(crate) camera: Option<String>,
    /// Scene: render the scene at this time in seconds (0 or more); with
    /// --frames A..B, frame n is rendered at n / --fps (default 30) as a sequence.
    #[arg(help_heading = SCENES, long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub(crate) time: Option<f64>,
    /// Scene: which glTF animations play: all (default), none, an index or a name.
    #[arg(help_heading = SCENES, long, value_name = "NAME|INDEX|all|none")]
    pub(crate) animation: Option<String>,
    /// Scene: loop the animations (the clock wraps at the longest one's end);
    /// without it, times after the last key hold the last pose.
    #[arg(help_heading = SCENES, long = "loop")]
    pub(crate) looping: bool,
    /// Scene: add N random point lights (at most 100000).
    #[arg(help_heading = SCENES, long, default_value_t = 0,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=MAX_LIGHTS))]
    pub(crate) lights: usize,
    /// Scene: seed of the random lights.
    #[arg(help_heading = SCENES, long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Scene: deferred (default), light-prepass or forward.
    #[arg(help_heading = SCENES, long, default_value = "deferred")]
    pub(crate) renderer: String,
    /// Scene: write every G-buffer image into DIR.
    #[arg(help_heading = SCENES, long, value_name = "DIR")]
    pub(crate) gbuffer: Option<PathBuf>,
    /// Scene: a file of MATERIAL definitions; a definition named like a scene
    /// material replaces it (docs/materials.md).
    #[arg(help_heading = SCENES, long, value_name = "FILE")]
    pub(crate) materials: Option<PathBuf>,
    /// Scene: SCENE_MATERIAL=DEFINITION: use a definition of --materials for a scene
    /// material (`*` for all of them). Repeatable.
    #[arg(help_heading = SCENES, long = "material", value_name = "NAME=DEF")]
    pub(crate) material: Vec<String>,
    /// Scene: how material features select code: preprocess (#ifdef variants,
    /// default), override (pipeline constants) or branch (run-time branches).
    #[arg(help_heading = SCENES, long, default_value = "preprocess")]
    pub(crate) variants: String,
    /// Scene: how the light passes pick each pixel's lights: clustered (tiles ×
    /// depth slices, default), volumes (a sphere or cone per light) or none
    /// (every light at every pixel).
    #[arg(help_heading = SCENES, long, default_value = "clustered")]
    pub(crate) light_culling: String,
    /// Scene: how deferred shading fills the G-buffer: fat (one raster pass
    /// runs the surface shaders, default) or visibility (depth and a triangle
    /// id per pixel, materials resolved in compute; docs/renderer.md).
    #[arg(help_heading = SCENES, long, default_value = "fat")]
    pub(crate) gbuffer_layout: String,
    /// Scene: fog in the lighting template, KEY=VALUE with the `fog` effect's
    /// parameters (mode, distance, color, density, start, end, height_falloff,
    /// fog_height), or `on` for its defaults. Repeatable.
    #[arg(help_heading = SCENES, long, value_name = "KEY=VALUE")]
    pub(crate) fog: Vec<String>,
    /// Scene: list each material (surface and lighting shader, variant features)
    /// and the pipelines compiled.
    #[arg(help_heading = SCENES, long)]
    pub(crate) describe_materials: bool,
    /// Scene: add ambient light of this radiance (V or R,G,B, linear); a scene
    /// otherwise renders only the lights it has.
    #[arg(help_heading = SCENES, long, value_name = "RGB")]
    pub(crate) ambient: Option<String>,
    /// Scene: shadow maps for the scene's lights: off, hard (one depth
    /// comparison) or pcf (filtered, default).
    #[arg(help_heading = SCENES, long, default_value = "pcf")]
    pub(crate) shadows: String,
    /// Scene: side of each shadow map in texels (256 to 8192, and the GPU's limit).
    #[arg(help_heading = SCENES, long, value_name = "N", default_value_t = fxgraph::render::renderer::DEFAULT_SHADOW_SIZE)]
    pub(crate) shadow_size: u32,
    /// Scene: image-based lighting from an equirectangular map of linear
    /// radiance (.exr, .hdr; Blender's and the glTF Sample Viewer's mapping),
    /// builtin:studio (the default), builtin:sky (with its sun), uniform:R,G,B,
    /// or none (the scene's lights only).
    #[arg(help_heading = SCENES, long, value_name = "FILE|builtin:NAME|none")]
    pub(crate) environment: Option<String>,
    /// Scene: multiplies the environment's radiance (not a sky's sun).
    #[arg(help_heading = SCENES, long, value_name = "X", default_value_t = 1.0, allow_negative_numbers = true)]
    pub(crate) environment_intensity: f32,
    /// Scene: turns the environment about +Y by DEGREES (+X towards -Z for 90).
    #[arg(help_heading = SCENES, long, value_name = "DEGREES", default_value_t = 0.0, allow_negative_numbers = true)]
    pub(crate) environment_rotation: f32,
    /// Scene: builtin:sky's sun as ELEVATION,AZIMUTH in degrees (azimuth 0
    /// towards +X, 90 towards +Z); default 40,120.
    #[arg(help_heading = SCENES, long, value_name = "ELEV,AZIM", allow_hyphen_values = true)]
    pub(crate) sun: Option<String>,
    /// Scene: builtin:sky's atmospheric turbidity, 1.7 (clear) to 10 (hazy);
    /// default 3.
    #[arg(help_heading = SCENES, long, value_name = "T")]
    pub(crate) turbidity: Option<f32>,
    /// Scene: what pixels without geometry show: color:R,G,B (linear; default
    /// the scene's colour), environment or environment:BLUR (0 sharp to 1), or
    /// transparent (alpha 0 in the HDR image).
    #[arg(help_heading = SCENES, long, value_name = "MODE")]
    pub(crate) background: Option<String>,
    /// Scene: shadow-map layers per frame (directional light 4, point 6, spot 1);
    /// lights past it are unshadowed, with a warning.
    #[arg(help_heading = SCENES, long, value_name = "N", default_value_t = fxgraph::render::renderer::DEFAULT_SHADOW_LAYERS)]
    pub(crate) shadow_layers: u32,
    /// Show the output in a window, live, instead of writing files: the same effects,
    /// inputs and scene options; a control panel with the parameters, every pass
    /// inspectable, hot reload of the effect and its shaders (keys: docs/cli.md).
    /// Needs a display (DISPLAY or WAYLAND_DISPLAY).
    #[arg(help_heading = VIEWER, long)]
    pub(crate) view: bool,
    /// --view, scripted (tests, bug reports): show N frames (a sequence advances one
    /// frame per frame), write --screenshot FILE, exit.
    #[arg(help_heading = VIEWER, long, value_name = "N")]
    pub(crate) view_frames: Option<u64>,
    /// --view: the file the screenshot key (P) and --view-frames write: what is shown
    /// at full resolution, as a normal run writes it.
    #[arg(help_heading = VIEWER, long, value_name = "FILE")]
    pub(crate) screenshot: Option<PathBuf>,
    /// --view-frames: after frame K, do ACTION: set NAME=VALUE, reset NAME, inspect
    /// PASS (or output, input, aux:NAME), key KEY, copy-set, wait-reload, pause.
    /// Repeatable.
    #[arg(help_heading = VIEWER, long = "view-do", value_name = "K:ACTION")]
    pub(crate) view_do: Vec<String>,
}
