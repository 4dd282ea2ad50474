// Motion vectors (AUX.motion): the screen-space displacement in pixels of the
// surface seen at each pixel, current minus previous position, x right, y down
// (a pixel at p was at p - motion one frame earlier). Both positions come from
// the cameras' *unjittered* projections, so the sub-pixel jitter never shows.
//
// 1. fs_camera (full screen): every pixel as if the world stood still: the
//    point reconstructed from the depth buffer (through the jittered
//    projection it was drawn with), projected by the previous and the current
//    camera. Pixels without geometry are directions at infinity (w = 0), moved
//    only by the camera's rotation.
// 2. vs_object / fs_object: the instances that moved (or deform) drawn again
//    with depth test EQUAL against the frame's depth, so only their visible
//    fragments overwrite step 1. The clip position repeats the geometry
//    template's expression exactly (@invariant), so the depths match bit for bit.

struct MotionFrame {
    // as the geometry passes (jittered projection)
    view: mat4x4<f32>,
    proj: mat4x4<f32>,
    // unjittered view-projection of this frame and of the previous one
    curr_vp: mat4x4<f32>,
    prev_vp: mat4x4<f32>,
    // inverse of proj * view (jittered): depth buffer -> world
    inv_vp: mat4x4<f32>,
    // world-space eye position (w = 1)
    eye: vec4<f32>,
    // width, height, 1 / width, 1 / height
    viewport: vec4<f32>,
}

@group(0) @binding(0) var<uniform> mf: MotionFrame;
@group(0) @binding(1) var<storage, read> fx_instances: array<FxInstance>;
@group(0) @binding(2) var<storage, read> prev_models: array<mat4x4<f32>>;
@group(1) @binding(0) var depth_tex: texture_depth_2d;

// Clip position -> pixel position (x right, y down, pixel centres at .5).
fn to_pixel(clip: vec4<f32>) -> vec2<f32> {
    let ndc = clip.xy / clip.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * mf.viewport.x, (0.5 - ndc.y * 0.5) * mf.viewport.y);
}

fn motion_of(x: vec4<f32>, prev_x: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(to_pixel(mf.curr_vp * x) - to_pixel(mf.prev_vp * prev_x), 0.0, 1.0);
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0), 0.0, 1.0);
}

@fragment
fn fs_camera(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let d = textureLoad(depth_tex, vec2<i32>(pos.xy), 0);
    let ndc = vec2<f32>(pos.x * mf.viewport.z * 2.0 - 1.0, 1.0 - pos.y * mf.viewport.w * 2.0);
    if d >= 1.0 {
        // no geometry: the direction through the pixel, at infinity
        let far = mf.inv_vp * vec4<f32>(ndc, 1.0, 1.0);
        let dir = vec4<f32>(far.xyz / far.w - mf.eye.xyz, 0.0);
        return motion_of(dir, dir);
    }
    let w = mf.inv_vp * vec4<f32>(ndc, d, 1.0);
    let x = vec4<f32>(w.xyz / w.w, 1.0);
    return motion_of(x, x);
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
