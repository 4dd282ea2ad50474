// Geometry passes: G-buffer fill (deferred), depth + normals and final geometry
// (light pre-pass), forward shading (opaque and transparent).

@group(2) @binding(0) var t_base: texture_2d<f32>;
@group(2) @binding(1) var t_normal_map: texture_2d<f32>;
@group(2) @binding(2) var t_emissive: texture_2d<f32>;
@group(2) @binding(3) var s_mat: sampler;

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
}

struct VsOut {
    // invariant: the light pre-pass final pass tests depth EQUAL-or-less against
    // the first pass
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
    @location(4) @interpolate(flat) material: u32,
}

@vertex
fn vs_geometry(v: VsIn, @builtin(instance_index) ii: u32) -> VsOut {
    let inst = instances[ii];
    let vp = frame.view * (inst.model * vec4<f32>(v.position, 1.0));
    let view3 = mat3x3<f32>(frame.view[0].xyz, frame.view[1].xyz, frame.view[2].xyz);
    let nrm3 = mat3x3<f32>(inst.normal[0].xyz, inst.normal[1].xyz, inst.normal[2].xyz);
    let model3 = mat3x3<f32>(inst.model[0].xyz, inst.model[1].xyz, inst.model[2].xyz);
    var out: VsOut;
    out.clip = frame.proj * vp;
    out.view_pos = vp.xyz;
    out.normal = view3 * (nrm3 * v.normal);
    out.uv = v.uv;
    out.tangent = vec4<f32>(view3 * (model3 * v.tangent.xyz), v.tangent.w);
    out.material = inst.material;
    return out;
}

struct Surface {
    albedo: vec3<f32>,
    alpha: f32,
    normal: vec3<f32>,
    emissive: vec3<f32>,
    specular: f32,
    shininess: f32,
}

fn surface(in: VsOut, front: bool) -> Surface {
    let m = materials[in.material];
    // Sample unconditionally (uniform control flow); absent textures are 1x1
    // white / flat-normal defaults.
    let base = m.base_color * textureSample(t_base, s_mat, in.uv);
    let nm = textureSample(t_normal_map, s_mat, in.uv).xyz * 2.0 - 1.0;
    let em = textureSample(t_emissive, s_mat, in.uv).rgb;
    var n = safe_normalize(in.normal);
    if (m.flags & FLAG_DOUBLE_SIDED) != 0u && !front {
        n = -n;
    }
    let tl = length(in.tangent.xyz);
    if (m.flags & FLAG_NORMAL_MAP) != 0u && tl > 1e-6 {
        let t = safe_normalize(in.tangent.xyz / tl - n * dot(n, in.tangent.xyz / tl));
        let b = cross(n, t) * select(1.0, -1.0, in.tangent.w < 0.0);
        let ts = vec3<f32>(nm.xy * m.normal_scale, nm.z);
        n = safe_normalize(t * ts.x + b * ts.y + n * ts.z);
    }
    var s: Surface;
    s.albedo = base.rgb;
    s.alpha = base.a;
    s.normal = n;
    s.emissive = m.emissive * em;
    s.specular = m.specular;
    s.shininess = m.shininess;
    return s;
}

fn masked(in: VsOut, s: Surface) -> bool {
    let m = materials[in.material];
    return (m.flags & FLAG_MASK) != 0u && s.alpha < m.alpha_cutoff;
}

struct GBufferOut {
    // rgb albedo, a = material id / 255 (seed 001 table 2)
    @location(0) albedo: vec4<f32>,
    // rg = encoded normal, b = specular k_s
    @location(1) normal: vec4<f32>,
    // the specular light buffer starts with the emission
    @location(2) emissive: vec4<f32>,
}

@fragment
fn fs_gbuffer(in: VsOut, @builtin(front_facing) front: bool) -> GBufferOut {
    let s = surface(in, front);
    if masked(in, s) {
        discard;
    }
    var out: GBufferOut;
    out.albedo = vec4<f32>(s.albedo, f32(in.material) / 255.0);
    out.normal = vec4<f32>(encode_normal(s.normal), s.specular, 1.0);
    out.emissive = vec4<f32>(s.emissive, 0.0);
    return out;
}

struct PrepassOut {
    // only alpha (the material id) is written: colour writes are masked
    @location(0) albedo: vec4<f32>,
    @location(1) normal: vec4<f32>,
}

@fragment
fn fs_prepass(in: VsOut, @builtin(front_facing) front: bool) -> PrepassOut {
    let s = surface(in, front);
    if masked(in, s) {
        discard;
    }
    var out: PrepassOut;
    out.albedo = vec4<f32>(0.0, 0.0, 0.0, f32(in.material) / 255.0);
    out.normal = vec4<f32>(encode_normal(s.normal), s.specular, 1.0);
    return out;
}

struct FinalOut {
    @location(0) scene: vec4<f32>,
    @location(1) albedo: vec4<f32>,
}

// Light pre-pass, third pass: the geometry again, reading the light buffers.
@fragment
fn fs_lpp_final(in: VsOut, @builtin(front_facing) front: bool) -> FinalOut {
    let s = surface(in, front);
    if masked(in, s) {
        discard;
    }
    let c = vec2<i32>(in.clip.xy);
    let diffuse = textureLoad(t_diffuse, c, 0).rgb;
    let specular = textureLoad(t_specular, c, 0).rgb;
    var out: FinalOut;
    out.scene = vec4<f32>(s.albedo * diffuse + specular + s.emissive, 1.0);
    out.albedo = vec4<f32>(s.albedo, f32(in.material) / 255.0);
    return out;
}

// Every visible light per fragment.
fn forward_color(s: Surface, p: vec3<f32>) -> vec3<f32> {
    let v = safe_normalize(-p);
    var diffuse = vec3<f32>(0.0);
    var specular = vec3<f32>(0.0);
    for (var i = 0u; i < frame.light_count; i++) {
        let lit = shade(lights[visible[i]], p, s.normal, v, s.shininess);
        diffuse += lit.diffuse;
        specular += lit.specular;
    }
    return s.albedo * diffuse + specular * s.specular + s.emissive;
}

struct ForwardOut {
    @location(0) scene: vec4<f32>,
    @location(1) albedo: vec4<f32>,
    @location(2) normal: vec4<f32>,
}

@fragment
fn fs_forward(in: VsOut, @builtin(front_facing) front: bool) -> ForwardOut {
    let s = surface(in, front);
    if masked(in, s) {
        discard;
    }
    var out: ForwardOut;
    out.scene = vec4<f32>(forward_color(s, in.view_pos), 1.0);
    out.albedo = vec4<f32>(s.albedo, f32(in.material) / 255.0);
    out.normal = vec4<f32>(encode_normal(s.normal), s.specular, 1.0);
    return out;
}

// Transparent (glTF BLEND) surfaces, blended over the composed image.
@fragment
fn fs_forward_blend(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let s = surface(in, front);
    return vec4<f32>(forward_color(s, in.view_pos), s.alpha);
}
