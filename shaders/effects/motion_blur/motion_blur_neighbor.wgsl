// mb_neighbor: the neighbour-max velocity of `motion_blur` (effects/motion_blur.fx):
// per tile, the longest motion vector of the tile and its 8 neighbours (the first
// of equal lengths, centre first). Any pixel whose blur can reach a pixel of this
// tile lies in one of these tiles, since the blur radius is at most a tile.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main` stages the
// 10 x 10 tiles around a workgroup's 8 x 8 in workgroup memory (each tile loaded
// once instead of 9 times) and scans the same 3 x 3 in the same order; `fs_main`
// loads the 9 where the output cannot be a storage texture. Both return the same
// texel (comparisons only): measured difference 0 (tests/compute_native.rs).
@group(0) @binding(0) var tiles: texture_2d<f32>;
@group(0) @binding(1) var out: texture_storage_2d<rg32float, write>;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(textureDimensions(tiles)) - vec2<i32>(1);
    var best = textureLoad(tiles, p, 0).xy;
    var best_len = dot(best, best);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy);
            if (any(q < vec2<i32>(0)) || any(q > hi)) {
                continue;
            }
            let v = textureLoad(tiles, q, 0).xy;
            let l = dot(v, v);
            if (l > best_len) {
                best_len = l;
                best = v;
            }
        }
    }
    return vec4<f32>(best, 0.0, 0.0);
}

// cs_main: the workgroup's 8 x 8 tiles and a ring of one around them (outside
// the image: never read, the scan skips those as fs_main does).
const GROUP: i32 = 8;
const SPAN: i32 = GROUP + 2;
var<workgroup> staged: array<vec2<f32>, 100>;

@compute @workgroup_size(8, 8, 1)
fn cs_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
) {
    let hi = vec2<i32>(textureDimensions(tiles)) - vec2<i32>(1);
    let base = vec2<i32>(group.xy) * GROUP - vec2<i32>(1);
    for (var i = i32(index); i < SPAN * SPAN; i += GROUP * GROUP) {
        let q = clamp(base + vec2<i32>(i % SPAN, i / SPAN), vec2<i32>(0), hi);
        staged[i] = textureLoad(tiles, q, 0).xy;
    }
    workgroupBarrier();
    let l0 = vec2<i32>(local.xy) + vec2<i32>(1);
    let p = base + l0;
    if (any(p > hi)) {
        return;
    }
    var best = staged[l0.y * SPAN + l0.x];
    var best_len = dot(best, best);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy);
            if (any(q < vec2<i32>(0)) || any(q > hi)) {
                continue;
            }
            let v = staged[(l0.y + dy) * SPAN + l0.x + dx];
            let l = dot(v, v);
            if (l > best_len) {
                best_len = l;
                best = v;
            }
        }
    }
    textureStore(out, p, vec4<f32>(best, 0.0, 0.0));
}
