// sobel: Sobel gradient magnitude of the luma of `img` (used by the `edges` effect).
//
// The script reads `img` with COLORSPACE = srgb, so the luma is taken on
// sRGB-encoded values (perceptual, like CPU tools working on 8-bit files):
//   Y' = 0.2126 R' + 0.7152 G' + 0.0722 B'                    (Rec.709 weights)
//   Gx = [-1 0 1; -2 0 2; -1 0 1] * Y',  Gy = [-1 -2 -1; 0 0 0; 1 2 1] * Y'
//   e  = scale * sqrt(Gx^2 + Gy^2) / 4   (a unit step gives e = scale next to it)
//   e  = 0 where e < threshold
// Borders are replicated (clamped texel coordinates). MODE 0 writes the grey level
// e (1 - e with `invert`); MODE 1 mixes `color` into the image by min(e, 1). The
// result is decoded back to linear light, so an 8-bit output file holds 255 e.
@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    scale: f32,       // @default(1) @range(0, 100) gain on the normalised gradient magnitude
    threshold: f32,   // @default(0) @range(0, 10) magnitudes below this (after scale) become 0
    invert: f32,      // @default(0) @range(0, 1) magnitude mode: 1 draws dark edges on white
    color: vec3<f32>, // @default(0, 0, 0) @range(0, 1) overlay mode: edge colour (sRGB-encoded)
}
@group(0) @binding(1) var<uniform> params: Params;

#define MODE 0

fn luma(p: vec2<i32>, hi: vec2<i32>) -> f32 {
    let c = textureLoad(img, clamp(p, vec2<i32>(0), hi), 0).rgb;
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

#include "lib/srgb.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(textureDimensions(img)) - 1;
    let tl = luma(p + vec2<i32>(-1, -1), hi);
    let t = luma(p + vec2<i32>(0, -1), hi);
    let tr = luma(p + vec2<i32>(1, -1), hi);
    let l = luma(p + vec2<i32>(-1, 0), hi);
    let r = luma(p + vec2<i32>(1, 0), hi);
    let bl = luma(p + vec2<i32>(-1, 1), hi);
    let b = luma(p + vec2<i32>(0, 1), hi);
    let br = luma(p + vec2<i32>(1, 1), hi);
    let gx = (tr + 2.0 * r + br) - (tl + 2.0 * l + bl);
    let gy = (bl + 2.0 * b + br) - (tl + 2.0 * t + tr);
    var e = params.scale * 0.25 * sqrt(gx * gx + gy * gy);
    e = select(e, 0.0, e < params.threshold);
    let centre = textureLoad(img, p, 0);
#if MODE == 0
    let v = clamp(mix(e, 1.0 - e, params.invert), 0.0, 1.0);
    return vec4<f32>(lib_srgb_to_linear(vec3<f32>(v)), centre.a);
#else
    let v = mix(centre.rgb, params.color, min(e, 1.0));
    return vec4<f32>(lib_srgb_to_linear(v), centre.a);
#endif
}
