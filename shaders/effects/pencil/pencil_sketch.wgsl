// pencil: colour-dodge pencil sketch (the last pass of the `pencil` effect).
//
// `img` is read sRGB-encoded (COLORSPACE = srgb), `blurred` holds G = blur(Y'),
// the Gaussian-blurred luma from the two pencil_blur passes, at any resolution
// (sampled bilinearly at this pixel's centre). With Y' the Rec.709 luma:
//   dodge(Y', blur(1 - Y')) = Y' / (1 - blur(1 - Y')) = Y' / G
//   s = clamp((Y' + eps) / (G + eps), 0, 1)             eps = 0.01
// eps keeps flat black areas white (the classic formula is 0/0 there) and tames
// noise in the darks. Then s = s^darkness, paper grain multiplies s by
// (1 - paper * n) with n a deterministic value noise in [0, 1], and the colour
// option tints: rgb' = s * mix(1, img', color). The sketch is a perceptual grey
// level; it is decoded to linear light, so an 8-bit output file holds 255 s.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var blurred: texture_2d<f32>;
@group(0) @binding(3) var blurred_sampler: sampler;

struct Params {
    darkness: f32, // @default(1) @range(0.1, 10) exponent on the sketch: > 1 darkens the strokes
    paper: f32,    // @default(0) @range(0, 1) strength of the paper grain
    color: f32,    // @default(0) @range(0, 1) 0: grey pencil; 1: tinted with the image colours
}
@group(0) @binding(2) var<uniform> params: Params;

const EPS: f32 = 0.01;

fn hash(p: vec2<u32>) -> f32 {
    var h = p.x * 0x8da6b343u ^ p.y * 0xd8163841u;
    h = (h ^ (h >> 15u)) * 0x2c1b3c6du;
    h = (h ^ (h >> 12u)) * 0x297a2d39u;
    h = h ^ (h >> 15u);
    return f32(h >> 8u) / 16777216.0;
}

// Value noise: bilinear interpolation of a hash lattice every `cell` pixels.
fn value_noise(pos: vec2<f32>, cell: f32) -> f32 {
    let q = pos / cell;
    let i = vec2<u32>(floor(q));
    let f = fract(q);
    let s = f * f * (3.0 - 2.0 * f);
    let a = mix(hash(i), hash(i + vec2<u32>(1u, 0u)), s.x);
    let b = mix(hash(i + vec2<u32>(0u, 1u)), hash(i + vec2<u32>(1u, 1u)), s.x);
    return mix(a, b, s.y);
}

#include "lib/srgb.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(img, p, 0);
    let y = dot(c.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
    let g = textureSampleLevel(blurred, blurred_sampler, uv, 0.0).r;
    var s = clamp((y + EPS) / (max(g, 0.0) + EPS), 0.0, 1.0);
    s = pow(s, params.darkness);
    if (params.paper > 0.0) {
        // Fibres: fine grain plus a softer, larger mottling.
        let n = 0.6 * hash(vec2<u32>(p)) + 0.4 * value_noise(pos.xy, 6.0);
        s *= 1.0 - params.paper * n;
    }
    let rgb = s * mix(vec3<f32>(1.0), c.rgb, params.color);
    return vec4<f32>(lib_srgb_to_linear(rgb), c.a);
}
