
// One drawn instance (gpu_types.rs `GpuInstance`), shared by the surface passes
// (engine.wgsl) and the shadow depth pass (shadow_depth.wgsl): appended to both.
struct FxInstance {
    model: mat4x4<f32>,
    // inverse transpose of `model`
    normal: mat4x4<f32>,
    material: u32,
    _p0: u32,
    _p1: u32,
    _p2: u32,
}
