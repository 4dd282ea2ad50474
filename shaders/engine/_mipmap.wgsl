// Built-in: one level of a mip chain, drawn from the level above it (`src`,
// a view of that one level). Each texel is the bilinear sample of `src` at the
// texel's centre, clamped at the edges: what Vulkan's vkCmdBlitImage with a
// linear filter gives (librashader's and RetroArch's mip chains). Where a side
// halves exactly, that is the mean of 2 x 2 texels: a box filter.
@group(0) @binding(0) var src: texture_2d<f32>;

fn texel(p: vec2<i32>, size: vec2<i32>) -> vec4<f32> {
    return textureLoad(src, clamp(p, vec2<i32>(0), size - 1), 0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(src));
    let dst = max(size / 2, vec2<i32>(1));
    // The destination texel's centre in source texels, from the first centre.
    let p = pos.xy * vec2<f32>(size) / vec2<f32>(dst) - 0.5;
    let f = floor(p);
    let t = p - f;
    let i = vec2<i32>(f);
    let top = mix(texel(i, size), texel(i + vec2<i32>(1, 0), size), t.x);
    let bottom = mix(texel(i + vec2<i32>(0, 1), size), texel(i + vec2<i32>(1, 1), size), t.x);
    return mix(top, bottom, t.y);
}
