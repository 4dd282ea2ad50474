// bloomDown: one level of bloom's downsample chain. The output is normally half the
// input's size; each output pixel is the 13-tap filter of Jimenez ("Next generation
// post processing in Call of Duty: Advanced Warfare", SIGGRAPH 2014): five 2x2 boxes
// of input texels (one centred, weight 1/2; four overlapping corner boxes, 1/8 each),
// taken with 13 bilinear taps at offsets of 0, 1 and 2 input texels. Weights sum to 1.
// TAPS = 4: a 4x4 box instead (4 bilinear taps at offsets (+-1, +-1)), a third of
// the cost; used on the first level, which reads the full-size input.
//
// PREFILTER = 1 (first level): the filtered colour is then scaled by a soft
// threshold on its brightness b = max(r, g, b):
//   contribution(b) = max(b - threshold, (clamp(b - threshold + knee, 0, 2 knee))^2 / (4 knee))
//   out = colour * contribution(b) / b
// (a quadratic knee of half-width `knee` around the threshold, linear above it).
// Values are clamped to [0, 65000] first so that infinities do not spread.
#define PREFILTER 0
#define TAPS 13

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
#if PREFILTER
    threshold: f32, // @default(1) @range(0, 65000) brightness (max of r, g, b, linear) where bloom starts
    knee: f32,      // @default(0.5) @range(0, 1000) half-width of the soft transition around the threshold
#endif
    img_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

fn tap(uv: vec2<f32>, dx: f32, dy: f32) -> vec3<f32> {
    return textureSampleLevel(img, img_sampler, uv + vec2<f32>(dx, dy) * params.img_texel, 0.0).rgb;
}

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
#if TAPS == 4
    var col = (tap(uv, -1.0, -1.0) + tap(uv, 1.0, -1.0) + tap(uv, -1.0, 1.0) + tap(uv, 1.0, 1.0)) * 0.25;
#else
    let a = tap(uv, -2.0, -2.0);
    let b = tap(uv, 0.0, -2.0);
    let c = tap(uv, 2.0, -2.0);
    let d = tap(uv, -2.0, 0.0);
    let e = tap(uv, 0.0, 0.0);
    let f = tap(uv, 2.0, 0.0);
    let g = tap(uv, -2.0, 2.0);
    let h = tap(uv, 0.0, 2.0);
    let i = tap(uv, 2.0, 2.0);
    let j = tap(uv, -1.0, -1.0);
    let k = tap(uv, 1.0, -1.0);
    let l = tap(uv, -1.0, 1.0);
    let m = tap(uv, 1.0, 1.0);
    var col = e * 0.125 + (a + c + g + i) * 0.03125 + (b + d + f + h) * 0.0625 + (j + k + l + m) * 0.125;
#endif
#if PREFILTER
    col = clamp(col, vec3<f32>(0.0), vec3<f32>(65000.0));
    let br = max(col.r, max(col.g, col.b));
    let kn = max(params.knee, 1e-5);
    let soft = clamp(br - params.threshold + kn, 0.0, 2.0 * kn);
    let contribution = max(soft * soft / (4.0 * kn), br - params.threshold);
    col *= max(contribution, 0.0) / max(br, 1e-5);
#endif
    return vec4<f32>(col, 1.0);
}
