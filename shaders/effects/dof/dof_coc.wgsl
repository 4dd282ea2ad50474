// dof_coc: signed circle-of-confusion radius in pixels from linear depth (used by the
// `dof` effect). Thin-lens model with a sharp band around the focus distance:
//   s_near = max(focus_distance - focal_range / 2, 0), s_far = focus_distance + focal_range / 2
//   d > s_far:          c = aperture * (1 - s_far / d)      (far field, > 0, -> aperture at infinity)
//   d < s_near:         c = -aperture * (s_near / d - 1)    (near field, < 0)
//   otherwise:          c = 0                               (in focus)
//   c = clamp(c, -max_radius, max_radius)
// (The thin-lens CoC diameter A f |d - s| / (d (s - f)) is proportional to
// |1 - s / d| for a focal length f much smaller than s; `aperture` is the radius it
// reaches at infinity, in pixels.) Pixels without geometry (depth 0 or not finite)
// are treated as infinitely far: c = min(aperture, max_radius).
@group(0) @binding(0) var depth: texture_2d<f32>;

struct Params {
    focus_distance: f32, // @default(10) @range(0.0001, 1000000) distance in focus (view-space units)
    focal_range: f32,    // @default(2) @range(0, 1000000) depth of the sharp band around the focus distance
    aperture: f32,       // @default(8) @range(0, 64) CoC radius in pixels of an object at infinity
    max_radius: f32,     // @default(16) @range(0, 64) largest CoC radius in pixels (near field)
}
@group(0) @binding(1) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let d = textureLoad(depth, vec2<i32>(pos.xy), 0).r;
    let s_near = max(params.focus_distance - 0.5 * params.focal_range, 0.0);
    let s_far = params.focus_distance + 0.5 * params.focal_range;
    var c = 0.0;
    if (!(d > 0.0 && d < 3.0e38)) {
        c = params.aperture;
    } else if (d > s_far) {
        c = params.aperture * (1.0 - s_far / d);
    } else if (d < s_near) {
        c = -params.aperture * (s_near / d - 1.0);
    }
    c = clamp(c, -params.max_radius, params.max_radius);
    return vec4<f32>(c, 0.0, 0.0, 1.0);
}
