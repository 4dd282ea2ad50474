// The viewer's image pass: draws the shown texture ("after") and, left of the
// split, the effect's input ("before") into the window's image area.
//
// Values (per side, `mode`):
//   0 codes:  8-bit textures read through their raw view: the stored codes, shown
//             as they are (the bytes a file gets; exact at 1:1 on a unorm surface)
//   1 colour: linear light (float textures, sRGB textures without a raw view),
//             times `exposure`, clamped to [0, 1] and sRGB-encoded (channels above
//             1 are marked when flag 1 is set)
//   2 data:   (v - lo) / (hi - lo), clamped, shown as codes (depth, normals,
//             motion, single-channel masks)
// Channels: 1 -> grey, 2 -> red/green, 4 -> RGB (alpha not shown).
// Magnified (flag 2) images are read texel by texel (nearest); minified ones
// average up to 4x4 texels of the footprint, so no format needs to be filterable.

struct View {
    rect: vec4<f32>,
    split: f32,
    exposure: f32,
    lo: f32,
    hi: f32,
    after_mode: u32,
    before_mode: u32,
    after_channels: u32,
    before_channels: u32,
    flags: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var after_tex: texture_2d<f32>;
@group(0) @binding(1) var before_tex: texture_2d<f32>;
@group(0) @binding(2) var<uniform> view: View;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i & 2u) * 2 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

fn srgb_decode(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

// The texel value at `uv` in [0, 1]^2 (nearest, or a box over the footprint).
fn fetch(t: texture_2d<f32>, uv: vec2<f32>) -> vec4<f32> {
    let size = vec2<f32>(textureDimensions(t));
    let p = uv * size;
    if (view.flags & 2u) != 0u {
        let c = clamp(vec2<i32>(floor(p)), vec2<i32>(0), vec2<i32>(size) - 1);
        return textureLoad(t, c, 0);
    }
    // Texels per screen pixel, per axis; at most 4x4 taps.
    let footprint = size / view.rect.zw;
    let n = vec2<i32>(clamp(ceil(footprint), vec2<f32>(1.0), vec2<f32>(4.0)));
    var sum = vec4<f32>(0.0);
    for (var j = 0; j < n.y; j++) {
        for (var i = 0; i < n.x; i++) {
            let q = p + (vec2<f32>(f32(i), f32(j)) + 0.5) / vec2<f32>(n) * footprint
                - footprint * 0.5;
            let c = clamp(vec2<i32>(floor(q)), vec2<i32>(0), vec2<i32>(size) - 1);
            sum += textureLoad(t, c, 0);
        }
    }
    return sum / f32(n.x * n.y);
}

fn expand(v: vec4<f32>, channels: u32) -> vec3<f32> {
    if channels == 1u {
        return vec3<f32>(v.r);
    }
    if channels == 2u {
        return vec3<f32>(v.r, v.g, 0.0);
    }
    return v.rgb;
}

// The display code (0..1, what the screen shows) of a value.
fn shade(v: vec4<f32>, mode: u32, channels: u32, pixel: vec2<f32>) -> vec3<f32> {
    let c = expand(v, channels);
    if mode == 0u {
        return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    if mode == 2u {
        return clamp((c - view.lo) / max(view.hi - view.lo, 1e-20), vec3<f32>(0.0), vec3<f32>(1.0));
    }
    let x = c * view.exposure;
    var code = srgb_encode(clamp(x, vec3<f32>(0.0), vec3<f32>(1.0)));
    if (view.flags & 1u) != 0u && any(x > vec3<f32>(1.0)) {
        // Diagonal stripes over clipped pixels.
        let stripe = (i32(floor((pixel.x + pixel.y) / 4.0)) & 1) == 0;
        code = select(vec3<f32>(0.0), vec3<f32>(1.0, 0.0, 1.0), stripe);
    }
    return code;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let uv = (pos.xy - view.rect.xy) / view.rect.zw;
    var code: vec3<f32>;
    if any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0)) {
        // Outside the image: the window's background (the frame's clear colour).
        code = vec3<f32>(0.02);
    } else if uv.x < view.split {
        code = shade(fetch(before_tex, uv), view.before_mode, view.before_channels, pos.xy);
    } else {
        code = shade(fetch(after_tex, uv), view.after_mode, view.after_channels, pos.xy);
    }
    if view.split > 0.0 && view.split < 1.0 && abs(pos.x - (view.rect.x + view.split * view.rect.z)) < 1.0 {
        code = vec3<f32>(1.0, 0.8, 0.0);
    }
    // Flag 4: the surface is sRGB (it encodes what we write): write linear light.
    if (view.flags & 4u) != 0u {
        return vec4<f32>(srgb_decode(code), 1.0);
    }
    return vec4<f32>(code, 1.0);
}
