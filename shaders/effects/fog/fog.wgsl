// fog: distance fog with optional exponential height falloff (used by the `fog`
// effect; the maths is documented in effects/fog.fx).
//
// Defines: MODE 0 linear, 1 exponential, 2 exponential squared;
//          DISTANCE 0 view depth (AUX.depth), 1 radial (|P|, P the view-space
//          position reconstructed from depth with inv_proj).
// Pixels without geometry (depth <= 0, infinite or NaN) are left unchanged. A zero
// `up` counts as (0, 1, 0).
#define MODE 1
#define DISTANCE 0

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var depth: texture_2d<f32>;

struct Params {
    color: vec3<f32>,     // @default(0.5, 0.6, 0.7) @range(0, 65504) fog colour (linear)
    density: f32,         // @default(0.05) @range(0, 1000000) exponential modes: extinction per view-space unit
    start: f32,           // @default(0) @range(0, 1000000000) linear mode: distance where the fog starts
    end: f32,             // @default(100) @range(0, 1000000000) linear mode: distance of full fog
    height_falloff: f32,  // @default(0) @range(0, 1000000) density falls by e per 1 / height_falloff units of height (0: off)
    fog_height: f32,      // @default(0) @range(-1000000000, 1000000000) world height where the density is nominal
    camera_height: f32,   // @default(0) @range(-1000000000, 1000000000) world height of the camera
    up: vec3<f32>,        // @default(0, 1, 0) @range(-1, 1) world up direction in view space
    inv_proj: mat4x4<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/view.wgsl"

// (1 - exp(-x)) / x, the mean of exp(-x t) over t in [0, 1]; 1 at x = 0.
fn mean_exp(x: f32) -> f32 {
    if (abs(x) < 1e-3) {
        return 1.0 - x * (0.5 - x / 6.0);
    }
    return (1.0 - exp(-x)) / x;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(img, p, 0);
    let d = textureLoad(depth, p, 0).r;
    if (!lib_has_geometry(d)) {
        return c;
    }
    let P = lib_texel_view_pos(params.inv_proj, p, vec2<f32>(textureDimensions(depth)), d);
#if DISTANCE == 1
    var dist = length(P);
#else
    var dist = d;
#endif
    if (params.height_falloff > 0.0) {
        let k = params.height_falloff;
        let ul = length(params.up);
        let up = select(vec3<f32>(0.0, 1.0, 0.0), params.up / ul, ul > 1e-6);
        dist *= exp(-k * (params.camera_height - params.fog_height)) * mean_exp(k * dot(P, up));
    }
#if MODE == 0
    let f = clamp((params.end - dist) / max(params.end - params.start, 1e-20), 0.0, 1.0);
#elif MODE == 1
    let f = exp(-params.density * dist);
#else
    let x = params.density * dist;
    let f = exp(-x * x);
#endif
    return vec4<f32>(mix(params.color, c.rgb, f), c.a);
}
