// The standard surface: glTF 2.0 metallic-roughness with KHR_materials_specular's
// F0 colour, up to eight texture maps, vertex colours and tangent-space normal
// mapping. Every map is optional: it is sampled only under its `HAS_<MAP>` flag,
// set when the material binds it; without maps the surface is the constant
// colours below.
//
// Maps (colour maps marked @srgb are sampled through an sRGB view):
//   base_color_map          @srgb  rgb x base_color.rgb, a x base_color.a
//   normal_map              linear tangent-space normal (glTF convention: +Y
//                                  green = bitangent), xy x normal_scale; used
//                                  when the mesh has tangents (HAS_TANGENTS)
//   metallic_roughness_map  linear g x roughness, b x metallic (glTF packing)
//   occlusion_map           linear occlusion = 1 + occlusion_strength (r - 1)
//   emissive_map            @srgb  rgb x emissive
//   specular_map            @srgb  rgb x specular (the dielectric F0 colour)
//   opacity_map             linear r x alpha
//   detail_map              @srgb  base rgb x detail rgb x 2 (0.5 grey leaves the
//                                  base unchanged), sampled at uv x detail_scale
//   clearcoat_map           linear r x clearcoat          (KHR_materials_clearcoat)
//   clearcoat_roughness_map linear g x clearcoat_roughness
//   clearcoat_normal_map    linear the coat's tangent-space normal, xy x
//                                  clearcoat_normal_scale (without it the coat
//                                  follows the vertex normal, not normal_map)
//   transmission_map        linear r x transmission       (KHR_materials_transmission)
//
// Each map X has its texture transform (KHR_texture_transform): X_uv holds the
// 2x2 matrix (xy = first column, zw = second column), X_uv_offset.xy the offset
// and X_uv_offset.z the texture coordinate set (0 or 1):
//   uv = mat2x2(X_uv.xy, X_uv.zw) * uv_set + X_uv_offset.xy
//
// Output: diffuse = base.rgb (1 - metallic); specular = mix(specular, base.rgb,
// metallic) (F0: dielectrics reflect the specular colour, metals their base
// colour); roughness, alpha, normal, emission and occlusion as above. The vertex
// colour (HAS_VERTEX_COLOR) multiplies the base colour. The clear coat and the
// transmission are the engine's layers (docs/materials.md): this surface only
// reports them.

#include "lib/normal.wgsl"

struct SurfaceParams {
    base_color: vec4<f32>, // @default(1, 1, 1, 1) linear base colour and alpha (glTF baseColorFactor)
    emissive: vec3<f32>, // @default(0, 0, 0) emitted radiance (glTF emissiveFactor x emissive strength)
    metallic: f32, // @default(0) @range(0, 1) 0 dielectric, 1 metal
    specular: vec3<f32>, // @default(0.04, 0.04, 0.04) F0 of the dielectric part: 0.04 for an index of refraction of 1.5 (KHR_materials_ior/specular change it)
    roughness: f32, // @default(0.5) @range(0, 1) perceptual roughness
    normal_scale: f32, // @default(1) scale of the normal map's xy
    occlusion_strength: f32, // @default(1) @range(0, 1) how much the occlusion map darkens ambient light
    detail_scale: f32, // @default(8) @range(0.001, 1000) repeats of the detail map per base texture repeat
    base_color_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of base_color_map (columns xy, zw)
    base_color_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset (xy) and texture coordinate set (z) of base_color_map
    normal_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of normal_map
    normal_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of normal_map
    metallic_roughness_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of metallic_roughness_map
    metallic_roughness_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of metallic_roughness_map
    occlusion_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of occlusion_map
    occlusion_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of occlusion_map
    emissive_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of emissive_map
    emissive_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of emissive_map
    specular_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of specular_map
    specular_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of specular_map
    opacity_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of opacity_map
    opacity_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of opacity_map
    detail_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of detail_map
    detail_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of detail_map
    clearcoat: f32, // @default(0) @range(0, 1) strength of the clear coat (0: none)
    clearcoat_roughness: f32, // @default(0) @range(0, 1) perceptual roughness of the clear coat
    clearcoat_normal_scale: f32, // @default(1) scale of the clear coat normal map's xy
    transmission: f32, // @default(0) @range(0, 1) thin-walled transmission of the light entering the surface
    clearcoat_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of clearcoat_map
    clearcoat_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of clearcoat_map
    clearcoat_roughness_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of clearcoat_roughness_map
    clearcoat_roughness_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of clearcoat_roughness_map
    clearcoat_normal_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of clearcoat_normal_map
    clearcoat_normal_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of clearcoat_normal_map
    transmission_map_uv: vec4<f32>, // @default(1, 0, 0, 1) texture transform matrix of transmission_map
    transmission_map_uv_offset: vec4<f32>, // @default(0, 0, 0, 0) offset and coordinate set of transmission_map
}

@group(2) @binding(0) var<uniform> material: SurfaceParams;
@group(2) @binding(1) var material_sampler: sampler;
@group(2) @binding(2) var base_color_map: texture_2d<f32>; // @srgb base colour (rgb) and alpha (a)
@group(2) @binding(3) var normal_map: texture_2d<f32>; // tangent-space normal
@group(2) @binding(4) var metallic_roughness_map: texture_2d<f32>; // roughness (g), metallic (b)
@group(2) @binding(5) var occlusion_map: texture_2d<f32>; // ambient occlusion (r)
@group(2) @binding(6) var emissive_map: texture_2d<f32>; // @srgb emitted colour
@group(2) @binding(7) var specular_map: texture_2d<f32>; // @srgb specular (F0) colour
@group(2) @binding(8) var opacity_map: texture_2d<f32>; // opacity (r)
@group(2) @binding(9) var detail_map: texture_2d<f32>; // @srgb detail colour, 0.5 = neutral
@group(2) @binding(10) var clearcoat_map: texture_2d<f32>; // clear coat strength (r)
@group(2) @binding(11) var clearcoat_roughness_map: texture_2d<f32>; // clear coat roughness (g)
@group(2) @binding(12) var clearcoat_normal_map: texture_2d<f32>; // clear coat tangent-space normal
@group(2) @binding(13) var transmission_map: texture_2d<f32>; // transmission (r)

// The texture coordinates of a map: its coordinate set, transformed.
fn standard_uv(in: SurfaceInput, m: vec4<f32>, o: vec4<f32>) -> vec2<f32> {
    let coords = select(in.uv0, in.uv1, o.z > 0.5);
    return mat2x2<f32>(m.xy, m.zw) * coords + o.xy;
}

fn surface(in: SurfaceInput) -> SurfaceOutput {
    var base = material.base_color;
#ifdef HAS_VERTEX_COLOR
    base *= in.color;
#endif
#ifdef HAS_BASE_COLOR_MAP
    base *= textureSample(base_color_map, material_sampler,
        standard_uv(in, material.base_color_map_uv, material.base_color_map_uv_offset));
#endif
#ifdef HAS_DETAIL_MAP
    let detail_uv = standard_uv(in, material.detail_map_uv, material.detail_map_uv_offset);
    let detail = textureSample(detail_map, material_sampler, detail_uv * material.detail_scale);
    base = vec4<f32>(base.rgb * detail.rgb * 2.0, base.a);
#endif

    var metallic = material.metallic;
    var roughness = material.roughness;
#ifdef HAS_METALLIC_ROUGHNESS_MAP
    let mr = textureSample(metallic_roughness_map, material_sampler,
        standard_uv(in, material.metallic_roughness_map_uv, material.metallic_roughness_map_uv_offset));
    roughness *= mr.g;
    metallic *= mr.b;
#endif

    var specular = material.specular;
#ifdef HAS_SPECULAR_MAP
    specular *= textureSample(specular_map, material_sampler,
        standard_uv(in, material.specular_map_uv, material.specular_map_uv_offset)).rgb;
#endif

    var alpha = base.a;
#ifdef HAS_OPACITY_MAP
    alpha *= textureSample(opacity_map, material_sampler,
        standard_uv(in, material.opacity_map_uv, material.opacity_map_uv_offset)).r;
#endif

    var emission = material.emissive;
#ifdef HAS_EMISSIVE_MAP
    emission *= textureSample(emissive_map, material_sampler,
        standard_uv(in, material.emissive_map_uv, material.emissive_map_uv_offset)).rgb;
#endif

    var occlusion = 1.0;
#ifdef HAS_OCCLUSION_MAP
    let ao = textureSample(occlusion_map, material_sampler,
        standard_uv(in, material.occlusion_map_uv, material.occlusion_map_uv_offset)).r;
    occlusion = 1.0 + material.occlusion_strength * (ao - 1.0);
#endif

    var normal = in.normal;
#ifdef HAS_NORMAL_MAP
#ifdef HAS_TANGENTS
    let texel = textureSample(normal_map, material_sampler,
        standard_uv(in, material.normal_map_uv, material.normal_map_uv_offset)).xyz;
    // Back faces (double-sided): turn the whole tangent frame round with the normal.
    let tangent = select(in.tangent, -in.tangent, !in.front_facing);
    normal = perturb_normal(in.normal, tangent, unpack_normal(texel, material.normal_scale));
#endif
#endif

    var clearcoat = material.clearcoat;
#ifdef HAS_CLEARCOAT_MAP
    clearcoat *= textureSample(clearcoat_map, material_sampler,
        standard_uv(in, material.clearcoat_map_uv, material.clearcoat_map_uv_offset)).r;
#endif
    var clearcoat_roughness = material.clearcoat_roughness;
#ifdef HAS_CLEARCOAT_ROUGHNESS_MAP
    clearcoat_roughness *= textureSample(clearcoat_roughness_map, material_sampler,
        standard_uv(in, material.clearcoat_roughness_map_uv, material.clearcoat_roughness_map_uv_offset)).g;
#endif
    // zero: the engine uses the vertex normal
    var clearcoat_normal = vec3<f32>(0.0);
#ifdef HAS_CLEARCOAT_NORMAL_MAP
#ifdef HAS_TANGENTS
    let coat_texel = textureSample(clearcoat_normal_map, material_sampler,
        standard_uv(in, material.clearcoat_normal_map_uv, material.clearcoat_normal_map_uv_offset)).xyz;
    let coat_tangent = select(in.tangent, -in.tangent, !in.front_facing);
    clearcoat_normal = perturb_normal(in.normal, coat_tangent, unpack_normal(coat_texel, material.clearcoat_normal_scale));
#endif
#endif
    var transmission = material.transmission;
#ifdef HAS_TRANSMISSION_MAP
    transmission *= textureSample(transmission_map, material_sampler,
        standard_uv(in, material.transmission_map_uv, material.transmission_map_uv_offset)).r;
#endif

    metallic = clamp(metallic, 0.0, 1.0);
    var out: SurfaceOutput;
    out.diffuse = base.rgb * (1.0 - metallic);
    out.specular = mix(specular, base.rgb, metallic);
    out.roughness = clamp(roughness, 0.0, 1.0);
    out.alpha = alpha;
    out.normal = normal;
    out.emission = emission;
    out.occlusion = occlusion;
    out.clearcoat = clearcoat;
    out.clearcoat_roughness = clearcoat_roughness;
    out.clearcoat_normal = clearcoat_normal;
    out.transmission = transmission;
    return out;
}
