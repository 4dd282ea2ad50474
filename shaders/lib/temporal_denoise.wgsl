// Shared pieces of the temporal_denoise passes (shaders/tdn_*.wgsl):
// `#include "lib/temporal_denoise.wgsl"`.

// The luma the motion search and the noise estimate work on: (r + 2g + b) / 4.
fn tdn_luma(c: vec4<f32>) -> f32 {
    return 0.25 * (c.r + 2.0 * c.g + c.b);
}

// Texel `p` of `t`, coordinates clamped to the texture (edge texels repeat).
fn tdn_load(t: texture_2d<f32>, p: vec2<i32>) -> vec4<f32> {
    let s = vec2<i32>(textureDimensions(t));
    return textureLoad(t, clamp(p, vec2<i32>(0), s - 1), 0);
}

// Motion field `mv` (one uv-unit vector per texel, at the texel centres) at `uv`,
// bilinearly interpolated between the four nearest vectors (read with textureLoad:
// rg32f is not filterable everywhere).
fn tdn_field(mv: texture_2d<f32>, uv: vec2<f32>) -> vec2<f32> {
    let g = uv * vec2<f32>(textureDimensions(mv)) - 0.5;
    let i = vec2<i32>(floor(g));
    let f = g - floor(g);
    let a = mix(tdn_load(mv, i).xy, tdn_load(mv, i + vec2<i32>(1, 0)).xy, f.x);
    let b = mix(tdn_load(mv, i + vec2<i32>(0, 1)).xy, tdn_load(mv, i + vec2<i32>(1, 1)).xy, f.x);
    return mix(a, b, f.y);
}

// Sub-texel offset of the minimum of the parabola through (-1, a), (0, b), (1, c)
// (the block matcher's cost around its best integer step), in [-0.5, 0.5].
fn tdn_parabola(a: f32, b: f32, c: f32) -> f32 {
    let den = a - 2.0 * b + c;
    if (den <= 1e-12) {
        return 0.0;
    }
    return clamp(0.5 * (a - c) / den, -0.5, 0.5);
}
