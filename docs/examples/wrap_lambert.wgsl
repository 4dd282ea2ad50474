// A user's lighting shader (docs/materials.md): "wrap" diffuse lighting, which
// lets light reach past the terminator (soft, skin-like falloff), normalised so a
// surface facing the light reflects what Lambert would at wrap = 0.

struct LightingParams {
    wrap: f32, // @default(0.3) @range(0, 1) how far light wraps past the terminator
}

fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput {
    let w = params.wrap;
    let d = max((dot(in.normal, in.light_dir) + w) / ((1.0 + w) * (1.0 + w)), 0.0);
    return LightingOutput(in.light * (d / FX_PI), vec3<f32>(0.0));
}
