// pencil_blur: one direction of the separable Gaussian blur of the `pencil` effect.
// Horizontal (default): blurs the Rec.709 luma of `img`'s rgb; VERTICAL = 1: blurs
// `img`'s red channel (the horizontal result). Writes the blurred value in .r.
//
// Same taps as blurX/blurY: exact normalised Gaussian weights over [-r, r], r =
// ceil(3 s), taken two at a time with one bilinear tap (lib/gauss_pairs.wgsl),
// sampled at the output's resolution (a smaller output also downsamples). The luma
// is linear in the channels, so the luma of a bilinear tap is the bilinear tap of
// the luma. s = sigma * scale is the standard deviation in output pixels: `sigma` is
// given in pixels of the effect input and `scale` is the pass's OUT.SCALE.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, the compute
// pass, runs under compute execution (`auto` on GPUs) wherever the output can
// be a storage texture (r16f, the effect's intermediates); `fs_main` is drawn
// elsewhere, and under fragment execution (`auto` on CPU adapters:
// `// @execution(compute)`, as on lavapipe cs_main costs more CPU than
// fs_main, docs/architecture.md). cs_main stages
// the input line under each output line once in workgroup memory (the value
// blurred, interpolated across the axis as the bilinear taps do: 256 outputs of
// a row, or 32 of each of 8 columns, and the input texels their taps reach),
// then takes the same taps with the same weights from there, interpolating
// along the axis itself: the bilinear filter written out, so a workgroup loads
// each input texel of its lines once instead of each output taking r + 1
// bilinear taps. Where a line's taps reach past WINDOW texels (radii beyond the
// effect's range) it samples as fs_main does. Against fs_main
// (tests/execution.rs, the compute run's r16f output against fs_main's at
// r32f), measured on lavapipe: 4.9e-4 (sigma 5 at half size), 2.4e-4
// (vertical, sigma 7), 4.9e-4 (sigma 100, sampled), relative: within one r16f
// step. The written-out filter's f32 weights come closer to the oracle than
// lavapipe's sampler: the effect is 1 LSB from the dodge oracle with cs_main,
// 2 to 4 with fs_main (tests/effects/pencil.rs).
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(5) @range(0.1, 256) standard deviation in pixels of the effect input
    scale: f32, // @default(1) @range(0.01, 1) the pass's OUT.SCALE (output pixels per input pixel)
    out_texel: vec2<f32>,
    out_size: vec2<f32>,
    img_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var out: texture_storage_2d<r16float, write>;

#define VERTICAL 0

#include "lib/gauss_pairs.wgsl"

// The value blurred: the red channel (VERTICAL) or the Rec.709 luma.
fn channel(c: vec4<f32>) -> f32 {
#if VERTICAL
    return c.r;
#else
    return dot(c.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
#endif
}

fn tap(uv: vec2<f32>) -> f32 {
    return channel(textureSampleLevel(img, img_sampler, uv, 0.0));
}

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let y = blur(uv);
    return vec4<f32>(y, y, y, 1.0);
}

// The blur at `uv` by bilinear taps (fs_main, and cs_main past its window).
fn blur(uv: vec2<f32>) -> f32 {
#if VERTICAL
    let dir = vec2<f32>(0.0, params.out_texel.y);
#else
    let dir = vec2<f32>(params.out_texel.x, 0.0);
#endif
    let sigma = params.sigma * params.scale;
    let r = i32(ceil(3.0 * sigma));
    var g = lib_gauss_pairs(sigma);
    var sum = tap(uv);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        let offset = (f32(i) * w.x + f32(i + 1) * w.y) / pair;
        sum += pair * (tap(uv + offset * dir) + tap(uv - offset * dir));
        total += 2.0 * pair;
    }
    return sum / total;
}

// cs_main's workgroup: ALONG outputs along the blur's axis on each of ACROSS
// lines; workgroup memory holds WINDOW input values per line.
#if VERTICAL
const ALONG: i32 = 32;
const ACROSS: i32 = 8;
#else
const ALONG: i32 = 256;
const ACROSS: i32 = 1;
#endif
const WINDOW: i32 = 4096 / ACROSS;

// 4096 values: 16 KiB, the WebGPU default limit.
var<workgroup> staged: array<f32, 4096>;

// The value at input texel `a` along the axis of the input line at `y` across
// it (texel units, texel centres at integers), interpolated between the two
// texels around `y` as the bilinear filter does; the border replicated.
fn line_value(a: i32, y: f32) -> f32 {
    let last = vec2<i32>(params.img_size) - 1;
    let y0 = floor(y);
    let f = y - y0;
    let j = i32(y0);
#if VERTICAL
    let p0 = vec2<i32>(clamp(j, 0, last.x), clamp(a, 0, last.y));
    let p1 = vec2<i32>(clamp(j + 1, 0, last.x), p0.y);
#else
    let p0 = vec2<i32>(clamp(a, 0, last.x), clamp(j, 0, last.y));
    let p1 = vec2<i32>(p0.x, clamp(j + 1, 0, last.y));
#endif
    let c0 = textureLoad(img, p0, 0);
    if (f == 0.0) {
        return channel(c0);
    }
    return channel(mix(c0, textureLoad(img, p1, 0), f));
}

// The bilinear tap at input coordinate `x` along the axis from the staged line
// starting at `base` (workgroup memory index of input texel 0).
fn staged_tap(base: i32, x: f32) -> f32 {
    let x0 = floor(x);
    let i = base + i32(x0);
    return mix(staged[i], staged[i + 1], x - x0);
}

// fs_main's taps at output position `o` along the axis, from the staged line:
// output coordinate o + 0.5 + s is input coordinate (o + 0.5 + s) * ratio - 0.5.
fn staged_blur(base: i32, o: f32, ratio: f32, sigma: f32, r: i32) -> f32 {
    var g = lib_gauss_pairs(sigma);
    var sum = staged_tap(base, (o + 0.5) * ratio - 0.5);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        let offset = (f32(i) * w.x + f32(i + 1) * w.y) / pair;
        sum += pair * (staged_tap(base, (o + 0.5 + offset) * ratio - 0.5)
                     + staged_tap(base, (o + 0.5 - offset) * ratio - 0.5));
        total += 2.0 * pair;
    }
    return sum / total;
}

// @execution(compute)
#if VERTICAL
@compute @workgroup_size(8, 32, 1)
#else
@compute @workgroup_size(256, 1, 1)
#endif
fn cs_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
) {
    let size = vec2<i32>(params.out_size);
    let ratio = params.img_size / params.out_size;
#if VERTICAL
    let k = i32(local.x);
    let l = i32(local.y);
    let line0 = i32(group.x) * ACROSS;
    let a0 = i32(group.y) * ALONG;
    let lines = size.x;
    let last = size.y - 1;
    let along = ratio.y;
    let across = ratio.x;
    let p = vec2<i32>(line0 + k, a0 + l);
#else
    let k = 0;
    let l = i32(local.x);
    let line0 = i32(group.y);
    let a0 = i32(group.x) * ALONG;
    let lines = size.y;
    let last = size.x - 1;
    let along = ratio.x;
    let across = ratio.y;
    let p = vec2<i32>(a0 + l, line0);
#endif
    let sigma = params.sigma * params.scale;
    let r = i32(ceil(3.0 * sigma));
    // The input texels the workgroup's taps reach (offsets up to r output
    // pixels), a texel of margin either side.
    let lo = i32(floor((f32(a0 - r) + 0.5) * along - 0.5)) - 1;
    let hi = i32(floor((f32(a0 + ALONG - 1 + r) + 0.5) * along - 0.5)) + 2;
    let span = hi - lo + 1;
    var y: f32;
    if (span <= WINDOW) {
        for (var i = i32(index); i < ACROSS * span; i += 256) {
            let kk = i % ACROSS;
            let t = i / ACROSS;
            let line = min(line0 + kk, lines - 1);
            staged[kk * WINDOW + t] = line_value(lo + t, (f32(line) + 0.5) * across - 0.5);
        }
        workgroupBarrier();
        if (a0 + l > last || line0 + k >= lines) {
            return;
        }
        y = staged_blur(k * WINDOW - lo, f32(a0 + l), along, sigma, r);
    } else {
        if (a0 + l > last || line0 + k >= lines) {
            return;
        }
        y = blur((vec2<f32>(p) + 0.5) * params.out_texel);
    }
    textureStore(out, p, vec4<f32>(y, y, y, 1.0));
}
