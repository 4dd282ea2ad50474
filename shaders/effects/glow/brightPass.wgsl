// brightPass: keeps what is brighter than `threshold` (in linear light), with a
// soft knee so the cut-off does not band. Used by `glow` and `bloom`.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    threshold: f32, // @default(0.4) @range(0, 1000) luminance above which light glows
    knee: f32,      // @default(0.3) @range(0, 10) width of the soft transition
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let c = textureSampleLevel(img, img_sampler, uv, 0.0);
    let luma = dot(c.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
    // Quadratic soft knee around the threshold, linear above it.
    let k = max(params.knee, 1e-5);
    let soft = clamp(luma - params.threshold + k, 0.0, 2.0 * k);
    let contribution = max(soft * soft / (4.0 * k), luma - params.threshold);
    let scale = max(contribution, 0.0) / max(luma, 1e-5);
    return vec4<f32>(c.rgb * scale, c.a);
}
