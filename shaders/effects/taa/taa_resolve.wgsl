// taa_resolve: the accumulation step of temporal anti-aliasing (effects/taa.fx has
// the method in words).
//
// Inputs: `cur` the current frame (linear light, rendered with sub-pixel jitter
// `params.jitter`), `hist` this pass's own output of the previous frame (rgb = the
// accumulated colour, a = n, the number of frames it stands for; zero before the
// first frame), `geo` / `geo_prev` the reprojection data of this frame and the
// previous one (shaders/effects/taa/taa_geometry.wgsl: nearest depth, its motion, own depth).
// Output: the new state at HISTORY_SCALE times the input's size (a texel covers
// 1/3 x 1/3 of an input pixel): rgb = colour, a = w, the sum of the sample
// weights it stands for.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main` stages the
// input pixels under a workgroup's 16 x 16 texels and a ring of one around them
// (at most 9 x 9, `sane` applied) in workgroup memory once, where each is read
// by the 9 x 9 texels whose 3 x 3 neighbourhood holds it; `fs_main` loads its 9
// where the output cannot be a storage texture. The same arithmetic on the same
// values: measured difference 0 (tests/compute_native.rs). Both sum the 3 x 3
// through `accumulate` (a 9-element array indexed in a loop made either entry
// point half again as slow on lavapipe).
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var hist: texture_2d<f32>;
@group(0) @binding(2) var hist_sampler: sampler;
@group(0) @binding(3) var geo: texture_2d<f32>;
@group(0) @binding(4) var geo_prev: texture_2d<f32>;

struct Params {
    frames: f32,           // @default(10) @range(1, 64) most frames the history stands for: the current frame's weight is at least 1 / frames
    clip_gamma: f32,       // @default(1.25) @range(0.25, 8) half-width of the history clipping box, in standard deviations of the 3x3 neighbourhood (YCoCg)
    filter_width: f32,     // @default(0.13) @range(0.05, 2) standard deviation in input pixels of the Gaussian that weighs each jittered sample into the history texels around it
    depth_tolerance: f32,  // @default(0.1) @range(0, 10) relative depth change beyond which the reprojected history is a disocclusion
    motion_tolerance: f32, // @default(2) @range(0, 1000) change of the motion vector, in pixels, beyond which the reprojected history is a disocclusion
    resample_limit: f32,   // @default(1) @range(0.01, 1000) caps the history length in sub-texel motion at resample_limit / s frames, s = fx (1 - fx) + fy (1 - fy) of the reprojected position's fraction (history texels)
    jitter: vec2<f32>,
    out_size: vec2<f32>,
    // 1 on the first frame after a camera cut (the standard value `cut`): the
    // history shows another shot and is dropped everywhere
    cut: f32,
}
@group(0) @binding(5) var<uniform> params: Params;
@group(0) @binding(6) var out: texture_storage_2d<rgba16float, write>;

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

// Cubic interpolation of the history at `p` (history texels) with 9 bilinear
// taps: Keys' cubic convolution kernel with a = -0.75, per axis the two middle
// weights merged into one bilinear fetch between the two middle texels (exact
// for the cubic, whose middle weights are positive; the sampler clamps at the
// border). Measured on tests/taa_scene.rs with the 3x history (error over the
// un-anti-aliased one): with the sample sigma at 0.15 px, a = -0.75 gives 0.588,
// -1 0.603, -0.5 (Catmull-Rom) more; at the defaults a = -0.75 gives 0.583 and a
// 6x6 Lanczos-3 0.587: at a third of a pixel the kernel matters less than the
// history's resolution.
fn keys_near(x: vec2<f32>) -> vec2<f32> {
    return (KEYS_A + 2.0) * x * x * x - (KEYS_A + 3.0) * x * x + 1.0;
}

fn keys_far(x: vec2<f32>) -> vec2<f32> {
    return KEYS_A * (((x - 5.0) * x + 8.0) * x - 4.0);
}

const KEYS_A: f32 = -0.75;

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

// The state's size over the input's, per axis (effects/taa.fx: OUT.SCALE = 3).
// Each resampling of the history in sub-pixel motion softens it a little, and
// the softening builds up over the frames the history stands for: at a third of
// an input pixel it is a ninth of what it is at the input's resolution. Measured
// on tests/taa_scene.rs (error against the 4x4 supersampled render over the
// un-anti-aliased one): 1x 0.795, 2x 0.62, 3x 0.583, 4x 0.56.
const HISTORY_SCALE: f32 = 3.0;

// The current samples around a texel: the Gaussian-weighted sum near x and its
// weight, the wide estimate and its weight, and the YCoCg moments and range of
// the 3x3.
struct Neighbourhood {
    sum: vec3<f32>,
    wsum: f32,
    wide: vec3<f32>,
    wide_w: f32,
    m1: vec3<f32>,
    m2: vec3<f32>,
    mn: vec3<f32>,
    mx: vec3<f32>,
}

const EMPTY: Neighbourhood = Neighbourhood(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0, vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(1e30), vec3<f32>(-1e30));

// 1. One current sample c of pixel q near x (input pixels), weighed by a
// Gaussian of its distance from x (sample q was taken at q + 0.5 + jitter);
// `wide`, a wider Gaussian (sigma 1/3 px), gives the fallback that stands in
// where no sample is near and the history is gone.
fn accumulate(n: ptr<function, Neighbourhood>, x: vec2<f32>, q: vec2<i32>, c: vec3<f32>) {
    let inv2s2 = 0.5 / (params.filter_width * params.filter_width);
    let d = vec2<f32>(q) + 0.5 + params.jitter - x;
    let w = exp(-dot(d, d) * inv2s2);
    (*n).sum += c * w;
    (*n).wsum += w;
    let ww = exp(-dot(d, d) * 4.5);
    (*n).wide += c * ww;
    (*n).wide_w += ww;
    let y = to_ycocg(c);
    (*n).m1 += y;
    (*n).m2 += y * y;
    (*n).mn = min((*n).mn, y);
    (*n).mx = max((*n).mx, y);
}

// Steps 2 to 5 for the texel at x (input pixels) in pixel p.
fn resolve(x: vec2<f32>, p: vec2<i32>, n: Neighbourhood) -> vec4<f32> {
    let in_size = params.out_size / HISTORY_SCALE;
    let hi = vec2<i32>(in_size) - vec2<i32>(1);
    let fallback = n.wide / n.wide_w;
    // 2. Where this texel was one frame earlier (the motion of its input pixel's
    // nearest surface), and 3. whether the surface seen there was the same one.
    let g = textureLoad(geo, p, 0);
    let prev = x - g.yz;
    var valid = params.cut < 0.5 && all(prev >= vec2<f32>(0.0)) && all(prev <= in_size);
    if (valid) {
        let gp = textureLoad(geo_prev, clamp(vec2<i32>(prev), vec2<i32>(0), hi), 0);
        let depth_off = abs(gp.x - g.x) > params.depth_tolerance * max(g.x, 1e-6);
        let motion_off = length(gp.yz - g.yz) > params.motion_tolerance;
        valid = !(depth_off || motion_off);
    }
    // The weight a texel gets from one frame on average over the jitter: the
    // Gaussian's integral (one sample per pixel^2).
    let per_frame = 6.2831853 * params.filter_width * params.filter_width;
    var w_prev = 0.0;
    var history = fallback;
    if (valid) {
        let ph = prev * HISTORY_SCALE;
        w_prev = textureSampleLevel(hist, hist_sampler, ph / params.out_size, 0.0).a;
        history = sane(history_cubic(ph));
        // Each resampling at a fractional position softens the history a
        // little (s: the blur a bilinear one would add, texels^2; 0 for
        // whole-texel motion): in sub-texel motion it stands for fewer frames.
        let f = fract(ph - 0.5);
        let s = dot(f, vec2<f32>(1.0) - f);
        w_prev = min(w_prev, per_frame * params.resample_limit / max(s, 1e-6));
    }
    // 4. Variance clipping in YCoCg: the box mean +- gamma sigma of the 3x3
    // samples around the texel, within their min/max, always holding the
    // current estimate.
    let mean = n.m1 / 9.0;
    let sigma = sqrt(max(n.m2 / 9.0 - mean * mean, vec3<f32>(0.0)));
    let cy = to_ycocg(select(fallback, n.sum / n.wsum, n.wsum > 1e-4));
    let lo = min(max(mean - params.clip_gamma * sigma, n.mn), cy);
    let hi_box = max(min(mean + params.clip_gamma * sigma, n.mx), cy);
    let clipped = from_ycocg(clip_box(lo, hi_box, to_ycocg(history)));
    // 5. Accumulate: the history's weight (at most `frames` frames' worth), this
    // frame's samples, and a little of the wide estimate where there is nothing else.
    let wh = min(max(w_prev, 0.0), per_frame * (params.frames - 1.0));
    let eps = 0.01 * per_frame;
    let w_new = wh + n.wsum + eps;
    let c = (clipped * wh + n.sum + fallback * eps) / w_new;
    return vec4<f32>(c, w_new);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    // This texel's centre in input pixels.
    let x = pos.xy / HISTORY_SCALE;
    let p = vec2<i32>(floor(x));
    let hi = vec2<i32>(params.out_size / HISTORY_SCALE) - vec2<i32>(1);
    var n = EMPTY;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy);
            accumulate(&n, x, q, sane(textureLoad(cur, clamp(q, vec2<i32>(0), hi), 0).rgb));
        }
    }
    return resolve(x, p, n);
}

// cs_main: 16 x 16 texels; the input pixels from floor(first texel / 3) - 1 to
// floor(last texel / 3) + 1 on each axis, at most 9 (16 texels span 6 1/3 px).
const GROUP: i32 = 16;
const SPAN: i32 = 9;
var<workgroup> staged: array<vec3<f32>, 81>;

@compute @workgroup_size(16, 16, 1)
fn cs_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
) {
    let hi = vec2<i32>(params.out_size / HISTORY_SCALE) - vec2<i32>(1);
    let first = vec2<i32>(group.xy) * GROUP;
    let base = vec2<i32>(floor((vec2<f32>(first) + 0.5) / HISTORY_SCALE)) - vec2<i32>(1);
    if (i32(index) < SPAN * SPAN) {
        let q = base + vec2<i32>(i32(index) % SPAN, i32(index) / SPAN);
        staged[index] = sane(textureLoad(cur, clamp(q, vec2<i32>(0), hi), 0).rgb);
    }
    workgroupBarrier();
    let o = first + vec2<i32>(local.xy);
    if (any(o >= vec2<i32>(params.out_size))) {
        return;
    }
    let x = (vec2<f32>(o) + 0.5) / HISTORY_SCALE;
    let p = vec2<i32>(floor(x));
    var n = EMPTY;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy);
            let s = q - base;
            accumulate(&n, x, q, staged[s.y * SPAN + s.x]);
        }
    }
    textureStore(out, o, resolve(x, p, n));
}
