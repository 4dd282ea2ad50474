// Triplanar: world-space projection for meshes without texture coordinates
// (terrain, rocks, procedural geometry). Each map is projected along the three
// world axes and the three samples are blended by the world normal:
//
//   weights = |world_normal|^sharpness, normalised to sum 1
//   uv      = world position / scale, on the plane across each axis
//
// The projections are oriented so a face seen from outside shows its texture the
// right way round (not mirrored, "up" along +Y on the side faces).
//
// Maps (both optional; without them the surface is a plain colour):
//   base_color_map  @srgb  rgb x base_color.rgb, a x base_color.a
//   normal_map      linear tangent-space normal (glTF convention), xy x
//                          normal_scale; the three projected normals are blended
//                          with the "whiteout" blend (UDN-like: the surface normal's
//                          tangent-plane part is added to the map's, the z parts
//                          multiplied) in world space, then rotated to view space
//                          with in.view_from_world
//
// Output: diffuse = base.rgb (1 - metallic); specular = mix(specular, base.rgb,
// metallic); roughness; alpha = base.a; no emission; occlusion 1.

struct SurfaceParams {
    base_color: vec4<f32>, // @default(1, 1, 1, 1) linear base colour and alpha
    specular: vec3<f32>, // @default(0.04, 0.04, 0.04) F0 of the dielectric part
    metallic: f32, // @default(0) @range(0, 1) 0 dielectric, 1 metal
    roughness: f32, // @default(0.5) @range(0, 1) perceptual roughness
    scale: f32, // @default(1) @range(0.0001, 100000) world units per texture repeat
    sharpness: f32, // @default(4) @range(1, 64) blend sharpness: higher narrows the seams between projections
    normal_scale: f32, // @default(1) scale of the normal map's xy
}

@group(2) @binding(0) var<uniform> material: SurfaceParams;
@group(2) @binding(1) var material_sampler: sampler;
@group(2) @binding(2) var base_color_map: texture_2d<f32>; // @srgb base colour (rgb) and alpha (a)
@group(2) @binding(3) var normal_map: texture_2d<f32>; // tangent-space normal

// The three projections at a point: per axis, the texture coordinates and the
// world-space tangent (direction of +u) and bitangent (glTF +Y: decreasing v).
struct TriplanarFrame {
    uv_x: vec2<f32>,
    uv_y: vec2<f32>,
    uv_z: vec2<f32>,
    t_x: vec3<f32>,
    t_y: vec3<f32>,
    t_z: vec3<f32>,
    b_x: vec3<f32>,
    b_y: vec3<f32>,
    b_z: vec3<f32>,
    weights: vec3<f32>,
}

fn triplanar_frame(p: vec3<f32>, n: vec3<f32>) -> TriplanarFrame {
    // The side of each axis the normal is on (+1 for 0), to un-mirror the far side.
    let s = select(vec3<f32>(-1.0), vec3<f32>(1.0), n >= vec3<f32>(0.0));
    var f: TriplanarFrame;
    // u = p.t, v = -(p.b); (t, b, axis * s) is right-handed on every face.
    f.t_x = vec3<f32>(0.0, 0.0, -s.x);
    f.b_x = vec3<f32>(0.0, 1.0, 0.0);
    f.t_y = vec3<f32>(s.y, 0.0, 0.0);
    f.b_y = vec3<f32>(0.0, 0.0, -1.0);
    f.t_z = vec3<f32>(s.z, 0.0, 0.0);
    f.b_z = vec3<f32>(0.0, 1.0, 0.0);
    f.uv_x = vec2<f32>(dot(p, f.t_x), -dot(p, f.b_x));
    f.uv_y = vec2<f32>(dot(p, f.t_y), -dot(p, f.b_y));
    f.uv_z = vec2<f32>(dot(p, f.t_z), -dot(p, f.b_z));
    let w = pow(abs(n), vec3<f32>(material.sharpness));
    f.weights = w / max(w.x + w.y + w.z, 1e-20);
    return f;
}

// Whiteout blend of one projection: the map's normal `ts` on the plane across
// `axis`, with the surface normal `n` in that plane's frame (t, b, axis), back
// in world space. A flat map gives `n` exactly.
fn triplanar_whiteout(ts: vec3<f32>, n: vec3<f32>, t: vec3<f32>, b: vec3<f32>, axis: vec3<f32>) -> vec3<f32> {
    let xy = ts.xy + vec2<f32>(dot(n, t), dot(n, b));
    let z = abs(ts.z) * dot(n, axis);
    return t * xy.x + b * xy.y + axis * z;
}

fn surface(in: SurfaceInput) -> SurfaceOutput {
    let n = normalize(in.world_normal);
    let f = triplanar_frame(in.world_position / material.scale, n);
    var base = material.base_color;
#ifdef HAS_BASE_COLOR_MAP
    let cx = textureSample(base_color_map, material_sampler, f.uv_x);
    let cy = textureSample(base_color_map, material_sampler, f.uv_y);
    let cz = textureSample(base_color_map, material_sampler, f.uv_z);
    base *= cx * f.weights.x + cy * f.weights.y + cz * f.weights.z;
#endif
    var normal = in.normal;
#ifdef HAS_NORMAL_MAP
    let k = material.normal_scale;
    let tx = textureSample(normal_map, material_sampler, f.uv_x).xyz * 2.0 - vec3<f32>(1.0);
    let ty = textureSample(normal_map, material_sampler, f.uv_y).xyz * 2.0 - vec3<f32>(1.0);
    let tz = textureSample(normal_map, material_sampler, f.uv_z).xyz * 2.0 - vec3<f32>(1.0);
    let wx = triplanar_whiteout(vec3<f32>(tx.xy * k, tx.z), n, f.t_x, f.b_x, vec3<f32>(1.0, 0.0, 0.0));
    let wy = triplanar_whiteout(vec3<f32>(ty.xy * k, ty.z), n, f.t_y, f.b_y, vec3<f32>(0.0, 1.0, 0.0));
    let wz = triplanar_whiteout(vec3<f32>(tz.xy * k, tz.z), n, f.t_z, f.b_z, vec3<f32>(0.0, 0.0, 1.0));
    let world = wx * f.weights.x + wy * f.weights.y + wz * f.weights.z;
    let len2 = dot(world, world);
    normal = select(in.normal, normalize(in.view_from_world * world), len2 > 1e-12);
#endif
    let metallic = clamp(material.metallic, 0.0, 1.0);
    var out: SurfaceOutput;
    out.diffuse = base.rgb * (1.0 - metallic);
    out.specular = mix(material.specular, base.rgb, metallic);
    out.roughness = clamp(material.roughness, 0.0, 1.0);
    out.alpha = base.a;
    out.normal = normal;
    out.emission = vec3<f32>(0.0);
    out.occlusion = 1.0;
    return out;
}
