// chroma_key: keys out a backdrop colour by its distance in the CbCr plane, with a
// linear soft band and spill suppression (the `chroma_key` and `chroma_composite`
// effects).
//
// `img` is read sRGB-encoded (COLORSPACE = srgb). With Rec.709 weights:
//   Y' = 0.2126 R' + 0.7152 G' + 0.0722 B',  Cb = (B' - Y') / 1.8556,  Cr = (R' - Y') / 1.5748
//   d  = |(Cb, Cr) - (Cb_key, Cr_key)|                 (luma is ignored)
//   alpha = clamp((d - tolerance) / softness, 0, 1)    (a step at tolerance if softness = 0)
// Spill: with k the unit vector of the key's chroma, the chroma's component along k
// is reduced: c -= spill * max(dot(c, k), 0) * k. Y' is kept, so brightness is.
// OUTPUT: 0 straight RGBA, 1 premultiplied RGBA, 2 the matte as grey (alpha 1).
// COMPOSITE = 1: the keyed image over `bg` (linear), alpha = a + bg.a (1 - a);
// `bg` is sampled at the pixel's place in the image, so a background of another
// size is stretched over it (at the same size, each pixel reads its own texel).
// Colours are decoded to linear light on output.
@group(0) @binding(0) var img: texture_2d<f32>;
#if COMPOSITE
@group(0) @binding(1) var bg: texture_2d<f32>;
@group(0) @binding(3) var bg_sampler: sampler;
#endif

struct Params {
    key: vec3<f32>,  // @default(0.2275, 0.8235, 0.2549) @range(0, 1) backdrop colour, sRGB-encoded 0..1
    tolerance: f32,  // @default(0.1) @range(0, 2) chroma distance keyed out completely
    softness: f32,   // @default(0.1) @range(0, 2) width of the band from transparent to opaque
    spill: f32,      // @default(1) @range(0, 1) fraction of key-coloured chroma removed from the foreground
}
@group(0) @binding(2) var<uniform> params: Params;

#define OUTPUT 0
#define COMPOSITE 0

const KR: f32 = 0.2126;
const KB: f32 = 0.0722;

fn ycc(c: vec3<f32>) -> vec3<f32> {
    let y = dot(c, vec3<f32>(KR, 1.0 - KR - KB, KB));
    return vec3<f32>(y, (c.b - y) / (2.0 * (1.0 - KB)), (c.r - y) / (2.0 * (1.0 - KR)));
}

fn rgb(v: vec3<f32>) -> vec3<f32> {
    let r = v.x + 2.0 * (1.0 - KR) * v.z;
    let b = v.x + 2.0 * (1.0 - KB) * v.y;
    let g = (v.x - KR * r - KB * b) / (1.0 - KR - KB);
    return vec3<f32>(r, g, b);
}

#include "lib/keyed.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let src = textureLoad(img, p, 0);
    let v = ycc(src.rgb);
    let k = ycc(params.key);
    let d = distance(v.yz, k.yz);
    var a = clamp((d - params.tolerance) / max(params.softness, 1e-6), 0.0, 1.0);
    a *= src.a;
    var c = v.yz;
    let kl = length(k.yz);
    if (kl > 1e-4) {
        let dir = k.yz / kl;
        c -= params.spill * max(dot(c, dir), 0.0) * dir;
    }
    let fg = lib_srgb_to_linear(rgb(vec3<f32>(v.x, c)));
#if COMPOSITE
    let uv = pos.xy / vec2<f32>(textureDimensions(img));
    let b = textureSampleLevel(bg, bg_sampler, uv, 0.0);
    return vec4<f32>(fg * a + b.rgb * (1.0 - a), a + b.a * (1.0 - a));
#else
    return lib_keyed_output(fg, a);
#endif
}
