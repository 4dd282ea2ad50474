// Shared by every renderer shader. The host prepends
// `const NORMAL_ENCODING: u32 = N;` (0 octahedral, 1 spheremap).

struct Frame {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    inv_proj: mat4x4<f32>,
    // width, height, 1 / width, 1 / height
    viewport: vec4<f32>,
    background: vec4<f32>,
    near: f32,
    far: f32,
    // number of entries of `visible` the forward loop reads
    light_count: u32,
    _pad: u32,
}

struct Material {
    base_color: vec4<f32>,
    emissive: vec3<f32>,
    specular: f32,
    shininess: f32,
    alpha_cutoff: f32,
    normal_scale: f32,
    flags: u32,
    roughness: f32,
    metallic: f32,
    _pad0: f32,
    _pad1: f32,
}

struct Instance {
    model: mat4x4<f32>,
    // inverse transpose of `model`
    normal: mat4x4<f32>,
    material: u32,
    _p0: u32,
    _p1: u32,
    _p2: u32,
}

// A light in view space.
struct Light {
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
    _pad: u32,
}

const KIND_AMBIENT: u32 = 0u;
const KIND_DIRECTIONAL: u32 = 1u;
const KIND_POINT: u32 = 2u;
const KIND_SPOT: u32 = 3u;

const FLAG_MASK: u32 = 1u;
const FLAG_BLEND: u32 = 2u;
const FLAG_DOUBLE_SIDED: u32 = 4u;
const FLAG_NORMAL_MAP: u32 = 8u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> materials: array<Material>;
@group(0) @binding(2) var<storage, read> instances: array<Instance>;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
@group(0) @binding(4) var<storage, read> visible: array<u32>;

fn safe_normalize(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if l > 1e-20 {
        return v / l;
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}

// Unit normal -> [0,1]^2 (see src/deferred/normal.rs for the same maths on the CPU).
fn encode_normal(n: vec3<f32>) -> vec2<f32> {
    if NORMAL_ENCODING == 1u {
        // seed 001, table 3 (spheremap / Lambert azimuthal equal-area)
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

fn decode_normal(e: vec2<f32>) -> vec3<f32> {
    if NORMAL_ENCODING == 1u {
        let fenc = e * 4.0 - 2.0;
        let f = dot(fenc, fenc);
        let g = sqrt(max(1.0 - f / 4.0, 0.0));
        return safe_normalize(vec3<f32>(fenc * g, 1.0 - f / 2.0));
    }
    let f = e * 2.0 - 1.0;
    var n = vec3<f32>(f, 1.0 - abs(f.x) - abs(f.y));
    let t = clamp(-n.z, 0.0, 1.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return safe_normalize(n);
}

// View-space position of the pixel at `frag_xy` (pixel coordinates) with depth
// buffer value `depth`, through the inverse projection.
fn view_position(frag_xy: vec2<f32>, depth: f32) -> vec3<f32> {
    let uv = frag_xy * frame.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let p = frame.inv_proj * ndc;
    return p.xyz / p.w;
}

struct Lit {
    diffuse: vec3<f32>,
    // not yet multiplied by k_s
    specular: vec3<f32>,
}

// Blinn-Phong, seed 001 eq. (8): f · L · (max(l·n, 0) + k_s max(h·n, 0)^α);
// ambient returns L_a as "diffuse" (composition multiplies by the albedo).
fn shade(l: Light, p: vec3<f32>, n: vec3<f32>, v: vec3<f32>, shininess: f32) -> Lit {
    var out = Lit(vec3<f32>(0.0), vec3<f32>(0.0));
    if l.kind == KIND_AMBIENT {
        out.diffuse = l.color;
        return out;
    }
    var dir = -l.direction;
    var f = 1.0;
    if l.kind != KIND_DIRECTIONAL {
        let to_light = l.position - p;
        let d = length(to_light);
        if d >= l.radius {
            return out;
        }
        dir = to_light / max(d, 1e-6);
        f = 1.0 / (l.atten.x + l.atten.y * d + l.atten.z * d * d);
        if l.kind == KIND_SPOT {
            f *= smoothstep(l.cos_outer, l.cos_inner, dot(-dir, l.direction));
        }
    }
    let ndl = dot(n, dir);
    if ndl <= 0.0 {
        return out;
    }
    out.diffuse = l.color * (f * ndl);
    let h = safe_normalize(dir + v);
    out.specular = l.color * (f * pow(max(dot(h, n), 0.0), shininess));
    return out;
}

// Full-screen triangle for vertex 0, 1, 2 (depth 0).
fn fullscreen_pos(vi: u32) -> vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}
