// Visibility buffer, raster half (src/render/visibility.rs): depth and, per
// pixel, the instance slot and the triangle drawn there (no surface shader).
// The clip position is computed exactly as geometry.wgsl's `fx_geometry_vertex`
// does (`@invariant`): the fallback G-buffer draws and the motion pass test
// depth against it. instance.wgsl (FxInstance) is appended.
enable primitive_index;

// The start of FxFrame (engine.wgsl): the view and the jittered projection.
struct FxVisFrame {
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> fx_frame: FxVisFrame;
@group(0) @binding(2) var<storage, read> fx_instances: array<FxInstance>;

struct FxVisOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) @interpolate(flat) slot: u32,
}

@vertex
fn fx_vs_visibility(@location(0) position: vec3<f32>, @builtin(instance_index) ii: u32) -> FxVisOut {
    let inst = fx_instances[ii];
    let wp = inst.model * vec4<f32>(position, 1.0);
    let vp = fx_frame.view * wp;
    var out: FxVisOut;
    out.clip = fx_frame.proj * vp;
    out.slot = ii;
    return out;
}

// x: the instance slot; y: the triangle within the draw (Vulkan and D3D count
// it from 0 for each instance of an instanced draw).
@fragment
fn fx_fs_visibility(in: FxVisOut, @builtin(primitive_index) triangle: u32) -> @location(0) vec2<u32> {
    return vec2<u32>(in.slot, triangle);
}
