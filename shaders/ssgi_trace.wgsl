// ssgi_trace: the raw one-bounce indirect light of the `ssgi` effect
// (effects/ssgi.fx has the method in words; shaders/ssgi_accum.wgsl denoises it in
// time, shaders/ssgi_out.wgsl in space and composites it).
//
// Inputs: `img` (IN, the lit scene: the radiance that leaves every visible point
// towards the camera), `depth` (AUX.depth, linear view depth; 0, non-finite or a
// zero normal = no geometry) and `normal` (AUX.normal, view-space normal), all read
// with textureLoad at the output's size.
//
// Per pixel, with P its view-space position (lib/view.wgsl) and n its normal turned
// towards the camera:
//   - DIRECTIONS directions w_i, cosine-distributed over the hemisphere around n:
//     sin(theta_i) = sqrt(u_i), u_i = (i + e) / DIRECTIONS (stratified in
//     elevation), azimuth i * golden angle + r, where r, e and the step offset j
//     come from a 4x4 tiled hash of the pixel (every phase once in a 4x4 block, so
//     the blur of shaders/ssgi_out.wgsl averages 16 patterns) shifted each frame
//     by the frame index times the golden ratio (the temporal pass averages those);
//   - each direction is a ray from O = P + bias n, marched in view space at
//     t_k = radius ((k + j) / STEPS)^2, k = 0 .. STEPS - 1 (denser near P). The
//     segment from the previous sample to X_k (depth interval [z_lo, z_hi]) is
//     tested against the pixel q that X_k projects to: its surface is taken as a
//     slab [d_q, d_q + thickness] along the view axis, and the ray hits it when
//         z_hi >= d_q   and   z_lo <= d_q + thickness.
//     A hit whose point Q lies on or below P's tangent plane (dot(Q - P, n) <=
//     bias: P's own surface, from pixel quantisation) is ignored and the march goes
//     on. A hit whose normal n_q faces away from P (dot(n_q, P - Q) <= 0: the back
//     of a surface) ends the ray in the dark; otherwise the ray brings L_i =
//     img(q), the radiance q sends to the camera, taken as what it sends to P (a
//     diffuse sender). Leaving the image, passing behind the camera or reaching the
//     radius without a hit: L_i = 0 (no bounce from that direction).
//   - out.rgb = (1 / DIRECTIONS) sum_i L_i: with cosine-distributed directions,
//     the Monte Carlo estimate of E / pi, E = integral of L cos(theta) dw the
//     indirect irradiance; the receiver's added radiance is albedo E / pi.
//   - out.a = the pixel's linear depth (the next frame's disocclusion test).
// Pixels without geometry: out = (0, 0, 0, 0).
#define DIRECTIONS 8
#define STEPS 12

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var depth: texture_2d<f32>;
@group(0) @binding(2) var normal: texture_2d<f32>;

struct Params {
    radius: f32,    // @default(2) @range(0.0001, 100000) longest ray in view-space units
    thickness: f32, // @default(0.5) @range(0.0001, 100000) assumed thickness of the surfaces in the depth buffer, view-space units
    bias: f32,      // @default(0.02) @range(0, 100000) ray start offset along the normal and tangent-plane bias, view-space units
    frame: u32,
    proj: mat4x4<f32>,
    inv_proj: mat4x4<f32>,
}
@group(0) @binding(3) var<uniform> params: Params;

#include "lib/view.wgsl"

// A hash of (x mod 4, y mod 4, seed) to [0, 1).
fn tile_hash(p: vec2<i32>, seed: u32) -> f32 {
    var h = u32(p.x & 3) * 0x9E3779B1u + u32(p.y & 3) * 0x85EBCA77u + seed * 0xC2B2AE3Du + 0x27d4eb2fu;
    h = (h ^ (h >> 15u)) * 0x2C1B3C6Du;
    h = (h ^ (h >> 12u)) * 0x297A2D39u;
    h = h ^ (h >> 15u);
    return f32(h >> 8u) / 16777216.0;
}

fn has_geometry(d: f32, n: vec3<f32>) -> bool {
    return lib_has_geometry(d) && length(n) > 1e-6;
}

// A view-space normal turned against the view ray of `uv`.
fn facing_camera(n: vec3<f32>, uv: vec2<f32>) -> vec3<f32> {
    let ray = lib_unproject(params.inv_proj, uv, 0.75) - lib_unproject(params.inv_proj, uv, 0.25);
    return select(n, -n, dot(n, ray) > 0.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let size = vec2<i32>(textureDimensions(depth));
    let sizef = vec2<f32>(size);
    let d = textureLoad(depth, p, 0).r;
    var n = textureLoad(normal, p, 0).xyz;
    if (!has_geometry(d, n)) {
        return vec4<f32>(0.0);
    }
    let uv = (vec2<f32>(p) + 0.5) / sizef;
    n = facing_camera(normalize(n), uv);
    let P = lib_view_pos(params.inv_proj, uv, d);
    // The sign that turns a view-space z into a linear depth.
    let s = select(-1.0, 1.0, lib_unproject(params.inv_proj, vec2<f32>(0.5), 0.25).z >= 0.0);
    // Per-pixel offsets (4x4 tile), moved on each frame by the golden ratio.
    let shift = fract(f32(params.frame % 4096u) * 0.61803399);
    let rot = 6.28318531 * fract(tile_hash(p, 0u) + shift);
    let elev = fract(tile_hash(p, 1u) + shift);
    let jit = fract(tile_hash(p, 2u) + 0.5 * shift);
    // Any tangent frame: the azimuths are rotated by `rot`.
    var a = vec3<f32>(1.0, 0.0, 0.0);
    if (abs(n.x) > 0.8) {
        a = vec3<f32>(0.0, 1.0, 0.0);
    }
    let t = normalize(a - n * dot(a, n));
    let b = cross(n, t);
    let O = P + params.bias * n;
    var sum = vec3<f32>(0.0);
    for (var i = 0; i < DIRECTIONS; i++) {
        let u = (f32(i) + elev) / f32(DIRECTIONS);
        let phi = f32(i) * 2.39996323 + rot;
        let st = sqrt(u);
        let w = (st * cos(phi)) * t + (st * sin(phi)) * b + sqrt(1.0 - u) * n;
        var z_prev = s * O.z;
        for (var k = 0; k < STEPS; k++) {
            let f = (f32(k) + jit) / f32(STEPS);
            let X = O + (params.radius * f * f) * w;
            let clip = params.proj * vec4<f32>(X, 1.0);
            if (!(clip.w > 0.0)) {
                break;
            }
            let ndc = clip.xy / clip.w;
            let xuv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
            if (any(xuv < vec2<f32>(0.0)) || any(xuv >= vec2<f32>(1.0))) {
                break;
            }
            let q = min(vec2<i32>(xuv * sizef), size - 1);
            let z = s * X.z;
            let z_lo = min(z_prev, z);
            let z_hi = max(z_prev, z);
            z_prev = z;
            if (all(q == p)) {
                continue;
            }
            let dq = textureLoad(depth, q, 0).r;
            let nq_raw = textureLoad(normal, q, 0).xyz;
            if (!has_geometry(dq, nq_raw) || z_hi < dq || z_lo > dq + params.thickness) {
                continue;
            }
            let Q = lib_texel_view_pos(params.inv_proj, q, sizef, dq);
            if (dot(Q - P, n) <= params.bias) {
                continue;
            }
            let nq = facing_camera(normalize(nq_raw), (vec2<f32>(q) + 0.5) / sizef);
            if (dot(nq, P - Q) > 0.0) {
                sum += textureLoad(img, q, 0).rgb;
            }
            break;
        }
    }
    let e = sum / f32(DIRECTIONS);
    // NaN and infinities of the scene must not reach the history.
    let finite = select(vec3<f32>(0.0), e, e == e);
    return vec4<f32>(clamp(finite, vec3<f32>(0.0), vec3<f32>(65504.0)), d);
}
