// mb_blur: the reconstruction filter of `motion_blur` (effects/motion_blur.fx),
// after McGuire, Hennessy, Bukowski and Osman, "A reconstruction filter for
// plausible motion blur" (I3D 2012), written from the paper's description.
//
// Inputs: `img` the sharp frame, `motion` the motion vectors (pixels per frame),
// `depth` linear depth (larger is farther), `neighbor` the neighbour-max motion
// per tile. Blur half-vectors: h = motion * shutter / 2 (the object moves by
// motion * shutter while the shutter is open, centred on the frame time),
// shortened to `radius` = min(max_length / 2, the narrowest tile in pixels).
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var motion: texture_2d<f32>;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var neighbor: texture_2d<f32>;

struct Params {
    shutter: f32,    // @default(0.5) @range(0, 1) fraction of the frame interval the shutter is open
    max_length: f32, // @default(64) @range(0, 64) longest blur in pixels
    samples: i32,    // @default(15) @range(3, 63) samples along the blur per pixel
    soft_depth: f32, // @default(0.05) @range(0.0001, 10) depth difference, relative to the pixel's depth, over which a sample goes from in front to behind
    out_size: vec2<f32>,
}
@group(0) @binding(4) var<uniform> params: Params;

var<private> radius: f32;

fn half_blur(m: vec2<f32>) -> vec2<f32> {
    let h = m * (0.5 * params.shutter);
    let l = length(h);
    if (l > radius) {
        return h * (radius / l);
    }
    return h;
}

fn cone(d: f32, l: f32) -> f32 {
    return clamp(1.0 - d / l, 0.0, 1.0);
}

fn cylinder(d: f32, l: f32) -> f32 {
    return 1.0 - smoothstep(0.95 * l, 1.05 * l, d);
}

// Interleaved gradient noise (Jimenez 2014): a per-pixel offset in [0, 1) for the
// sample positions, so that the few samples per pixel band less.
fn noise(p: vec2<f32>) -> f32 {
    return fract(52.9829189 * fract(dot(p, vec2<f32>(0.06711056, 0.00583715))));
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(pos.xy);
    let size = vec2<i32>(params.out_size);
    let hi = size - vec2<i32>(1);
    let tiles = vec2<i32>(textureDimensions(neighbor));
    // Pixel x is in tile floor(x tiles / size); the narrowest tile is
    // floor(size / tiles) pixels.
    let tile_px = floor(params.out_size / vec2<f32>(tiles));
    radius = min(0.5 * params.max_length, min(tile_px.x, tile_px.y));
    let cx = textureLoad(img, px, 0);
    let tile = min(px * tiles / size, tiles - vec2<i32>(1));
    let hn = half_blur(textureLoad(neighbor, tile, 0).xy);
    // No motion of half a pixel or more nearby: the pixel as it is.
    if (length(hn) <= 0.5) {
        return cx;
    }
    let lx = max(length(half_blur(textureLoad(motion, px, 0).xy)), 0.5);
    let zx = textureLoad(depth, px, 0).r;
    let ext = params.soft_depth * max(abs(zx), 1e-6);
    var wsum = 1.0 / lx;
    var sum = cx * wsum;
    let j = noise(pos.xy) - 0.5;
    let n = params.samples;
    for (var i = 0; i < n; i++) {
        // The middle sample would be (about) the pixel itself.
        if (2 * i == n - 1) {
            continue;
        }
        let t = mix(-1.0, 1.0, (f32(i) + j + 1.0) / (f32(n) + 1.0));
        let py = clamp(vec2<i32>(floor(pos.xy + hn * t)), vec2<i32>(0), hi);
        let y = vec2<f32>(py) + 0.5;
        let d = length(y - pos.xy);
        let ly = max(length(half_blur(textureLoad(motion, py, 0).xy)), 0.5);
        let zy = textureLoad(depth, py, 0).r;
        // 1 where Y is in front of X (nearer or level), falling to 0 over `ext`.
        let front = clamp(1.0 - (zy - zx) / ext, 0.0, 1.0);
        // 1 where Y is behind X.
        let back = clamp(1.0 - (zx - zy) / ext, 0.0, 1.0);
        // Y in front, blurred over X; Y behind a blurred X (seen through its blur);
        // both blurred over each other.
        let a = front * cone(d, ly) + back * cone(d, lx) + cylinder(d, ly) * cylinder(d, lx) * 2.0;
        sum += a * textureLoad(img, py, 0);
        wsum += a;
    }
    return sum / wsum;
}
