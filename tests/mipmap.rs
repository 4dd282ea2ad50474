//! Mip chains (`NAME.MIPMAP = true`, docs/language.md "Sampling") and
//! auxiliary images of their own size, on the GPU against CPU oracles:
//! - the chain of a 64 x 64 input, levels 1 to 6 read with `textureLoad`,
//!   against a box filter of the 8-bit codes computed here (each level from the
//!   previous one rounded to 8 bits, as the GPU stores it): within 1 code, on
//!   both execution paths (the copy into level 0 runs as compute under compute
//!   execution);
//! - `textureSampleLevel(img, s, uv, 2.0)` reads level 2, exactly;
//! - sides that do not halve exactly: each level against the definition of
//!   Vulkan's linear blit (librashader's), within 1 code;
//! - `textureSample` of a mipmapped input at a quarter of its size reads level
//!   2 on both execution paths (the pass stays a fragment pass under compute);
//! - an `AUX` image of another size than the input keeps its size: sampled over
//!   the output and its `NAME_size` standard value;
//! - on the CPU, the plan: which textures get a chain, the copies, the bytes.

use crate::common;

use common::mips::box_level;
use fxgraph::app::apply_in_memory;
use fxgraph::gpu::executor::{Engine, Execution};
use fxgraph::graph::plan::{mip_levels, plan, InputDesc, PassShader, PlanOptions, Resource, View};
use fxgraph::graph::Graph;
use fxgraph::io::{Image, Pixels};
use fxgraph::script::types::Format;
use std::path::{Path, PathBuf};

/// The input: 64 x 64 codes with edges and noise, so that every level differs.
fn input() -> Image {
    common::image_u8(64, 64, |x, y| {
        let h = (x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663)) % 251;
        [
            (x * 4) as u8,
            h as u8,
            if (x / 3 + y / 5) % 2 == 0 { 230 } else { 20 },
            255,
        ]
    })
}

fn here() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mipmap")
}

/// `effect` (a file of tests/mipmap) on `img` with `aux`, codes as they are,
/// on `engine` under `execution`: the output's RGBA codes.
fn run(
    engine: &mut Engine,
    execution: Execution,
    effect: &str,
    img: &Image,
    aux: &[(String, &Image)],
) -> (u32, u32, Vec<u8>) {
    run_set(engine, execution, (effect, &[]), img, aux)
}

/// [`run`] with `--set` values `sets`.
fn run_set(
    engine: &mut Engine,
    execution: Execution,
    (effect, sets): (&str, &[String]),
    img: &Image,
    aux: &[(String, &Image)],
) -> (u32, u32, Vec<u8>) {
    let before = engine.execution();
    engine.set_execution(execution);
    let fx = here().join(effect).display().to_string();
    let ran = apply_in_memory(engine, &[fx], sets, img, aux, Format::Rgba8, true);
    engine.set_execution(before);
    let (w, h, px) = ran.unwrap_or_else(|e| panic!("{effect} ({execution}): {e}"));
    let Pixels::U8(v) = px else {
        panic!("rgba8 output reads back as bytes")
    };
    (w, h, v)
}

#[test]
fn the_chain_is_a_box_filter_and_an_explicit_level_reads_it() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let img = input();
    let Pixels::U8(codes) = &img.pixels else {
        unreachable!()
    };
    for execution in [Execution::Fragment, Execution::Compute] {
        let (w, h, out) = run(&mut engine, execution, "mips.fx", &img, &[]);
        assert_eq!((w, h), (64, 64));
        let mut worst = 0i32;
        for level in 1..=6u32 {
            let (side, want) = box_level(codes, (64, 64), level);
            let x0 = 64 - (128 >> level);
            for y in 0..side {
                for x in 0..side {
                    for c in 0..4 {
                        let got = out[4 * (y * 64 + x0 + x) + c];
                        let d = (i32::from(got) - i32::from(want[4 * (y * side + x) + c])).abs();
                        assert!(
                            d <= 1,
                            "{execution}: level {level} texel ({x}, {y}) channel {c}: {got}, box filter {}",
                            want[4 * (y * side + x) + c]
                        );
                        worst = worst.max(d);
                    }
                }
            }
        }
        // Rows 32..64: level 2 (16 x 16) at uv, nearest: texel (x / 4, y' / 2).
        let (_, level2) = box_level(codes, (64, 64), 2);
        for y in 0..32usize {
            for x in 0..64usize {
                let t = 4 * ((y / 2) * 16 + x / 4);
                let texel_in_atlas = 4 * ((y / 2) * 64 + 32 + x / 4);
                let at = 4 * ((32 + y) * 64 + x);
                // The sampled level is the level the atlas shows (exactly), and
                // that level is the box filter's (within 1 code, above).
                assert_eq!(
                    &out[at..at + 4],
                    &out[texel_in_atlas..texel_in_atlas + 4],
                    "{execution}: level 2.0 at pixel ({x}, {})",
                    32 + y
                );
                let d = out[at..at + 4]
                    .iter()
                    .zip(&level2[t..t + 4])
                    .map(|(a, b)| (i32::from(*a) - i32::from(*b)).abs())
                    .max()
                    .unwrap();
                assert!(d <= 1, "{execution}: level 2.0 at ({x}, {y})");
            }
        }
        eprintln!("{execution}: largest difference from the box filter {worst} code(s)");
    }
}

/// An input whose sides do not halve exactly (48 x 20: 3 x 2 and 1 x 1 at the
/// end): every level against the linear blit's definition, within 1 code.
#[test]
fn odd_sides_follow_the_linear_blit() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let img = common::image_u8(48, 20, |x, y| {
        [
            (x * 5) as u8,
            (y * 12) as u8,
            ((x * 7 + y * 13) % 256) as u8,
            255,
        ]
    });
    let Pixels::U8(codes) = &img.pixels else {
        unreachable!()
    };
    assert_eq!(mip_levels(48, 20), 6);
    for level in 1..6u32 {
        let sets = [format!("level={level}")];
        let (w, _, out) = run_set(
            &mut engine,
            Execution::Fragment,
            ("level.fx", &sets),
            &img,
            &[],
        );
        let ((lw, lh), want) = common::mips::blit_level(codes, (48, 20), level);
        for y in 0..lh {
            for x in 0..lw {
                for c in 0..4 {
                    let got = out[4 * (y * w as usize + x) + c];
                    let expected = want[4 * (y * lw + x) + c];
                    assert!(
                        got.abs_diff(expected) <= 1,
                        "level {level} ({lw}x{lh}) texel ({x}, {y}) channel {c}: {got}, blit {expected}"
                    );
                }
            }
        }
    }
}

#[test]
fn an_implicit_level_follows_the_derivatives_on_both_paths() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let img = input();
    let Pixels::U8(codes) = &img.pixels else {
        unreachable!()
    };
    let (_, level2) = box_level(codes, (64, 64), 2);
    let fragment = run(&mut engine, Execution::Fragment, "lod.fx", &img, &[]);
    let compute = run(&mut engine, Execution::Compute, "lod.fx", &img, &[]);
    assert_eq!((fragment.0, fragment.1), (16, 16));
    assert_eq!(fragment.2, compute.2, "the two execution paths differ");
    let worst = fragment
        .2
        .iter()
        .zip(&level2)
        .map(|(a, b)| (i32::from(*a) - i32::from(*b)).abs())
        .max()
        .unwrap();
    assert!(worst <= 1, "not level 2: {worst} codes off the box filter");
}

#[test]
fn an_auxiliary_image_keeps_its_own_size() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let img = input();
    let lut = common::image_u8(24, 40, |x, y| [(x * 10) as u8, (y * 6) as u8, 99, 255]);
    let aux = [("lut".to_string(), &lut)];
    let (w, h, out) = run(&mut engine, Execution::Fragment, "lut.fx", &img, &aux);
    assert_eq!((w, h), (64, 64), "the output has the input's size");
    assert_eq!(&out[..4], &[24, 40, 0, 255], "`lut_size` is the LUT's size");
    for y in 1..64usize {
        for x in 0..64usize {
            // (x + 0.5) * 24 / 64 and (y + 0.5) * 40 / 64 are never whole.
            let (lx, ly) = ((2 * x + 1) * 24 / 128, (2 * y + 1) * 40 / 128);
            let want = [(lx * 10) as u8, (ly * 6) as u8, 99, 255];
            let at = 4 * (y * 64 + x);
            assert_eq!(&out[at..at + 4], &want, "pixel ({x}, {y})");
        }
    }
}

/// The graph of an effect script `text` (no error).
fn graph_of(text: &str) -> Graph {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.fx");
    std::fs::write(&path, text).unwrap();
    let (g, d, s) = common::compile::compile_file(&path);
    assert!(!d.has_errors(), "{}", d.render(&s));
    g.unwrap()
}

/// `img.MIPMAP = true`: a pass output gets the full chain in its own texture
/// (no copy), the input is copied once into a mipmapped texture (read raw, so
/// the copy is rgba8), the plan counts every level's bytes, and an auxiliary
/// image keeps its own size.
#[test]
fn mipmapped_inputs_get_their_chain_in_the_plan() {
    let g = graph_of("EFFECT.m = { PASS = {
        a = SHADER.s { img = IN  img.MIPMAP = true  img.COLORSPACE = srgb  OUT.FORMAT = rgba8 }
        b = SHADER.s { img = PASS.a  img.MIPMAP = true  other = IN  other.MIPMAP = true  other.COLORSPACE = srgb }
        c = SHADER.s { img = PASS.b  lut = AUX.lut  lut.MIPMAP = true }
    } OUT = c }");
    assert_eq!(mip_levels(40, 24), 6);
    assert_eq!(mip_levels(1, 1), 1);
    let input = InputDesc::rgba8_srgb(40, 24)
        .with_aux_of(&g)
        .with_aux_size("lut", (8, 5));
    let (p, _) = plan(&g, &input, &PlanOptions::default()).unwrap();
    p.validate().unwrap();
    let paths: Vec<&str> = p.passes.iter().map(|p| p.path.as_str()).collect();
    assert_eq!(
        paths,
        ["m/a:img:mips", "m/a", "m/b", "m/c:lut:mips", "m/c"],
        "one copy of IN, shared"
    );
    assert_eq!(p.passes[0].shader, PassShader::Mips);
    assert_eq!(p.passes[0].inputs[0].view, View::Raw);
    let copy = match p.passes[0].output {
        Resource::Value(v) => p.values[v].desc,
        _ => panic!("the copy is a value"),
    };
    assert_eq!((copy.format, copy.mips), (Format::Rgba8, 6));
    let a_out = match p.passes[1].output {
        Resource::Value(v) => p.values[v].desc,
        _ => panic!("a writes a value"),
    };
    assert_eq!(a_out.mips, 6, "a's own texture has the chain");
    assert_eq!(
        p.passes[2].inputs[1].resource,
        p.passes[1].inputs[0].resource
    );
    // 40x24 + 20x12 + 10x6 + 5x3 + 2x1 + 1x1 texels of 4 bytes.
    assert_eq!(a_out.bytes(), 4 * (960 + 240 + 60 + 15 + 2 + 1));
    let lut = &p.passes[3].inputs[0];
    assert_eq!(
        (lut.desc.width, lut.desc.height),
        (8, 5),
        "the LUT's own size"
    );
    let lut_copy = match p.passes[3].output {
        Resource::Value(v) => p.values[v].desc,
        _ => panic!("the copy is a value"),
    };
    assert_eq!((lut_copy.width, lut_copy.height, lut_copy.mips), (8, 5, 4));
    let b_out = match p.passes[2].output {
        Resource::Value(v) => p.values[v].desc,
        _ => panic!("b writes a value"),
    };
    assert_eq!(b_out.mips, 1, "read without MIPMAP: one level");
}
