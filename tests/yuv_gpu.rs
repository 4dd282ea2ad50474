//! GPU-side Y'CbCr conversion against the CPU conversion for every y4m colour
//! space (`gpu::yuv` against `io::yuv`), both ways, on random planes and random
//! pixels (noise: the hardest case for chroma resampling), odd sizes (the last
//! column and row of subsampled chroma), every matrix (BT.601, BT.709, BT.2020)
//! in limited and full range, progressive and interlaced 4:2:0.
//!
//! Tolerances: planes within one code at the stream's depth; 8-bit RGB within one
//! code; linear rgba32f within 2e-5 (the CPU's polynomial sRGB curve is within 4e-6
//! of the formula, one 16-bit code is 1.5e-5 of R'); rgba16f within 2^-10 of the
//! value (one half-float step) plus 1e-6. The largest differences are printed.

use crate::common;

use common::rng::Rng;
use fxgraph::app::planes::plane_layout;
use fxgraph::gpu::context::GpuContext;
use fxgraph::gpu::transfer::upload_image;
use fxgraph::gpu::yuv::{PlanesToRgb, RgbToPlanes};
use fxgraph::io::y4m::{
    rgba_f32_to_yuv, rgba_u8_to_yuv, yuv_to_rgba_f32, yuv_to_rgba_u8, Matrix, Range, Y4mHeader,
    YuvConversion, YuvFrame,
};
use fxgraph::io::{FileFormat, Image, Pixels, SourceInfo};
use fxgraph::script::types::Format;

/// Every colour space of the y4m reader: the `C` tag, interlacing, extensions.
const SPACES: &[(&str, char, &str)] = &[
    ("420jpeg", 'p', ""),
    ("420jpeg", 't', ""),
    ("420paldv", 'b', ""),
    ("420mpeg2", 'p', ""),
    ("420mpeg2", 'b', ""),
    ("420", 'p', ""),
    ("422", 'p', ""),
    ("444", 'p', ""),
    ("mono", 'p', ""),
    ("420jpeg", 'p', "XYSCSS=420JPEG"),
    ("420p9", 'p', ""),
    ("420p10", 'p', "XYSCSS=420P10"),
    ("420p10", 't', ""),
    ("420p12", 'p', ""),
    ("420p14", 'p', ""),
    ("420p16", 'p', ""),
    ("422p10", 'p', "XYSCSS=422P10"),
    ("422p12", 'p', ""),
    ("422p16", 'p', ""),
    ("444p10", 'p', ""),
    ("444p12", 'p', ""),
    ("444p16", 'p', "XYSCSS=444P16"),
    ("mono9", 'p', ""),
    ("mono10", 'p', ""),
    ("mono12", 'p', ""),
    ("mono16", 'p', ""),
];

const MATRICES: [Matrix; 3] = [Matrix::Bt601, Matrix::Bt709, Matrix::Bt2020];
const RANGES: [Range; 2] = [Range::Limited, Range::Full];
const F32_TOL: f32 = 2e-5;

fn header(tag: &str, interlace: char, extra: &str, w: u32, h: u32) -> Y4mHeader {
    let x = if extra.is_empty() {
        String::new()
    } else {
        format!(" X{extra}")
    };
    let line = format!("YUV4MPEG2 W{w} H{h} F25:1 I{interlace} A1:1 C{tag}{x}");
    Y4mHeader::parse(line.as_bytes()).unwrap_or_else(|e| panic!("{line}: {e}"))
}

/// Random planes: codes over the whole range of the depth (below and above a
/// limited range's nominal codes too).
fn random_frame(h: &Y4mHeader, rng: &mut Rng) -> YuvFrame {
    let (yn, cn) = h.plane_bytes();
    let max = h.max_code() as usize + 1;
    let mut plane = |n: usize| -> Vec<u8> {
        if h.depth == 8 {
            return rng.bytes(n);
        }
        (0..n / 2)
            .flat_map(|_| (rng.below(max) as u16).to_le_bytes())
            .collect()
    };
    YuvFrame {
        y: plane(yn),
        u: plane(cn),
        v: plane(cn),
        params: Vec::new(),
    }
}

/// The format the pipeline gives frames of `depth` bits (and rgba32f, the float
/// path at every depth).
fn formats(depth: u8) -> Vec<Format> {
    let own = match depth {
        8 => Format::Rgba8Srgb,
        9 | 10 => Format::Rgba16f,
        _ => Format::Rgba32f,
    };
    let mut v = vec![own];
    if own != Format::Rgba32f {
        v.push(Format::Rgba32f);
    }
    v
}

fn f16s(raw: &[u8]) -> Vec<f32> {
    raw.chunks_exact(2)
        .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
        .collect()
}

fn f32s(raw: &[u8]) -> Vec<f32> {
    raw.chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// The largest difference of two RGBA images of `format` (raw texel bytes from the
/// GPU, the CPU's pixels), in codes for 8 bits and relative to the tolerance for
/// floats (so <= 1 passes either way), and the largest absolute difference.
fn rgb_difference(format: Format, gpu: &[u8], cpu: &Pixels) -> (f32, f32) {
    match (format, cpu) {
        (Format::Rgba8Srgb, Pixels::U8(c)) => {
            let d = gpu.iter().zip(c).map(|(&a, &b)| a.abs_diff(b)).max();
            let d = d.unwrap_or(0) as f32;
            (d, d)
        }
        (Format::Rgba16f | Format::Rgba32f, Pixels::F32(c)) => {
            let g = if format == Format::Rgba16f {
                f16s(gpu)
            } else {
                f32s(gpu)
            };
            let mut worst = (0f32, 0f32);
            for (&a, &b) in g.iter().zip(c) {
                let tol = if format == Format::Rgba16f {
                    b.abs() / 1024.0 + 1e-6
                } else {
                    F32_TOL
                };
                let d = (a - b).abs();
                worst = (worst.0.max(d / tol), worst.1.max(d));
            }
            worst
        }
        _ => panic!("{format}: no comparison"),
    }
}

fn to_rgb_case(
    ctx: &GpuContext,
    h: &Y4mHeader,
    conv: &YuvConversion,
    format: Format,
    rng: &mut Rng,
) -> (f32, f32) {
    let frame = random_frame(h, rng);
    let n = (h.width * h.height * 4) as usize;
    let cpu = if format == Format::Rgba8Srgb {
        let mut out = vec![0u8; n];
        yuv_to_rgba_u8(&frame, h, conv, &mut out).unwrap();
        Pixels::U8(out)
    } else {
        let mut out = vec![0f32; n];
        yuv_to_rgba_f32(&frame, h, conv, &mut out).unwrap();
        Pixels::F32(out)
    };
    let layout = plane_layout(h, conv);
    let mut up = PlanesToRgb::new(ctx, &layout, format).unwrap();
    let target = up.create_texture(ctx, "yuv test target").unwrap();
    let fields = frame.field_chroma(h, conv);
    up.convert(ctx, [&frame.y, &frame.u, &frame.v], fields, &target)
        .unwrap();
    let gpu = ctx.read_texture(&target).unwrap();
    rgb_difference(format, &gpu, &cpu)
}

/// Random pixels for `format`: 8-bit codes, or linear floats in [-0.1, 1.2] (past
/// both ends of the cube) rounded to half floats for rgba16f (what the texture
/// holds).
fn random_image(h: &Y4mHeader, format: Format, rng: &mut Rng) -> Image {
    let n = (h.width * h.height * 4) as usize;
    let pixels = if format == Format::Rgba8Srgb {
        Pixels::U8(rng.bytes(n))
    } else {
        let v = (0..n).map(|_| {
            let x = rng.below(1 << 20) as f32 / (1 << 20) as f32 * 1.3 - 0.1;
            if format == Format::Rgba16f {
                half::f16::from_f32(x).to_f32()
            } else {
                x
            }
        });
        Pixels::F32(v.collect())
    };
    Image {
        width: h.width,
        height: h.height,
        pixels,
        source: SourceInfo {
            format: FileFormat::Pnm,
            bit_depth: h.depth,
            has_alpha: false,
            float: true,
        },
    }
}

/// The largest difference in codes between the GPU's planes and the CPU's.
fn plane_difference(h: &Y4mHeader, gpu: &[u8], cpu: &YuvFrame) -> u32 {
    let want: Vec<u8> = [&cpu.y[..], &cpu.u, &cpu.v].concat();
    assert_eq!(gpu.len(), want.len(), "frame bytes");
    if h.depth == 8 {
        return gpu
            .iter()
            .zip(&want)
            .map(|(&a, &b)| a.abs_diff(b) as u32)
            .max()
            .unwrap_or(0);
    }
    let word = |c: &[u8]| u16::from_le_bytes([c[0], c[1]]);
    gpu.chunks_exact(2)
        .zip(want.chunks_exact(2))
        .map(|(a, b)| word(a).abs_diff(word(b)) as u32)
        .max()
        .unwrap_or(0)
}

fn to_planes_case(
    ctx: &GpuContext,
    h: &Y4mHeader,
    conv: &YuvConversion,
    format: Format,
    rng: &mut Rng,
) -> u32 {
    let img = random_image(h, format, rng);
    let mut cpu = YuvFrame::default();
    match &img.pixels {
        Pixels::U8(v) => rgba_u8_to_yuv(v, h, conv, &mut cpu).unwrap(),
        Pixels::F32(v) => rgba_f32_to_yuv(v, h, conv, &mut cpu).unwrap(),
    }
    let fields = cpu.field_chroma(h, conv);
    let layout = plane_layout(h, conv);
    let mut down = RgbToPlanes::new(ctx, &layout, format, fields).unwrap();
    let texture = upload_image(ctx, "yuv test source", &img, format).unwrap();
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("yuv test"),
        });
    let pending = down.encode(ctx, &mut enc, &texture).unwrap();
    ctx.queue.submit([enc.finish()]);
    let gpu = pending.finish().unwrap();
    plane_difference(h, &gpu, &cpu)
}

/// Every colour space, matrix and range, each RGB format, both directions; `clip`
/// false keeps R'G'B' outside the cube (floats only).
fn every_space(ctx: &GpuContext, (w, h): (u32, u32), clip: bool) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ u64::from(w));
    let (mut worst_rgb, mut worst_planes) = (Vec::new(), 0u32);
    for &(tag, interlace, extra) in SPACES {
        let hd = header(tag, interlace, extra, w, h);
        for (matrix, range) in MATRICES.iter().flat_map(|m| RANGES.map(|r| (*m, r))) {
            let mut conv = YuvConversion::for_header(&hd);
            (conv.matrix, conv.range, conv.clip) = (matrix, range, clip);
            for format in formats(hd.depth) {
                if !clip && format == Format::Rgba8Srgb {
                    continue; // 8-bit R'G'B' is always clipped
                }
                let what = format!("C{tag} I{interlace} {matrix:?} {range:?} {format} clip {clip}");
                let (rel, abs) = to_rgb_case(ctx, &hd, &conv, format, &mut rng);
                assert!(rel <= 1.0, "{what}: to RGB off by {abs} (tolerance x{rel})");
                worst_rgb.push((rel, abs, what.clone()));
                let codes = to_planes_case(ctx, &hd, &conv, format, &mut rng);
                assert!(codes <= 1, "{what}: to planes off by {codes} codes");
                worst_planes = worst_planes.max(codes);
            }
        }
    }
    for format in ["rgba8-srgb", "rgba16f", "rgba32f"] {
        let worst = worst_rgb
            .iter()
            .filter(|(_, _, w)| w.contains(&format!(" {format} ")))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((rel, abs, what)) = worst {
            eprintln!("{w}x{h} clip {clip}: to RGB {format}: max difference {abs:e} ({rel:.3} of the tolerance) at {what}");
        }
    }
    eprintln!("{w}x{h} clip {clip}: to planes: max difference {worst_planes} code(s)");
}

#[test]
fn gpu_ycbcr_conversion_matches_the_cpu_for_every_y4m_colour_space() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    // Odd sizes: the last chroma column and row cover one luma sample.
    every_space(&gpu, (37, 23), true);
    every_space(&gpu, (64, 48), true);
}

#[test]
fn unclipped_conversion_keeps_colours_outside_the_cube_like_the_cpu() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    every_space(&gpu, (37, 23), false);
}

/// A y4m file of `frames` random frames.
fn write_y4m(path: &std::path::Path, hd: &Y4mHeader, frames: usize, rng: &mut Rng) {
    let file = std::fs::File::create(path).unwrap();
    let mut w = fxgraph::io::y4m::Y4mWriter::new(file, hd.clone(), "test").unwrap();
    for _ in 0..frames {
        w.write_frame(&random_frame(hd, rng)).unwrap();
    }
    w.into_inner().unwrap();
}

/// Run `vignette` with strength 0 (an identity) over a y4m file into another,
/// converting Y'CbCr where `ycbcr` says; the output's bytes and where it converted.
fn identity_run(
    engine: &mut fxgraph::gpu::executor::Engine,
    input: &std::path::Path,
    output: &std::path::Path,
    ycbcr: fxgraph::app::planes::PlaneConversion,
) -> (Vec<u8>, [bool; 2]) {
    use fxgraph::app::*;
    let opened = OpenedInput::open(&StreamInput::Y4mFile(input.into())).unwrap();
    let settings = OutputSettings::new(opened.header.clone(), opened.conversion);
    let out = open_output(&StreamOutput::Y4mFile(output.into()), &settings).unwrap();
    let fx = format!("{}/effects/vignette.fx", env!("CARGO_MANIFEST_DIR"));
    let mut effect = Effect::compile(&[fx], &["strength=0".into()]).unwrap();
    let opts = SequenceOptions {
        output_format: out.texture_format,
        ycbcr,
        ..Default::default()
    };
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let source = opened.into_source(0, None);
    let report = run_sequence(
        Device::Engine(engine),
        &mut effect,
        source,
        out.sink,
        &opts,
        None,
        stop,
        |_| {},
    )
    .unwrap();
    (std::fs::read(output).unwrap(), report.ycbcr_on_gpu)
}

#[test]
fn a_y4m_file_through_an_identity_effect_is_written_alike_by_both_conversions() {
    use fxgraph::app::planes::PlaneConversion;
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(7);
    for (tag, interlace, extra) in [
        ("420jpeg", 'p', ""),
        ("420p10", 't', ""),
        ("444p16", 'p', "COLORRANGE=FULL"),
        ("mono", 'p', ""),
    ] {
        let hd = header(tag, interlace, extra, 45, 31);
        let input = dir.path().join(format!("in_{tag}.y4m"));
        write_y4m(&input, &hd, 3, &mut rng);
        let gpu_out = dir.path().join(format!("gpu_{tag}.y4m"));
        let cpu_out = dir.path().join(format!("cpu_{tag}.y4m"));
        let (gpu, on_gpu) = identity_run(&mut engine, &input, &gpu_out, PlaneConversion::Gpu);
        let (cpu, on_cpu) = identity_run(&mut engine, &input, &cpu_out, PlaneConversion::Cpu);
        assert_eq!(
            on_gpu,
            [true, true],
            "C{tag}: converted on the GPU both ways"
        );
        assert_eq!(
            on_cpu,
            [false, false],
            "C{tag}: converted on the CPU both ways"
        );
        assert_eq!(gpu.len(), cpu.len(), "C{tag}: file sizes");
        // The same header and FRAME lines: the files differ only in plane samples.
        let header_len = cpu.iter().position(|&b| b == b'\n').unwrap() + 1;
        assert_eq!(gpu[..header_len], cpu[..header_len], "C{tag}: header");
        let frame_len = hd.frame_bytes() + 6; // "FRAME\n"
        let mut worst = 0u32;
        for (g, c) in gpu[header_len..]
            .chunks(frame_len)
            .zip(cpu[header_len..].chunks(frame_len))
        {
            assert_eq!(g[..6], c[..6], "C{tag}: FRAME line");
            let (g, c) = (&g[6..], &c[6..]);
            let d = if hd.depth == 8 {
                g.iter().zip(c).map(|(&a, &b)| a.abs_diff(b) as u32).max()
            } else {
                let word = |x: &[u8]| u16::from_le_bytes([x[0], x[1]]);
                g.chunks(2)
                    .zip(c.chunks(2))
                    .map(|(a, b)| word(a).abs_diff(word(b)) as u32)
                    .max()
            };
            worst = worst.max(d.unwrap_or(0));
        }
        eprintln!(
            "C{tag} I{interlace}: GPU and CPU conversions' files differ by at most {worst} code(s)"
        );
        assert!(worst <= 1, "C{tag}: {worst} codes apart");
    }
}
