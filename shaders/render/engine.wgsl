// Engine part of every generated renderer shader: frame data, instances, lights,
// per-material data (group 0) and shared helpers. The host prepends
// `const NORMAL_ENCODING: u32 = N;` (0 octahedral, 1 spheremap).

// Fog (src/render/fog.rs; the maths of the `fog` effect, effects/fog.fx).
struct FxFog {
    color: vec3<f32>,
    density: f32,
    // the world's up direction in view space
    up: vec3<f32>,
    start: f32,
    end: f32,
    height_falloff: f32,
    fog_height: f32,
    camera_height: f32,
    // 0 none, 1 linear, 2 exponential, 3 exponential squared
    mode: u32,
    // 0 view-axis depth, 1 radial
    distance: u32,
    _p0: u32,
    _p1: u32,
}

struct FxFrame {
    view: mat4x4<f32>,
    // jittered when the frame is (docs/renderer.md, motion vectors)
    proj: mat4x4<f32>,
    inv_proj: mat4x4<f32>,
    // the unjittered projection, and view space -> the previous frame's
    // unjittered clip space: the motion vectors of the resolve pass
    proj_unjittered: mat4x4<f32>,
    reproject: mat4x4<f32>,
    // width, height, 1 / width, 1 / height
    viewport: vec4<f32>,
    background: vec4<f32>,
    // sum of the scene's ambient lights (rgb), applied as diffuse × occlusion
    ambient: vec4<f32>,
    near: f32,
    far: f32,
    // entries of `fx_visible` the forward loop reads (run-time-branching mode)
    light_count: u32,
    // global (directional) lights at the start of `fx_cluster_lights`
    global_lights: u32,
    // tiles x, tiles y, depth slices, tile size in pixels (0: no cluster lists)
    cluster: vec4<u32>,
    // x = slices / ln(far / near), y = near of the slices (the geometry's depth
    // range, not the camera's)
    cluster_z: vec4<f32>,
    fog: FxFog,
}

// FxInstance: instance.wgsl (appended).

// Per material: what the engine needs outside the surface shader.
struct FxMaterialInfo {
    // lighting model id (index into the scene's lighting shaders)
    model: u32,
    alpha_cutoff: f32,
    _p0: u32,
    _p1: u32,
}

// A light in view space.
struct FxLight {
    position: vec3<f32>,
    // distance where the attenuation reaches the threshold (shading cut-off)
    radius: f32,
    // colour × intensity
    color: vec3<f32>,
    kind: u32,
    // the direction the light travels
    direction: vec3<f32>,
    // sphere proxy scale (circumscribes the true sphere)
    volume_scale: f32,
    // a, b, c of 1 / (a + b d + c d^2)
    atten: vec3<f32>,
    cos_outer: f32,
    cos_inner: f32,
    // base radius of the cone proxy
    cone_radius: f32,
    // 0 full screen, 1 sphere, 2 cone
    volume: u32,
    // KHR_lights_punctual range (0: none): window clamp(1 - (d / range)^4, 0, 1)
    range: f32,
    // shadow maps (shadow.wgsl): first layer, layer count (0: unshadowed) and
    // filter (1 hard, 2 PCF)
    shadow_first: u32,
    shadow_count: u32,
    shadow_filter: u32,
    // (the host's: whether the light may cast shadows)
    casts_shadows: u32,
}

const FX_KIND_DIRECTIONAL: u32 = 1u;
const FX_KIND_POINT: u32 = 2u;
const FX_KIND_SPOT: u32 = 3u;

@group(0) @binding(0) var<uniform> fx_frame: FxFrame;
@group(0) @binding(1) var<storage, read> fx_materials: array<FxMaterialInfo>;
@group(0) @binding(2) var<storage, read> fx_instances: array<FxInstance>;
@group(0) @binding(3) var<storage, read> fx_lights: array<FxLight>;
@group(0) @binding(4) var<storage, read> fx_visible: array<u32>;
// (offset, count) of each cluster's lights in `fx_cluster_lights`
@group(0) @binding(5) var<storage, read> fx_cluster_ranges: array<vec2<u32>>;
// global lights, then every cluster's light indices
@group(0) @binding(6) var<storage, read> fx_cluster_lights: array<u32>;

// The cluster of the pixel at `frag_xy` with view depth `depth` (positive), as
// src/render/clusters.rs bins them: tiles of cluster.w pixels, slices spaced
// exponentially from near to far.
fn fx_cluster_range(frag_xy: vec2<f32>, depth: f32) -> vec2<u32> {
    let g = fx_frame.cluster;
    let tx = min(u32(frag_xy.x) / g.w, g.x - 1u);
    let ty = min(u32(frag_xy.y) / g.w, g.y - 1u);
    let s = floor(log(max(depth, fx_frame.cluster_z.y) / fx_frame.cluster_z.y) * fx_frame.cluster_z.x);
    let slice = min(u32(max(s, 0.0)), g.z - 1u);
    return fx_cluster_ranges[(slice * g.y + ty) * g.x + tx];
}

fn fx_safe_normalize(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if l > 1e-20 {
        return v / l;
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}

// Unit normal -> [0,1]^2 (src/render/normal.rs has the same maths on the CPU).
fn fx_encode_normal(n: vec3<f32>) -> vec2<f32> {
    if NORMAL_ENCODING == 1u {
        // Tang et al., table 3 (spheremap / Lambert azimuthal equal-area)
        let d = sqrt(max(n.z * 8.0 + 8.0, 1e-12));
        return clamp(n.xy / d + 0.5, vec2<f32>(0.0), vec2<f32>(1.0));
    }
    var p = n.xy / max(abs(n.x) + abs(n.y) + abs(n.z), 1e-20);
    if n.z < 0.0 {
        let s = select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
        p = (vec2<f32>(1.0) - abs(p.yx)) * s;
    }
    return p * 0.5 + 0.5;
}

fn fx_decode_normal(e: vec2<f32>) -> vec3<f32> {
    if NORMAL_ENCODING == 1u {
        let fenc = e * 4.0 - 2.0;
        let f = dot(fenc, fenc);
        let g = sqrt(max(1.0 - f / 4.0, 0.0));
        return fx_safe_normalize(vec3<f32>(fenc * g, 1.0 - f / 2.0));
    }
    let f = e * 2.0 - 1.0;
    var n = vec3<f32>(f, 1.0 - abs(f.x) - abs(f.y));
    let t = clamp(-n.z, 0.0, 1.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return fx_safe_normalize(n);
}

// View-space position of the pixel at `frag_xy` (pixel coordinates) with depth
// buffer value `depth`, through the inverse projection.
fn fx_view_position(frag_xy: vec2<f32>, depth: f32) -> vec3<f32> {
    let uv = frag_xy * fx_frame.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let p = fx_frame.inv_proj * ndc;
    return p.xyz / p.w;
}

struct FxLightSample {
    // unit direction towards the light
    dir: vec3<f32>,
    // illuminance on a surface facing the light
    light: vec3<f32>,
    // false: the point is outside the light's reach
    lit: bool,
}

// Direction and illuminance of light `l` at view-space point `p`: inverse-square
// style falloff 1 / (a + b d + c d^2) cut at the volume radius, the
// KHR_lights_punctual range window and spot cone (t^2, as the extension).
fn fx_light_sample(l: FxLight, p: vec3<f32>) -> FxLightSample {
    var out = FxLightSample(-l.direction, l.color, true);
    if l.kind == FX_KIND_DIRECTIONAL {
        return out;
    }
    let to_light = l.position - p;
    let d = length(to_light);
    if d >= l.radius {
        out.lit = false;
        out.light = vec3<f32>(0.0);
        return out;
    }
    out.dir = to_light / max(d, 1e-6);
    let dc = max(d, 1e-3);
    var f = 1.0 / max(l.atten.x + l.atten.y * dc + l.atten.z * dc * dc, 1e-12);
    if l.range > 0.0 {
        let q = d / l.range;
        f *= clamp(1.0 - q * q * q * q, 0.0, 1.0);
    }
    if l.kind == FX_KIND_SPOT {
        let t = clamp((dot(-out.dir, l.direction) - l.cos_outer) / max(l.cos_inner - l.cos_outer, 1e-4), 0.0, 1.0);
        f *= t * t;
    }
    out.light = l.color * f;
    return out;
}

// (1 - exp(-x)) / x, the mean of exp(-x t) over t in [0, 1]; 1 at x = 0.
fn fx_fog_mean_exp(x: f32) -> f32 {
    if abs(x) < 1e-3 {
        return 1.0 - x * (0.5 - x / 6.0);
    }
    return (1.0 - exp(-x)) / x;
}

// Colour `c` of the surface at view-space point `p` seen through the frame's
// fog: transmittance f of the (height-weighted) distance, mix(fog colour, c, f).
fn fx_fog(c: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let fog = fx_frame.fog;
    if fog.mode == 0u {
        return c;
    }
    var dist = select(-p.z, length(p), fog.distance == 1u);
    if fog.height_falloff > 0.0 {
        let k = fog.height_falloff;
        dist *= exp(-k * (fog.camera_height - fog.fog_height)) * fx_fog_mean_exp(k * dot(p, fog.up));
    }
    var f: f32;
    switch fog.mode {
        case 1u: {
            f = clamp((fog.end - dist) / max(fog.end - fog.start, 1e-20), 0.0, 1.0);
        }
        case 2u: {
            f = exp(-fog.density * dist);
        }
        default: {
            let x = fog.density * dist;
            f = exp(-x * x);
        }
    }
    return mix(fog.color, c, f);
}

// Full-screen triangle for vertex 0, 1, 2 (depth 0).
fn fx_fullscreen_pos(vi: u32) -> vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}
