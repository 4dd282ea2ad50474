// Geometry template: the vertex stage and every geometry fragment stage (G-buffer,
// light pre-pass depth+normals and final pass, forward, forward transparency).
// The generator appends the material's surface shader (`fn surface`), its
// lighting shader renamed `lmK_*` with the dispatch `fx_lighting`, and the
// interface types; `#ifdef` on feature flags here and in the surface shader is
// resolved per compilation mode (preprocessor, override constants or uniform
// branches). FX_LIGHT_COUNT is the forward light loop's bound.

// Light buffers, read by the light pre-pass final geometry pass.
@group(1) @binding(0) var fx_light_diffuse: texture_2d<f32>;
@group(1) @binding(1) var fx_light_specular: texture_2d<f32>;

struct FxVsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv0: vec2<f32>,
    @location(3) uv1: vec2<f32>,
    @location(4) tangent: vec4<f32>,
    @location(5) color: vec4<f32>,
}

struct FxVsOut {
    // invariant: the light pre-pass final pass tests depth EQUAL-or-less against
    // the first pass
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv0: vec2<f32>,
    @location(3) uv1: vec2<f32>,
    @location(4) tangent: vec4<f32>,
    @location(5) color: vec4<f32>,
    @location(6) world_pos: vec3<f32>,
    @location(7) world_normal: vec3<f32>,
    @location(8) @interpolate(flat) material: u32,
}

@vertex
fn fx_vs_geometry(v: FxVsIn, @builtin(instance_index) ii: u32) -> FxVsOut {
    return fx_geometry_vertex(v, ii);
}

// A vertex of instance slot `ii`: what the vertex stage hands the rasteriser,
// and what the visibility buffer's material resolve interpolates itself
// (visibility_resolve.wgsl).
fn fx_geometry_vertex(v: FxVsIn, ii: u32) -> FxVsOut {
    let inst = fx_instances[ii];
    let wp = inst.model * vec4<f32>(v.position, 1.0);
    let vp = fx_frame.view * wp;
    let view3 = mat3x3<f32>(fx_frame.view[0].xyz, fx_frame.view[1].xyz, fx_frame.view[2].xyz);
    let nrm3 = mat3x3<f32>(inst.normal[0].xyz, inst.normal[1].xyz, inst.normal[2].xyz);
    let model3 = mat3x3<f32>(inst.model[0].xyz, inst.model[1].xyz, inst.model[2].xyz);
    var out: FxVsOut;
    out.clip = fx_frame.proj * vp;
    out.view_pos = vp.xyz;
    out.world_pos = wp.xyz;
    out.world_normal = nrm3 * v.normal;
    out.normal = view3 * out.world_normal;
    out.uv0 = v.uv0;
    out.uv1 = v.uv1;
    // a mirroring transform turns the bitangent round
    let handedness = select(1.0, -1.0, determinant(model3) < 0.0);
    out.tangent = vec4<f32>(view3 * (model3 * v.tangent.xyz), v.tangent.w * handedness);
    out.color = v.color;
    out.material = inst.material;
    return out;
}

// The surface shader's input for this fragment.
fn fx_surface_input(in: FxVsOut, front: bool) -> SurfaceInput {
    var si: SurfaceInput;
    si.view_position = in.view_pos;
    si.world_position = in.world_pos;
    si.normal = fx_safe_normalize(in.normal);
    si.world_normal = fx_safe_normalize(in.world_normal);
#ifdef DOUBLE_SIDED
    if !front {
        si.normal = -si.normal;
        si.world_normal = -si.world_normal;
    }
#endif
    let tl = length(in.tangent.xyz);
    si.tangent = vec4<f32>(0.0);
    if tl > 1e-6 && in.tangent.w != 0.0 {
        si.tangent = vec4<f32>(in.tangent.xyz / tl, select(1.0, -1.0, in.tangent.w < 0.0));
    }
    si.uv0 = in.uv0;
    si.uv1 = in.uv1;
    si.color = in.color;
    si.front_facing = front;
    si.view_from_world = mat3x3<f32>(fx_frame.view[0].xyz, fx_frame.view[1].xyz, fx_frame.view[2].xyz);
    return si;
}

// The surface with the engine's post-conditions (unit normal, clamped ranges).
fn fx_surface(in: FxVsOut, front: bool) -> SurfaceOutput {
    let si = fx_surface_input(in, front);
    var s = surface(si);
    s.normal = fx_safe_normalize(s.normal);
    s.roughness = clamp(s.roughness, 0.0, 1.0);
    // what the 8-bit G-buffer can hold, in every technique alike
    s.diffuse = clamp(s.diffuse, vec3<f32>(0.0), vec3<f32>(1.0));
    s.alpha = clamp(s.alpha, 0.0, 1.0);
    s.specular = clamp(s.specular, vec3<f32>(0.0), vec3<f32>(1.0));
    s.occlusion = clamp(s.occlusion, 0.0, 1.0);
    // the layers (layers.wgsl): a coat without a normal of its own follows the
    // vertex normal
    s.clearcoat = clamp(s.clearcoat, 0.0, 1.0);
    s.clearcoat_roughness = clamp(s.clearcoat_roughness, 0.0, 1.0);
    let cn = s.clearcoat_normal;
    s.clearcoat_normal = select(si.normal, cn * inverseSqrt(dot(cn, cn)), dot(cn, cn) > 1e-12);
    s.transmission = clamp(s.transmission, 0.0, 1.0);
    return s;
}

// MASK coverage test.
fn fx_masked(in: FxVsOut, s: SurfaceOutput) -> bool {
    var masked = false;
#ifdef ALPHA_MASK
    masked = s.alpha < fx_materials[in.material].alpha_cutoff;
#endif
    return masked;
}

// Light that needs no light loop: emission, ambient × occlusion and the
// environment (environment.wgsl) of the surface at view-space point `p`.
fn fx_unlit(s: SurfaceOutput, p: vec3<f32>, material: u32) -> vec3<f32> {
    return fx_unlit_local(s) + fx_environment(s, p, material);
}

// Emission and ambient × occlusion: what the deferred geometry pass writes
// (the composition adds the environment from the G-buffer, in compute where
// the light pass is: light.wgsl `fx_deferred_environment`).
fn fx_unlit_local(s: SurfaceOutput) -> vec3<f32> {
    return s.emission + s.diffuse * fx_frame.ambient.rgb * s.occlusion;
}

struct FxGBufferOut {
    // rgb diffuse colour, a = material id / 255 (Tang et al., table 2)
    @location(0) albedo: vec4<f32>,
    // rg = encoded normal, b = roughness, a = 0 where the pixel is already lit
    // (a layered surface: the light pass leaves it alone), else 1
    @location(1) normal: vec4<f32>,
    // rgb specular colour F0 (sRGB storage), a = lighting model id / 255
    @location(2) specular: vec4<f32>,
    // rgb: the specular light buffer starts with emission + ambient (the
    // composition adds the environment); a: the material's occlusion, which
    // the composition's environment term reads (the lights add 0 to it)
    @location(3) light: vec4<f32>,
}

@fragment
fn fx_fs_gbuffer(in: FxVsOut, @builtin(front_facing) front: bool) -> FxGBufferOut {
    let s = fx_surface(in, front);
    if fx_masked(in, s) {
        discard;
    }
    var out: FxGBufferOut;
    var layered = false;
#ifdef HAS_LAYERS
    layered = fx_layered(s);
#endif
    out.albedo = vec4<f32>(s.diffuse, f32(in.material) / 255.0);
    out.normal = vec4<f32>(fx_encode_normal(s.normal), s.roughness, select(1.0, 0.0, layered));
    out.specular = vec4<f32>(s.specular, f32(fx_materials[in.material].model) / 255.0);
    out.light = vec4<f32>(fx_unlit_local(s), s.occlusion);
#ifdef HAS_LAYERS
    if layered {
        // clear coat or transmission: every light here, as forward does
        out.light = vec4<f32>(fx_lit_color(s, in.view_pos, in.clip.xy, in.material, fx_frame.light_count), 0.0);
    }
#endif
    return out;
}

struct FxPrepassOut {
    // only alpha (the material id) is written: colour writes are masked
    @location(0) albedo: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) specular: vec4<f32>,
}

@fragment
fn fx_fs_prepass(in: FxVsOut, @builtin(front_facing) front: bool) -> FxPrepassOut {
    let s = fx_surface(in, front);
    if fx_masked(in, s) {
        discard;
    }
    var out: FxPrepassOut;
    var layered = false;
#ifdef HAS_LAYERS
    layered = fx_layered(s);
#endif
    out.albedo = vec4<f32>(0.0, 0.0, 0.0, f32(in.material) / 255.0);
    out.normal = vec4<f32>(fx_encode_normal(s.normal), s.roughness, select(1.0, 0.0, layered));
    out.specular = vec4<f32>(s.specular, f32(fx_materials[in.material].model) / 255.0);
    return out;
}

struct FxFinalOut {
    @location(0) scene: vec4<f32>,
    @location(1) albedo: vec4<f32>,
}

// Light pre-pass, third pass: the geometry again, reading the light buffers.
@fragment
fn fx_fs_lpp_final(in: FxVsOut, @builtin(front_facing) front: bool) -> FxFinalOut {
    let s = fx_surface(in, front);
    if fx_masked(in, s) {
        discard;
    }
    let c = vec2<i32>(in.clip.xy);
    let diffuse = textureLoad(fx_light_diffuse, c, 0).rgb;
    let specular = textureLoad(fx_light_specular, c, 0).rgb;
    var color = s.diffuse * diffuse + specular + fx_unlit(s, in.view_pos, in.material);
#ifdef HAS_LAYERS
    if fx_layered(s) {
        // clear coat or transmission: the light pass skipped it; every light here
        color = fx_lit_color(s, in.view_pos, in.clip.xy, in.material, fx_frame.light_count);
    }
#endif
    var out: FxFinalOut;
    out.scene = vec4<f32>(fx_fog(color, in.view_pos), 1.0);
    out.albedo = vec4<f32>(s.diffuse, f32(in.material) / 255.0);
    return out;
}

// The lights of a fragment at `frag_xy`: with cluster lists (cluster.w > 0)
// the global lights and the fragment's cluster; otherwise every visible light,
// the loop bound a compile-time constant in the preprocessor and override modes
// (the padding past the visible lights is skipped). A surface with a layer
// (clear coat, transmission) goes to `fx_lit_color` (layers.wgsl); this loop is
// kept apart from that one because sharing it (with the layers' per-light
// branches) made the forward pass of the built-in room 1.4x slower on lavapipe.
fn fx_forward_color(s: SurfaceOutput, p: vec3<f32>, frag_xy: vec2<f32>, material: u32) -> vec3<f32> {
#ifdef HAS_LAYERS
    if fx_layered(s) {
        return fx_lit_color(s, p, frag_xy, material, FX_LIGHT_COUNT);
    }
#endif
    let v = fx_safe_normalize(-p);
    var diffuse = vec3<f32>(0.0);
    var specular = vec3<f32>(0.0);
    if fx_frame.cluster.w != 0u {
        let range = fx_cluster_range(frag_xy, -p.z);
        let globals = fx_frame.global_lights;
        for (var i = 0u; i < globals + range.y; i++) {
            // (the unselected operand may wrap round: u32 arithmetic is modular)
            let j = select(range.x + i - globals, i, i < globals);
            let ls = fx_light_sample_shadowed(fx_lights[fx_cluster_lights[j]], p, s.normal);
            if ls.lit {
                let lo = fx_lighting(material, LightingInput(s.normal, v, ls.dir, ls.light, s.specular, s.roughness));
                diffuse += lo.diffuse;
                specular += lo.specular;
            }
        }
    } else {
        for (var i = 0u; i < FX_LIGHT_COUNT; i++) {
            let ls = fx_light_sample_shadowed(fx_lights[fx_visible[i]], p, s.normal);
            // lights past the visible ones pad the constant loop: not shaded
            if ls.lit && i < fx_frame.light_count {
                let lo = fx_lighting(material, LightingInput(s.normal, v, ls.dir, ls.light, s.specular, s.roughness));
                diffuse += lo.diffuse;
                specular += lo.specular;
            }
        }
    }
    return s.diffuse * diffuse + specular + fx_unlit(s, p, material);
}

struct FxForwardOut {
    @location(0) scene: vec4<f32>,
    @location(1) albedo: vec4<f32>,
    @location(2) normal: vec4<f32>,
    @location(3) specular: vec4<f32>,
}

@fragment
fn fx_fs_forward(in: FxVsOut, @builtin(front_facing) front: bool) -> FxForwardOut {
    let s = fx_surface(in, front);
    if fx_masked(in, s) {
        discard;
    }
    var out: FxForwardOut;
    out.scene = vec4<f32>(fx_fog(fx_forward_color(s, in.view_pos, in.clip.xy, in.material), in.view_pos), 1.0);
    out.albedo = vec4<f32>(s.diffuse, f32(in.material) / 255.0);
    out.normal = vec4<f32>(fx_encode_normal(s.normal), s.roughness, 1.0);
    out.specular = vec4<f32>(s.specular, f32(fx_materials[in.material].model) / 255.0);
    return out;
}

// Transparent (BLEND) surfaces, blended over the composed image.
@fragment
fn fx_fs_forward_blend(in: FxVsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let s = fx_surface(in, front);
    return vec4<f32>(fx_fog(fx_forward_color(s, in.view_pos, in.clip.xy, in.material), in.view_pos), s.alpha);
}
