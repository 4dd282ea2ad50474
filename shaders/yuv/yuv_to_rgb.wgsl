// Y'CbCr planes to RGBA texels (src/gpu/yuv/to_rgb.rs), the GPU twin of
// src/io/yuv/to_rgb.rs: chroma interpolated vertically between the two rows of the
// luma row's tap (per frame or per field), upsampled across at the layout's siting,
// the matrix, then 8-bit sRGB-encoded codes or linear floats. One invocation per
// pixel; `yuv_params.wgsl` is prepended.

struct UpTap {
    i0: u32,
    i1: u32,
    w: f32,
    pad: u32,
};

@group(0) @binding(0) var<uniform> p: Params;
// The frame's planes as a y4m frame stores them: Y, Cb, Cr, packed in words.
@group(0) @binding(1) var<storage, read> planes: array<u32>;
// Per luma row: progressive taps, then per-field taps.
@group(0) @binding(2) var<storage, read> taps: array<UpTap>;
// The texels, `row_words` words per row, copied into the texture afterwards.
@group(0) @binding(3) var<storage, read_write> texels: array<u32>;

// The code of sample `i` (counted in samples from the start of the frame).
fn sample(i: u32) -> f32 {
    if p.bytes == 1u {
        return f32((planes[i >> 2u] >> ((i & 3u) * 8u)) & 0xffu);
    }
    return f32((planes[i >> 1u] >> ((i & 1u) * 16u)) & 0xffffu);
}

// Chroma column `c` of the plane starting at sample `base`, interpolated between
// the tap's rows: scaled and centred (`w0`, `w1` carry the scale).
fn column(base: u32, t: UpTap, c: u32, w0: f32, w1: f32, c0s: f32) -> f32 {
    let cw = p.chroma_width;
    return sample(base + t.i0 * cw + c) * w0 + sample(base + t.i1 * cw + c) * w1 - c0s;
}

// The chroma of luma column `x`: bilinear at the siting's positions, edges clamped.
fn upsampled(base: u32, t: UpTap, x: u32, w0: f32, w1: f32, c0s: f32) -> f32 {
    if p.h_siting == 0u {
        return column(base, t, x, w0, w1, c0s);
    }
    let last = p.chroma_width - 1u;
    let i = x / 2u;
    let c = column(base, t, i, w0, w1, c0s);
    let even = (x & 1u) == 0u;
    if p.h_siting == 1u {
        let j = select(min(i + 1u, last), max(i, 1u) - 1u, even);
        return 0.75 * c + 0.25 * column(base, t, j, w0, w1, c0s);
    }
    if even {
        return c;
    }
    return 0.5 * (c + column(base, t, min(i + 1u, last), w0, w1, c0s));
}

// sRGB-encoded to linear light: clipped to [0, 1] first, or extended past it.
fn decode(v: f32) -> f32 {
    var x = v;
    if p.clip == 1u {
        x = clamp(x, 0.0, 1.0);
    }
    if x <= 0.04045 {
        return x / 12.92;
    }
    return pow((x + 0.055) / 1.055, 2.4);
}

// An 8-bit code: rounded to nearest (ties to even), saturating.
fn code8(v: f32) -> u32 {
    return u32(round(clamp(v, 0.0, 255.0)));
}

fn store(x: u32, y: u32, rgb: vec3<f32>) {
    let o = y * p.row_words;
    if p.rgb == 0u {
        texels[o + x] = code8(rgb.r) | (code8(rgb.g) << 8u) | (code8(rgb.b) << 16u) | 0xff000000u;
        return;
    }
    let lin = vec3<f32>(decode(rgb.r), decode(rgb.g), decode(rgb.b));
    if p.rgb == 1u {
        texels[o + 2u * x] = pack2x16float(lin.rg);
        texels[o + 2u * x + 1u] = pack2x16float(vec2<f32>(lin.b, 1.0));
        return;
    }
    texels[o + 4u * x] = bitcast<u32>(lin.r);
    texels[o + 4u * x + 1u] = bitcast<u32>(lin.g);
    texels[o + 4u * x + 2u] = bitcast<u32>(lin.b);
    texels[o + 4u * x + 3u] = bitcast<u32>(1.0);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= p.width || id.y >= p.height {
        return;
    }
    // R'G'B' in units of `scale` (255 for codes, 1 for floats).
    let scale = select(1.0, 255.0, p.rgb == 0u);
    let ys = scale / p.y_scale;
    let y0s = -p.y_off * ys;
    let yv = sample(id.y * p.width + id.x) * ys + y0s;
    var rgb = vec3<f32>(yv);
    if p.chroma_width > 0u {
        let cs = scale / p.c_scale;
        let c0s = p.c_mid * cs;
        let t = taps[p.fields * p.height + id.y];
        let w0 = (1.0 - t.w) * cs;
        let w1 = t.w * cs;
        let ub = p.width * p.height;
        let vb = ub + p.chroma_width * p.chroma_height;
        let pb = upsampled(ub, t, id.x, w0, w1, c0s);
        let pr = upsampled(vb, t, id.x, w0, w1, c0s);
        rgb = vec3<f32>(yv + p.rv * pr, yv + p.gu * pb + p.gv * pr, yv + p.bu * pb);
    }
    store(id.x, id.y, rgb);
}
