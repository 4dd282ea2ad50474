// RGBA texels to Y'CbCr planes (src/gpu/yuv/from_rgb.rs), the GPU twin of
// src/io/yuv/from_rgb.rs: the matrix, chroma downsampled across at the layout's
// siting and down the rows of the chroma row's taps (per frame or per field),
// rounded to codes of the stream's depth. One invocation per word of the frame as
// a y4m frame stores it (Y, Cb, Cr); `yuv_params.wgsl` is prepended.

struct DownTap {
    r0: u32,
    r1: u32,
    r2: u32,
    pad: u32,
    w0: f32,
    w1: f32,
    w2: f32,
    pad2: f32,
};

@group(0) @binding(0) var<uniform> p: Params;
// The effect's output: 8-bit sRGB-encoded codes through a raw view, or linear floats.
@group(0) @binding(1) var rgba: texture_2d<f32>;
// Per chroma row: progressive taps, then per-field taps.
@group(0) @binding(2) var<storage, read> taps: array<DownTap>;
@group(0) @binding(3) var<storage, read_write> frame: array<u32>;

fn nan0(v: f32) -> f32 {
    return select(v, 0.0, v != v);
}

// Linear light to sRGB-encoded: clipped to [0, 1] first (NaN as 0), or extended.
fn encode(v: f32) -> f32 {
    var x = v;
    if p.clip == 1u {
        x = min(max(nan0(x), 0.0), 1.0);
    }
    if x <= 0.0031308 {
        return x * 12.92;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

fn rgb_prime(x: u32, y: u32) -> vec3<f32> {
    let c = textureLoad(rgba, vec2<i32>(i32(x), i32(y)), 0).rgb;
    if p.rgb == 0u {
        return c;
    }
    return vec3<f32>(encode(c.r), encode(c.g), encode(c.b));
}

// A code of the stream's depth: rounded to nearest (ties to even), saturating, NaN 0.
fn code(v: f32) -> u32 {
    return u32(round(clamp(nan0(v), 0.0, p.max_code)));
}

fn luma(x: u32, y: u32) -> f32 {
    let c = rgb_prime(x, y);
    return p.y_off + p.y_scale * (p.kr * c.r + p.kg * c.g + p.kb * c.b);
}

// Pb (plane 0) or Pr (plane 1) of one pixel, in codes, without the offset.
fn chroma_pixel(x: u32, y: u32, plane: u32) -> f32 {
    let c = rgb_prime(x, y);
    let yl = p.kr * c.r + p.kg * c.g + p.kb * c.b;
    if plane == 0u {
        return p.c_scale * (0.5 / (1.0 - p.kb)) * (c.b - yl);
    }
    return p.c_scale * (0.5 / (1.0 - p.kr)) * (c.r - yl);
}

// Row `y` downsampled across to chroma column `cx`: a 2-tap box for chroma between
// columns, [1 2 1]/4 for co-sited chroma, edges clamped.
fn across(cx: u32, y: u32, plane: u32) -> f32 {
    if p.h_siting == 0u {
        return chroma_pixel(cx, y, plane);
    }
    let last = p.width - 1u;
    let x = 2u * cx;
    if p.h_siting == 1u {
        if x + 1u > last {
            return chroma_pixel(last, y, plane);
        }
        return 0.5 * (chroma_pixel(x, y, plane) + chroma_pixel(x + 1u, y, plane));
    }
    let a = chroma_pixel(max(x, 1u) - 1u, y, plane);
    let b = chroma_pixel(x, y, plane);
    let c = chroma_pixel(min(x + 1u, last), y, plane);
    return 0.25 * a + 0.5 * b + 0.25 * c;
}

fn chroma(cx: u32, cy: u32, plane: u32) -> f32 {
    let t = taps[p.fields * p.chroma_height + cy];
    var v = p.c_mid + t.w0 * across(cx, t.r0, plane);
    if t.w1 != 0.0 {
        v += t.w1 * across(cx, t.r1, plane);
    }
    if t.w2 != 0.0 {
        v += t.w2 * across(cx, t.r2, plane);
    }
    return v;
}

// The code of sample `s` (counted in samples from the start of the frame); 0 past
// the last plane (the padding of the last word).
fn sample_code(s: u32) -> u32 {
    let ny = p.width * p.height;
    if s < ny {
        return code(luma(s % p.width, s / p.width));
    }
    let nc = p.chroma_width * p.chroma_height;
    let i = s - ny;
    if nc == 0u || i >= 2u * nc {
        return 0u;
    }
    let j = i % nc;
    return code(chroma(j % p.chroma_width, j / p.chroma_width, i / nc));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let word = id.x + id.y * p.groups_x;
    if word >= p.words {
        return;
    }
    let per = 4u / p.bytes;
    var out = 0u;
    for (var k = 0u; k < per; k++) {
        out |= sample_code(word * per + k) << (k * 8u * p.bytes);
    }
    frame[word] = out;
}
