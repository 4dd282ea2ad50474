// taa_geometry: the reprojection data of the `taa` effect (effects/taa.fx).
//
// Per pixel: r = the nearest (smallest) linear depth of the 3x3 neighbourhood,
// g, b = the motion vector (pixels, current minus previous position) of that
// nearest pixel, a = the pixel's own depth. Taking the motion of the nearest
// neighbour dilates the foreground's motion by one pixel over its silhouette, so
// an anti-aliased edge pixel is reprojected with the object it belongs to rather
// than with the background behind it. Ties keep the centre, then the first in
// row order. The pass is also kept for one frame (PASS.geo[-1]): the resolve
// compares it with the current one to find disocclusions.
@group(0) @binding(0) var depth: texture_2d<f32>;
@group(0) @binding(1) var motion: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(textureDimensions(depth)) - vec2<i32>(1);
    let own = textureLoad(depth, p, 0).r;
    var dmin = own;
    var best = p;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = clamp(p + vec2<i32>(dx, dy), vec2<i32>(0), hi);
            let d = textureLoad(depth, q, 0).r;
            if (d < dmin) {
                dmin = d;
                best = q;
            }
        }
    }
    let m = textureLoad(motion, best, 0).xy;
    return vec4<f32>(dmin, m, own);
}
