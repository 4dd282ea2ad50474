// outline_apply: draws the outline found by shaders/effects/outline/outline_detect.wgsl, or blends
// across the detected edges (edge anti-aliasing); used by the `outline` effect.
//
// MODE 0 (overlay): coverage c = max over the outline pixels q within `width` of p
//        of clamp(width - |q - p|, 0, 1) (width 1: the outline pixels themselves);
//        out = vec4(mix(img.rgb, color, opacity * c), img.a)
// MODE 1 (mask):    out = vec4(c, c, c, 1)
// MODE 2 (antialias): with E the 4-neighbours across an edge of p (any side),
//        out = mix(img(p), mean of img(q) over E, strength / 2)  (all four channels;
//        unchanged where E is empty); strength 1 makes both pixels of an edge pair
//        their average.
#define MODE 0

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var edges: texture_2d<f32>;

struct Params {
    color: vec3<f32>, // @default(0, 0, 0) @range(0, 65504) outline colour (linear)
    opacity: f32,     // @default(1) @range(0, 1) opacity of the outline
    width: f32,       // @default(1) @range(1, 8) outline width in pixels (from the silhouette inwards and outwards)
    strength: f32,    // @default(1) @range(0, 1) antialias mode: how far to blend across the edges
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let size = vec2<i32>(textureDimensions(img));
    let c0 = textureLoad(img, p, 0);
#if MODE == 2
    let flags = u32(textureLoad(edges, p, 0).y + 0.5);
    let offsets = array<vec2<i32>, 4>(vec2<i32>(-1, 0), vec2<i32>(1, 0), vec2<i32>(0, -1), vec2<i32>(0, 1));
    var sum = vec4<f32>(0.0);
    var count = 0.0;
    for (var k = 0; k < 4; k++) {
        if ((flags & (1u << u32(k))) != 0u) {
            sum += textureLoad(img, p + offsets[k], 0);
            count += 1.0;
        }
    }
    if (count == 0.0) {
        return c0;
    }
    return mix(c0, sum / count, 0.5 * params.strength);
#else
    let r = i32(ceil(params.width - 1.0));
    var cov = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let q = p + vec2<i32>(dx, dy);
            if (any(q < vec2<i32>(0)) || any(q >= size)) {
                continue;
            }
            if (textureLoad(edges, q, 0).x > 0.5) {
                cov = max(cov, clamp(params.width - length(vec2<f32>(f32(dx), f32(dy))), 0.0, 1.0));
            }
        }
    }
#if MODE == 1
    return vec4<f32>(cov, cov, cov, 1.0);
#else
    return vec4<f32>(mix(c0.rgb, params.color, params.opacity * cov), c0.a);
#endif
#endif
}
