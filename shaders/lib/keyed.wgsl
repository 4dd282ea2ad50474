// The output forms of a keyed colour (shaders/effects/chroma_key/chroma_key.wgsl, chroma_key_temporal_out.wgsl):
// `#define OUTPUT` then `#include "lib/keyed.wgsl"`.

#include "srgb.wgsl"

// The keyed colour `fg` (linear) with alpha `a`, as OUTPUT selects: 0 straight RGBA,
// 1 premultiplied RGBA, 2 the matte as grey with alpha 1 (sRGB-decoded, so that an
// 8-bit file holds the alpha as its code value).
fn lib_keyed_output(fg: vec3<f32>, a: f32) -> vec4<f32> {
#if OUTPUT == 0
    return vec4<f32>(fg, a);
#elif OUTPUT == 1
    return vec4<f32>(fg * a, a);
#else
    return vec4<f32>(lib_srgb_to_linear(vec3<f32>(a)), 1.0);
#endif
}
