// vignette: darkens the image away from a centre.
//   q = (uv - center) * 2 * s,  s = mix((1, 1), a, roundness),
//       a = (w / h, 1) for landscape, (1, h / w) for portrait
//   (roundness 0: an ellipse fitted to the frame, distance 1 at the edge midpoints
//    for the default centre; roundness 1: a circle in pixels, distance 1 at the
//    shorter edges)
//   t = clamp((length(q) - radius) / softness, 0, 1);  v = t^2 (3 - 2 t)
//   out = in * (1 - strength * v)   (rgb; alpha kept)
@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    strength: f32,     // @default(0.5) @range(0, 1) darkening at the outside (1: black)
    radius: f32,       // @default(0.8) @range(0, 4) distance where the darkening starts
    softness: f32,     // @default(0.8) @range(0, 4) width of the transition to full darkening
    center: vec2<f32>, // @default(0.5, 0.5) @range(-1, 2) centre, in 0..1 of the width and height
    roundness: f32,    // @default(1) @range(0, 1) 1: circular in pixels; 0: elliptical, following the frame
    out_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let uv = pos.xy / params.out_size;
    let w = params.out_size.x;
    let h = params.out_size.y;
    let a = select(vec2<f32>(1.0, h / w), vec2<f32>(w / h, 1.0), w >= h);
    let s = mix(vec2<f32>(1.0), a, params.roundness);
    let q = (uv - params.center) * 2.0 * s;
    let t = clamp((length(q) - params.radius) / max(params.softness, 1e-5), 0.0, 1.0);
    let v = t * t * (3.0 - 2.0 * t);
    return vec4<f32>(c.rgb * (1.0 - params.strength * v), c.a);
}
