// The sRGB transfer curve for shaders that compute in sRGB-encoded values and
// write linear ones (shaders/effects/chroma_key/chroma_key.wgsl, edges_sobel.wgsl, pencil_sketch.wgsl, and
// lib/keyed.wgsl): `#include "lib/srgb.wgsl"`.

// sRGB-encoded -> linear (the exact curve), the input clamped to [0, 1] first.
fn lib_srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(pow((x + 0.055) / 1.055, vec3<f32>(2.4)), x / 12.92, x <= vec3<f32>(0.04045));
}
