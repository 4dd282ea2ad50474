// mb_tilemax: one axis of the tile-max velocity reduction of `motion_blur`
// (effects/motion_blur.fx). Each output texel i covers the input texels x with
// floor(x w / W) = i, that is [ceil(i W / w), ceil((i + 1) W / w)), along the axis
// AXIS (0: x, 1: y; W the input's size, w the output's) and returns the longest of their motion vectors
// (pixels; the first of equal lengths). Run once per axis: tiles of the motion
// image, each the longest vector of its rectangle of pixels.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main` gives each
// output texel LANES = 32 invocations (8 output texels per workgroup of 256):
// lane z loads the texels z, z + 32, ... of the footprint (one each for 32-pixel
// tiles) and the 32 candidates are combined in a tree in workgroup memory,
// keeping the longest vector and, of equal lengths, the one at the lowest index.
// `fs_main` walks the footprint in one invocation where the output cannot be a
// storage texture. Both return the same texel (comparisons only): measured
// difference 0 (tests/compute_native.rs). Lanes share a texel, so fragment
// execution (`auto` on lavapipe) draws `fs_main`.
@group(0) @binding(0) var motion: texture_2d<f32>;

struct Params {
    out_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var out: texture_storage_2d<rg32float, write>;

#define AXIS 0

// The footprint of output texel `o`: its first input texel, the step to the
// next and the number of texels.
struct Footprint {
    start: vec2<i32>,
    step: vec2<i32>,
    count: i32,
}

fn footprint(o: vec2<i32>) -> Footprint {
    let size_in = vec2<i32>(textureDimensions(motion));
    let size_out = vec2<i32>(params.out_size);
#if AXIS == 0
    let a0 = min((o.x * size_in.x + size_out.x - 1) / size_out.x, size_in.x - 1);
    let a1 = max(((o.x + 1) * size_in.x + size_out.x - 1) / size_out.x, a0 + 1);
    return Footprint(vec2<i32>(a0, min(o.y, size_in.y - 1)), vec2<i32>(1, 0), a1 - a0);
#else
    let a0 = min((o.y * size_in.y + size_out.y - 1) / size_out.y, size_in.y - 1);
    let a1 = max(((o.y + 1) * size_in.y + size_out.y - 1) / size_out.y, a0 + 1);
    return Footprint(vec2<i32>(min(o.x, size_in.x - 1), a0), vec2<i32>(0, 1), a1 - a0);
#endif
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let o = vec2<i32>(pos.xy);
    let size_in = vec2<i32>(textureDimensions(motion));
    let size_out = vec2<i32>(params.out_size);
#if AXIS == 0
    let a0 = min((o.x * size_in.x + size_out.x - 1) / size_out.x, size_in.x - 1);
    let a1 = max(((o.x + 1) * size_in.x + size_out.x - 1) / size_out.x, a0 + 1);
    let step = vec2<i32>(1, 0);
    let start = vec2<i32>(a0, min(o.y, size_in.y - 1));
#else
    let a0 = min((o.y * size_in.y + size_out.y - 1) / size_out.y, size_in.y - 1);
    let a1 = max(((o.y + 1) * size_in.y + size_out.y - 1) / size_out.y, a0 + 1);
    let step = vec2<i32>(0, 1);
    let start = vec2<i32>(min(o.x, size_in.x - 1), a0);
#endif
    var best = vec2<f32>(0.0);
    var best_len = -1.0;
    for (var i = 0; i < a1 - a0; i++) {
        let v = textureLoad(motion, start + step * i, 0).xy;
        let l = dot(v, v);
        if (l > best_len) {
            best_len = l;
            best = v;
        }
    }
    return vec4<f32>(best, 0.0, 0.0);
}

// cs_main: 8 output texels (a column of a row of tiles across the axis) of
// LANES invocations each; their candidates (vector, squared length, index in
// the footprint) in workgroup memory, slot = texel * LANES + lane.
const LANES: i32 = 32;
var<workgroup> cand_vec: array<vec2<f32>, 256>;
var<workgroup> cand_len: array<f32, 256>;
var<workgroup> cand_idx: array<i32, 256>;

#if AXIS == 0
@compute @workgroup_size(1, 8, 32)
#else
@compute @workgroup_size(8, 1, 32)
#endif
fn cs_main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
) {
    let o = vec2<i32>(id.xy);
    let lane = i32(local.z);
    let slot = i32(local.x + local.y) * LANES + lane;
    let inside = all(o < vec2<i32>(params.out_size));
    // This lane's longest vector (the first of equal lengths: ascending index).
    var best = vec2<f32>(0.0);
    var best_len = -1.0;
    var best_idx = 0x7fffffff;
    if (inside) {
        let f = footprint(o);
        for (var i = lane; i < f.count; i += LANES) {
            let v = textureLoad(motion, f.start + f.step * i, 0).xy;
            let l = dot(v, v);
            if (l > best_len) {
                best_len = l;
                best = v;
                best_idx = i;
            }
        }
    }
    cand_vec[slot] = best;
    cand_len[slot] = best_len;
    cand_idx[slot] = best_idx;
    for (var s = LANES / 2; s > 0; s /= 2) {
        workgroupBarrier();
        if (lane < s) {
            let other = slot + s;
            let l = cand_len[other];
            let i = cand_idx[other];
            if (l > cand_len[slot] || (l == cand_len[slot] && i < cand_idx[slot])) {
                cand_vec[slot] = cand_vec[other];
                cand_len[slot] = l;
                cand_idx[slot] = i;
            }
        }
    }
    if (!inside || lane != 0) {
        return;
    }
    textureStore(out, o, vec4<f32>(cand_vec[slot], 0.0, 0.0));
}
