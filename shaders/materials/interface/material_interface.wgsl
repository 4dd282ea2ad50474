// The types every material shader sees (fxgraph appends this file to each surface
// and lighting shader; do not declare these names yourself). Identifiers that
// start with `fx_` are reserved for the engine.
//
// Spaces: "view" space has the camera at the origin looking down -Z (+Y up);
// "world" space is the scene's (+Y up, right-handed). Colours are linear RGB.

// What the engine knows about the fragment being shaded.
struct SurfaceInput {
    // view-space position of the fragment
    view_position: vec3<f32>,
    // world-space position of the fragment
    world_position: vec3<f32>,
    // unit interpolated vertex normal, view space; on the back face of a
    // double-sided material it is flipped to face the viewer
    normal: vec3<f32>,
    // the same normal in world space (flipped alike)
    world_normal: vec3<f32>,
    // view-space unit tangent (xyz) and bitangent sign (w = +1 or -1);
    // w = 0 when the mesh has neither tangents nor texture coordinates
    tangent: vec4<f32>,
    // texture coordinates, sets 0 and 1 (0 where the mesh has none)
    uv0: vec2<f32>,
    uv1: vec2<f32>,
    // linear vertex colour (1, 1, 1, 1 where the mesh has none)
    color: vec4<f32>,
    // the fragment belongs to a front face
    front_facing: bool,
    // rotates world-space directions into view space (the camera's rotation)
    view_from_world: mat3x3<f32>,
}

// What a surface shader computes (the paper's "diffuse and specular colour,
// transparency, normal, emission", plus roughness and ambient occlusion).
struct SurfaceOutput {
    // diffuse reflectance (albedo), linear; metals have none
    diffuse: vec3<f32>,
    // specular reflectance at normal incidence (F0), linear
    specular: vec3<f32>,
    // perceptual roughness 0 (mirror) .. 1 (rough), as in glTF
    roughness: f32,
    // coverage 0..1 (alpha modes: mask discards below the cut-off, blend blends)
    alpha: f32,
    // unit shading normal, view space
    normal: vec3<f32>,
    // emitted radiance, linear (added as is)
    emission: vec3<f32>,
    // ambient occlusion 0..1: scales ambient and environment light only
    occlusion: f32,
    // Optional layers (0 when a shader leaves them unset: `var out: SurfaceOutput;`
    // starts zeroed). A clear coat over the surface (KHR_materials_clearcoat):
    // its strength 0..1, perceptual roughness and unit view-space normal (a zero
    // vector means the interpolated vertex normal, without normal mapping).
    clearcoat: f32,
    clearcoat_roughness: f32,
    clearcoat_normal: vec3<f32>,
    // thin-walled transmission 0..1 (KHR_materials_transmission): the fraction of
    // the light entering the surface that passes through it, tinted by `diffuse`,
    // instead of being diffusely reflected
    transmission: f32,
}

// One light as a lighting shader sees it.
struct LightingInput {
    // unit shading normal, view space
    normal: vec3<f32>,
    // unit direction from the surface towards the eye
    view_dir: vec3<f32>,
    // unit direction from the surface towards the light
    light_dir: vec3<f32>,
    // illuminance of the light on a surface facing it: colour x intensity x
    // distance and cone attenuation (lux for glTF lights); not yet multiplied by
    // the cosine of the incidence angle
    light: vec3<f32>,
    // the surface's specular reflectance F0 and perceptual roughness
    specular: vec3<f32>,
    roughness: f32,
}

// A lighting shader's answer for one light.
struct LightingOutput {
    // reflected radiance before the diffuse colour: the engine multiplies it by
    // SurfaceOutput.diffuse (e.g. Lambert: light * max(n.l, 0) / pi)
    diffuse: vec3<f32>,
    // reflected specular radiance, added as is (Fresnel and F0 included)
    specular: vec3<f32>,
}

// What the environment gives a surface (image-based lighting), for a lighting
// shader's optional `fn environment(in: EnvironmentInput) -> LightingOutput`
// (or with `params: LightingParams`), which replaces the engine's environment
// term for its materials.
struct EnvironmentInput {
    // unit shading normal and direction towards the eye, view space
    normal: vec3<f32>,
    view_dir: vec3<f32>,
    // the surface's F0, perceptual roughness and ambient occlusion
    specular: vec3<f32>,
    roughness: f32,
    occlusion: f32,
    // cosine-weighted mean radiance about the normal (irradiance / pi), times
    // the environment's intensity
    irradiance: vec3<f32>,
    // the radiance of the specular lobe of `roughness` at this n.v: the lobe
    // model's weighted reads of the GGX-prefiltered map about the lobe's
    // dominant direction (environment.wgsl, fx_env_prefiltered), times the
    // intensity
    prefiltered: vec3<f32>,
    // the split-sum terms A, B: the specular albedo of the glTF BRDF (Schlick
    // Fresnel, GGX, height-correlated Smith) for this n.v and roughness is
    // specular * dfg.x + dfg.y
    dfg: vec2<f32>,
}

const FX_PI: f32 = 3.14159265358979;
