// ckt_matte: temporally smoothed matte for the `chroma_key_temporal` effect
// (effects/chroma_key_temporal.fx). Writes the matte in r.
//
//   D   = cur - prev                       input colours, sRGB-encoded (r, g, b)
//   m   = max(|mean of D over 3x3|, |D| / 3), averaged over r, g, b
//   h   = strength * exp(-m^2 / (2 sigma^2))
//   out = (1 - h) * keyed.a + h * hist.r   (hist: this pass's previous output)
// First output (frame 0, subframe 0; no history): out = keyed.a.
@group(0) @binding(0) var keyed: texture_2d<f32>;
@group(0) @binding(1) var cur: texture_2d<f32>;
@group(0) @binding(2) var prev: texture_2d<f32>;
@group(0) @binding(3) var hist: texture_2d<f32>;

struct Params {
    strength: f32, // @default(0.8) @range(0, 0.99) weight of the previous matte where the colour is stable
    sigma: f32,    // @default(0.05) @range(0.0001, 10) colour change (sRGB-encoded units) counted as motion, about the input noise level or above
    frame: u32,
    subframe: u32,
}
@group(0) @binding(4) var<uniform> params: Params;

fn diff_at(p: vec2<i32>, s: vec2<i32>) -> vec3<f32> {
    let q = clamp(p, vec2<i32>(0), s - 1);
    return textureLoad(cur, q, 0).rgb - textureLoad(prev, q, 0).rgb;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let a = textureLoad(keyed, p, 0).a;
    if (params.frame == 0u && params.subframe == 0u) {
        return vec4<f32>(a, 0.0, 0.0, 1.0);
    }
    let s = vec2<i32>(textureDimensions(cur));
    var box = vec3<f32>(0.0);
    for (var dy = -1; dy <= 1; dy = dy + 1) {
        for (var dx = -1; dx <= 1; dx = dx + 1) {
            box += diff_at(p + vec2<i32>(dx, dy), s);
        }
    }
    let m_box = dot(abs(box / 9.0), vec3<f32>(1.0 / 3.0));
    let m_px = dot(abs(diff_at(p, s)), vec3<f32>(1.0 / 3.0)) / 3.0;
    let m = max(m_box, m_px);
    let sg = max(params.sigma, 1e-6);
    let h = params.strength * exp(-0.5 * (m * m) / (sg * sg));
    let smoothed = mix(a, textureLoad(hist, p, 0).r, h);
    return vec4<f32>(smoothed, 0.0, 0.0, 1.0);
}
