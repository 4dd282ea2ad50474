// gauss: one direction of a separable Gaussian blur at the input's resolution (the
// output has the input's size). Used by `gaussian_blur` and `sharpen`.
//
// Radius r = (ksize - 1) / 2 with ksize = round(6 sigma + 1) | 1 (OpenCV's rule for
// 8-bit images, round half to even); weights exp(-i^2 / (2 sigma^2)) for i in
// [-r, r], normalised to a sum of 1. The border is replicated (clamp-to-edge).
//
// Defines:
//   VERTICAL = 0: horizontal (default); 1: vertical.
//   EXACT = 0: two texels per bilinear tap at the weighted position between them
//              (r + 1 fetches; the default, fastest);
//           1: one textureLoad per texel (2r + 1 fetches; no dependence on the
//              sampler's sub-texel precision).
//   UNSHARP = 1: unsharp mask instead of a blur: `orig + amount * (orig - blur)`
//              where |orig - blur| >= threshold (per channel), clamped at 0,
//              alpha of `orig` (`sharpen` runs its vertical blur this way,
//              saving a pass).
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, the compute
// pass, and `fs_main`. cs_main runs under compute execution (`auto` on GPUs)
// wherever the output can be a storage texture (rgba16f: EXR and other float
// inputs); `fs_main` is drawn elsewhere: under fragment execution (`auto` on
// CPU adapters: `// @execution(compute)`, as on lavapipe cs_main costs more
// CPU than fs_main, docs/architecture.md), for an 8-bit sRGB output, on an
// adapter without rgba16float storage. cs_main stages each line segment once
// in workgroup memory (VERTICAL: 32 pixels of each of 8 columns, otherwise 256
// pixels of a row, plus r on either side, the border replicated) and sums
// EXACT = 1's weights there, in its order (pairs around the centre; radii past
// one window, r > 48 down columns: rounds of 97 taps, weights from w(-r)), so a
// workgroup loads ALONG + 2r texels per line for ALONG outputs instead of r + 1
// bilinear taps (EXACT = 0) or 2r + 1 loads (EXACT = 1) per output. Against
// fs_main (tests/execution.rs, the compute run's rgba16f output against
// fs_main's at rgba32f), measured on lavapipe: 2.4e-4 (EXACT = 0, sigma 3.5),
// 4.9e-4 (EXACT = 1, sigma 20, two rounds), 9.2e-4 (UNSHARP, amount 1.5,
// outputs up to 3.25), relative: within one rgba16f step (2^-10).
#define VERTICAL 0
#define EXACT 0
#define UNSHARP 0

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;
#if UNSHARP
@group(0) @binding(3) var orig: texture_2d<f32>;
#endif
@group(0) @binding(4) var out: texture_storage_2d<rgba16float, write>;

struct Params {
    sigma: f32, // @default(2) @range(0.1, 128) standard deviation in pixels
#if UNSHARP
    amount: f32,    // @default(1) @range(0, 20) strength: orig + amount * (orig - blur)
    threshold: f32, // @default(0) @range(0, 1) per-channel differences below this are not sharpened
#endif
    img_size: vec2<f32>,
    img_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/gauss_pairs.wgsl"

fn radius(sigma: f32) -> i32 {
    // WGSL round() rounds half to even, like OpenCV's cvRound.
    let ksize = i32(round(sigma * 6.0 + 1.0)) | 1;
    return (ksize - 1) / 2;
}

// The blur at `p` minus the centre texel `c`: weighted differences from the centre
// are summed, so that a flat area gives exactly 0 (and the blur exactly `c`) even
// where the target format rounds towards zero.
fn blur_delta(p: vec2<i32>, c: vec4<f32>) -> vec4<f32> {
    let r = radius(params.sigma);
    var sum = vec4<f32>(0.0);
    var total = 1.0;
#if EXACT
    // w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)); w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = q;         // w(1)
    var step = q * q2; // w(2) / w(1) = q^3
#if VERTICAL
    let last = i32(params.img_size.y) - 1;
    let k = p.y;
#else
    let last = i32(params.img_size.x) - 1;
    let k = p.x;
#endif
    for (var i = 1; i <= r; i++) {
        let a = max(k - i, 0);
        let b = min(k + i, last);
#if VERTICAL
        let s = textureLoad(img, vec2<i32>(p.x, a), 0) + textureLoad(img, vec2<i32>(p.x, b), 0);
#else
        let s = textureLoad(img, vec2<i32>(a, p.y), 0) + textureLoad(img, vec2<i32>(b, p.y), 0);
#endif
        sum += w * (s - 2.0 * c);
        total += 2.0 * w;
        w *= step;
        step *= q2;
    }
#else
#if VERTICAL
    let dir = vec2<f32>(0.0, params.img_texel.y);
#else
    let dir = vec2<f32>(params.img_texel.x, 0.0);
#endif
    let uv = (vec2<f32>(p) + 0.5) * params.img_texel;
    var g = lib_gauss_pairs(params.sigma);
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        // Sampling between texels i and i+1 at this offset weights them w(i) : w(i+1);
        // clamp-to-edge makes texels past the border replicate the edge.
        let offset = f32(i) + w.y / max(pair, 1e-30);
        let s = textureSampleLevel(img, img_sampler, uv + offset * dir, 0.0)
              + textureSampleLevel(img, img_sampler, uv - offset * dir, 0.0);
        sum += pair * (s - 2.0 * c);
        total += 2.0 * pair;
    }
#endif
    return sum / total;
}

// The pass's output at `p` from the blur `blurred` (the centre texel `c` of
// `img` plus the weighted differences).
fn finish(p: vec2<i32>, blurred: vec4<f32>) -> vec4<f32> {
#if UNSHARP
    let o = textureLoad(orig, p, 0);
    let d = o.rgb - blurred.rgb;
    let keep = select(vec3<f32>(0.0), vec3<f32>(1.0), abs(d) >= vec3<f32>(params.threshold));
    return vec4<f32>(max(o.rgb + params.amount * d * keep, vec3<f32>(0.0)), o.a);
#else
    return blurred;
#endif
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    // The blur's centre is `img` (for UNSHARP the horizontal blur, not `orig`).
    let c = textureLoad(img, p, 0);
    return finish(p, c + blur_delta(p, c));
}

// cs_main's workgroup: ALONG outputs along the blur's axis on each of ACROSS
// lines; workgroup memory holds WINDOW texels per line (texel t of line k at
// t * ACROSS + k, so neighbouring invocations read neighbouring words), so one
// window covers TAPS taps: r <= 48 down columns, r <= 384 along rows; larger
// radii take rounds of TAPS taps.
#if VERTICAL
const ALONG: i32 = 32;
const ACROSS: i32 = 8;
#else
const ALONG: i32 = 256;
const ACROSS: i32 = 1;
#endif
const WINDOW: i32 = 1024 / ACROSS;
const TAPS: i32 = WINDOW - ALONG + 1;

// 1024 texels: 16 KiB, the WebGPU default limit.
var<workgroup> segment: array<vec4<f32>, 1024>;

// Stages texels `first` .. `first + span - 1` along the axis of the workgroup's
// lines `line0` .. (the border replicated: `last` is the last texel along the
// axis, `lines` the number of lines). `index` is local_invocation_index.
fn stage(index: i32, line0: i32, lines: i32, first: i32, last: i32, span: i32) {
    for (var i = index; i < ACROSS * span; i += 256) {
        let line = min(line0 + i % ACROSS, lines - 1);
        let a = clamp(first + i / ACROSS, 0, last);
#if VERTICAL
        segment[i] = textureLoad(img, vec2<i32>(line, a), 0);
#else
        segment[i] = textureLoad(img, vec2<i32>(a, line), 0);
#endif
    }
}

// The blur's weighted differences from the centre `c` (blur_delta's sum and
// total) at output `l` of line `k` of a workgroup whose outputs start at `a0`,
// from windows of TAPS taps: w(j) = q^(j*j) for j = -r..r by products,
// w(j+1) = w(j) * q^(2j+1). For radii past one window.
fn rounds(index: i32, k: i32, l: i32, line0: i32, lines: i32, a0: i32, last: i32, c: vec4<f32>) -> vec4<f32> {
    let r = radius(params.sigma);
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = pow(q, f32(r * r));
    var step = pow(q, f32(1 - 2 * r));
    var sum = vec4<f32>(0.0);
    var total = 0.0;
    for (var lo = -r; lo <= r; lo += TAPS) {
        let n = min(TAPS, r + 1 - lo);
        // The previous round's reads are done before the window is refilled.
        workgroupBarrier();
        stage(index, line0, lines, a0 + lo, last, ALONG + n - 1);
        workgroupBarrier();
        for (var j = 0; j < n; j++) {
            sum += w * (segment[(l + j) * ACROSS + k] - c);
            total += w;
            w *= step;
            step *= q2;
        }
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
    let size = vec2<i32>(params.img_size);
#if VERTICAL
    let k = i32(local.x);
    let l = i32(local.y);
    let line0 = i32(group.x) * ACROSS;
    let a0 = i32(group.y) * ALONG;
    let lines = size.x;
    let last = size.y - 1;
    let p = vec2<i32>(min(line0 + k, lines - 1), min(a0 + l, last));
#else
    let k = 0;
    let l = i32(local.x);
    let line0 = i32(group.y);
    let a0 = i32(group.x) * ALONG;
    let lines = size.y;
    let last = size.x - 1;
    let p = vec2<i32>(min(a0 + l, last), min(line0, lines - 1));
#endif
    let r = radius(params.sigma);
    var c: vec4<f32>;
    var delta: vec4<f32>;
    if (2 * r < TAPS) {
        // One window: the pairs (-i, i) around the centre, as blur_delta.
        stage(i32(index), line0, lines, a0 - r, last, ALONG + 2 * r);
        workgroupBarrier();
        let j = (l + r) * ACROSS + k;
        c = segment[j];
        let q = exp(-0.5 / (params.sigma * params.sigma));
        let q2 = q * q;
        var w = q;
        var step = q * q2;
        var sum = vec4<f32>(0.0);
        var total = 1.0;
        for (var i = 1; i <= r; i++) {
            let s = segment[j - i * ACROSS] + segment[j + i * ACROSS];
            sum += w * (s - 2.0 * c);
            total += 2.0 * w;
            w *= step;
            step *= q2;
        }
        delta = sum / total;
    } else {
        c = textureLoad(img, p, 0);
        delta = rounds(i32(index), k, l, line0, lines, a0, last, c);
    }
    if (a0 + l > last || line0 + k >= lines) {
        return;
    }
    textureStore(out, p, finish(p, c + delta));
}
