// Box prefilter of a downsampling pass (shaders/blurX.wgsl, blurY.wgsl):
// `#include "lib/prefilter.wgsl"`.

// The mean of the input texels under the output texel at `uv` (0..1): `m` bilinear
// fetches per axis, each at a texel-pair centre (one fetch averages 2x2 texels),
// spaced two input texels apart (`spacing` = 2 / input size).
fn lib_box_prefilter(
    img: texture_2d<f32>,
    img_sampler: sampler,
    uv: vec2<f32>,
    spacing: vec2<f32>,
    m: vec2<i32>,
) -> vec4<f32> {
    var box = vec4<f32>(0.0);
    for (var j = 0; j < m.y; j++) {
        for (var k = 0; k < m.x; k++) {
            let o = (vec2<f32>(f32(k), f32(j)) - 0.5 * vec2<f32>(m - 1)) * spacing;
            box += textureSampleLevel(img, img_sampler, uv + o, 0.0);
        }
    }
    return box / f32(m.x * m.y);
}
