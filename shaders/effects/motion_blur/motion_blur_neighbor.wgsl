// mb_neighbor: the neighbour-max velocity of `motion_blur` (effects/motion_blur.fx):
// per tile, the longest motion vector of the tile and its 8 neighbours (the first
// of equal lengths, centre first). Any pixel whose blur can reach a pixel of this
// tile lies in one of these tiles, since the blur radius is at most a tile.
@group(0) @binding(0) var tiles: texture_2d<f32>;

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
