// Motion vectors (AUX.motion) of the instances that moved: the screen-space
// displacement in pixels of the surface seen at each pixel, current minus
// previous position, x right, y down (a pixel at p was at p - motion one frame
// earlier). Both positions come from the cameras' *unjittered* projections, so
// the sub-pixel jitter never shows.
//
// The resolve pass (fx_fs_aux_a, light.wgsl) has written the camera motion of a
// still world for every pixel; vs_object / fs_object draw the moved instances
// again with depth test EQUAL against the frame's depth, so only their visible
// fragments overwrite it. The clip position repeats the geometry template's
// expression exactly (@invariant), so the depths match bit for bit.

struct MotionFrame {
    // as the geometry passes (jittered projection)
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    // unjittered view-projection of this frame and of the previous one
    curr_vp: mat4x4<f32>,
    prev_vp: mat4x4<f32>,
    // width, height, 1 / width, 1 / height
    viewport: vec4<f32>,
}

@group(0) @binding(0) var<uniform> mf: MotionFrame;
@group(0) @binding(1) var<storage, read> fx_instances: array<FxInstance>;
@group(0) @binding(2) var<storage, read> prev_models: array<mat4x4<f32>>;

// Clip position -> pixel position (x right, y down, pixel centres at .5).
fn to_pixel(clip: vec4<f32>) -> vec2<f32> {
    let ndc = clip.xy / clip.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * mf.viewport.x, (0.5 - ndc.y * 0.5) * mf.viewport.y);
}

struct ObjectOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) curr: vec4<f32>,
    @location(1) prev: vec4<f32>,
}

@vertex
fn vs_object(
    @location(0) position: vec3<f32>,
    @location(1) prev_position: vec3<f32>,
    @builtin(instance_index) ii: u32,
) -> ObjectOut {
    let inst = fx_instances[ii];
    // exactly as fx_vs_geometry (geometry.wgsl)
    let wp = inst.model * vec4<f32>(position, 1.0);
    let vp = mf.view * wp;
    var out: ObjectOut;
    out.clip = mf.proj * vp;
    out.curr = mf.curr_vp * wp;
    out.prev = mf.prev_vp * (prev_models[ii] * vec4<f32>(prev_position, 1.0));
    return out;
}

@fragment
fn fs_object(in: ObjectOut) -> @location(0) vec4<f32> {
    return vec4<f32>(to_pixel(in.curr) - to_pixel(in.prev), 0.0, 1.0);
}
