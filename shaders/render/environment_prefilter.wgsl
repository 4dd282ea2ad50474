// Prefiltering an environment map on the GPU (src/render/environment/prefilter.rs
// runs these passes once per map; dfg.rs the table once per renderer):
//
// 1. fs_equirect: the equirectangular map (u = 0.5 + atan2(d.z, d.x) / 2pi,
//    v = acos(d.y) / pi) resampled into the faces of the source cube map.
// 2. fs_downsample: each mip level of the source cube the mean of 2x2 texels of
//    the level above (a box filter), for the filtered importance sampling.
// 3. fs_filter: the GGX-prefiltered specular levels: importance sampling with
//    Hammersley points and filtered importance sampling (Krivanek and Colbert,
//    "Real-time shading with filtered importance sampling", EGSR 2008), the
//    samples and their source levels computed once per level by prefilter.rs
//    (`lobe_samples`). The GGX lobe is taken with n = v = r (the split sum's
//    assumption), each sample weighted by the BRDF's f cos / pdf there, G1(l)
//    (`smith_g1`; the Khronos glTF Sample Viewer and Filament weight by n.l,
//    which narrows rough lobes: issue 29).
// 3b. fs_convolve: the same lobes summed over every texel of the map made into
//    a 16x16 cube on the CPU (1536 texels, each its direction, solid angle and
//    mean radiance), normalised by the sum of the weights: no noise, for the
//    wide lobes (irradiance, roughness >= 0.75), where 5.6-degree texels are
//    much finer than the lobe.
// 4. fs_dfg: the split-sum table: for n.v (x) and perceptual roughness (y),
//    A = integral of (1 - Fc) f cos / F and B = integral of Fc f cos / F, with
//    Fc = (1 - v.h)^5, so that the specular albedo under Schlick's Fresnel is
//    F0 A + B (Karis 2013); f is the glTF BRDF's specular term (GGX, height-
//    correlated Smith visibility, alpha = roughness^2).

struct Prefilter {
    face: u32,
    // 0 GGX, 1 cosine (irradiance)
    distribution: u32,
    samples: u32,
    _p0: u32,
    // side of the source cube's level 0, in texels
    source_size: f32,
    roughness: f32,
    // side of the level being written
    size: f32,
    // the source's last mip level
    max_lod: f32,
}

@group(0) @binding(0) var<uniform> pf: Prefilter;
@group(0) @binding(1) var equirect: texture_2d<f32>;
@group(0) @binding(2) var source: texture_cube<f32>;
@group(0) @binding(3) var level_above: texture_2d<f32>;
// linear, mipmapped; repeats across u (the equirectangular map's seam)
@group(0) @binding(4) var lin: sampler;
// fs_convolve's source: the map as a small cube (prefilter.rs `cube_texels`):
// each texel's unit direction and solid angle, and its mean radiance
struct CubeTexel {
    dir_omega: vec4<f32>,
    radiance: vec4<f32>,
}
@group(0) @binding(7) var<storage, read> cube_texels: array<CubeTexel>;
// fs_filter's samples in the tangent frame of the texel's direction (xyz, z
// along it) and the source level each reads (w): the same for every texel, so
// prefilter.rs computes them once per level
@group(0) @binding(6) var<storage, read> lobe: array<vec4<f32>>;

const PI: f32 = 3.14159265358979;

@vertex
fn vs_fullscreen(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}

// The direction of texel position `uv` (0..1, v down the rows) on cube face
// `face`, as the Vulkan / WebGPU cube face selection table reads it
// (+X, -X, +Y, -Y, +Z, -Z; sc, tc = 2 uv - 1).
fn face_direction(face: u32, uv: vec2<f32>) -> vec3<f32> {
    let s = uv.x * 2.0 - 1.0;
    let t = uv.y * 2.0 - 1.0;
    var d: vec3<f32>;
    switch face {
        case 0u: { d = vec3<f32>(1.0, -t, -s); }
        case 1u: { d = vec3<f32>(-1.0, -t, s); }
        case 2u: { d = vec3<f32>(s, 1.0, t); }
        case 3u: { d = vec3<f32>(s, -1.0, -t); }
        case 4u: { d = vec3<f32>(s, -t, 1.0); }
        default: { d = vec3<f32>(-s, -t, -1.0); }
    }
    return normalize(d);
}

fn texel_direction(pos: vec2<f32>) -> vec3<f32> {
    return face_direction(pf.face, pos / pf.size);
}

@fragment
fn fs_equirect(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let d = texel_direction(pos.xy);
    let uv = vec2<f32>(0.5 + atan2(d.z, d.x) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
    return vec4<f32>(textureSampleLevel(equirect, lin, uv, 0.0).rgb, 1.0);
}

@fragment
fn fs_downsample(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = vec2<i32>(pos.xy) * 2;
    let s = textureLoad(level_above, c, 0) + textureLoad(level_above, c + vec2<i32>(1, 0), 0)
        + textureLoad(level_above, c + vec2<i32>(0, 1), 0) + textureLoad(level_above, c + vec2<i32>(1, 1), 0);
    return vec4<f32>(s.rgb * 0.25, 1.0);
}

// The i-th of n Hammersley points.
fn hammersley(i: u32, n: u32) -> vec2<f32> {
    return vec2<f32>(f32(i) / f32(n), f32(reverseBits(i)) * 2.3283064365386963e-10);
}

// A tangent frame with `n` as its z axis.
fn frame(n: vec3<f32>) -> mat3x3<f32> {
    let up = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), abs(n.z) < 0.999);
    let t = normalize(cross(up, n));
    return mat3x3<f32>(t, cross(n, t), n);
}

fn d_ggx(ndh: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = ndh * ndh * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Smith's masking G1 of GGX (height-correlated G2 at n = v, where Lambda(v) = 0)
// for a direction at cosine `c` from the normal: with the split sum's n = v =
// r, the glTF BRDF's f cos over a solid angle of l is D(h) G1(l) / 4, so this,
// not n.l, is the weight of the lobe's radiance.
fn smith_g1(c: f32, alpha: f32) -> f32 {
    let c2 = max(c * c, 1e-8);
    let a2 = alpha * alpha;
    return 2.0 / (1.0 + sqrt(1.0 + a2 * (1.0 - c2) / c2));
}

// The GGX half vector of sample xi (local frame, z = normal).
fn ggx_half(xi: vec2<f32>, alpha: f32) -> vec3<f32> {
    let a2 = alpha * alpha;
    let cos_t = sqrt(max((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y), 0.0));
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let phi = 2.0 * PI * xi.x;
    return vec3<f32>(sin_t * cos(phi), sin_t * sin(phi), cos_t);
}

@fragment
fn fs_filter(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let tbn = frame(texel_direction(pos.xy));
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    let count = arrayLength(&lobe);
    for (var i = 0u; i < count; i++) {
        let s = lobe[i];
        // GGX samples are weighted by f cos / pdf = G1(l) (cosine samples by 1,
        // their z ignored)
        let w = select(1.0, smith_g1(s.z, max(pf.roughness * pf.roughness, 1e-3)), pf.distribution == 0u);
        sum += textureSampleLevel(source, lin, tbn * s.xyz, s.w).rgb * w;
        weight += w;
    }
    return vec4<f32>(sum / max(weight, 1e-12), 1.0);
}

@fragment
fn fs_convolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let n = texel_direction(pos.xy);
    let alpha = max(pf.roughness * pf.roughness, 1e-3);
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    let count = arrayLength(&cube_texels);
    for (var i = 0u; i < count; i++) {
        let t = cube_texels[i];
        let l = t.dir_omega.xyz;
        let ndl = dot(n, l);
        if ndl <= 0.0 {
            continue;
        }
        var w = t.dir_omega.w;
        if pf.distribution == 0u {
            w *= d_ggx(dot(n, normalize(n + l)), alpha) * smith_g1(ndl, alpha);
        } else {
            w *= ndl;
        }
        sum += t.radiance.rgb * w;
        weight += w;
    }
    return vec4<f32>(sum / max(weight, 1e-30), 1.0);
}

fn v_smith_correlated(ndv: f32, ndl: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = ndl * sqrt(ndv * ndv * (1.0 - a2) + a2);
    let gl = ndv * sqrt(ndl * ndl * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-12);
}

@fragment
fn fs_dfg(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let ndv = pos.x / pf.size;
    let roughness = pos.y / pf.size;
    let alpha = max(roughness * roughness, 1e-3);
    let v = vec3<f32>(sqrt(1.0 - ndv * ndv), 0.0, ndv);
    var a = 0.0;
    var b = 0.0;
    for (var i = 0u; i < pf.samples; i++) {
        let h = ggx_half(hammersley(i, pf.samples), alpha);
        let vdh = dot(v, h);
        let l = 2.0 * vdh * h - v;
        if l.z > 0.0 && vdh > 0.0 {
            // f cos / pdf, with pdf = D (n.h) / (4 v.h): 4 V (v.h) (n.l) / (n.h)
            let g = 4.0 * v_smith_correlated(ndv, l.z, alpha) * vdh * l.z / max(h.z, 1e-12);
            let fc = pow(clamp(1.0 - vdh, 0.0, 1.0), 5.0);
            a += (1.0 - fc) * g;
            b += fc * g;
        }
    }
    let n = f32(pf.samples);
    return vec4<f32>(a / n, b / n, 0.0, 1.0);
}
