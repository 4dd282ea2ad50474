// ssgi_trace: the raw one-bounce indirect light of the `ssgi` effect
// (effects/ssgi.fx has the method in words; shaders/effects/ssgi/ssgi_accum.wgsl denoises it in
// time, shaders/effects/ssgi/ssgi_out.wgsl in space and composites it).
//
// Inputs: `img` (IN, the lit scene: the radiance that leaves every visible point
// towards the camera), `depth` (AUX.depth, linear view depth; 0, non-finite or a
// zero normal = no geometry) and `normal` (AUX.normal, view-space normal), all read
// with textureLoad at the output's size.
//
// Per pixel, with P its view-space position (lib/view.wgsl) and n its normal turned
// towards the camera:
//   - DIRECTIONS directions w_i, cosine-distributed over the hemisphere around n,
//     taken from one set of M = 16 DIRECTIONS directions shared by a 4x4 block of
//     pixels: the pixel with index b (0..15, a 4x4 Bayer matrix: neighbours far
//     apart in the set) takes j = 16 i + b, i = 0 .. DIRECTIONS - 1, with
//         sin^2(theta_j) = (j + o) / M,   phi_j = j * golden angle + r
//     (a Fibonacci spiral on the projected disk: the M directions are evenly
//     spread, so the blur of shaders/effects/ssgi/ssgi_out.wgsl, which weighs the 16 pixels of
//     every 4x4 block alike, averages a well-spread set of M rays, not 16 random
//     patterns); o, r and the step offset are moved each frame by the golden
//     ratio (R2 sequence), so the temporal pass averages other sets;
//   - each direction is a ray from O = P + bias n, marched in view space at
//     t_k = radius ((k + s_j) / STEPS)^2, k = 0 .. STEPS - 1 (denser near P; s_j
//     in [0, 1) a golden-ratio sequence over j and the frames). Sample X_k (view
//     depth z) projects to the pixel q of depth d_q; the previous sample had
//     depth z' at a pixel of depth d'. The ray hits q when X_k lies behind q's
//     surface by at most `thickness` (the depth buffer's surfaces taken as slabs):
//         d_q <= z <= d_q + thickness.
//     Otherwise, when the previous sample was in front of its surface (z' < d')
//     and this one is farther behind q's surface (z > d_q) or off the silhouette
//     of the previous surface (d_q > d' + thickness), the segment may have passed
//     through the previous surface: where it crosses that surface's plane, if that
//     point's own pixel holds the surface (depth within 1 % + bias), that pixel is
//     hit. (Without this, a step that crosses a wall near its top and lands
//     beyond its silhouette missed it: 10-20 % of a wall's form factor a few wall
//     heights away, tests/ssgi.rs; and a small thickness lost rays that stepped
//     through a surface.)
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

// The 4x4 Bayer matrix, row by row: a pixel's index in the shared direction set.
const BAYER = array<i32, 16>(0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);

// The pixel that view-space point X projects to; (-1, -1) when X is behind the
// camera or outside the image.
fn pixel_of(X: vec3<f32>, sizef: vec2<f32>) -> vec2<i32> {
    let clip = params.proj * vec4<f32>(X, 1.0);
    if (!(clip.w > 0.0)) {
        return vec2<i32>(-1);
    }
    let ndc = clip.xy / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) {
        return vec2<i32>(-1);
    }
    return min(vec2<i32>(uv * sizef), vec2<i32>(sizef) - 1);
}

// Where the segment A -> B crosses the surface of pixel q (depth d, plane from
// its normal), when that point is on the surface there: the pixel it projects
// to if its depth agrees (within 1 % + bias: a crossing of the plane beyond the
// surface's edge lands on another surface), else (-1, -1).
fn crossing(A: vec3<f32>, B: vec3<f32>, q: vec2<i32>, d: f32, s: f32, sizef: vec2<f32>) -> vec2<i32> {
    let nq = textureLoad(normal, q, 0).xyz;
    if (!(length(nq) > 1e-6)) {
        return vec2<i32>(-1);
    }
    let Q = lib_texel_view_pos(params.inv_proj, q, sizef, d);
    let sa = dot(A - Q, nq);
    let sb = dot(B - Q, nq);
    if (sa * sb > 0.0 || sa == sb) {
        return vec2<i32>(-1);
    }
    let C = mix(A, B, sa / (sa - sb));
    let qc = pixel_of(C, sizef);
    if (qc.x < 0) {
        return qc;
    }
    let dc = textureLoad(depth, qc, 0).r;
    if (!lib_has_geometry(dc) || abs(s * C.z - dc) > 0.01 * dc + params.bias) {
        return vec2<i32>(-1);
    }
    return qc;
}

// What a ray from P (normal n) that reaches the surface of pixel q brings: a = 0
// when q lies on or below P's tangent plane (P's own surface) or has no normal
// (the background): the ray goes on;
// else a = 1 with rgb = q's light if q's surface faces P, 0 if it turns its back.
fn sent(q: vec2<i32>, P: vec3<f32>, n: vec3<f32>, sizef: vec2<f32>) -> vec4<f32> {
    let Q = lib_texel_view_pos(params.inv_proj, q, sizef, textureLoad(depth, q, 0).r);
    if (dot(Q - P, n) <= params.bias) {
        return vec4<f32>(0.0);
    }
    let nq = textureLoad(normal, q, 0).xyz;
    if (!(length(nq) > 1e-6)) {
        return vec4<f32>(0.0);
    }
    let facing = lib_facing_camera(params.inv_proj, normalize(nq), (vec2<f32>(q) + 0.5) / sizef);
    if (dot(facing, P - Q) > 0.0) {
        return vec4<f32>(textureLoad(img, q, 0).rgb, 1.0);
    }
    return vec4<f32>(0.0, 0.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let size = vec2<i32>(textureDimensions(depth));
    let sizef = vec2<f32>(size);
    let d = textureLoad(depth, p, 0).r;
    var n = textureLoad(normal, p, 0).xyz;
    if (!lib_has_surface(d, n)) {
        return vec4<f32>(0.0);
    }
    let uv = (vec2<f32>(p) + 0.5) / sizef;
    n = lib_facing_camera(params.inv_proj, normalize(n), uv);
    let P = lib_view_pos(params.inv_proj, uv, d);
    let s = lib_forward_sign(params.inv_proj);
    // The frame's offsets (an R2 low-discrepancy sequence over the frames) and
    // the pixel's place in its 4x4 block.
    let fr = f32(params.frame % 65536u);
    let o = fract(0.5 + fr * 0.75487767);
    let r = 6.28318531 * fract(fr * 0.56984029);
    let b = BAYER[(p.y & 3) * 4 + (p.x & 3)];
    let m = 16.0 * f32(DIRECTIONS);
    // Any tangent frame: the azimuths are rotated by `r`.
    var a = vec3<f32>(1.0, 0.0, 0.0);
    if (abs(n.x) > 0.8) {
        a = vec3<f32>(0.0, 1.0, 0.0);
    }
    let t = normalize(a - n * dot(a, n));
    let bt = cross(n, t);
    let O = P + params.bias * n;
    var sum = vec3<f32>(0.0);
    for (var i = 0; i < DIRECTIONS; i++) {
        let j = f32(16 * i + b);
        let u = (j + o) / m;
        let phi = j * 2.39996323 + r;
        let st = sqrt(u);
        let w = (st * cos(phi)) * t + (st * sin(phi)) * bt + sqrt(1.0 - u) * n;
        // The step offset of ray j: golden-ratio steps over j and the frames.
        let jit = fract(0.5 + j * 0.61803399 + fr * 0.41421356);
        var X_prev = O;
        var q_prev = p;
        var d_prev = d;
        for (var k = 0; k < STEPS; k++) {
            let f = (f32(k) + jit) / f32(STEPS);
            let X = O + (params.radius * f * f) * w;
            let q = pixel_of(X, sizef);
            if (q.x < 0) {
                break;
            }
            let z = s * X.z;
            let z_prev = s * X_prev.z;
            var hit_px = vec2<i32>(-1);
            let dq = textureLoad(depth, q, 0).r;
            if (!all(q == p) && lib_has_geometry(dq)) {
                if (z >= dq && z <= dq + params.thickness) {
                    hit_px = q;
                } else if (z_prev < d_prev && (z > dq || dq > d_prev + params.thickness)) {
                    // The previous sample was in front of its surface and this one
                    // is far behind a surface, or off that surface's silhouette:
                    // the segment may have passed through that surface.
                    hit_px = crossing(X_prev, X, q_prev, d_prev, s, sizef);
                }
            }
            X_prev = X;
            q_prev = q;
            d_prev = dq;
            if (hit_px.x < 0 || all(hit_px == p)) {
                continue;
            }
            let light = sent(hit_px, P, n, sizef);
            if (light.a > 0.0) {
                sum += light.rgb;
                break;
            }
        }
    }
    let e = sum / f32(DIRECTIONS);
    // NaN and infinities of the scene must not reach the history.
    let finite = select(vec3<f32>(0.0), e, e == e);
    return vec4<f32>(clamp(finite, vec3<f32>(0.0), vec3<f32>(65504.0)), d);
}
