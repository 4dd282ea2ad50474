// The Gaussian blur along one axis of shaders/effects/glow/blurX.wgsl (VERTICAL = 0) and
// blurY.wgsl (VERTICAL = 1), with the standard deviation in output pixels:
// `#define VERTICAL 0` then `#include "lib/blur_axis.wgsl"`.
//
// Same size as the input: exact normalised Gaussian weights over [-r, r],
// r = ceil(3 sigma), taken two at a time with one bilinear tap (lib/gauss_pairs.wgsl).
//
// Smaller than the input (a downsampling blur, e.g. glow's half-size pass): the
// input is first box-filtered over the texels each output texel covers (2x2
// texels per bilinear fetch at a texel-pair centre, ceil(ratio / 2) fetches per
// axis), then blurred with the exact weights at every output column (row) in
// [-r, r], edge columns (rows) repeated (lib/prefilter.wgsl). Taking the
// bilinear-pair taps at output spacing there would skip input columns (rows) and
// leave stripes in the halo.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, the compute
// pass that runs wherever the output can be a storage texture, and `fs_main`,
// the same blur as a fragment pass, drawn where it cannot (an adapter without
// compute or without rgba16float storage, or a pass of another format).
// cs_main stages each line's values once in workgroup memory (for a
// downsampling blur: the box-prefiltered values, one fetch each at ratio 2;
// otherwise the input texels) and sums the exact weights there: a workgroup
// fetches ALONG + 2r values per line for ALONG outputs instead of r + 1 (same
// size) or 2r + 1 (downsampling) per output. The downsampling result is
// fs_main's (same values, weights and order); at the same size the exact
// weights replace the bilinear pairs (equal within the sampler's weight
// precision).
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(4) @range(0.1, 256) standard deviation in output pixels
    out_texel: vec2<f32>,
    out_size: vec2<f32>,
    img_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var out: texture_storage_2d<rgba16float, write>;

#include "prefilter.wgsl"
#include "gauss_pairs.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
#if VERTICAL
    let axis = vec2<f32>(0.0, 1.0);
    let dir = vec2<f32>(0.0, params.out_texel.y);
#else
    let axis = vec2<f32>(1.0, 0.0);
    let dir = vec2<f32>(params.out_texel.x, 0.0);
#endif
    let ratio = params.img_size / params.out_size;
    if (any(ratio > vec2<f32>(1.0))) {
        return lib_downsampling_blur(
            img, img_sampler, pos.xy, axis, params.sigma,
            params.out_texel, params.out_size, params.img_size,
        );
    }
    let r = i32(ceil(3.0 * params.sigma));
    var g = lib_gauss_pairs(params.sigma);
    var sum = textureSampleLevel(img, img_sampler, uv, 0.0);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        let offset = (f32(i) * w.x + f32(i + 1) * w.y) / pair;
        sum += pair * (textureSampleLevel(img, img_sampler, uv + offset * dir, 0.0)
                     + textureSampleLevel(img, img_sampler, uv - offset * dir, 0.0));
        total += 2.0 * pair;
    }
    return sum / total;
}

// cs_main's workgroup: ALONG outputs along the blur's axis on each of ACROSS
// lines; workgroup memory holds WINDOW values per line, so one round of staging
// covers TAPS taps (a radius up to (TAPS - 1) / 2: sigma 128 across rows, 16
// down columns); larger radii take more rounds.
#if VERTICAL
const ALONG: i32 = 32;
const ACROSS: i32 = 8;
#else
const ALONG: i32 = 256;
const ACROSS: i32 = 1;
#endif
const WINDOW: i32 = 1024 / ACROSS;
const TAPS: i32 = WINDOW - ALONG + 1;

// 1024 values: 16 KiB, the WebGPU default limit.
var<workgroup> lib_blur_window: array<vec4<f32>, 1024>;

// The value the blur weights at output pixel `along` of output line `line`: the
// box-prefiltered input under it (downsampling), the input texel (same size) or
// the bilinear sample at its centre (upsampling).
fn lib_blur_staged(along: i32, line: i32) -> vec4<f32> {
#if VERTICAL
    let p = vec2<f32>(f32(line), f32(along)) + 0.5;
#else
    let p = vec2<f32>(f32(along), f32(line)) + 0.5;
#endif
    let uv = p * params.out_texel;
    let ratio = params.img_size / params.out_size;
    if (any(ratio > vec2<f32>(1.0))) {
        let m = max(vec2<i32>(ceil(ratio * 0.5 - 1e-4)), vec2<i32>(1));
        if (all(m == vec2<i32>(1))) {
            return textureSampleLevel(img, img_sampler, uv, 0.0);
        }
        return lib_box_prefilter(img, img_sampler, uv, 2.0 / params.img_size, m);
    }
    if (all(ratio == vec2<f32>(1.0))) {
        return textureLoad(img, vec2<i32>(p), 0);
    }
    return textureSampleLevel(img, img_sampler, uv, 0.0);
}

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
#if VERTICAL
    let k = i32(local.x);
    let l = i32(local.y);
    let line0 = i32(group.x) * ACROSS;
    let a0 = i32(group.y) * ALONG;
    let lines = size.x;
    let last = size.y - 1;
#else
    let k = 0;
    let l = i32(local.x);
    let line0 = i32(group.y);
    let a0 = i32(group.x) * ALONG;
    let lines = size.y;
    let last = size.x - 1;
#endif
    let r = i32(ceil(3.0 * params.sigma));
    // w(i) = q^(i*i) for i = -r..r by products, as lib_downsampling_blur.
    let q = exp(-0.5 / (params.sigma * params.sigma));
    var w = pow(q, f32(r * r));
    var step = pow(q, f32(1 - 2 * r));
    let q2 = q * q;
    var sum = vec4<f32>(0.0);
    var total = 0.0;
    for (var lo = -r; lo <= r; lo += TAPS) {
        let n = min(TAPS, r + 1 - lo);
        let span = ALONG + n - 1;
        // The previous round's reads are done before the window is refilled.
        workgroupBarrier();
        for (var i = i32(index); i < ACROSS * span; i += 256) {
            let kk = i % ACROSS;
            let t = i / ACROSS;
            let line = min(line0 + kk, lines - 1);
            lib_blur_window[kk * WINDOW + t] = lib_blur_staged(clamp(a0 + lo + t, 0, last), line);
        }
        workgroupBarrier();
        for (var j = 0; j < n; j++) {
            sum += w * lib_blur_window[k * WINDOW + l + j];
            total += w;
            w *= step;
            step *= q2;
        }
    }
    let along = a0 + l;
    let line = line0 + k;
    if (along > last || line >= lines) {
        return;
    }
#if VERTICAL
    textureStore(out, vec2<i32>(line, along), sum / total);
#else
    textureStore(out, vec2<i32>(along, line), sum / total);
#endif
}
