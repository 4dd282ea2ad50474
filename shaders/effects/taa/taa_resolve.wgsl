// taa_resolve: the accumulation step of temporal anti-aliasing (effects/taa.fx has
// the method in words).
//
// Inputs: `cur` the current frame (linear light, rendered with sub-pixel jitter
// `params.jitter`), `hist` this pass's own output of the previous frame (rgb = the
// accumulated colour, a = n, the number of frames it stands for; zero before the
// first frame), `geo` / `geo_prev` the reprojection data of this frame and the
// previous one (shaders/effects/taa/taa_geometry.wgsl: nearest depth, its motion, own depth).
// Output: the new state, rgb = colour, a = n.
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var hist: texture_2d<f32>;
@group(0) @binding(2) var hist_sampler: sampler;
@group(0) @binding(3) var geo: texture_2d<f32>;
@group(0) @binding(4) var geo_prev: texture_2d<f32>;

struct Params {
    frames: f32,           // @default(10) @range(1, 64) most frames the history stands for: the current frame's weight is at least 1 / frames
    clip_gamma: f32,       // @default(1.25) @range(0.25, 8) half-width of the history clipping box, in standard deviations of the 3x3 neighbourhood (YCoCg)
    filter_width: f32,     // @default(0.33) @range(0.1, 2) standard deviation in pixels of the Gaussian that rebuilds the unjittered current pixel from its 3x3 jittered samples
    depth_tolerance: f32,  // @default(0.1) @range(0, 10) relative depth change beyond which the reprojected history is a disocclusion
    motion_tolerance: f32, // @default(2) @range(0, 1000) change of the motion vector, in pixels, beyond which the reprojected history is a disocclusion
    resample_limit: f32,   // @default(0.5) @range(0.01, 1000) caps the history length in sub-pixel motion at resample_limit / s frames, s = fx (1 - fx) + fy (1 - fy) of the reprojected position's fraction
    jitter: vec2<f32>,
    out_size: vec2<f32>,
    // 1 on the first frame after a camera cut (the standard value `cut`): the
    // history shows another shot and is dropped everywhere
    cut: f32,
}
@group(0) @binding(5) var<uniform> params: Params;

fn to_ycocg(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        0.25 * c.r + 0.5 * c.g + 0.25 * c.b,
        0.5 * c.r - 0.5 * c.b,
        -0.25 * c.r + 0.5 * c.g - 0.25 * c.b,
    );
}

fn from_ycocg(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// Values within what rgba16f holds, NaN as 0: NaN and infinities in the input
// must not enter the history, where they would stay.
fn sane(c: vec3<f32>) -> vec3<f32> {
    let finite = select(vec3<f32>(0.0), c, c == c);
    return clamp(finite, vec3<f32>(-65504.0), vec3<f32>(65504.0));
}

// Cubic interpolation of the history at `p` (pixel coordinates) with 9 bilinear
// taps: Keys' cubic convolution kernel with a = -1 (Catmull-Rom is a = -0.5),
// per axis the two middle weights merged into one bilinear fetch between the two
// middle texels (exact for the cubic; the sampler clamps at the border). The
// history is resampled at every frame of sub-pixel motion, and each resampling
// loses some of its finest detail: a = -1 keeps more of it (at a half-pixel
// shift a detail 2.7 px across keeps 71 % of its amplitude, 55 % with
// Catmull-Rom). On tests/taa_scene.rs's moving bars the error against the
// supersampled render is 0.796 of the un-anti-aliased one, 0.837 with
// Catmull-Rom (-1.5: 0.81, -2: 0.85).
fn keys_near(x: vec2<f32>) -> vec2<f32> {
    return (KEYS_A + 2.0) * x * x * x - (KEYS_A + 3.0) * x * x + 1.0;
}

fn keys_far(x: vec2<f32>) -> vec2<f32> {
    return KEYS_A * (((x - 5.0) * x + 8.0) * x - 4.0);
}

const KEYS_A: f32 = -1.0;

fn history_cubic(p: vec2<f32>) -> vec3<f32> {
    let t1 = floor(p - 0.5) + 0.5;
    let f = p - t1;
    let w0 = keys_far(1.0 + f);
    let w1 = keys_near(f);
    let w2 = keys_near(1.0 - f);
    let w3 = keys_far(2.0 - f);
    let w12 = w1 + w2;
    let t0 = (t1 - 1.0) / params.out_size;
    let t3 = (t1 + 2.0) / params.out_size;
    let t12 = (t1 + w2 / w12) / params.out_size;
    var c = vec3<f32>(0.0);
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t0.x, t0.y), 0.0).rgb * w0.x * w0.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t12.x, t0.y), 0.0).rgb * w12.x * w0.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t3.x, t0.y), 0.0).rgb * w3.x * w0.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t0.x, t12.y), 0.0).rgb * w0.x * w12.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t12.x, t12.y), 0.0).rgb * w12.x * w12.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t3.x, t12.y), 0.0).rgb * w3.x * w12.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t0.x, t3.y), 0.0).rgb * w0.x * w3.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t12.x, t3.y), 0.0).rgb * w12.x * w3.y;
    c += textureSampleLevel(hist, hist_sampler, vec2<f32>(t3.x, t3.y), 0.0).rgb * w3.x * w3.y;
    return c;
}

// Clip `q` towards the centre of the box [lo, hi] onto its surface (when outside).
fn clip_box(lo: vec3<f32>, hi: vec3<f32>, q: vec3<f32>) -> vec3<f32> {
    let c = 0.5 * (hi + lo);
    let e = 0.5 * (hi - lo) + vec3<f32>(1e-6);
    let v = q - c;
    let a = abs(v / e);
    let m = max(a.x, max(a.y, a.z));
    if (m > 1.0) {
        return c + v / m;
    }
    return q;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(params.out_size) - vec2<i32>(1);
    // 1. The current pixel without its jitter, and the neighbourhood's moments.
    // Sample q = p + o was taken at (q + 0.5 + jitter): at o + jitter from p's centre.
    let inv2s2 = 0.5 / (params.filter_width * params.filter_width);
    var sum = vec3<f32>(0.0);
    var wsum = 0.0;
    var m1 = vec3<f32>(0.0);
    var m2 = vec3<f32>(0.0);
    var mn = vec3<f32>(1e30);
    var mx = vec3<f32>(-1e30);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let o = vec2<i32>(dx, dy);
            let c = sane(textureLoad(cur, clamp(p + o, vec2<i32>(0), hi), 0).rgb);
            let d = vec2<f32>(o) + params.jitter;
            let w = exp(-dot(d, d) * inv2s2);
            sum += c * w;
            wsum += w;
            let y = to_ycocg(c);
            m1 += y;
            m2 += y * y;
            mn = min(mn, y);
            mx = max(mx, y);
        }
    }
    let current = sum / wsum;
    // 2. Where this pixel was one frame earlier.
    let g = textureLoad(geo, p, 0);
    let prev = pos.xy - g.yz;
    var valid = params.cut < 0.5 && all(prev >= vec2<f32>(0.0)) && all(prev <= params.out_size);
    // 3. Disocclusion: the surface seen there one frame earlier is another one
    // (its nearest depth or its motion differ).
    if (valid) {
        let gp = textureLoad(geo_prev, clamp(vec2<i32>(prev), vec2<i32>(0), hi), 0);
        let depth_off = abs(gp.x - g.x) > params.depth_tolerance * max(g.x, 1e-6);
        let motion_off = length(gp.yz - g.yz) > params.motion_tolerance;
        valid = !(depth_off || motion_off);
    }
    var n_prev = 0.0;
    var history = current;
    if (valid) {
        n_prev = textureSampleLevel(hist, hist_sampler, prev / params.out_size, 0.0).a;
        history = sane(history_cubic(prev));
        // Each resampling at a fractional position softens the history a little
        // (s: the blur a bilinear one would add, px^2; 0 for whole-pixel motion):
        // in sub-pixel motion it may stand for fewer frames.
        let f = fract(prev - 0.5);
        let s = dot(f, vec2<f32>(1.0) - f);
        n_prev = min(n_prev, params.resample_limit / max(s, 1e-6));
    }
    // 4. Variance clipping in YCoCg: the box mean +- gamma sigma of the 3x3
    // samples, within their min/max, always holding the current pixel.
    let mean = m1 / 9.0;
    let sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3<f32>(0.0)));
    let cy = to_ycocg(current);
    let lo = min(max(mean - params.clip_gamma * sigma, mn), cy);
    let hi_box = max(min(mean + params.clip_gamma * sigma, mx), cy);
    let clipped = from_ycocg(clip_box(lo, hi_box, to_ycocg(history)));
    // 5. Blend: the state stands for n frames, the current one weighs 1 / n.
    let n = min(max(n_prev, 0.0), params.frames - 1.0) + 1.0;
    return vec4<f32>(mix(clipped, current, 1.0 / n), n);
}
