// ssao: raw screen-space ambient occlusion from the G-buffer (used by the `ssao`
// effect; the bilateral blur and the composite are shaders/effects/ssao/ssao_blur.wgsl).
//
// Inputs: `depth` (AUX.depth, linear view-space depth > 0; 0 or non-finite = no
// geometry) and `normal` (AUX.normal, view-space normal in xyz). Both are read with
// textureLoad at the output's size (no filtering: r32f need not be filterable).
//
// Per pixel, with P its view-space position (reconstructed from depth with inv_proj,
// see lib/view.wgsl) and n its normal (flipped to face the camera if needed):
//   - a tangent frame (t, b, n) rotated about n by an angle from a 4x4 tiled hash
//     of the pixel coordinates (the "rotation noise" texture, computed here);
//   - SAMPLES kernel points k_i in the unit hemisphere around +z: directions uniform
//     over the hemisphere (height 1 - (i + 1/2) / SAMPLES) on a golden-angle
//     spiral, lengths mix(0.1, 1, t^2) with t from the base-2 radical inverse of i
//     (more samples close to P);
//   - S_i = P + radius (k_i.x t + k_i.y b + k_i.z n), projected with proj to the
//     pixel x_i; samples outside the image or behind the camera count as open;
//   - the scene point Q_i at x_i (its texel centre and stored depth) occludes when
//     it is in front of S_i along the view axis by more than `bias` and above the
//     tangent plane of P by more than `bias`:
//         depth(Q_i) < depth(S_i) - bias   and   dot(Q_i - P, n) > bias
//     (the second test keeps pixel quantisation of a flat or grazing surface from
//     occluding itself), weighted by the range check
//         r_i = 1 - smoothstep(radius, 2 radius, |Q_i - P|)
//     so that geometry far from P (a foreground silhouette) does not darken it;
//   - ao = clamp(1 - intensity * sum(occluded_i r_i) / SAMPLES, 0, 1).
// Pixels without geometry get ao = 1. Output: ao in every channel (r16f target).
#define SAMPLES 16

@group(0) @binding(0) var depth: texture_2d<f32>;
@group(0) @binding(1) var normal: texture_2d<f32>;

struct Params {
    radius: f32,    // @default(0.5) @range(0.0001, 100000) sampling radius in view-space units
    bias: f32,      // @default(0.02) @range(0, 100000) depth and plane bias in view-space units
    intensity: f32, // @default(2) @range(0, 100) strength: ao = 1 - intensity * occlusion
    proj: mat4x4<f32>,
    inv_proj: mat4x4<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/view.wgsl"

// The 4x4 rotation noise: a hash of (x mod 4, y mod 4) to [0, 1).
fn noise(p: vec2<i32>) -> f32 {
    var h = u32(p.x & 3) * 0x9E3779B1u + u32(p.y & 3) * 0x85EBCA77u + 0x27d4eb2fu;
    h = (h ^ (h >> 15u)) * 0x2C1B3C6Du;
    h = (h ^ (h >> 12u)) * 0x297A2D39u;
    h = h ^ (h >> 15u);
    return f32(h >> 8u) / 16777216.0;
}

// Kernel point i of SAMPLES in the unit hemisphere around +z.
fn kernel(i: i32) -> vec3<f32> {
    let n = f32(SAMPLES);
    let u = (f32(i) + 0.5) / n;
    let phi = f32(i) * 2.39996323;
    let z = 1.0 - u;
    let r = sqrt(1.0 - z * z);
    let dir = vec3<f32>(r * cos(phi), r * sin(phi), z);
    let t = f32(reverseBits(u32(i))) / 4294967296.0 + 0.5 / n;
    return dir * mix(0.1, 1.0, t * t);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let size = vec2<i32>(textureDimensions(depth));
    let sizef = vec2<f32>(size);
    let d = textureLoad(depth, p, 0).r;
    var n = textureLoad(normal, p, 0).xyz;
    if (!lib_has_surface(d, n)) {
        return vec4<f32>(1.0);
    }
    n = normalize(n);
    let uv = (vec2<f32>(p) + 0.5) / sizef;
    let P = lib_view_pos(params.inv_proj, uv, d);
    let s = lib_forward_sign(params.inv_proj);
    n = lib_facing_camera(params.inv_proj, n, uv);
    // Tangent frame rotated by the noise angle about n.
    let ang = 6.28318531 * noise(p);
    var rv = vec3<f32>(cos(ang), sin(ang), 0.0);
    if (abs(n.z) < 0.5) {
        rv = vec3<f32>(0.0, cos(ang), sin(ang));
        if (abs(n.x) < 0.5) {
            rv = vec3<f32>(cos(ang), 0.0, sin(ang));
        }
    }
    let t = normalize(rv - n * dot(rv, n));
    let b = cross(n, t);
    var occ = 0.0;
    for (var i = 0; i < SAMPLES; i++) {
        let k = kernel(i);
        let S = P + params.radius * (k.x * t + k.y * b + k.z * n);
        let clip = params.proj * vec4<f32>(S, 1.0);
        if (!(clip.w > 0.0)) {
            continue;
        }
        let ndc = clip.xy / clip.w;
        let suv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        if (any(suv < vec2<f32>(0.0)) || any(suv >= vec2<f32>(1.0))) {
            continue;
        }
        let q = min(vec2<i32>(suv * sizef), size - 1);
        let dq = textureLoad(depth, q, 0).r;
        if (!lib_has_geometry(dq)) {
            continue;
        }
        let Q = lib_texel_view_pos(params.inv_proj, q, sizef, dq);
        let v = Q - P;
        if (dq < s * S.z - params.bias && dot(v, n) > params.bias) {
            occ += 1.0 - smoothstep(params.radius, 2.0 * params.radius, length(v));
        }
    }
    let ao = clamp(1.0 - params.intensity * occ / f32(SAMPLES), 0.0, 1.0);
    return vec4<f32>(ao);
}
