// Light-pass template: light volumes and full-screen lights over the G-buffer
// (deferred and light pre-pass), composition, and the G-buffer resolve into the
// AUX images. The generator appends every lighting shader of the scene renamed
// `lmK_*` and the dispatch `fx_lighting(material, in)`, which switches on the
// lighting model id stored in the G-buffer.

@group(1) @binding(0) var fx_t_depth: texture_depth_2d;
// rgb diffuse colour (sRGB storage, linear when loaded), a = material id / 255
@group(1) @binding(1) var fx_t_albedo: texture_2d<f32>;
// rg encoded view-space normal, b = roughness, a = 0 for a layered surface (lit
// in its geometry pass: the light passes skip it)
@group(1) @binding(2) var fx_t_normal: texture_2d<f32>;
// rgb specular colour F0, a = lighting model id / 255
@group(1) @binding(3) var fx_t_specular: texture_2d<f32>;
@group(1) @binding(4) var fx_t_light_diffuse: texture_2d<f32>;
@group(1) @binding(5) var fx_t_light_specular: texture_2d<f32>;

struct FxLightVsOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) light: u32,
}

// A light volume: unit icosphere scaled to the light's radius, or a unit cone
// (apex at the origin, axis +Z, base radius 1 at z = 1) oriented along the light.
@vertex
fn fx_vs_volume(@location(0) p: vec3<f32>, @builtin(instance_index) ii: u32) -> FxLightVsOut {
    let index = fx_visible[ii];
    let l = fx_lights[index];
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
    var out: FxLightVsOut;
    out.pos = fx_frame.proj * vec4<f32>(vp, 1.0);
    out.light = index;
    return out;
}

@vertex
fn fx_vs_light_fullscreen(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> FxLightVsOut {
    var out: FxLightVsOut;
    out.pos = fx_fullscreen_pos(vi);
    out.light = fx_visible[ii];
    return out;
}

struct FxLightOut {
    @location(0) diffuse: vec4<f32>,
    @location(1) specular: vec4<f32>,
}

@fragment
fn fx_fs_light(in: FxLightVsOut) -> FxLightOut {
    let c = vec2<i32>(in.pos.xy);
    let depth = textureLoad(fx_t_depth, c, 0);
    if depth >= 1.0 {
        return FxLightOut(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let p = fx_view_position(in.pos.xy, depth);
    let g = textureLoad(fx_t_normal, c, 0);
    if g.a < 0.5 {
        // a layered surface (clear coat, transmission), lit in its geometry pass
        return FxLightOut(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let n = fx_decode_normal(g.xy);
    let ls = fx_light_sample_shadowed(fx_lights[in.light], p, n);
    if !ls.lit {
        return FxLightOut(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let sp = textureLoad(fx_t_specular, c, 0);
    let material = u32(round(textureLoad(fx_t_albedo, c, 0).a * 255.0));
    let model = u32(round(sp.a * 255.0));
    let li = LightingInput(n, fx_safe_normalize(-p), ls.dir, ls.light, sp.rgb, g.z);
    let lo = fx_lighting_model(model, material, li);
    return FxLightOut(vec4<f32>(lo.diffuse, 0.0), vec4<f32>(lo.specular, 0.0));
}

// One pixel of the G-buffer, read once by the clustered light pass and the
// deferred composition.
struct FxGbufferPixel {
    // depth (1 where nothing was drawn: the other fields are then unset)
    depth: f32,
    // view-space position
    p: vec3<f32>,
    // encoded normal, roughness, 0 for a layered surface
    normal: vec4<f32>,
    // F0, lighting model id / 255
    specular: vec4<f32>,
    // diffuse colour, material id / 255
    albedo: vec4<f32>,
}

fn fx_gbuffer_pixel(xy: vec2<f32>) -> FxGbufferPixel {
    let c = vec2<i32>(xy);
    var px: FxGbufferPixel;
    px.depth = textureLoad(fx_t_depth, c, 0);
    if px.depth < 1.0 {
        px.p = fx_view_position(xy, px.depth);
        px.normal = textureLoad(fx_t_normal, c, 0);
        px.specular = textureLoad(fx_t_specular, c, 0);
        px.albedo = textureLoad(fx_t_albedo, c, 0);
    }
    return px;
}

// The lights of G-buffer pixel `px` at `xy` (pixel centre): the global lights
// and the lights of its cluster (src/render/clusters.rs).
fn fx_light_clustered(xy: vec2<f32>, px: FxGbufferPixel) -> FxLightOut {
    if px.depth >= 1.0 || px.normal.a < 0.5 {
        // nothing drawn, or a layered surface (clear coat, transmission), lit
        // in its geometry pass
        return FxLightOut(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let p = px.p;
    let g = px.normal;
    let sp = px.specular;
    let material = u32(round(px.albedo.a * 255.0));
    let model = u32(round(sp.a * 255.0));
    let n = fx_decode_normal(g.xy);
    let v = fx_safe_normalize(-p);
    var diffuse = vec3<f32>(0.0);
    var specular = vec3<f32>(0.0);
    let range = fx_cluster_range(xy, -p.z);
    let globals = fx_frame.global_lights;
    for (var i = 0u; i < globals + range.y; i++) {
        // (the unselected operand may wrap round: u32 arithmetic is modular)
        let j = select(range.x + i - globals, i, i < globals);
        let ls = fx_light_sample_shadowed(fx_lights[fx_cluster_lights[j]], p, n);
        if ls.lit {
            let lo = fx_lighting_model(model, material, LightingInput(n, v, ls.dir, ls.light, sp.rgb, g.z));
            diffuse += lo.diffuse;
            specular += lo.specular;
        }
    }
    return FxLightOut(vec4<f32>(diffuse, 0.0), vec4<f32>(specular, 0.0));
}

// The clustered light pass as a fragment shader: one full-screen triangle,
// added to the light buffers by blending.
@fragment
fn fx_fs_light_clustered(@builtin(position) pos: vec4<f32>) -> FxLightOut {
    return fx_light_clustered(pos.xy, fx_gbuffer_pixel(pos.xy));
}

// The clustered light pass in compute (src/render/light_compute.rs): one
// invocation per pixel in 8 × 8 tiles, writing the light buffers once. The
// specular buffer starts from what the geometry pass wrote (emission, ambient;
// a: the occlusion; zero in the light pre-pass), read from `fx_c_emission`.
@group(2) @binding(0) var fx_c_diffuse: texture_storage_2d<rgba16float, write>;
@group(2) @binding(1) var fx_c_specular: texture_storage_2d<rgba16float, write>;
@group(2) @binding(2) var fx_c_scene: texture_storage_2d<rgba16float, write>;
@group(2) @binding(3) var fx_c_emission: texture_2d<f32>;

// Lights G-buffer pixel `px` at `id`; returns its light buffers (written).
fn fx_cs_light_pixel(id: vec2<u32>, px: FxGbufferPixel, emission: bool) -> FxLightOut {
    let c = vec2<i32>(id);
    var lit = fx_light_clustered(vec2<f32>(id) + 0.5, px);
    if emission {
        lit.specular += textureLoad(fx_c_emission, c, 0);
    }
    textureStore(fx_c_diffuse, c, lit.diffuse);
    textureStore(fx_c_specular, c, lit.specular);
    return lit;
}

fn fx_cs_inside(id: vec3<u32>) -> bool {
    return f32(id.x) < fx_frame.viewport.x && f32(id.y) < fx_frame.viewport.y;
}

// Light pre-pass: the light buffers alone (the final geometry pass reads them).
@compute @workgroup_size(8, 8)
fn fx_cs_light(@builtin(global_invocation_id) id: vec3<u32>) {
    if fx_cs_inside(id) {
        fx_cs_light_pixel(id.xy, fx_gbuffer_pixel(vec2<f32>(id.xy) + 0.5), false);
    }
}

// Deferred: the light buffers and the composition (fx_fs_compose's maths) in
// one pass.
@compute @workgroup_size(8, 8)
fn fx_cs_light_compose(@builtin(global_invocation_id) id: vec3<u32>) {
    if !fx_cs_inside(id) {
        return;
    }
    let c = vec2<i32>(id.xy);
    let xy = vec2<f32>(id.xy) + 0.5;
    let px = fx_gbuffer_pixel(xy);
    let lit = fx_cs_light_pixel(id.xy, px, true);
    if px.depth >= 1.0 {
        textureStore(fx_c_scene, c, fx_background(xy));
        return;
    }
    let environment = fx_deferred_environment(px, lit.specular.a);
    let albedo = px.albedo.rgb;
    textureStore(fx_c_scene, c, vec4<f32>(fx_fog(albedo * lit.diffuse.rgb + lit.specular.rgb + environment, px.p), 1.0));
}

@vertex
fn fx_vs_fullscreen(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return fx_fullscreen_pos(vi);
}

// The environment's light (environment.wgsl) at deferred G-buffer pixel `px`:
// evaluated here, once per pixel and in compute where the light pass runs in
// compute, rather than in the geometry pass (on
// GPUs whose rasterisation is a small part of the chip, its lookups cost the
// G-buffer pass half its time; issue 26). `occlusion` is the specular light
// buffer's alpha, where the geometry pass wrote the material's occlusion. A
// layered surface (clear coat, transmission) was lit whole, environment
// included, in its geometry pass.
fn fx_deferred_environment(px: FxGbufferPixel, occlusion: f32) -> vec3<f32> {
    if px.normal.a < 0.5 || fx_env.flags.x == 0u {
        return vec3<f32>(0.0);
    }
    var s: SurfaceOutput;
    s.normal = fx_decode_normal(px.normal.xy);
    s.diffuse = px.albedo.rgb;
    s.specular = px.specular.rgb;
    s.roughness = px.normal.z;
    s.occlusion = occlusion;
    return fx_environment(s, px.p, u32(round(px.albedo.a * 255.0)));
}

// diffuse colour × diffuse light + specular light (which started as emission +
// ambient in the geometry pass) + the environment, through the fog
@fragment
fn fx_fs_compose(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = vec2<i32>(pos.xy);
    let px = fx_gbuffer_pixel(pos.xy);
    if px.depth >= 1.0 {
        return fx_background(pos.xy);
    }
    let diffuse = textureLoad(fx_t_light_diffuse, c, 0).rgb;
    let specular = textureLoad(fx_t_light_specular, c, 0);
    let environment = fx_deferred_environment(px, specular.a);
    return vec4<f32>(fx_fog(px.albedo.rgb * diffuse + specular.rgb + environment, px.p), 1.0);
}

// The environment behind the geometry (light pre-pass and forward; deferred
// draws it in the composition): only where nothing was drawn.
@fragment
fn fx_fs_background(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    if textureLoad(fx_t_depth, vec2<i32>(pos.xy), 0) < 1.0 {
        discard;
    }
    return fx_background(pos.xy);
}

struct FxAuxA {
    // linear view depth (positive distance along the view axis)
    @location(0) depth: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) position: vec4<f32>,
    // motion vectors of a still world (camera motion alone; the instances that
    // moved are drawn over it by motion.wgsl)
    @location(3) motion: vec4<f32>,
}

// Clip position -> pixel position (x right, y down).
fn fx_to_pixel(clip: vec4<f32>) -> vec2<f32> {
    let ndc = clip.xy / clip.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * fx_frame.viewport.x, (0.5 - ndc.y * 0.5) * fx_frame.viewport.y);
}

// Pixels, current minus previous unjittered position, of the view-space point
// (w = 1) or direction at infinity (w = 0) `v`.
fn fx_camera_motion(v: vec4<f32>) -> vec4<f32> {
    let m = fx_to_pixel(fx_frame.proj_unjittered * v) - fx_to_pixel(fx_frame.reproject * v);
    return vec4<f32>(m, 0.0, 1.0);
}

// The AUX images of the pixel whose centre is `xy`.
fn fx_aux_a(xy: vec2<f32>) -> FxAuxA {
    let c = vec2<i32>(xy);
    let depth = textureLoad(fx_t_depth, c, 0);
    var out: FxAuxA;
    if depth >= 1.0 {
        let p = fx_view_position(xy, 1.0);
        out.depth = vec4<f32>(fx_frame.far, 0.0, 0.0, 0.0);
        out.normal = vec4<f32>(0.0);
        out.position = vec4<f32>(p, 0.0);
        out.motion = fx_camera_motion(vec4<f32>(p, 0.0));
        return out;
    }
    let p = fx_view_position(xy, depth);
    let g = textureLoad(fx_t_normal, c, 0);
    out.depth = vec4<f32>(-p.z, 0.0, 0.0, 0.0);
    out.normal = vec4<f32>(fx_decode_normal(g.xy), 1.0);
    out.position = vec4<f32>(p, 1.0);
    out.motion = fx_camera_motion(vec4<f32>(p, 1.0));
    return out;
}

@fragment
fn fx_fs_aux_a(@builtin(position) pos: vec4<f32>) -> FxAuxA {
    return fx_aux_a(pos.xy);
}

// The same resolve as a compute dispatch (src/render/light_compute.rs), where
// the adapter can store to the AUX images' formats.
@group(2) @binding(4) var fx_a_depth: texture_storage_2d<r32float, write>;
@group(2) @binding(5) var fx_a_normal: texture_storage_2d<rgba16float, write>;
@group(2) @binding(6) var fx_a_position: texture_storage_2d<rgba16float, write>;
@group(2) @binding(7) var fx_a_motion: texture_storage_2d<rg16float, write>;

@compute @workgroup_size(8, 8)
fn fx_cs_aux_a(@builtin(global_invocation_id) id: vec3<u32>) {
    if !fx_cs_inside(id) {
        return;
    }
    let a = fx_aux_a(vec2<f32>(id.xy) + 0.5);
    let c = vec2<i32>(id.xy);
    textureStore(fx_a_depth, c, a.depth);
    textureStore(fx_a_normal, c, a.normal);
    textureStore(fx_a_position, c, a.position);
    textureStore(fx_a_motion, c, a.motion);
}

struct FxAuxB {
    @location(0) albedo: vec4<f32>,
    // r = material id / 255, g = lighting model id / 255, b = roughness, a = 1
    @location(1) material: vec4<f32>,
    // mean specular reflectance F0
    @location(2) specular: vec4<f32>,
}

// The albedo, material and specular AUX images of the pixel whose centre is `xy`.
fn fx_aux_b(xy: vec2<f32>) -> FxAuxB {
    let c = vec2<i32>(xy);
    let depth = textureLoad(fx_t_depth, c, 0);
    var out: FxAuxB;
    if depth >= 1.0 {
        out.albedo = vec4<f32>(0.0);
        out.material = vec4<f32>(0.0);
        out.specular = vec4<f32>(0.0);
        return out;
    }
    let a = textureLoad(fx_t_albedo, c, 0);
    let sp = textureLoad(fx_t_specular, c, 0);
    out.albedo = vec4<f32>(a.rgb, 1.0);
    out.material = vec4<f32>(a.a, sp.a, textureLoad(fx_t_normal, c, 0).z, 1.0);
    out.specular = vec4<f32>(dot(sp.rgb, vec3<f32>(1.0 / 3.0)), 0.0, 0.0, 0.0);
    return out;
}

@fragment
fn fx_fs_aux_b(@builtin(position) pos: vec4<f32>) -> FxAuxB {
    return fx_aux_b(pos.xy);
}

// `fxgraph_srgb_encode` (linear -> sRGB, what an sRGB render target encodes)
// is appended to this module by src/render/material/template.rs, from
// `crate::shader::compute::SRGB_ENCODE`, the executor's compute paths' own: the
// compute resolve stores AUX.albedo through its raw `rgba8unorm` twin (a
// storage texture cannot be sRGB; src/render/targets.rs copies it into the sRGB
// image).

// The same as a compute dispatch (src/render/light_compute.rs), where the
// adapter can store to the images' formats (its own dispatch: a stage binds at
// most 4 storage textures by default).
@group(2) @binding(8) var fx_b_albedo: texture_storage_2d<rgba8unorm, write>;
@group(2) @binding(9) var fx_b_material: texture_storage_2d<rgba8unorm, write>;
@group(2) @binding(10) var fx_b_specular: texture_storage_2d<r16float, write>;

@compute @workgroup_size(8, 8)
fn fx_cs_aux_b(@builtin(global_invocation_id) id: vec3<u32>) {
    if !fx_cs_inside(id) {
        return;
    }
    let b = fx_aux_b(vec2<f32>(id.xy) + 0.5);
    let c = vec2<i32>(id.xy);
    textureStore(fx_b_albedo, c, fxgraph_srgb_encode(b.albedo));
    textureStore(fx_b_material, c, b.material);
    textureStore(fx_b_specular, c, b.specular);
}
