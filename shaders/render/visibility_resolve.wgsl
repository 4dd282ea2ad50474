// Visibility buffer, material resolve (src/render/visibility.rs): appended to a
// material variant's geometry module (geometry.wgsl, its surface shader with
// `textureSample` turned into `fx_vis_sample`, and the interface types). One
// invocation per pixel rebuilds the fragment the G-buffer pass would have
// shaded: the triangle the raster half stored, the barycentrics of the ray
// through the pixel centre (perspective-correct: the ray meets the view-space
// triangle), and its corners interpolated and transformed by
// `fx_geometry_vertex`; then it writes the G-buffer pass's outputs. The host
// prepends `const FX_VIS_GRADIENTS: bool = ...;` (the surface samples
// textures). SRGB_ENCODE (`fxgraph_srgb_encode`) is appended.

struct FxVisSlot {
    first_index: u32,
    base_vertex: i32,
    // the resolve dispatch (material and mesh features) of the slot
    group: u32,
    // bit 0: clockwise triangles are the front faces (a mirroring transform)
    flags: u32,
}

struct FxVisDispatch {
    // the dispatch's tile list (visibility_classify.wgsl)
    group: u32,
    // 1: the clearing dispatch, over the tiles with a pixel nothing was
    // resolved at (it clears those pixels only)
    clear: u32,
    _p0: u32,
    _p1: u32,
}

@group(1) @binding(2) var fx_vis_ids: texture_2d<u32>;
@group(1) @binding(3) var<storage, read> fx_vis_vertices: array<f32>;
@group(1) @binding(4) var<storage, read> fx_vis_indices: array<u32>;
@group(1) @binding(5) var<storage, read> fx_vis_slots: array<FxVisSlot>;
@group(1) @binding(6) var<uniform> fx_vis_dispatch: FxVisDispatch;
// the sRGB targets through raw twins (copied in afterwards), the normal and
// the light the G-buffer pass starts with as they are
@group(1) @binding(7) var fx_vis_albedo: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(8) var fx_vis_normal: texture_storage_2d<rgb10a2unorm, write>;
@group(1) @binding(9) var fx_vis_specular: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(10) var fx_vis_light: texture_storage_2d<rgba16float, write>;
// the classification's tile lists and their lengths
@group(1) @binding(11) var<storage, read> fx_vis_tiles: array<u32>;
@group(1) @binding(12) var<storage, read> fx_vis_counts: array<u32>;

const FX_VIS_NONE: u32 = 0xffffffffu;
// f32 words per vertex (gpu_types.rs `Vertex`, 72 bytes)
const FX_VIS_STRIDE: u32 = 18u;
// texture reads per surface given their own gradients; later ones read level 0
const FX_VIS_SAMPLES: u32 = 16u;

// Gradients of the surface's texture coordinates: the surface runs first at
// the pixel one to the right (mode 1) and one below (mode 2), on the plane of
// the same triangle, recording the coordinates of each read in call order; the
// shading run (mode 0) samples with their differences, as a 2x2 quad of
// fragments differences them.
var<private> fx_vis_mode: u32;
var<private> fx_vis_k: u32;
var<private> fx_vis_dx: array<vec2<f32>, FX_VIS_SAMPLES>;
var<private> fx_vis_dy: array<vec2<f32>, FX_VIS_SAMPLES>;

fn fx_vis_sample(t: texture_2d<f32>, s: sampler, uv: vec2<f32>) -> vec4<f32> {
    let k = fx_vis_k;
    fx_vis_k = k + 1u;
    if k >= FX_VIS_SAMPLES {
        return textureSampleLevel(t, s, uv, 0.0);
    }
    if fx_vis_mode == 1u {
        fx_vis_dx[k] = uv;
        return vec4<f32>(0.0);
    }
    if fx_vis_mode == 2u {
        fx_vis_dy[k] = uv;
        return vec4<f32>(0.0);
    }
    return textureSampleGrad(t, s, uv, fx_vis_dx[k] - uv, fx_vis_dy[k] - uv);
}

fn fx_vis_v2(b: u32) -> vec2<f32> {
    return vec2<f32>(fx_vis_vertices[b], fx_vis_vertices[b + 1u]);
}

fn fx_vis_v3(b: u32) -> vec3<f32> {
    return vec3<f32>(fx_vis_vertices[b], fx_vis_vertices[b + 1u], fx_vis_vertices[b + 2u]);
}

fn fx_vis_v4(b: u32) -> vec4<f32> {
    return vec4<f32>(fx_vis_v3(b), fx_vis_vertices[b + 3u]);
}

// Corner `vertex` of the triangle, as the vertex buffer holds it.
fn fx_vis_corner(vertex: u32) -> FxVsIn {
    let b = vertex * FX_VIS_STRIDE;
    var v: FxVsIn;
    v.position = fx_vis_v3(b);
    v.normal = fx_vis_v3(b + 3u);
    v.uv0 = fx_vis_v2(b + 6u);
    v.uv1 = fx_vis_v2(b + 8u);
    v.tangent = fx_vis_v4(b + 10u);
    v.color = fx_vis_v4(b + 14u);
    return v;
}

// The view-space position of corner `v` of instance `inst` (as
// fx_geometry_vertex computes it).
fn fx_vis_view_pos(inst: FxInstance, v: FxVsIn) -> vec3<f32> {
    return (fx_frame.view * (inst.model * vec4<f32>(v.position, 1.0))).xyz;
}

// The view-space ray through framebuffer point `xy`: origin and direction
// (through the inverse of the jittered projection: perspective or orthographic).
struct FxVisRay {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

fn fx_vis_ray(xy: vec2<f32>) -> FxVisRay {
    let ndc = vec2<f32>(xy.x * 2.0 * fx_frame.viewport.z - 1.0, 1.0 - xy.y * 2.0 * fx_frame.viewport.w);
    let a = fx_frame.inv_proj * vec4<f32>(ndc, 0.0, 1.0);
    let b = fx_frame.inv_proj * vec4<f32>(ndc, 0.5, 1.0);
    let o = a.xyz / a.w;
    return FxVisRay(o, b.xyz / b.w - o);
}

// Barycentrics of the point where `ray` meets the plane of p0 p1 p2
// (Möller and Trumbore), outside the triangle too (a neighbour's gradients).
fn fx_vis_barycentrics(ray: FxVisRay, p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> vec3<f32> {
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let pv = cross(ray.dir, e2);
    let det = dot(e1, pv);
    if abs(det) < 1e-30 {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let inv = 1.0 / det;
    let tv = ray.origin - p0;
    let u = dot(tv, pv) * inv;
    let v = dot(ray.dir, cross(tv, e1)) * inv;
    return vec3<f32>(1.0 - u - v, u, v);
}

// The fragment at barycentrics `w` of corners a, b, c of instance slot
// `slot`; `xy` its framebuffer position. The vertex stage's transforms are
// linear in its inputs, so the corners are interpolated first and transformed
// once (what the rasteriser interpolates, up to rounding).
fn fx_vis_fragment(a: FxVsIn, b: FxVsIn, c: FxVsIn, w: vec3<f32>, slot: u32, xy: vec2<f32>) -> FxVsOut {
    var v: FxVsIn;
    v.position = a.position * w.x + b.position * w.y + c.position * w.z;
    v.normal = a.normal * w.x + b.normal * w.y + c.normal * w.z;
    v.uv0 = a.uv0 * w.x + b.uv0 * w.y + c.uv0 * w.z;
    v.uv1 = a.uv1 * w.x + b.uv1 * w.y + c.uv1 * w.z;
    v.tangent = a.tangent * w.x + b.tangent * w.y + c.tangent * w.z;
    v.color = a.color * w.x + b.color * w.y + c.color * w.z;
    var f = fx_geometry_vertex(v, slot);
    f.clip = vec4<f32>(xy, 0.0, 1.0);
    return f;
}

fn fx_vis_store(c: vec2<i32>, albedo: vec4<f32>, normal: vec4<f32>, specular: vec4<f32>, light: vec4<f32>) {
    textureStore(fx_vis_albedo, c, fxgraph_srgb_encode(albedo));
    textureStore(fx_vis_normal, c, normal);
    textureStore(fx_vis_specular, c, fxgraph_srgb_encode(specular));
    textureStore(fx_vis_light, c, light);
}

// One 8 x 8 tile of the dispatch's list per workgroup (65535 a row).
@compute @workgroup_size(8, 8)
fn fx_cs_visibility_resolve(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
) {
    let list = fx_vis_dispatch.group;
    let k = wg.y * 65535u + wg.x;
    if k >= fx_vis_counts[list] {
        return;
    }
    let size = textureDimensions(fx_vis_ids);
    let tiles_x = (size.x + 7u) / 8u;
    let tile = fx_vis_tiles[list * tiles_x * ((size.y + 7u) / 8u) + k];
    let gid = vec2<u32>(tile % tiles_x, tile / tiles_x) * 8u + lid.xy;
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let c = vec2<i32>(gid);
    let id = textureLoad(fx_vis_ids, c, 0).xy;
    if fx_vis_dispatch.clear != 0u {
        // nothing resolved here: the G-buffer pass's clear (its fallback
        // draws, if any, come afterwards)
        if id.x == FX_VIS_NONE {
            let zero = vec4<f32>(0.0);
            fx_vis_store(c, zero, zero, zero, zero);
        }
        return;
    }
    if id.x == FX_VIS_NONE {
        return;
    }
    let slot = fx_vis_slots[id.x];
    if slot.group != list {
        return;
    }
    let first = slot.first_index + 3u * id.y;
    let a = fx_vis_corner(u32(i32(fx_vis_indices[first]) + slot.base_vertex));
    let b = fx_vis_corner(u32(i32(fx_vis_indices[first + 1u]) + slot.base_vertex));
    let cc = fx_vis_corner(u32(i32(fx_vis_indices[first + 2u]) + slot.base_vertex));
    let inst = fx_instances[id.x];
    let p0 = fx_vis_view_pos(inst, a);
    let p1 = fx_vis_view_pos(inst, b);
    let p2 = fx_vis_view_pos(inst, cc);
    let xy = vec2<f32>(gid.xy) + 0.5;
    let ray = fx_vis_ray(xy);
    // counter-clockwise on screen: the geometric normal faces the eye
    let ccw = dot(cross(p1 - p0, p2 - p0), ray.dir) < 0.0;
    let front = ccw != ((slot.flags & 1u) != 0u);
    if FX_VIS_GRADIENTS {
        for (var m = 1u; m <= 2u; m++) {
            let nxy = xy + select(vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), m == 1u);
            let w = fx_vis_barycentrics(fx_vis_ray(nxy), p0, p1, p2);
            fx_vis_mode = m;
            fx_vis_k = 0u;
            _ = fx_surface(fx_vis_fragment(a, b, cc, w, id.x, nxy), front);
        }
        fx_vis_mode = 0u;
        fx_vis_k = 0u;
    }
    let w = fx_vis_barycentrics(ray, p0, p1, p2);
    let f = fx_vis_fragment(a, b, cc, w, id.x, xy);
    let s = fx_surface(f, front);
    // fx_fs_gbuffer's outputs (layered and MASK materials are not resolved here)
    fx_vis_store(
        c,
        vec4<f32>(s.diffuse, f32(f.material) / 255.0),
        vec4<f32>(fx_encode_normal(s.normal), s.roughness, 1.0),
        vec4<f32>(s.specular, f32(fx_materials[f.material].model) / 255.0),
        vec4<f32>(fx_unlit_local(s), s.occlusion),
    );
}
