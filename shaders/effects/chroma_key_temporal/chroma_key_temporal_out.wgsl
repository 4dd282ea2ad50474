// ckt_out: the keyed colour with the smoothed matte (the `chroma_key_temporal`
// effect). `keyed` is chroma_key's straight output (linear, despilled), `matte.r`
// the smoothed alpha.
// OUTPUT: 0 straight RGBA, 1 premultiplied RGBA, 2 the matte as grey (alpha 1; the
// grey is sRGB-decoded so an 8-bit file holds the alpha as its code value, like
// chroma_key's matte output).
@group(0) @binding(0) var keyed: texture_2d<f32>;
@group(0) @binding(1) var matte: texture_2d<f32>;

#define OUTPUT 0

#include "lib/keyed.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let fg = textureLoad(keyed, p, 0).rgb;
    let a = clamp(textureLoad(matte, p, 0).r, 0.0, 1.0);
    return lib_keyed_output(fg, a);
}
