// Visibility buffer, tile classification (src/render/visibility.rs): before
// the material resolve, each 8 x 8 tile of the id target is appended to the
// list of every resolve dispatch with a pixel in it (list FX_VIS_GROUPS: the
// tiles with a pixel nothing was resolved at, which the clearing dispatch
// takes), so each dispatch runs over its own tiles only (indirect). The host
// prepends `const FX_VIS_GROUPS: u32 = N;`.

const FX_VIS_NONE: u32 = 0xffffffffu;
const FX_VIS_LISTS: u32 = FX_VIS_GROUPS + 1u;
const FX_VIS_WORDS: u32 = (FX_VIS_LISTS + 31u) / 32u;
// the most workgroups along x of an indirect dispatch (the rest go along y)
const FX_VIS_ROW: u32 = 65535u;

struct FxVisSlot {
    first_index: u32,
    base_vertex: i32,
    group: u32,
    flags: u32,
}

@group(0) @binding(0) var fx_vis_ids: texture_2d<u32>;
@group(0) @binding(1) var<storage, read> fx_vis_slots: array<FxVisSlot>;
// tiles per list (cleared before the pass)
@group(0) @binding(2) var<storage, read_write> fx_vis_counts: array<atomic<u32>>;
// list k's tiles at k x (the frame's tile count)
@group(0) @binding(3) var<storage, read_write> fx_vis_tiles: array<u32>;
// per list: the resolve dispatch's workgroups (x, y, z)
@group(0) @binding(4) var<storage, read_write> fx_vis_args: array<u32>;

var<workgroup> fx_vis_mask: array<atomic<u32>, FX_VIS_WORDS>;

@compute @workgroup_size(8, 8)
fn fx_cs_visibility_classify(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) wg: vec3<u32>,
) {
    let size = textureDimensions(fx_vis_ids);
    for (var w = li; w < FX_VIS_WORDS; w += 64u) {
        atomicStore(&fx_vis_mask[w], 0u);
    }
    workgroupBarrier();
    if gid.x < size.x && gid.y < size.y {
        let id = textureLoad(fx_vis_ids, vec2<i32>(gid.xy), 0).x;
        var list = FX_VIS_GROUPS;
        if id != FX_VIS_NONE {
            list = min(fx_vis_slots[id].group, FX_VIS_GROUPS);
        }
        atomicOr(&fx_vis_mask[list / 32u], 1u << (list % 32u));
    }
    workgroupBarrier();
    let tiles_x = (size.x + 7u) / 8u;
    let tiles = tiles_x * ((size.y + 7u) / 8u);
    let tile = wg.y * tiles_x + wg.x;
    for (var w = li; w < FX_VIS_WORDS; w += 64u) {
        var bits = atomicLoad(&fx_vis_mask[w]);
        while bits != 0u {
            let list = w * 32u + firstTrailingBit(bits);
            bits &= bits - 1u;
            let at = atomicAdd(&fx_vis_counts[list], 1u);
            fx_vis_tiles[list * tiles + at] = tile;
        }
    }
}

// Each list's tile count as an indirect dispatch: up to FX_VIS_ROW
// workgroups a row.
@compute @workgroup_size(64)
fn fx_cs_visibility_args(@builtin(global_invocation_id) gid: vec3<u32>) {
    let list = gid.x;
    if list >= FX_VIS_LISTS {
        return;
    }
    let n = atomicLoad(&fx_vis_counts[list]);
    fx_vis_args[list * 3u] = min(n, FX_VIS_ROW);
    fx_vis_args[list * 3u + 1u] = (n + FX_VIS_ROW - 1u) / FX_VIS_ROW;
    fx_vis_args[list * 3u + 2u] = 1u;
}
