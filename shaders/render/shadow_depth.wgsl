// Shadow-map depth pass: positions only, one render pass per layer; the layer's
// world -> light clip matrix comes at a dynamic offset of `fx_shadow_pass`.
// (Standalone: no surface shader runs, so MASK materials cast as opaque.)

struct FxShadowPass {
    clip_from_world: mat4x4<f32>,
}

// FxInstance: instance.wgsl (appended).

@group(0) @binding(0) var<uniform> fx_shadow_pass: FxShadowPass;
@group(0) @binding(1) var<storage, read> fx_instances: array<FxInstance>;

@vertex
fn fx_vs_shadow(@location(0) position: vec3<f32>, @builtin(instance_index) ii: u32) -> @builtin(position) vec4<f32> {
    return fx_shadow_pass.clip_from_world * (fx_instances[ii].model * vec4<f32>(position, 1.0));
}
