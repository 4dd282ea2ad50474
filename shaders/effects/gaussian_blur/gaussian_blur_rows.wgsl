// gaussian_blur_rows: the horizontal pass of a separable Gaussian blur as a
// compute pass (docs/shaders.md, "Compute passes"). Used by `gaussian_blur` and
// `sharpen`.
//
// A workgroup of 256 invocations blurs 256 pixels of one row. It first copies
// the row segment they read, 256 + 2r texels (the border replicated), into
// workgroup memory, so each texel is fetched from the texture once per
// workgroup instead of 2r + 1 times, then each invocation sums its taps there.
//
// The maths is gaussian_blur.wgsl's with EXACT = 1: radius r = (ksize - 1) / 2,
// ksize = round(6 sigma + 1) | 1 (OpenCV's rule for 8-bit images), weights
// w(i) = exp(-i^2 / (2 sigma^2)) by products, normalised; the weighted
// differences from the centre are summed, so a flat area stays exactly flat.
//
// `fs_main` is the same blur as a fragment pass (one textureLoad per tap), drawn
// where the compute pass cannot run (docs/shaders.md, "Compute passes": an
// adapter that cannot store to rgba16float, a pass of another format). Same
// texels, weights and order: the two agree to f32 rounding.

const TILE: i32 = 256;
// sigma <= 128 (the effects' range): r <= (round(6 * 128 + 1) | 1 - 1) / 2 = 384.
const MAX_R: i32 = 384;

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(3) var out: texture_storage_2d<rgba16float, write>;

struct Params {
    sigma: f32, // @default(2) @range(0.1, 128) standard deviation in pixels
    img_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

// TILE + 2 MAX_R texels of the row: 16 KiB, the WebGPU default limit.
var<workgroup> row: array<vec4<f32>, 1024>;

fn radius(sigma: f32) -> i32 {
    // WGSL round() rounds half to even, like OpenCV's cvRound.
    let ksize = i32(round(sigma * 6.0 + 1.0)) | 1;
    return min((ksize - 1) / 2, MAX_R);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(params.img_size);
    let r = radius(params.sigma);
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(img, p, 0);
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = q;
    var step = q * q2;
    var sum = vec4<f32>(0.0);
    var total = 1.0;
    for (var i = 1; i <= r; i++) {
        let a = textureLoad(img, vec2<i32>(max(p.x - i, 0), p.y), 0);
        let b = textureLoad(img, vec2<i32>(min(p.x + i, size.x - 1), p.y), 0);
        sum += w * (a + b - 2.0 * c);
        total += 2.0 * w;
        w *= step;
        step *= q2;
    }
    return c + sum / total;
}

@compute @workgroup_size(256, 1, 1)
fn cs_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let size = vec2<i32>(params.img_size);
    let r = radius(params.sigma);
    let x0 = i32(group.x) * TILE;
    let y = min(i32(group.y), size.y - 1);
    // The segment [x0 - r, x0 + TILE + r), clamped to the row (replicated border).
    for (var i = i32(local); i < TILE + 2 * r; i += TILE) {
        let x = clamp(x0 - r + i, 0, size.x - 1);
        row[i] = textureLoad(img, vec2<i32>(x, y), 0);
    }
    workgroupBarrier();
    let x = x0 + i32(local);
    if x >= size.x || i32(group.y) >= size.y {
        return;
    }
    let k = i32(local) + r;
    let c = row[k];
    // w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)); w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = q;
    var step = q * q2;
    var sum = vec4<f32>(0.0);
    var total = 1.0;
    for (var i = 1; i <= r; i++) {
        let s = row[k - i] + row[k + i];
        sum += w * (s - 2.0 * c);
        total += 2.0 * w;
        w *= step;
        step *= q2;
    }
    textureStore(out, vec2<i32>(x, y), c + sum / total);
}
