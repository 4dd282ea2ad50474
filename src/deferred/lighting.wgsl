// Light accumulation (light volumes and full-screen lights), composition and the
// G-buffer resolve into the AUX images.

struct LightVsOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) light: u32,
}

// A light volume: unit icosphere scaled to the light's radius, or a unit cone
// (apex at the origin, axis +Z, base radius 1 at z = 1) oriented along the light.
@vertex
fn vs_volume(@location(0) p: vec3<f32>, @builtin(instance_index) ii: u32) -> LightVsOut {
    let index = visible[ii];
    let l = lights[index];
    var vp: vec3<f32>;
    if l.volume == 2u {
        let d = l.direction;
        let helper = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(d.y) > 0.9);
        let t = normalize(cross(helper, d));
        let b = cross(d, t);
        vp = l.position + (t * p.x + b * p.y) * l.cone_radius + d * (p.z * l.radius * l.volume_scale);
    } else {
        vp = l.position + p * (l.radius * l.volume_scale);
    }
    var out: LightVsOut;
    out.pos = frame.proj * vec4<f32>(vp, 1.0);
    out.light = index;
    return out;
}

@vertex
fn vs_light_fullscreen(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> LightVsOut {
    var out: LightVsOut;
    out.pos = fullscreen_pos(vi);
    out.light = visible[ii];
    return out;
}

struct LightOut {
    @location(0) diffuse: vec4<f32>,
    @location(1) specular: vec4<f32>,
}

@fragment
fn fs_light(in: LightVsOut) -> LightOut {
    let c = vec2<i32>(in.pos.xy);
    let depth = textureLoad(t_depth, c, 0);
    if depth >= 1.0 {
        return LightOut(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let p = view_position(in.pos.xy, depth);
    let g = textureLoad(t_gnormal, c, 0);
    let n = decode_normal(g.xy);
    let id = u32(round(textureLoad(t_albedo, c, 0).a * 255.0));
    let lit = shade(lights[in.light], p, n, safe_normalize(-p), materials[id].shininess);
    return LightOut(vec4<f32>(lit.diffuse, 0.0), vec4<f32>(lit.specular * g.z, 0.0));
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_pos(vi);
}

// albedo × (ambient + diffuse) + specular (+ emission, already in the specular buffer)
@fragment
fn fs_compose(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = vec2<i32>(pos.xy);
    let depth = textureLoad(t_depth, c, 0);
    if depth >= 1.0 {
        return vec4<f32>(frame.background.rgb, 1.0);
    }
    let albedo = textureLoad(t_albedo, c, 0).rgb;
    let diffuse = textureLoad(t_diffuse, c, 0).rgb;
    let specular = textureLoad(t_specular, c, 0).rgb;
    return vec4<f32>(albedo * diffuse + specular, 1.0);
}

struct AuxA {
    // linear view depth (positive distance along the view axis)
    @location(0) depth: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) position: vec4<f32>,
}

@fragment
fn fs_aux_a(@builtin(position) pos: vec4<f32>) -> AuxA {
    let c = vec2<i32>(pos.xy);
    let depth = textureLoad(t_depth, c, 0);
    var out: AuxA;
    if depth >= 1.0 {
        let p = view_position(pos.xy, 1.0);
        out.depth = vec4<f32>(frame.far, 0.0, 0.0, 0.0);
        out.normal = vec4<f32>(0.0);
        out.position = vec4<f32>(p, 0.0);
        return out;
    }
    let p = view_position(pos.xy, depth);
    let g = textureLoad(t_gnormal, c, 0);
    out.depth = vec4<f32>(-p.z, 0.0, 0.0, 0.0);
    out.normal = vec4<f32>(decode_normal(g.xy), 1.0);
    out.position = vec4<f32>(p, 1.0);
    return out;
}

struct AuxB {
    @location(0) albedo: vec4<f32>,
    // r = id / 255, g = log2(shininess) / 11, b = roughness, a = metallic
    @location(1) material: vec4<f32>,
    @location(2) specular: vec4<f32>,
}

@fragment
fn fs_aux_b(@builtin(position) pos: vec4<f32>) -> AuxB {
    let c = vec2<i32>(pos.xy);
    let depth = textureLoad(t_depth, c, 0);
    var out: AuxB;
    if depth >= 1.0 {
        out.albedo = vec4<f32>(0.0);
        out.material = vec4<f32>(0.0);
        out.specular = vec4<f32>(0.0);
        return out;
    }
    let a = textureLoad(t_albedo, c, 0);
    let id = u32(round(a.a * 255.0));
    let m = materials[id];
    out.albedo = vec4<f32>(a.rgb, 1.0);
    out.material = vec4<f32>(f32(id) / 255.0, clamp(log2(max(m.shininess, 1.0)) / 11.0, 0.0, 1.0), m.roughness, m.metallic);
    out.specular = vec4<f32>(textureLoad(t_gnormal, c, 0).z, 0.0, 0.0, 0.0);
    return out;
}
