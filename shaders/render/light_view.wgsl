// The lights of a clustered (or unculled) frame moved into view space on the
// GPU (src/render/light_view_gpu.rs): the host uploads the world-space lights
// only when they change, and per frame only the view, the frustum and the grid.
//
// 1. fx_cs_light_view: one invocation per light: the light array the shaders
//    read (`fx_lights`), its position and direction in view space.
// 2. fx_cs_light_records: one invocation per point or spot light: its culling
//    sphere in view space, tested against the frustum planes (the CPU's test,
//    term for term), then the tiles and slices it may touch (the CPU
//    reference's `ClusterGrid::footprint`) and its chunks of CHUNK clusters;
//    the visible lights and the footprints' clusters are counted.
// 3. fx_cs_light_scan: one workgroup turns the chunk counts into each light's
//    first chunk (an exclusive prefix sum, in light order) and writes the
//    count and fill dispatches' indirect arguments.

struct Params {
    view: mat4x4<f32>,
    // n · p + d >= 0 inside (view space)
    planes: array<vec4<f32>, 6>,
    // p00, p02, p11, p12 of the projection
    proj: vec4<f32>,
    // width, height, grid near, grid far
    size: vec4<f32>,
    // tiles x, tiles y, slices, tile size in pixels
    grid: vec4<u32>,
    // lights, point and spot lights, one cluster (1: every light everywhere), -
    counts: vec4<u32>,
    // slices / ln(far / near), -, -, -
    scale: vec4<f32>,
}

// GpuLight (src/render/gpu_types.rs) as words: position in [0].xyz, kind in
// [1].w, direction in [2].xyz; the rest is copied as it is.
struct Light {
    w: array<vec4<u32>, 6>,
}

struct WorldLocal {
    center: vec3<f32>,
    radius: f32,
    index: u32,
}

// ClusterLight of clusters.wgsl; `first` holds the light's chunk count until
// the scan.
struct ClusterLight {
    center: vec3<f32>,
    radius: f32,
    index: u32,
    tiles_x: u32,
    tiles_y: u32,
    slices: u32,
    first: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> world: array<Light>;
@group(0) @binding(2) var<storage, read> locals: array<WorldLocal>;
@group(0) @binding(3) var<storage, read_write> lights: array<Light>;
@group(0) @binding(4) var<storage, read_write> records: array<ClusterLight>;
// indirect arguments of the count and fill dispatches (x, y, z), chunks,
// visible point and spot lights, clusters of their footprints
@group(0) @binding(5) var<storage, read_write> summary: array<atomic<u32>, 8>;

const WORKGROUP: u32 = 64u;
const CHUNK: u32 = 256u;
const SCAN: u32 = 256u;
const ROW: u32 = 32768u;
const KIND_DIRECTIONAL: u32 = 1u;
const INFINITY: f32 = 3.4028235e38;

@compute @workgroup_size(64)
fn fx_cs_light_view(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * ROW * WORKGROUP;
    if i >= params.counts.x {
        return;
    }
    var l = world[i];
    if l.w[1].w != KIND_DIRECTIONAL {
        let p = params.view * vec4<f32>(bitcast<vec3<f32>>(l.w[0].xyz), 1.0);
        l.w[0] = vec4<u32>(bitcast<vec3<u32>>(p.xyz), l.w[0].w);
    }
    let d = (params.view * vec4<f32>(bitcast<vec3<f32>>(l.w[2].xyz), 0.0)).xyz;
    let n = select(vec3<f32>(0.0, 0.0, -1.0), normalize(d), dot(d, d) > 0.0);
    l.w[2] = vec4<u32>(bitcast<vec3<u32>>(n), l.w[2].w);
    lights[i] = l;
}

fn slice_of(d: f32) -> u32 {
    let near = params.size.z;
    let s = floor(log(max(d, near) / near) * params.scale.x);
    return min(u32(max(s, 0.0)), params.grid.z - 1u);
}

fn pack(a: u32, b: u32) -> u32 {
    return a | (b << 16u);
}

// The footprint of sphere (c, r) into `rec` (tiles and slices); false when it
// misses the grid. As `ClusterGrid::footprint` (src/render/clusters.rs).
fn footprint(c: vec3<f32>, r: f32, rec: ptr<function, ClusterLight>) -> bool {
    let tiles = params.grid.xy;
    if params.counts.z != 0u {
        (*rec).tiles_x = 0u;
        (*rec).tiles_y = 0u;
        (*rec).slices = 0u;
        return true;
    }
    let near = params.size.z;
    let dmin = -c.z - r;
    let dmax = -c.z + r;
    if dmax < near || dmin > params.size.w {
        return false;
    }
    (*rec).slices = pack(slice_of(dmin), slice_of(dmax));
    (*rec).tiles_x = pack(0u, tiles.x - 1u);
    (*rec).tiles_y = pack(0u, tiles.y - 1u);
    if dmin <= near * 0.5 {
        return true;
    }
    let p00 = params.proj.x;
    let p02 = params.proj.y;
    let p11 = params.proj.z;
    let p12 = params.proj.w;
    var lo = vec2<f32>(INFINITY);
    var hi = vec2<f32>(-INFINITY);
    for (var k = 0u; k < 8u; k++) {
        let p = c + vec3<f32>(
            select(-r, r, (k & 1u) != 0u),
            select(-r, r, (k & 2u) != 0u),
            select(-r, r, (k & 4u) != 0u),
        );
        let d = -p.z;
        let ndc = vec2<f32>(p.x * p00 / d - p02, p.y * p11 / d - p12);
        lo = min(lo, ndc);
        hi = max(hi, ndc);
    }
    if hi.x < -1.0 || lo.x > 1.0 || hi.y < -1.0 || lo.y > 1.0 {
        return false;
    }
    let w = params.size.x;
    let h = params.size.y;
    let t = params.grid.w;
    let x0 = u32((clamp(lo.x, -1.0, 1.0) + 1.0) * 0.5 * w) / t;
    let x1 = u32((clamp(hi.x, -1.0, 1.0) + 1.0) * 0.5 * w) / t;
    let y0 = u32((1.0 - clamp(hi.y, -1.0, 1.0)) * 0.5 * h) / t;
    let y1 = u32((1.0 - clamp(lo.y, -1.0, 1.0)) * 0.5 * h) / t;
    (*rec).tiles_x = pack(min(x0, tiles.x - 1u), min(x1, tiles.x - 1u));
    (*rec).tiles_y = pack(min(y0, tiles.y - 1u), min(y1, tiles.y - 1u));
    return true;
}

fn span(packed: u32) -> u32 {
    return (packed >> 16u) - (packed & 0xffffu) + 1u;
}

@compute @workgroup_size(64)
fn fx_cs_light_records(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x + id.y * ROW * WORKGROUP;
    if k >= params.counts.y {
        return;
    }
    let l = locals[k];
    let c = (params.view * vec4<f32>(l.center, 1.0)).xyz;
    let r = l.radius;
    // one cluster lists every light: a sphere that touches everything
    let radius = select(r, INFINITY, params.counts.z != 0u);
    var rec = ClusterLight(c, radius, l.index, 0u, 0u, 0u, 0u);
    var outside = false;
    for (var i = 0u; i < 6u; i++) {
        let p = params.planes[i];
        outside = outside || dot(p.xyz, c) + p.w < -r;
    }
    if !outside {
        atomicAdd(&summary[4], 1u);
        if footprint(c, r, &rec) {
            let clusters = span(rec.tiles_x) * span(rec.tiles_y) * span(rec.slices);
            rec.first = (clusters + CHUNK - 1u) / CHUNK;
            atomicAdd(&summary[5], clusters);
        }
    }
    records[k] = rec;
}

var<workgroup> sums: array<u32, SCAN>;

// One workgroup: each invocation sums a run of lights' chunks, the workgroup
// scans the sums (Hillis and Steele), then each invocation writes its run's
// first chunks.
@compute @workgroup_size(256)
fn fx_cs_light_scan(@builtin(local_invocation_index) i: u32) {
    let n = params.counts.y;
    let per = (n + SCAN - 1u) / SCAN;
    let start = min(i * per, n);
    let end = min(start + per, n);
    var total = 0u;
    for (var k = start; k < end; k++) {
        total += records[k].first;
    }
    sums[i] = total;
    workgroupBarrier();
    for (var d = 1u; d < SCAN; d <<= 1u) {
        var add = 0u;
        if i >= d {
            add = sums[i - d];
        }
        workgroupBarrier();
        sums[i] += add;
        workgroupBarrier();
    }
    var first = sums[i] - total;
    for (var k = start; k < end; k++) {
        let chunks = records[k].first;
        records[k].first = first;
        first += chunks;
    }
    if i == SCAN - 1u {
        let chunks = sums[i];
        atomicStore(&summary[0], min(chunks, ROW));
        atomicStore(&summary[1], (chunks + ROW - 1u) / ROW);
        atomicStore(&summary[2], 1u);
        atomicStore(&summary[3], chunks);
    }
}
