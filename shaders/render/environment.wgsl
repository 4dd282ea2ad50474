// Image-based lighting, part of every generated module (after the engine part):
// the environment's prefiltered maps (src/render/environment/), the default
// environment term of a surface and the background. The generator appends
// `fx_environment_lighting(material, in)`: the material's lighting shader's
// `environment` function when it has one, else `fx_environment_default`.

struct FxEnvironment {
    // view-space directions -> the map's frame (world, turned back by the
    // environment's rotation about +Y)
    map_from_view: mat3x3<f32>,
    // x intensity, y the specular map's last level (roughness 1), z the
    // background's level, w the fog transmittance of the background
    params: vec4<f32>,
    // rgb: the fog colour the background is mixed towards
    fog_color: vec4<f32>,
    // x: 1 when an environment lights the scene; y: the background (0 the
    // frame's colour, 1 the environment, 2 transparent); z: bright cells
    flags: vec4<u32>,
    // the normalisation of fx_env_bright_lobe at roughness i / 15 (element i
    // of the 16): the integral of the prefiltered lobe's weight D G1 / 4
    bright_norm: array<vec4<f32>, 4>,
    // the map's brightest parts, taken out of the specular levels from level 1
    // on and shaded exactly (src/render/environment/bright.rs)
    bright: array<FxEnvBright, 128>,
}

struct FxEnvBright {
    // unit direction in the map's frame, angular radius (radians)
    direction_radius: vec4<f32>,
    // the excess radiance times the solid angle (rgb), the solid angle
    power_omega: vec4<f32>,
}

// GGX-prefiltered radiance: level k holds perceptual roughness
// fx_env_level_roughness(k / (levels - 1))
@group(0) @binding(11) var fx_env_specular: texture_cube<f32>;
// cosine-weighted mean radiance (irradiance / pi)
@group(0) @binding(12) var fx_env_irradiance: texture_cube<f32>;
// x = n.v, y = roughness; layer 0: the split sum's r = A, g = B (albedo F0 A +
// B); layers 1, 2, 3: the lobe model's four taps' offsets, roughnesses and
// weights, rgba = taps 0-3 (src/render/environment/lobe.rs)
@group(0) @binding(13) var fx_env_dfg: texture_2d_array<f32>;
@group(0) @binding(14) var fx_env_sampler: sampler;
@group(0) @binding(15) var<uniform> fx_env: FxEnvironment;

// The spread of the prefiltered lobe of perceptual roughness `roughness` (the
// glTF BRDF's f cos at n = v, D(n.h) G1(n.l), normalised): 1 - its mean cosine
// about its centre. A rational fit in alpha = roughness^2 of that integral
// (tabulated by quadrature; relative error below 1 % from roughness 0.05 on;
// src/render/environment/spread.rs checks it against the integral).
fn fx_env_lobe_spread(roughness: f32) -> f32 {
    let a = max(roughness * roughness, 1e-3);
    let sa = sqrt(a);
    return a * a * (30.124 - 9.4665 * sa + 1.4145 * a) / (1.0 + 8.8945 * sa + 3.2514 * a + 46.424 * a * a);
}

// Level m of the specular map (of `last` + 1) holds the perceptual roughness
// at x = m / last, piecewise linear between these knots at x = 0, 1/6, ..., 1:
// closer together at low roughness (src/render/environment/levels.rs).
const FX_ENV_LEVEL_ROUGHNESS = array<f32, 7>(0.0, 0.1, 0.2, 0.3, 0.45, 0.7, 1.0);
// Segments between the knots.
const FX_ENV_SEGMENTS = 6u;

// The roughness at position `x` (0 ..= 1) of the chain.
fn fx_env_level_roughness(x: f32) -> f32 {
    var knots = FX_ENV_LEVEL_ROUGHNESS;
    let t = clamp(x, 0.0, 1.0) * f32(FX_ENV_SEGMENTS);
    let i = min(u32(t), FX_ENV_SEGMENTS - 1u);
    return mix(knots[i], knots[i + 1u], t - f32(i));
}

// The position (0 ..= 1) in the chain of roughness `roughness`.
fn fx_env_level_position(roughness: f32) -> f32 {
    var knots = FX_ENV_LEVEL_ROUGHNESS;
    let r = clamp(roughness, 0.0, 1.0);
    var i = 0u;
    loop {
        if i + 1u >= FX_ENV_SEGMENTS || r <= knots[i + 1u] {
            break;
        }
        i += 1u;
    }
    return (f32(i) + (r - knots[i]) / (knots[i + 1u] - knots[i])) / f32(FX_ENV_SEGMENTS);
}

// The level of the specular map to read for perceptual roughness `roughness`.
// Level k holds the lobe of roughness fx_env_level_roughness(k / last) (last =
// params.y); between two levels the trilinear lookup mixes their lobes, and
// the fraction is chosen so that the mix spreads as far as the lobe it stands
// for: linear in the lobe's spread (`fx_env_lobe_spread`), not in roughness.
// Linear in roughness weighs the wider lobe too much at low roughness (at 0.3,
// between levels of 0.2 and 0.4: 1/2 instead of 0.38) and too little at high
// roughness (issue 29).
fn fx_env_specular_level(roughness: f32) -> f32 {
    let last = max(fx_env.params.y, 1.0);
    let r = clamp(roughness, 0.0, 1.0);
    let k = min(floor(fx_env_level_position(r) * last), last - 1.0);
    let s0 = fx_env_lobe_spread(fx_env_level_roughness(k / last));
    let s1 = fx_env_lobe_spread(fx_env_level_roughness((k + 1.0) / last));
    return k + clamp((fx_env_lobe_spread(r) - s0) / max(s1 - s0, 1e-12), 0.0, 1.0);
}

// The prefiltered radiance of the specular lobe at normal `n`, view `v`: the
// lobe model of src/render/environment/lobe.rs, fitted offline to the glTF
// BRDF's lobe at n != v (examples/ibl_lobe_fit.rs; issue 29). Four reads of
// the specular map, each along the dominant direction `r` offset by o in the
// plane of incidence (towards the normal), at the level of its roughness,
// weighted; the weights sum to 1, so a constant environment is kept. The
// split sum's single read along `r` at the surface's roughness is what the
// fit replaces: at n != v the true lobe is stretched along the plane of
// incidence and narrower across it.
fn fx_env_prefiltered(n: vec3<f32>, v: vec3<f32>, roughness: f32) -> vec3<f32> {
    let r = fx_env_dominant(n, v, roughness);
    let across = n - dot(n, r) * r;
    let t = across * inverseSqrt(max(dot(across, across), 1e-12));
    let uv = vec2<f32>(max(dot(n, v), 1e-4), roughness);
    let offset = textureSampleLevel(fx_env_dfg, fx_env_sampler, uv, 1, 0.0);
    let level = textureSampleLevel(fx_env_dfg, fx_env_sampler, uv, 2, 0.0);
    let weight = textureSampleLevel(fx_env_dfg, fx_env_sampler, uv, 3, 0.0);
    var sum = vec3<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let d = normalize(r + offset[k] * t);
        sum += weight[k] * textureSampleLevel(fx_env_specular, fx_env_sampler, fx_env.map_from_view * d, fx_env_specular_level(level[k])).rgb;
    }
    return sum / max(dot(weight, vec4<f32>(1.0)), 1e-6);
}

// The dominant direction of the specular lobe: it leans from the mirror
// direction towards the normal as the surface gets rough (Lagarde and de
// Rousiers, "Moving Frostbite to PBR", 2014, listing 22; alpha = roughness^2).
fn fx_env_dominant(n: vec3<f32>, v: vec3<f32>, roughness: f32) -> vec3<f32> {
    let alpha = roughness * roughness;
    let gloss = 1.0 - alpha;
    return normalize(mix(n, reflect(-v, n), gloss * (sqrt(gloss) + alpha)));
}

// The bright cells' share of the specular light at `roughness`: level 0 of the
// specular map (a mirror) holds the whole map, the levels from 1 on the
// residual, so the cells count as much as level 1 does in the trilinear read.
fn fx_env_bright_share(roughness: f32) -> f32 {
    return clamp(fx_env_specular_level(roughness), 0.0, 1.0);
}

fn fx_env_d_ggx(ndh: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = ndh * ndh * (a2 - 1.0) + 1.0;
    return a2 / (3.14159265358979 * d * d);
}

// GGX of `alpha` widened by a cell of angular radius `radius` (the half vector
// spreads half as far as the light direction), so that a cell reflected by a
// smooth surface is a patch of its size, not a point.
fn fx_env_cell_alpha(alpha: f32, radius: f32) -> f32 {
    return sqrt(alpha * alpha + 0.25 * radius * radius);
}

// GGX D at normal `n` for view `v` and light `l` (unit vectors) of a cell of
// angular radius `radius` (fx_env_cell_alpha).
fn fx_env_cell_d(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, alpha: f32, radius: f32) -> f32 {
    return fx_env_d_ggx(max(dot(n, normalize(v + l)), 0.0), fx_env_cell_alpha(alpha, radius));
}

// The glTF BRDF's single-scattering specular term (GGX, height-correlated
// Smith, Schlick's Fresnel) summed over the bright cells: the cells' share of
// the environment's specular light at view-space normal `n` and view `v`.
fn fx_env_bright_specular(n: vec3<f32>, v: vec3<f32>, f0: vec3<f32>, roughness: f32) -> vec3<f32> {
    let count = fx_env.flags.z;
    if count == 0u {
        return vec3<f32>(0.0);
    }
    let nm = fx_env.map_from_view * n;
    let vm = fx_env.map_from_view * v;
    let alpha = max(roughness * roughness, 1e-3);
    let a2 = alpha * alpha;
    let ndv = max(dot(nm, vm), 1e-4);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < count; i++) {
        let c = fx_env.bright[i];
        let l = c.direction_radius.xyz;
        let ndl = dot(nm, l);
        if ndl <= 0.0 {
            continue;
        }
        let h = normalize(vm + l);
        let d = fx_env_cell_d(nm, vm, l, alpha, c.direction_radius.w);
        let vis = 0.5 / max(ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2), 1e-12);
        // clamped: v.h of unit vectors can round above 1, and pow of a
        // negative base is NaN (a cell behind the camera lit a wall's pixel
        // NaN, which the effect chain spread into black squares)
        let f = f0 + (vec3<f32>(1.0) - f0) * pow(clamp(1.0 - dot(vm, h), 0.0, 1.0), 5.0);
        sum += c.power_omega.rgb * f * (d * vis * ndl);
    }
    return sum * (fx_env.params.x * fx_env_bright_share(roughness));
}

// The normalisation of fx_env_bright_lobe at `roughness` (linear between the
// 16 tabulated values).
fn fx_env_bright_norm(roughness: f32) -> f32 {
    let x = clamp(roughness, 0.0, 1.0) * 15.0;
    let i = min(u32(x), 14u);
    let a = fx_env.bright_norm[i / 4u][i % 4u];
    let b = fx_env.bright_norm[(i + 1u) / 4u][(i + 1u) % 4u];
    return mix(a, b, x - f32(i));
}

// The bright cells as a prefiltered level would hold them about view-space
// direction `d` (the split sum's n = v = r, weight D G1 / 4, normalised):
// what the reads of the specular map miss from level 1 on, for the terms that
// use those reads (a lighting shader's own environment function, the coat,
// transmission, a blurred background).
fn fx_env_bright_lobe(d: vec3<f32>, roughness: f32) -> vec3<f32> {
    let count = fx_env.flags.z;
    if count == 0u {
        return vec3<f32>(0.0);
    }
    let dm = fx_env.map_from_view * d;
    let alpha = max(roughness * roughness, 1e-3);
    let a2 = alpha * alpha;
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < count; i++) {
        let c = fx_env.bright[i];
        let l = c.direction_radius.xyz;
        let ndl = dot(dm, l);
        if ndl <= 0.0 {
            continue;
        }
        let dd = fx_env_cell_d(dm, dm, l, alpha, c.direction_radius.w);
        let c2 = max(ndl * ndl, 1e-8);
        let g1 = 2.0 / (1.0 + sqrt(1.0 + a2 * (1.0 - c2) / c2));
        sum += c.power_omega.rgb * (dd * g1);
    }
    let share = fx_env.params.x * fx_env_bright_share(roughness);
    return sum * (share / (4.0 * max(fx_env_bright_norm(roughness), 1e-6)));
}

// `e` with the bright cells folded into its prefiltered radiance (for a
// lighting shader's own environment function).
fn fx_env_with_bright(e: EnvironmentInput) -> EnvironmentInput {
    var out = e;
    out.prefiltered += fx_env_bright_lobe(fx_env_dominant(e.normal, e.view_dir, e.roughness), e.roughness);
    return out;
}

// The lookups of the surface at view-space point `p`.
fn fx_environment_input(s: SurfaceOutput, p: vec3<f32>) -> EnvironmentInput {
    var e: EnvironmentInput;
    let v = fx_safe_normalize(-p);
    let n = s.normal;
    let ndv = max(dot(n, v), 1e-4);
    let intensity = fx_env.params.x;
    e.normal = n;
    e.view_dir = v;
    e.specular = s.specular;
    e.roughness = s.roughness;
    e.occlusion = s.occlusion;
    e.irradiance = textureSampleLevel(fx_env_irradiance, fx_env_sampler, fx_env.map_from_view * n, 0.0).rgb * intensity;
    e.prefiltered = fx_env_prefiltered(n, v, s.roughness) * intensity;
    e.dfg = textureSampleLevel(fx_env_dfg, fx_env_sampler, vec2<f32>(ndv, s.roughness), 0, 0.0).rg;
    return e;
}

// The default environment term: the split sum with Fdez-Aguera's
// multiple-scattering compensation ("A Multiple-Scattering Microfacet Model for
// Real-Time Image-based Lighting", JCGT 2019) and Lagarde and de Rousiers'
// specular occlusion from the material's occlusion (Frostbite 2014).
fn fx_environment_default(e: EnvironmentInput) -> LightingOutput {
    let f0 = e.specular;
    // single scattering: F0 A + B; its energy for F0 = 1: A + B
    let fss_ess = f0 * e.dfg.x + e.dfg.y;
    let ess = e.dfg.x + e.dfg.y;
    let ems = 1.0 - ess;
    // the hemispherical average of Schlick's Fresnel, and the multiple-
    // scattering lobe it feeds (a cosine lobe: irradiance)
    let f_avg = f0 + (vec3<f32>(1.0) - f0) / 21.0;
    let fms = fss_ess * f_avg / (vec3<f32>(1.0) - ems * f_avg);
    let ndv = max(dot(e.normal, e.view_dir), 1e-4);
    let ao = e.occlusion;
    let spec_ao = clamp(pow(ndv + ao, exp2(-16.0 * e.roughness * e.roughness - 1.0)) - 1.0 + ao, 0.0, 1.0);
    // the bright cells (bright.rs) with the BRDF itself, the rest from the maps
    let bright = fx_env_bright_specular(e.normal, e.view_dir, f0, e.roughness);
    let specular = (fss_ess * e.prefiltered + fms * ems * e.irradiance + bright) * spec_ao;
    // what the specular layer leaves to the diffuse one
    let kd = vec3<f32>(1.0) - (fss_ess + fms * ems);
    return LightingOutput(kd * e.irradiance * ao, specular);
}

// The environment's light reflected by surface `s` at view-space point `p`.
fn fx_environment(s: SurfaceOutput, p: vec3<f32>, material: u32) -> vec3<f32> {
    if fx_env.flags.x == 0u {
        return vec3<f32>(0.0);
    }
    let e = fx_environment_input(s, p);
    let lo = fx_environment_lighting(material, e);
    var diffuse = lo.diffuse;
    if s.transmission > 0.0 {
        // KHR_materials_transmission (layers.wgsl): the base's diffuse lobe gives
        // way to the light through the wall
        diffuse = mix(diffuse, fx_environment_transmitted(e), s.transmission);
    }
    return s.diffuse * diffuse + lo.specular;
}

// The environment seen through the thin wall, before the diffuse colour and the
// transmission factor: the prefiltered radiance at the surface's roughness along
// the mirrored dominant direction of its reflection lobe (-v for a mirror), times
// the transmitted albedo (1 - F0) A of the split sum (the integral of the BTDF
// term above over a constant environment).
fn fx_environment_transmitted(e: EnvironmentInput) -> vec3<f32> {
    let n = e.normal;
    let r = fx_env_dominant(n, e.view_dir, e.roughness);
    let t = r - 2.0 * dot(n, r) * n;
    let radiance = textureSampleLevel(fx_env_specular, fx_env_sampler, fx_env.map_from_view * t, fx_env_specular_level(e.roughness)).rgb * fx_env.params.x
        + fx_env_bright_lobe(t, e.roughness);
    return radiance * (vec3<f32>(1.0) - e.specular) * e.dfg.x;
}

// The coat's reflection of the environment (before w): the split sum of its lobe
// without Fresnel, (A + B) x the prefiltered radiance at the coat's roughness
// about its normal, with the specular occlusion of the base's term.
fn fx_environment_coat(s: SurfaceOutput, p: vec3<f32>) -> vec3<f32> {
    if fx_env.flags.x == 0u {
        return vec3<f32>(0.0);
    }
    var c = s;
    c.normal = s.clearcoat_normal;
    c.roughness = s.clearcoat_roughness;
    let e = fx_env_with_bright(fx_environment_input(c, p));
    let ndv = max(dot(e.normal, e.view_dir), 1e-4);
    let spec_ao = clamp(pow(ndv + e.occlusion, exp2(-16.0 * e.roughness * e.roughness - 1.0)) - 1.0 + e.occlusion, 0.0, 1.0);
    return e.prefiltered * (e.dfg.x + e.dfg.y) * spec_ao;
}

// What the pixel at `frag_xy` shows where no geometry is: the frame's colour,
// the environment (blurred to its level, fogged as the background colour is), or
// nothing (alpha 0).
fn fx_background(frag_xy: vec2<f32>) -> vec4<f32> {
    switch fx_env.flags.y {
        case 1u: {
            let d = fx_env.map_from_view * fx_safe_normalize(fx_view_position(frag_xy, 1.0));
            let level = fx_env.params.z;
            var c = textureSampleLevel(fx_env_specular, fx_env_sampler, d, level).rgb * fx_env.params.x;
            if level > 0.0 {
                let view_d = fx_safe_normalize(fx_view_position(frag_xy, 1.0));
                c += fx_env_bright_lobe(view_d, fx_env_level_roughness(level / max(fx_env.params.y, 1.0)));
            }
            return vec4<f32>(mix(fx_env.fog_color.rgb, c, fx_env.params.w), 1.0);
        }
        case 2u: {
            return vec4<f32>(0.0);
        }
        default: {
            return vec4<f32>(fx_frame.background.rgb, 1.0);
        }
    }
}
