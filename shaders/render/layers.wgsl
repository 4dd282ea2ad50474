// Layers over a material, part of every geometry module (after the geometry
// template; their environment lookups are in environment.wgsl):
// the clear coat of KHR_materials_clearcoat and the thin-walled transmission of
// KHR_materials_transmission, computed by the engine from SurfaceOutput's
// `clearcoat*` and `transmission` fields whatever the material's lighting shader.
//
// From the extensions' specifications:
//   coated = mix(material, coat_brdf, w),  w = clearcoat * (0.04 + 0.96 (1 - |n_c.v|)^5)
//     coat_brdf = D V (the glTF specular BRDF without Fresnel, alpha = coat roughness^2,
//     about the coat's normal n_c); emission is under the coat (darkened by 1 - w);
//   base = mix(diffuse_brdf, specular_btdf * diffuse colour, transmission) inside the
//     dielectric's fresnel_mix; thin walled: the BTDF is the GGX lobe of the
//     reflection mirrored through the surface (light leaves along the line of sight).
// The surface's pixels that use a layer are shaded in one place, `fx_lit_color`
// below, in all three techniques (docs/materials.md).

// Whether surface `s` has a layer (else every technique shades it as before); a
// surface without a diffuse colour (a metal) transmits nothing.
fn fx_layered(s: SurfaceOutput) -> bool {
    return s.clearcoat > 0.0 || (s.transmission > 0.0 && any(s.diffuse > vec3<f32>(0.0)));
}

// Schlick's Fresnel term's weight (1 - c)^5.
fn fx_schlick_weight(c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

// The coat's share of the pixel: clearcoat x Schlick(F0 = 0.04 (ior 1.5), |n_c.v|).
fn fx_coat_weight(s: SurfaceOutput, v: vec3<f32>) -> f32 {
    return s.clearcoat * (0.04 + 0.96 * fx_schlick_weight(abs(dot(s.clearcoat_normal, v))));
}

// The glTF specular lobe D V times n.l (no Fresnel) for a light from `l` seen from
// `v` about normal `n`; alpha = roughness^2, clamped as cook_torrance.wgsl does.
fn fx_ggx_lobe(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, roughness: f32) -> f32 {
    let ndl = dot(n, l);
    if ndl <= 0.0 {
        return 0.0;
    }
    let ndv = max(dot(n, v), 1e-4);
    let hv = l + v;
    let h = select(n, normalize(hv), dot(hv, hv) > 1e-12);
    let ndh = max(dot(n, h), 0.0);
    let a = max(roughness * roughness, 1e-3);
    let a2 = a * a;
    let dd = ndh * ndh * (a2 - 1.0) + 1.0;
    let d = a2 / (FX_PI * dd * dd);
    let g = ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2);
    return ndl * d * select(0.0, 0.5 / g, g > 0.0);
}

// The coat's radiance under illuminance `light` from `l` (before the weight w).
fn fx_coat_light(s: SurfaceOutput, v: vec3<f32>, l: vec3<f32>, light: vec3<f32>) -> vec3<f32> {
    return light * fx_ggx_lobe(s.clearcoat_normal, v, l, s.clearcoat_roughness);
}

// The light from `l` behind the surface (n.l < 0) that the thin wall transmits
// towards `v`, before the diffuse colour and the transmission factor: the
// extension's microfacet BTDF V_T D_T (its implementation notes: GGX D_T and the
// separable Smith V_T, about the transmission half vector h = normalize(v + l_m)
// with the mirrored direction l_m = l - 2 (n.l) n), times |n.l| and the base's
// share 1 - F(v.h) of the dielectric's Fresnel mix.
fn fx_transmitted_light(s: SurfaceOutput, v: vec3<f32>, l: vec3<f32>, light: vec3<f32>) -> vec3<f32> {
    let n = s.normal;
    let ndl = abs(dot(n, l));
    let lm = l + 2.0 * ndl * n;
    let hv = lm + v;
    let h = select(n, normalize(hv), dot(hv, hv) > 1e-12);
    let ndv = max(dot(n, v), 1e-4);
    let ndh = max(dot(n, h), 0.0);
    let a = max(s.roughness * s.roughness, 1e-3);
    let a2 = a * a;
    let dd = ndh * ndh * (a2 - 1.0) + 1.0;
    let d = a2 / (FX_PI * dd * dd);
    // The notes' chi+(h.v / n.v); their chi+(h.l / n.l) is left out: with the
    // mirrored direction it removes about a third of what a roughness-0.6 wall
    // transmits and three quarters at roughness 1 (measured on the CPU), which
    // the environment's (1 - F0) A below does not, nor the Khronos sample viewer.
    let seen = dot(h, v) >= 0.0;
    let vt = 1.0 / ((ndl + sqrt(a2 + (1.0 - a2) * ndl * ndl)) * (ndv + sqrt(a2 + (1.0 - a2) * ndv * ndv)));
    let f = s.specular + (vec3<f32>(1.0) - s.specular) * fx_schlick_weight(abs(dot(v, h)));
    return light * (vec3<f32>(1.0) - f) * select(0.0, ndl * d * vt, seen);
}

// Light summed over the punctual lights for one pixel.
struct FxLightSums {
    // the lighting shader's parts
    diffuse: vec3<f32>,
    specular: vec3<f32>,
    // the coat lobe (before w) and the transmitted light (before colour and factor)
    coat: vec3<f32>,
    transmitted: vec3<f32>,
}

// Adds light `light` (index into fx_lights) at view-space point `p` of surface `s`
// seen from `v`; `skip`: a padding entry of the constant forward loop.
fn fx_add_light(sums: ptr<function, FxLightSums>, s: SurfaceOutput, p: vec3<f32>, v: vec3<f32>, light: u32, material: u32, skip: bool) {
    let ls = fx_light_sample_shadowed(fx_lights[light], p, s.normal);
    if !ls.lit || skip {
        return;
    }
    let lo = fx_lighting(material, LightingInput(s.normal, v, ls.dir, ls.light, s.specular, s.roughness));
    (*sums).diffuse += lo.diffuse;
    (*sums).specular += lo.specular;
    if s.clearcoat > 0.0 {
        (*sums).coat += fx_coat_light(s, v, ls.dir, ls.light);
    }
    if s.transmission > 0.0 && dot(s.normal, ls.dir) < 0.0 {
        // the shadow offset goes towards the light, out of the wall's own shadow
        let back = fx_light_sample_shadowed(fx_lights[light], p, -s.normal);
        (*sums).transmitted += fx_transmitted_light(s, v, back.dir, back.light);
    }
}

// The light of layered surface `s` at view-space point `p` from every light of
// the fragment at `frag_xy` (as `fx_forward_color` iterates them; with a list,
// its first `light_count` entries, padding skipped), plus its unlit light and
// its layers. Forward calls it per fragment, deferred in its G-buffer pass, the
// light pre-pass in its final geometry pass.
fn fx_lit_color(s: SurfaceOutput, p: vec3<f32>, frag_xy: vec2<f32>, material: u32, light_count: u32) -> vec3<f32> {
    let v = fx_safe_normalize(-p);
    var sums: FxLightSums;
    if fx_frame.cluster.w != 0u {
        let range = fx_cluster_range(frag_xy, -p.z);
        let globals = fx_frame.global_lights;
        for (var i = 0u; i < globals + range.y; i++) {
            let j = select(range.x + i - globals, i, i < globals);
            fx_add_light(&sums, s, p, v, fx_cluster_lights[j], material, false);
        }
    } else {
        for (var i = 0u; i < light_count; i++) {
            fx_add_light(&sums, s, p, v, fx_visible[i], material, i >= fx_frame.light_count);
        }
    }
    var diffuse = sums.diffuse;
    if s.transmission > 0.0 {
        diffuse = mix(diffuse, sums.transmitted, s.transmission);
    }
    var color = s.diffuse * diffuse + sums.specular + fx_unlit(s, p, material);
    if s.clearcoat > 0.0 {
        // the coat over everything below it, emission included
        color = mix(color, sums.coat + fx_environment_coat(s, p), fx_coat_weight(s, v));
    }
    return color;
}
