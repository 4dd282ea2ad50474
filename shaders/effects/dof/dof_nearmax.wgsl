// dof_nearmax: one direction of a separable maximum filter of the near-field CoC
// (used by the `dof` effect): the largest near-field CoC radius that can reach a
// pixel, which sizes the near-field gather of shaders/effects/dof/dof_near.wgsl.
//   VERTICAL = 0: m(p) = max over |dx| <= R of max(-coc(p + (dx, 0)), 0)
//   VERTICAL = 1: m(p) = max over |dy| <= R of src(p + (0, dy))
// with R = ceil(max_radius); texels outside the image are skipped.
#define VERTICAL 0

@group(0) @binding(0) var src: texture_2d<f32>;

struct Params {
    max_radius: f32, // @default(16) @range(0, 64) search radius in pixels (the largest CoC)
}
@group(0) @binding(1) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let size = vec2<i32>(textureDimensions(src));
    let r = i32(ceil(params.max_radius));
#if VERTICAL
    let lo = max(p.y - r, 0);
    let hi = min(p.y + r, size.y - 1);
#else
    let lo = max(p.x - r, 0);
    let hi = min(p.x + r, size.x - 1);
#endif
    var m = 0.0;
    for (var i = lo; i <= hi; i++) {
#if VERTICAL
        m = max(m, textureLoad(src, vec2<i32>(p.x, i), 0).r);
#else
        m = max(m, -textureLoad(src, vec2<i32>(i, p.y), 0).r);
#endif
    }
    return vec4<f32>(m, 0.0, 0.0, 1.0);
}
