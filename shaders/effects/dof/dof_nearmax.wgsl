// dof_nearmax: one direction of a separable maximum filter of the near-field CoC
// (used by the `dof` effect): the largest near-field CoC radius that can reach a
// pixel, which sizes the near-field gather of shaders/effects/dof/dof_near.wgsl.
//   VERTICAL = 0: m(p) = max over |dx| <= R of max(-coc(p + (dx, 0)), 0)
//   VERTICAL = 1: m(p) = max over |dy| <= R of src(p + (0, dy))
// with R = ceil(max_radius); texels outside the image are skipped.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main` stages each
// line segment once in workgroup memory (256 pixels of a row, or 32 of each of
// 8 columns, plus R on either side; outside the image: 0, which a maximum of
// values >= 0 ignores) and takes the maximum there, wherever the output can be
// a storage texture; `fs_main` loads 2R + 1 texels per pixel where it cannot.
// Both give the same values (a maximum of the same texels).
#define VERTICAL 0

@group(0) @binding(0) var src: texture_2d<f32>;

struct Params {
    max_radius: f32, // @default(16) @range(0, 64) search radius in pixels (the largest CoC)
}
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var out: texture_storage_2d<r16float, write>;

// The filtered value of texel `p` (inside the image).
fn term(p: vec2<i32>) -> f32 {
#if VERTICAL
    return textureLoad(src, p, 0).r;
#else
    return max(-textureLoad(src, p, 0).r, 0.0);
#endif
}

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
        m = max(m, term(vec2<i32>(p.x, i)));
#else
        m = max(m, term(vec2<i32>(i, p.y)));
#endif
    }
    return vec4<f32>(m, 0.0, 0.0, 1.0);
}

// cs_main's workgroup: ALONG pixels along the filter's axis on ACROSS lines,
// each line's segment ALONG + 2 R_MAX long (R_MAX = 64, the parameter's range).
#if VERTICAL
const ALONG: i32 = 32;
const ACROSS: i32 = 8;
#else
const ALONG: i32 = 256;
const ACROSS: i32 = 1;
#endif
const R_MAX: i32 = 64;
const SPAN: i32 = ALONG + 2 * R_MAX;
var<workgroup> segment: array<f32, 1280>;

#if VERTICAL
@compute @workgroup_size(8, 32, 1)
#else
@compute @workgroup_size(256, 1, 1)
#endif
fn cs_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
) {
    let size = vec2<i32>(textureDimensions(src));
    let r = min(i32(ceil(params.max_radius)), R_MAX);
#if VERTICAL
    let k = i32(local.x);
    let l = i32(local.y);
    let line0 = i32(group.x) * ACROSS;
    let a0 = i32(group.y) * ALONG;
    let lines = size.x;
    let n = size.y;
#else
    let k = 0;
    let l = i32(local.x);
    let line0 = i32(group.y);
    let a0 = i32(group.x) * ALONG;
    let lines = size.y;
    let n = size.x;
#endif
    let span = ALONG + 2 * r;
    for (var i = i32(index); i < ACROSS * span; i += 256) {
        let kk = i % ACROSS;
        let t = i / ACROSS;
        let a = a0 - r + t;
        let line = min(line0 + kk, lines - 1);
        var v = 0.0;
        if (a >= 0 && a < n) {
#if VERTICAL
            v = term(vec2<i32>(line, a));
#else
            v = term(vec2<i32>(a, line));
#endif
        }
        segment[kk * SPAN + t] = v;
    }
    workgroupBarrier();
    let along = a0 + l;
    let line = line0 + k;
    if (along >= n || line >= lines) {
        return;
    }
    var m = 0.0;
    for (var j = 0; j <= 2 * r; j++) {
        m = max(m, segment[k * SPAN + l + j]);
    }
#if VERTICAL
    textureStore(out, vec2<i32>(line, along), vec4<f32>(m, 0.0, 0.0, 1.0));
#else
    textureStore(out, vec2<i32>(along, line), vec4<f32>(m, 0.0, 0.0, 1.0));
#endif
}
