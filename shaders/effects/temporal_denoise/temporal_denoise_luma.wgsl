// tdn_luma: one level of the luma pyramid of temporal_denoise's motion search
// (effects/temporal_denoise.fx): a 2x2 box downsample, one bilinear tap at the
// corner the four input texels share (the output is half the input's size).
// LUMA = 1: the input is the colour image and the level holds its luma
// (r + 2g + b) / 4; LUMA = 0: the input is already a luma level.
// The tap is placed from the pixel's position, not the interpolated `uv`: the
// two differ in their last bits between fragment and compute execution, and
// the motion search's discrete choices turned that into visible differences
// (5.8e-2 on a noisy sequence); from `pos` both paths sample the same point.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    out_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#define LUMA 0

#include "lib/temporal_denoise.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureSampleLevel(img, img_sampler, pos.xy * params.out_texel, 0.0);
#if LUMA == 1
    return vec4<f32>(tdn_luma(c), 0.0, 0.0, 1.0);
#else
    return vec4<f32>(c.r, 0.0, 0.0, 1.0);
#endif
}
