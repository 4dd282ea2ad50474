// tdenoise: recursive temporal average with motion rejection (the
// `temporal_denoise` effect; the maths is documented in effects/temporal_denoise.fx).
//
//   D      = cur - hist                               per pixel, per channel
//   m      = max(|mean over 3x3 of D|, |D| / 3)       averaged over r, g, b
//   h      = strength * exp(-m^2 / (2 sigma^2))       weight of the history
//   out    = cur + h * (hist - cur)                   all four channels
// At the first output (frame 0, subframe 0) the history is empty (feedback reads
// zero): out = cur.
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var hist: texture_2d<f32>;

struct Params {
    strength: f32, // @default(0.9) @range(0, 0.99) weight of the history where nothing moves
    sigma: f32,    // @default(0.05) @range(0.0001, 10) noise level (linear units): differences well above it count as motion
    frame: u32,
    subframe: u32,
}
@group(0) @binding(2) var<uniform> params: Params;

fn diff_at(p: vec2<i32>, s: vec2<i32>) -> vec3<f32> {
    let q = clamp(p, vec2<i32>(0), s - 1);
    return textureLoad(cur, q, 0).rgb - textureLoad(hist, q, 0).rgb;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(cur, p, 0);
    if (params.frame == 0u && params.subframe == 0u) {
        return c;
    }
    let h0 = textureLoad(hist, p, 0);
    let s = vec2<i32>(textureDimensions(cur));
    var box = vec3<f32>(0.0);
    for (var dy = -1; dy <= 1; dy = dy + 1) {
        for (var dx = -1; dx <= 1; dx = dx + 1) {
            box += diff_at(p + vec2<i32>(dx, dy), s);
        }
    }
    let m_box = dot(abs(box / 9.0), vec3<f32>(1.0 / 3.0));
    let m_px = dot(abs(c.rgb - h0.rgb), vec3<f32>(1.0 / 3.0)) / 3.0;
    let m = max(m_box, m_px);
    let sg = max(params.sigma, 1e-6);
    let h = params.strength * exp(-0.5 * (m * m) / (sg * sg));
    return mix(c, h0, h);
}
