// Shadow-map lookups, part of the geometry and the light modules (after the
// engine part). src/render/shadows.rs plans the layers, shadow_pass.rs renders
// them. Every light's sample goes through `fx_light_sample_shadowed`, so every
// lighting shader, the users' included, is shadowed without knowing it.

// One layer of the shadow-map array.
struct FxShadowLayer {
    // view space -> the light's clip space (depth 0..1)
    clip_from_view: mat4x4<f32>,
    // directional cascades: far end of the cascade (positive view depth)
    split: f32,
    // world size of a texel: absolute (orthographic) or at unit distance (perspective)
    texel: f32,
    perspective: u32,
    _p0: u32,
}

@group(0) @binding(8) var fx_shadow_maps: texture_depth_2d_array;
// comparison sampler: linear (PCF) or nearest (hard), clamped to the edge
@group(0) @binding(9) var fx_shadow_sampler: sampler_comparison;
@group(0) @binding(10) var<storage, read> fx_shadow_layers: array<FxShadowLayer>;

// Normal offset at lookup, in texels: moves the point off its own surface by more
// than the depth error of a texel, so lit surfaces do not shadow themselves (acne).
const FX_SHADOW_NORMAL_OFFSET: f32 = 1.5;

// The layer that holds view-space point `p` for light `l`, or -1 (outside every
// cascade). Point lights: the cube face of the major axis of the light -> point
// vector in world space (the faces are along the world axes).
fn fx_shadow_layer(l: FxLight, p: vec3<f32>) -> i32 {
    if l.kind == FX_KIND_DIRECTIONAL {
        let depth = -p.z;
        for (var i = 0u; i < l.shadow_count; i++) {
            if depth <= fx_shadow_layers[l.shadow_first + i].split {
                return i32(l.shadow_first + i);
            }
        }
        return -1;
    }
    if l.kind == FX_KIND_POINT {
        let view3 = mat3x3<f32>(fx_frame.view[0].xyz, fx_frame.view[1].xyz, fx_frame.view[2].xyz);
        // the inverse of the view rotation is its transpose
        let w = transpose(view3) * (p - l.position);
        let a = abs(w);
        var face = 0u;
        if a.x >= a.y && a.x >= a.z {
            face = select(1u, 0u, w.x > 0.0);
        } else if a.y >= a.z {
            face = select(3u, 2u, w.y > 0.0);
        } else {
            face = select(5u, 4u, w.z > 0.0);
        }
        return i32(l.shadow_first + face);
    }
    return i32(l.shadow_first);
}

// Fraction of light `l` that reaches view-space point `p` with normal `n`
// (0 shadowed .. 1 lit).
fn fx_shadow_factor(l: FxLight, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let index = fx_shadow_layer(l, p);
    if index < 0 {
        return 1.0;
    }
    let layer = fx_shadow_layers[index];
    var texel = layer.texel;
    if layer.perspective != 0u {
        texel *= length(p - l.position);
    }
    let q = p + n * (texel * FX_SHADOW_NORMAL_OFFSET);
    let c = layer.clip_from_view * vec4<f32>(q, 1.0);
    let ndc = c.xyz / c.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    // outside the map, or beyond its depth range: nothing there casts
    if c.w <= 0.0 || any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || ndc.z > 1.0 || ndc.z < 0.0 {
        return 1.0;
    }
    if l.shadow_filter == 1u {
        return textureSampleCompareLevel(fx_shadow_maps, fx_shadow_sampler, uv, index, ndc.z);
    }
    // PCF: 3x3 bilinear comparison taps one texel apart (a 4x4 texel footprint)
    let step = 1.0 / vec2<f32>(textureDimensions(fx_shadow_maps).xy);
    var sum = 0.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let o = vec2<f32>(f32(x), f32(y)) * step;
            sum += textureSampleCompareLevel(fx_shadow_maps, fx_shadow_sampler, uv + o, index, ndc.z);
        }
    }
    return sum / 9.0;
}

// `fx_light_sample` with the light's shadow applied to the illuminance; `n` is the
// shading normal (view space).
fn fx_light_sample_shadowed(l: FxLight, p: vec3<f32>, n: vec3<f32>) -> FxLightSample {
    var s = fx_light_sample(l, p);
    if s.lit && l.shadow_count > 0u {
        s.light *= fx_shadow_factor(l, p, n);
    }
    return s;
}
