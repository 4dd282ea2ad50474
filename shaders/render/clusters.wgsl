// Clustered light lists built on the GPU (src/render/cluster_gpu.rs): five
// dispatches per frame over the point and spot lights as view-space spheres
// with the tiles and slices they may touch and their first chunk, which the
// light view pass (light_view.wgsl) writes before them.
//
// 1. fx_cs_cluster_bounds: each cluster's view-space box; its counter zeroed.
// 2. fx_cs_cluster_count: a light's footprint (its slices × its tile
//    rectangle) is cut into chunks of CHUNK clusters, one workgroup each (the
//    light view pass numbers the chunks, lights[i].first, and sizes these
//    dispatches); the lanes test the light's
//    sphere against the chunk's cluster boxes in turn and count the hits per
//    cluster. A light over the whole screen thus spreads over hundreds of
//    workgroups, and 16,384 small lights take one each.
// 3. fx_cs_cluster_offsets: one workgroup turns the counts into (offset, count)
//    ranges (an exclusive prefix sum after the global lights), the entry total,
//    the longest list and the indirect arguments of step 5. When the entries
//    exceed the room reserved, every cluster lists every point and spot light
//    instead (exact, slower; the host reserves more for the next frames).
// 4. fx_cs_cluster_fill: the same chunks and tests again, each hit appended to
//    its cluster's range in arrival order (with the cluster it belongs to).
// 5. fx_cs_cluster_sort: one invocation per entry places it at its rank among
//    its cluster's lights, so every list runs in light order as the CPU
//    reference (clusters.rs `build`) lists it: a pixel adds its lights in the
//    same order whatever the culling, and a frame renders the same every time.
//
// The sphere/box test is the CPU reference's, term for term.

struct Params {
    // tiles x, tiles y, slices, clusters
    grid: vec4<u32>,
    // local lights, global lights, capacity of the index lists, -
    counts: vec4<u32>,
}

// A point or spot light's bounding sphere in view space, its index in the
// light array, the tiles (x0 | x1 << 16, y0 | y1 << 16) and slices
// (s0 | s1 << 16) it may touch, and its first chunk (lights in order: the
// chunks before it are those of the lights before it).
struct ClusterLight {
    center: vec3<f32>,
    radius: f32,
    index: u32,
    tiles_x: u32,
    tiles_y: u32,
    slices: u32,
    first: u32,
}

struct Bounds {
    lo: vec4<f32>,
    hi: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
// x slopes of the tile columns' edges (tiles x + 1), then the y slopes of the
// rows' edges, top to bottom (tiles y + 1), then the slices' start depths
// (slices + 1): view x = slope × depth
@group(0) @binding(1) var<storage, read> edges: array<f32>;
@group(0) @binding(2) var<storage, read> lights: array<ClusterLight>;
@group(0) @binding(3) var<storage, read_write> bounds: array<Bounds>;
@group(0) @binding(4) var<storage, read_write> counts: array<atomic<u32>>;
// (offset, count) per cluster: the lighting passes' fx_cluster_ranges
@group(0) @binding(5) var<storage, read_write> ranges: array<vec2<u32>>;
// entries in arrival order (the global lights first, written by the host) and
// the cluster of each
@group(0) @binding(6) var<storage, read_write> unsorted: array<u32>;
@group(0) @binding(7) var<storage, read_write> owner: array<u32>;
// the lists in light order: the lighting passes' fx_cluster_lights
@group(0) @binding(8) var<storage, read_write> sorted: array<u32>;
// indirect arguments of the sort (x, y, z), cluster entries, longest list,
// 1 when the entries did not fit (every cluster lists every light)
@group(0) @binding(9) var<storage, read_write> summary: array<atomic<u32>, 8>;
// the light view pass's summary: its word 3 is the number of chunks
@group(0) @binding(10) var<storage, read> chunking: array<u32, 8>;

const WORKGROUP: u32 = 64u;
// clusters of a light's footprint per workgroup of the count and fill passes
const CHUNK: u32 = 256u;
const SCAN: u32 = 256u;
// workgroups per row of a 2D dispatch
const ROW: u32 = 32768u;

fn tiles_x() -> u32 {
    return params.grid.x;
}

fn tiles_y() -> u32 {
    return params.grid.y;
}

fn slice_depth(s: u32) -> f32 {
    return edges[tiles_x() + tiles_y() + 2u + s];
}

@compute @workgroup_size(64)
fn fx_cs_cluster_bounds(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x + id.y * ROW * WORKGROUP;
    if c >= params.grid.w {
        return;
    }
    let tx = c % tiles_x();
    let ty = (c / tiles_x()) % tiles_y();
    let s = c / (tiles_x() * tiles_y());
    let dn = slice_depth(s);
    let df = slice_depth(s + 1u);
    let left = edges[tx];
    let right = edges[tx + 1u];
    // rows run top to bottom: edge ty is above edge ty + 1
    let top = edges[tiles_x() + 1u + ty];
    let bottom = edges[tiles_x() + 1u + ty + 1u];
    let xmin = left * select(dn, df, left < 0.0);
    let xmax = right * select(dn, df, right > 0.0);
    let ymax = top * select(dn, df, top > 0.0);
    let ymin = bottom * select(dn, df, bottom < 0.0);
    // z is the positive view depth here (the view looks down -z)
    bounds[c] = Bounds(vec4<f32>(xmin, ymin, dn, 0.0), vec4<f32>(xmax, ymax, df, 0.0));
    atomicStore(&counts[c], 0u);
}

// Tests light `l`'s sphere against cluster `cluster` (tile `tx`, `ty` of slice
// `s`) and, on a hit, counts it (`mode` 0) or appends it (1). The tests are the
// CPU reference's in its order: the slab along z, the row along y, the tile
// along x. Every cluster of a slice has the slice's z range and every cluster
// of a row the row's y range (computed from the same edges), so the cluster's
// own box gives the three terms.
fn test_cluster(l: ClusterLight, cluster: u32, mode: u32) {
    let c = l.center;
    let r2 = l.radius * l.radius;
    let b = bounds[cluster];
    // distance² along z from the centre to the slab
    let dz = clamp(-c.z, b.lo.z, b.hi.z) + c.z;
    let dz2 = dz * dz;
    if dz2 > r2 {
        return;
    }
    let dy = clamp(c.y, b.lo.y, b.hi.y) - c.y;
    let dyz2 = dz2 + dy * dy;
    if dyz2 > r2 {
        return;
    }
    let dx = clamp(c.x, b.lo.x, b.hi.x) - c.x;
    if dyz2 + dx * dx > r2 {
        return;
    }
    if mode == 0u {
        atomicAdd(&counts[cluster], 1u);
    } else {
        let slot = ranges[cluster].x + atomicAdd(&counts[cluster], 1u);
        // (the offsets pass made room for every entry, else no fill runs)
        if slot < params.counts.z {
            unsorted[slot] = l.index;
            owner[slot] = cluster;
        }
    }
}

// One workgroup per chunk of CHUNK clusters of a light's footprint (its slices
// × its tile rectangle, numbered slice by slice, row by row): the lanes take
// the chunk's clusters in turn. Light i's chunks start at lights[i].first, so
// the workgroup finds its light by a binary search (the same for every lane).
fn light_chunk(group: vec3<u32>, lane: u32, mode: u32) {
    let w = group.x + group.y * ROW;
    if w >= chunking[3] || (mode == 1u && atomicLoad(&summary[5]) != 0u) {
        return;
    }
    var lo = 0u;
    var hi = params.counts.x - 1u;
    while lo < hi {
        let mid = (lo + hi + 1u) / 2u;
        if lights[mid].first <= w {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    let l = lights[lo];
    let x0 = l.tiles_x & 0xffffu;
    let y0 = l.tiles_y & 0xffffu;
    let s0 = l.slices & 0xffffu;
    let width = (l.tiles_x >> 16u) - x0 + 1u;
    let area = width * ((l.tiles_y >> 16u) - y0 + 1u);
    let total = area * ((l.slices >> 16u) - s0 + 1u);
    let start = (w - l.first) * CHUNK;
    let end = min(start + CHUNK, total);
    for (var t = start + lane; t < end; t += WORKGROUP) {
        let s = s0 + t / area;
        let r = t % area;
        let ty = y0 + r / width;
        let tx = x0 + r % width;
        test_cluster(l, (s * tiles_y() + ty) * tiles_x() + tx, mode);
    }
}

@compute @workgroup_size(64)
fn fx_cs_cluster_count(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    light_chunk(group, lane, 0u);
}

var<workgroup> sums: array<u32, SCAN>;
var<workgroup> longest: array<u32, SCAN>;

// One workgroup: each invocation sums a run of clusters, the workgroup scans
// the sums (Hillis and Steele), then each invocation writes its run's ranges.
@compute @workgroup_size(256)
fn fx_cs_cluster_offsets(@builtin(local_invocation_index) i: u32) {
    let n = params.grid.w;
    let per = (n + SCAN - 1u) / SCAN;
    let start = min(i * per, n);
    let end = min(start + per, n);
    var total = 0u;
    var most = 0u;
    for (var c = start; c < end; c++) {
        let k = atomicLoad(&counts[c]);
        total += k;
        most = max(most, k);
    }
    sums[i] = total;
    longest[i] = most;
    workgroupBarrier();
    for (var d = 1u; d < SCAN; d <<= 1u) {
        var add = 0u;
        var m = 0u;
        if i >= d {
            add = sums[i - d];
            m = longest[i - d];
        }
        workgroupBarrier();
        sums[i] += add;
        longest[i] = max(longest[i], m);
        workgroupBarrier();
    }
    // the entries do not fit: every cluster lists every point and spot light
    let overflow = params.counts.y + sums[SCAN - 1u] > params.counts.z;
    var offset = params.counts.y + sums[i] - total;
    for (var c = start; c < end; c++) {
        let k = atomicLoad(&counts[c]);
        ranges[c] = select(vec2<u32>(offset, k), params.counts.yx, overflow);
        offset += k;
        // the fill pass counts again from 0
        atomicStore(&counts[c], 0u);
    }
    if i == SCAN - 1u {
        let entries = params.counts.y + select(sums[i], params.counts.x, overflow);
        let groups = (min(entries, params.counts.z) + WORKGROUP - 1u) / WORKGROUP;
        atomicStore(&summary[0], min(groups, ROW));
        atomicStore(&summary[1], (groups + ROW - 1u) / ROW);
        atomicStore(&summary[2], 1u);
        atomicStore(&summary[3], sums[i]);
        atomicStore(&summary[4], select(longest[i], params.counts.x, overflow));
        atomicStore(&summary[5], select(0u, 1u, overflow));
    }
}

@compute @workgroup_size(64)
fn fx_cs_cluster_fill(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    light_chunk(group, lane, 1u);
}

@compute @workgroup_size(64)
fn fx_cs_cluster_sort(@builtin(global_invocation_id) id: vec3<u32>) {
    let e = id.x + id.y * ROW * WORKGROUP;
    let overflow = atomicLoad(&summary[5]) != 0u;
    let listed = select(atomicLoad(&summary[3]), params.counts.x, overflow);
    let entries = min(params.counts.y + listed, params.counts.z);
    if e >= entries {
        return;
    }
    if e < params.counts.y {
        sorted[e] = unsorted[e];
        return;
    }
    if overflow {
        // the point and spot lights in light order
        sorted[e] = lights[e - params.counts.y].index;
        return;
    }
    let light = unsorted[e];
    let range = ranges[owner[e]];
    // a light is listed at most once per cluster: its rank is the number of
    // smaller indices in the list
    var rank = 0u;
    for (var k = range.x; k < range.x + range.y; k++) {
        rank += select(0u, 1u, unsorted[k] < light);
    }
    sorted[range.x + rank] = light;
}
