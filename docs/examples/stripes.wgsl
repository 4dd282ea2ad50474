// A user's surface shader (docs/materials.md): horizontal stripes in world space,
// two colours, so it needs no texture coordinates.

struct SurfaceParams {
    color_a: vec4<f32>, // @default(0.9, 0.9, 0.85, 1) first stripe colour (linear)
    color_b: vec4<f32>, // @default(0.1, 0.3, 0.6, 1) second stripe colour (linear)
    width: f32, // @default(0.25) @range(0.001, 100) stripe width in world units
    roughness: f32, // @default(0.5) @range(0, 1) perceptual roughness
}

@group(2) @binding(0) var<uniform> params: SurfaceParams;

fn surface(in: SurfaceInput) -> SurfaceOutput {
    let t = fract(in.world_position.y / (2.0 * params.width));
    let c = select(params.color_b, params.color_a, t < 0.5);
    var out: SurfaceOutput;
    out.diffuse = c.rgb;
    out.specular = vec3<f32>(0.04);
    out.roughness = params.roughness;
    out.alpha = c.a;
    out.normal = in.normal;
    out.emission = vec3<f32>(0.0);
    out.occlusion = 1.0;
    return out;
}
