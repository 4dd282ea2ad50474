//! RetroArch slang presets (docs/slang.md):
//! - the corpus presets (`../shared/corpus/slang`, used by path, never copied)
//!   against librashader's own Vulkan runtime: `tests/slang/refs/*.png`, rendered
//!   once by `tests/slang/make_refs.sh` from `tests/slang/input.png`; at least
//!   40 dB PSNR (8-bit RGB) for each preset fxgraph runs;
//! - history (`OriginalHistory1`) and feedback (`PassFeedback0`) on a sequence
//!   of images and on a y4m video,
//!   `--set` of a `#pragma parameter`, against the formulas of small presets
//!   written here (in stored 8-bit codes, as RetroArch's UNORM framebuffers hold
//!   them; ±1 code for the rounding of the 8-bit stores);
//! - every error class: its message names the file (and line) and the cause, exit
//!   status 1, no panic.

use crate::common;

use common::cli::{arg, code, fxrun, save, stderr};
use common::{image_u8, psnr};
use fxgraph::io::{load_image, Pixels};
use std::path::{Path, PathBuf};

/// The least PSNR (dB) of a corpus preset's output against librashader's.
const MIN_PSNR: f64 = 40.0;

/// Corpus presets held to a lower figure than [`MIN_PSNR`], and why.
/// `crt-blurPi-sharp` samples `Source` with nearest filtering 1.5 texels off each
/// pixel centre (`blurRadius` 1.5 at scale 1): every tap lies on a texel
/// boundary, where which texel wins is the rasteriser's rounding of the
/// interpolated coordinate against fxgraph's per-pixel one (678 of 6,144 pixels
/// differ; 36.4 dB measured).
const LOWER: &[(&str, f64)] = &[("crt/crt-blurPi-sharp", 36.0)];

/// Corpus presets compared without their first column, at [`MIN_PSNR`], and why.
/// `crt-1tap`: in column 0 the shader takes `pow` of `2 * (o - s * fract)`, where
/// `fract` is a rounding residue of the interpolated coordinate: slightly
/// negative in the rasteriser (NaN, black) and exactly 0 in fxgraph's per-pixel
/// one (the edge texel); the other 95 columns are bit-exact (24.6 dB with
/// column 0).
const WITHOUT_COLUMN_0: &[&str] = &["crt/crt-1tap"];

/// Corpus presets fxgraph runs and matches (docs/slang.md lists the others and
/// why).
const RUNS: &[&str] = &[
    "blurs/smart-blur",
    "crt/crt-hyllian-3d",
    "crt/crt-hyllian-fast",
    "crt/crt-lottes-fast",
    "crt/monoCRT",
    "crt/newpixie-mini",
    "crt/shaders/guest/pre-scaler-presets/xbr-lv2",
    "crt/shaders/guest/pre-scaler-presets/xbr-lv3",
    "deinterlacing/bob-deinterlacing",
    "deinterlacing/interpolation-deinterlacer",
    "deinterlacing/motion-adaptive-deinterlacing",
    "deinterlacing/reinterlacing",
    "denoisers/median_3x3",
    "denoisers/median_5x5",
    "dithering/cbod_v1",
    "edge-smoothing/ddt/cut",
    "edge-smoothing/ddt/ddt-extended",
    "edge-smoothing/ddt/ddt-xbr-lv1",
    "edge-smoothing/nis/nis",
    "edge-smoothing/fsr/fsr",
    "edge-smoothing/fsr/fsr-easu",
    "edge-smoothing/omniscale/omniscale",
    "edge-smoothing/xbr/other presets/xbr-lv1-standalone",
    "edge-smoothing/xbr/other presets/xbr-lv2-hd",
    "edge-smoothing/xbr/other presets/xbr-lv3-9x-standalone",
    "edge-smoothing/xbr/other presets/xbr-lv3-standalone",
    "handheld/color-mod/NSO-gba-color",
    "handheld/color-mod/gbc-gambatte-color",
    "handheld/color-mod/palm-color",
    "handheld/dot",
    "handheld/lcd3x",
    "handheld/retro-tiles",
    "handheld/sameboy-lcd",
    "interpolation/b-spline-4-taps",
    "interpolation/b-spline-fast",
    "interpolation/bicubic-fast",
    "interpolation/catmull-rom",
    "interpolation/linear-gamma-presets/b-spline-fast",
    "interpolation/linear-gamma-presets/bicubic-fast",
    "misc/bead",
    "misc/color-mangler",
    "misc/relief",
    "pixel-art-scaling/sharp-bilinear",
    "pixel-art-scaling/sharp-bilinear-scanlines",
    "pixel-art-scaling/sharp-bilinear-simple",
    "presets/blurs/smartblur-bspline-4taps-fsr",
    "scanlines/res-independent-scanlines",
    "scanlines/scanline-fract",
    "scanlines/scanlines-sine-abs",
    "sharpen/adaptive-sharpen",
    "sharpen/adaptive-sharpen-multipass",
    "sharpen/rca_sharpen",
    "stereoscopic-3d/anaglyph-to-side-by-side",
    "stereoscopic-3d/side-by-side-simple",
    "subframe-bfi/bfi-simple",
    "subframe-bfi/crt-beam-simulator",
    "subframe-bfi/motionblur_test",
];

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/slang");
    if dir.join("presets.json").is_file() {
        Some(dir)
    } else {
        eprintln!("skipped: {} is absent (the slang corpus)", dir.display());
        None
    }
}

fn here() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/slang")
}

/// 8-bit RGB values of a PNG, as f32 codes.
fn rgb(path: &Path) -> (u32, u32, Vec<f32>) {
    let img =
        load_image(path, &Default::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let Pixels::U8(p) = &img.pixels else {
        panic!("{}: not 8-bit", path.display())
    };
    let v = p
        .chunks(4)
        .flat_map(|c| c[..3].iter().map(|&x| f32::from(x)))
        .collect();
    (img.width, img.height, v)
}

#[test]
fn corpus_presets_match_librashader() {
    let Some(corpus) = corpus() else { return };
    let out = tempfile::tempdir().unwrap();
    let mut report = Vec::new();
    let held: Vec<(&str, f64)> = RUNS
        .iter()
        .map(|&n| (n, MIN_PSNR))
        .chain(LOWER.iter().copied())
        .chain(WITHOUT_COLUMN_0.iter().map(|&n| (n, MIN_PSNR)))
        .collect();
    for (name, min_db) in held {
        let file = name.replace('/', "__").replace(' ', "_");
        let preset = corpus.join(format!("{name}.slangp"));
        let dst = out.path().join(format!("{file}.png"));
        let input = here().join("input.png");
        let o = fxrun(&[arg(&preset), "-i", arg(&input), "-o", arg(&dst)]);
        assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
        let (w, h, ours) = rgb(&dst);
        let (rw, rh, theirs) = rgb(&here().join(format!("refs/{file}.png")));
        assert_eq!((w, h), (rw, rh), "{name}: size");
        let (ours, theirs) = if WITHOUT_COLUMN_0.contains(&name) {
            (without_column_0(&ours, w), without_column_0(&theirs, w))
        } else {
            (ours, theirs)
        };
        let db = psnr(&ours, &theirs, 255.0);
        report.push(format!("{name}: {db:.1} dB"));
        if db < min_db {
            panic!(
                "{name}: {db:.1} dB against librashader (< {min_db})\n{}",
                report.join("\n")
            );
        }
    }
    eprintln!("{}", report.join("\n"));
}

/// RGB samples of an image `w` pixels wide, its column 0 left out.
fn without_column_0(rgb: &[f32], w: u32) -> Vec<f32> {
    rgb.chunks(3)
        .enumerate()
        .filter(|(i, _)| i % w as usize != 0)
        .flat_map(|(_, px)| px.iter().copied())
        .collect()
}

/// A one-pass preset (`common::slang`).
fn preset(dir: &Path, name: &str, decls: &str, body: &str, extra: &str) -> PathBuf {
    common::slang::one_pass_preset(dir, name, decls, body, extra)
}

/// Frames `in/0000.png`... of flat grey levels `levels`.
fn grey_sequence(dir: &Path, levels: &[u8]) -> String {
    std::fs::create_dir_all(dir.join("in")).unwrap();
    for (i, &l) in levels.iter().enumerate() {
        save(
            &dir.join(format!("in/{i:04}.png")),
            &image_u8(8, 8, |_, _| [l, l, l, 255]),
        );
    }
    dir.join("in/%04d.png").display().to_string()
}

/// The red code of output frame `i`'s centre.
fn red(dir: &Path, i: usize) -> f32 {
    rgb(&dir.join(format!("out/{i:04}.png"))).2[3 * (4 * 8 + 4)]
}

#[test]
fn history_and_feedback_carry_earlier_frames() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let levels = [20u8, 200, 80, 140];
    let input = grey_sequence(d, &levels);
    // out[n] = (in[n] + in[n-1]) / 2 + (out[n-1]) / 4, out[-1] = 0, in[-1] = in[0]
    let p = preset(d, "temporal", "", common::slang::TEMPORAL_BODY, "");
    std::fs::create_dir_all(d.join("out")).unwrap();
    let out = d.join("out/%04d.png").display().to_string();
    let o = fxrun(&[arg(&p), "-i", &input, "-o", &out]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    common::slang::check_temporal(&levels, |n| f64::from(red(d, n)), 1.5);
}

/// A preset with `mipmap_input0` and a LUT (32 x 48, not the input's size)
/// with `lut_mipmap`: its top half reads `Source` at level 2, its bottom half
/// the LUT at level 1 (nearest filtering).
const MIPS_PRESET: &str = "shaders = 1\nshader0 = mips.slang\nfilter_linear0 = false\n\
    mipmap_input0 = true\ntextures = \"lut\"\nlut = lut.png\nlut_linear = false\n\
    lut_mipmap = true\n";
const MIPS_SHADER: &str = "#version 450
layout(push_constant) uniform Push { vec4 SourceSize; vec4 lutSize; } params;
layout(std140, set = 0, binding = 0) uniform UBO { mat4 MVP; } global;
#pragma stage vertex
layout(location = 0) in vec4 Position;
layout(location = 1) in vec2 TexCoord;
layout(location = 0) out vec2 vTexCoord;
void main() { gl_Position = global.MVP * Position; vTexCoord = TexCoord; }
#pragma stage fragment
layout(location = 0) in vec2 vTexCoord;
layout(location = 0) out vec4 FragColor;
layout(set = 0, binding = 2) uniform sampler2D Source;
layout(set = 0, binding = 3) uniform sampler2D lut;
void main() {
    FragColor = vTexCoord.y < 0.5 ? textureLod(Source, vTexCoord, 2.0) : textureLod(lut, vTexCoord, 1.0);
}
";

/// `mipmap_input` and LUT `mipmap` against the box-filtered chains of the 8-bit
/// codes (RetroArch's UNORM textures), within 1 code: no corpus preset sets
/// either, so no librashader reference covers them.
#[test]
fn mipmap_input_and_lut_mipmap_read_box_filtered_levels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("mips.slangp"), MIPS_PRESET).unwrap();
    std::fs::write(d.join("mips.slang"), MIPS_SHADER).unwrap();
    let input = image_u8(64, 64, |x, y| {
        [
            (x * 4) as u8,
            ((x ^ y) * 37 % 256) as u8,
            (y * 3) as u8,
            255,
        ]
    });
    let lut = image_u8(32, 48, |x, y| {
        [(x * 8) as u8, (y * 5) as u8, ((x + y) % 7 * 30) as u8, 255]
    });
    save(&d.join("in.png"), &input);
    save(&d.join("lut.png"), &lut);
    let o = fxrun(&[
        arg(&d.join("mips.slangp")),
        "-i",
        arg(&d.join("in.png")),
        "-o",
        arg(&d.join("out.png")),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let out = load_image(&d.join("out.png"), &Default::default()).unwrap();
    let (Pixels::U8(got), Pixels::U8(src), Pixels::U8(l)) =
        (&out.pixels, &input.pixels, &lut.pixels)
    else {
        panic!("8-bit images")
    };
    assert_eq!((out.width, out.height), (64, 64));
    let (_, source2) = common::mips::box_level(src, (64, 64), 2);
    let (_, lut1) = common::mips::box_level(l, (32, 48), 1);
    for y in 0..64usize {
        for x in 0..64usize {
            // Texel centres of neither level lie on a pixel centre's uv.
            let want = if y < 32 {
                let t = 4 * ((y / 4) * 16 + x / 4);
                &source2[t..t + 3]
            } else {
                let t = 4 * ((2 * y + 1) * 24 / 128 * 16 + x / 4);
                &lut1[t..t + 3]
            };
            let at = 4 * (y * 64 + x);
            for c in 0..3 {
                let diff = (i32::from(got[at + c]) - i32::from(want[c])).abs();
                assert!(
                    diff <= 1,
                    "pixel ({x}, {y}) channel {c}: {}, box filter {}",
                    got[at + c],
                    want[c]
                );
            }
        }
    }
}

/// A y4m stream (8x8, 4:4:4, full range) of flat grey levels `levels`.
fn grey_y4m(path: &Path, levels: &[u8]) {
    let mut bytes = b"YUV4MPEG2 W8 H8 F25:1 Ip A1:1 C444 XCOLORRANGE=FULL\n".to_vec();
    for &l in levels {
        bytes.extend_from_slice(b"FRAME\n");
        bytes.extend(std::iter::repeat_n(l, 64));
        bytes.extend(std::iter::repeat_n(128u8, 128));
    }
    std::fs::write(path, bytes).unwrap();
}

/// The luma of the centre pixel of each frame of an 8x8 4:4:4 8-bit y4m stream.
fn y4m_centre_luma(path: &Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    let header_end = bytes.iter().position(|&b| b == b'\n').unwrap() + 1;
    let header = String::from_utf8_lossy(&bytes[..header_end]).to_string();
    assert!(
        header.contains("W8 H8") && header.contains("C444"),
        "{header}"
    );
    let mut out = Vec::new();
    let mut at = header_end;
    while at < bytes.len() {
        let line_end = at + bytes[at..].iter().position(|&b| b == b'\n').unwrap() + 1;
        assert!(bytes[at..].starts_with(b"FRAME"), "frame {}", out.len());
        out.push(f64::from(bytes[line_end + 4 * 8 + 4]));
        at = line_end + 3 * 64;
    }
    out
}

/// The same history-and-feedback preset on a y4m video, in and out as Y'CbCr:
/// grey in full range is its own luma, so the formula holds on the Y plane.
#[test]
fn history_and_feedback_carry_earlier_frames_of_a_video() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let levels = [20u8, 200, 80, 140, 40];
    let input = d.join("in.y4m");
    grey_y4m(&input, &levels);
    let p = preset(d, "temporal", "", common::slang::TEMPORAL_BODY, "");
    let out = d.join("out.y4m");
    let o = fxrun(&[arg(&p), "-i", arg(&input), "-o", arg(&out)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let got = y4m_centre_luma(&out);
    assert_eq!(got.len(), levels.len(), "frames out");
    // ±1.5 codes for the 8-bit stores, as above, and 1 for the Y'CbCr round trip.
    common::slang::check_temporal(&levels, |n| got[n], 2.5);
}

#[test]
fn set_changes_a_parameter_as_the_shader_says() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = preset(
        d,
        "gain",
        "float gain;",
        "FragColor = texture(Source, vTexCoord) * params.gain;",
        "#pragma parameter gain \"Gain\" 1.0 0.0 2.0 0.05",
    );
    let input = grey_sequence(d, &[180]);
    std::fs::create_dir_all(d.join("out")).unwrap();
    let out = d.join("out/%04d.png").display().to_string();
    for (gain, expected) in [("1", 180.0), ("0.25", 45.0)] {
        let set = format!("gain={gain}");
        let o = fxrun(&[arg(&p), "--set", &set, "-i", &input, "-o", &out]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        let got = red(d, 0);
        assert!(
            (got - expected).abs() <= 1.0,
            "gain {gain}: {got}, expected {expected}"
        );
    }
    let o = fxrun(&[arg(&p), "--describe"]);
    let text = common::cli::stdout(&o);
    assert!(
        text.contains("gain") && text.contains("range [0, 2] step 0.05"),
        "{text}"
    );
}

/// Two passes: pass 0 `absolute` 40 px wide by half the viewport's height
/// (one axis in pixels, the other relative), writing its own size and the
/// viewport's (`OutputSize`, `FinalViewportSize`) as codes; pass 1, the last,
/// at the viewport's size, passes them on with its own. The viewport is the
/// input's size by default and `--size`'s when given.
#[test]
fn size_chooses_the_viewport_and_axes_may_mix_pixels_and_scale() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sizes = "vec4 OutputSize; vec4 FinalViewportSize;";
    let first = "FragColor = vec4(params.OutputSize.xy, params.FinalViewportSize.xy) / 255.0;";
    let last = "vec4 s = texture(Source, vTexCoord);\n\
                FragColor = vec4(s.rg, params.OutputSize.xy / 255.0);";
    for (name, body) in [("first", first), ("last", last)] {
        let shader = common::slang::one_pass_shader(sizes, body, "");
        std::fs::write(d.join(format!("{name}.slang")), shader).unwrap();
    }
    let p = d.join("viewport.slangp");
    std::fs::write(
        &p,
        "shaders = 2\nshader0 = first.slang\nfilter_linear0 = false\n\
         scale_type_x0 = absolute\nscale_x0 = 40\nscale_type_y0 = viewport\nscale_y0 = 0.5\n\
         shader1 = last.slang\nfilter_linear1 = false\n",
    )
    .unwrap();
    let input = d.join("in.png");
    save(&input, &image_u8(16, 8, |_, _| [0, 0, 0, 255]));
    let out = d.join("out.png");
    // (viewport, expected codes of every pixel: pass 0's size, the viewport's)
    for (size, expected) in [
        (None, [40.0, 4.0, 16.0, 8.0]),
        (Some("60x50"), [40.0, 25.0, 60.0, 50.0]),
    ] {
        let mut args = vec![arg(&p), "-i", arg(&input), "-o", arg(&out)];
        args.extend(size.iter().flat_map(|s| ["--size", *s]));
        let o = fxrun(&args);
        assert_eq!(code(&o), 0, "{size:?}: {}", stderr(&o));
        let img = load_image(&out, &Default::default()).unwrap();
        let Pixels::U8(px) = &img.pixels else {
            panic!("not 8-bit")
        };
        let (w, h) = (expected[2] as u32, expected[3] as u32);
        assert_eq!((img.width, img.height), (w, h), "{size:?}: output size");
        for (i, c) in px.chunks(4).enumerate() {
            let got = [c[0], c[1], c[2], c[3]].map(f64::from);
            assert_eq!(got, expected, "{size:?}: pixel {i}");
        }
    }
    // An effect with no pass that scales from the viewport refuses --size.
    let o = fxrun(&[
        "tonemap",
        "-i",
        arg(&input),
        "-o",
        arg(&out),
        "--size",
        "60x50",
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("sets the viewport"), "{}", stderr(&o));
}

/// A preset with a LUT of its own size (16x8, the input's 8x8), on every kind
/// of input: a batch, a numbered sequence, a y4m video and a rendered scene.
/// The shader reads the LUT's right half, (0, 200, 40), at every pixel.
#[test]
fn a_lut_preset_runs_on_batches_sequences_video_and_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // (no history or feedback binding: a still effect, which batches take)
    let shader =
        common::slang::one_pass_shader("", "FragColor = texture(lut, vec2(0.75, 0.25));", "")
            .replace(
                "uniform sampler2D OriginalHistory1;",
                "uniform sampler2D lut;",
            )
            .replace(
                "layout(set = 0, binding = 4) uniform sampler2D PassFeedback0;\n",
                "",
            );
    std::fs::write(d.join("lut.slang"), shader).unwrap();
    let half = |x: u32| {
        if x < 8 {
            [255, 0, 0, 255]
        } else {
            [0, 200, 40, 255]
        }
    };
    save(&d.join("lut.png"), &image_u8(16, 8, |x, _| half(x)));
    let p = d.join("lut.slangp");
    std::fs::write(
        &p,
        "shaders = 1\nshader0 = lut.slang\nfilter_linear0 = false\n\
         textures = \"lut\"\nlut = lut.png\nlut_linear = false\n",
    )
    .unwrap();
    let input = grey_sequence(d, &[60, 90, 120]);
    std::fs::create_dir_all(d.join("out")).unwrap();
    let sequence_out = d.join("out/%04d.png").display().to_string();
    let (a, b) = (d.join("in/0000.png"), d.join("in/0001.png"));
    let batch_out = d.join("batch");
    let y4m = d.join("in.y4m");
    grey_y4m(&y4m, &[60, 90]);
    let y4m_out = d.join("out.y4m");
    let scene_out = d.join("scene.png");
    let runs: [Vec<&str>; 4] = [
        vec![arg(&p), "-i", &input, "-o", &sequence_out],
        vec![arg(&p), "-i", arg(&a), "-i", arg(&b), "-o", arg(&batch_out)],
        vec![arg(&p), "-i", arg(&y4m), "-o", arg(&y4m_out)],
        vec![
            "--scene",
            "builtin:room",
            arg(&p),
            "--size",
            "32x18",
            "-o",
            arg(&scene_out),
        ],
    ];
    for args in &runs {
        let o = fxrun(args);
        assert_eq!(code(&o), 0, "{args:?}: {}", stderr(&o));
    }
    let expect = [0.0f32, 200.0, 40.0];
    for png in [
        d.join("out/0002.png"),
        batch_out.join("0001.png"),
        scene_out,
    ] {
        let (_, _, px) = rgb(&png);
        for c in px.chunks(3) {
            assert!(
                c.iter().zip(expect).all(|(g, e)| (g - e).abs() <= 1.0),
                "{}: {c:?}",
                png.display()
            );
        }
    }
    // Y'CbCr 4:4:4, full range (the input's): luma of (0, 200, 40), BT.601.
    let luma = 0.587 * 200.0 + 0.114 * 40.0;
    for (n, l) in y4m_centre_luma(&y4m_out).iter().enumerate() {
        assert!(
            (l - luma).abs() <= 2.0,
            "y4m frame {n}: luma {l}, expected {luma:.1}"
        );
    }
}

/// The frontend's semantics, as librashader binds them: `OriginalFPS` the
/// input's rate, `FrameTimeDelta` its frame interval in milliseconds (0 on the
/// first frame), `BrightnessNits` 200 and `HDRMode` 0 (an SDR display),
/// `Gyroscope` (0, 0, 0). A sequence at `--fps 50`: (50, 0, 200) on frame 0,
/// (50, 20, 200) after, as stored codes.
#[test]
fn frontend_semantics_have_librashaders_values() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = preset(
        d,
        "frontend",
        "float OriginalFPS; uint FrameTimeDelta; float BrightnessNits; uint HDRMode; vec3 Gyroscope;",
        "FragColor = vec4(params.OriginalFPS, float(params.FrameTimeDelta), \
         params.BrightnessNits - float(params.HDRMode) - length(params.Gyroscope), 255.0) / 255.0 \
         + 0.0 * texture(Source, vTexCoord) + 0.0 * texture(OriginalHistory1, vTexCoord) \
         + 0.0 * texture(PassFeedback0, vTexCoord);",
        "",
    );
    let input = grey_sequence(d, &[10, 20, 30]);
    std::fs::create_dir_all(d.join("out")).unwrap();
    let out = d.join("out/%04d.png").display().to_string();
    let o = fxrun(&[arg(&p), "--fps", "50", "-i", &input, "-o", &out]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    for (n, delta) in [(0, 0.0), (1, 20.0), (2, 20.0)] {
        let (_, _, px) = rgb(&d.join(format!("out/{n:04}.png")));
        assert_eq!(&px[..3], &[50.0, delta, 200.0], "frame {n}");
    }
}

/// Runs `--check` on `p` and returns its message, which must give status 1
/// and contain each of `needles`, without a panic or a wgpu error chain.
fn rejected(p: &Path, needles: &[&str]) -> String {
    let o = fxrun(&[arg(p), "--check"]);
    let msg = stderr(&o);
    assert_eq!(code(&o), 1, "{msg}");
    for n in needles {
        assert!(msg.contains(n), "`{n}` not in:\n{msg}");
    }
    assert!(!msg.contains("panicked") && !msg.contains("wgpu"), "{msg}");
    msg
}

#[test]
fn every_error_class_names_its_file_and_cause() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // the preset itself
    let bad = d.join("bad.slangp");
    std::fs::write(&bad, "shaders = 2\nshader0 = nothere.slang\n").unwrap();
    rejected(&bad, &["bad.slangp", "cannot parse the preset"]);
    // a missing include
    let p = preset(
        d,
        "inc",
        "",
        "FragColor = vec4(1.0);",
        "#include \"missing.inc\"",
    );
    rejected(
        &p,
        &["inc.slang", "cannot preprocess the shader", "missing.inc"],
    );
    // a GLSL error at its line in the file: the body is on line 16, after the
    // `#pragma stage` lines (librashader's `#line` markers are one short there,
    // and fxgraph corrects them: docs/slang.md, "Errors")
    let p = preset(d, "glsl", "", "FragColor = undefined_thing;", "");
    rejected(&p, &["glsl.slang:16: GLSL error", "undefined_thing"]);
    // ... and in an included file, and in the shader after the include:
    // (shader, fragment body, the included file, the expected location)
    for (name, body, included, at) in [
        (
            "inc_err",
            "FragColor = vec4(1.0);",
            "// 1\n// 2\nfloat f() { return missing_in_include; }\n",
            "part.inc:3: GLSL error",
        ),
        (
            "after_inc",
            "FragColor = after_include;",
            "// 1\n",
            "after_inc.slang:16: GLSL error",
        ),
    ] {
        std::fs::write(d.join("part.inc"), included).unwrap();
        let p = preset(d, name, "", body, "#include \"part.inc\"");
        rejected(&p, &[at]);
    }
    // an unknown uniform semantic (no `#pragma parameter` declares it)
    let p = preset(
        d,
        "sem",
        "float mystery;",
        "FragColor = vec4(params.mystery);",
        "",
    );
    rejected(&p, &["sem.slang", "unknown semantic `mystery`"]);
    // a shader that translates but cannot run as a pass (an integer colour
    // output): the error lies in the generated WGSL, and names the `.slang` file
    let float_out = "layout(location = 0) out vec4 FragColor;";
    let shader = common::slang::one_pass_shader(
        "",
        "FragColor = ivec4(texture(Source, vTexCoord) * 255.0);",
        "",
    )
    .replace(float_out, "layout(location = 0) out ivec4 FragColor;");
    std::fs::write(d.join("int_out.slang"), shader).unwrap();
    let p = d.join("int_out.slangp");
    std::fs::write(&p, "shaders = 1\nshader0 = int_out.slang\n").unwrap();
    let slang = d.join("int_out.slang").display().to_string();
    let msg = rejected(
        &p,
        &[
            "WGSL validation",
            "generated this WGSL from",
            &slang,
            "pass 0 of",
        ],
    );
    assert!(msg.contains("int_out_pass0.wgsl:"), "{msg}");
}
