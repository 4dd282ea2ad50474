// GPU skinning and morphing (src/render/skinning.rs): one invocation per vertex
// of a deformed instance writes its morphed and skinned object-space position,
// normal and tangent into the instance's private vertex range (`now`), and its
// position one frame earlier into the same range of the previous-position
// buffer (`prev`, read by the motion-vector pass). No shared memory, no
// barriers.
//
// The same formulas as the CPU reference, src/scene/animation/skin.rs
// (`Pose::deformed_mesh`), which the tests compare this with:
// 1. morph: attribute + sum_k weight_k * delta_k (positions, normals, tangent xyz);
// 2. skin: M = sum of weight * jointMatrix[joint] over 4 or 8 influences
//    (influences of weight 0 or a joint beyond the skin's are skipped); the
//    identity when the instance is not skinned;
// 3. position M * p; normal by the inverse transpose of M's 3x3 (the 3x3
//    itself where it is singular), tangent xyz by the 3x3, both renormalised
//    (kept unnormalised where they collapse to zero);
// 4. flat-shaded meshes (unshared triangles): the face normal of the deformed
//    triangle.

struct SkinInfo {
    // vertices of the mesh (invocations)
    vertices: u32,
    // influence sets per vertex: 0 (not skinned), 1 (4 weights) or 2 (8)
    sets: u32,
    // joint matrices per frame in `pose`
    joints: u32,
    // morph targets (their offsets in `targets`, weights in `pose`)
    targets: u32,
    // first vec4 of this mesh in `mesh` (rest vertices: 3 vec4 each)
    mesh_base: u32,
    // first vec4 of the influences in `mesh` (2 vec4 per vertex and set:
    // joint indices as floats, weights)
    influences: u32,
    // first entry of this mesh's morph targets in `targets`
    target_base: u32,
    // first vec4 of this instance's pose in `pose`: a header (x: 1 deformed,
    // 0 at rest), joint matrices now then one frame earlier (4 vec4 each),
    // morph weights now then one frame earlier (4 per vec4)
    pose_base: u32,
    // 1: flat-shaded (face normals of the deformed triangles)
    flat: u32,
    // invocations per row of workgroups (dispatches wider than 65535 groups)
    row: u32,
    _pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> info: SkinInfo;
@group(0) @binding(1) var<storage, read> mesh: array<vec4<f32>>;
// per target: first vec4 of its position, normal and tangent deltas in `mesh`
// (NONE: the target does not displace that attribute)
@group(0) @binding(2) var<storage, read> targets: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read> pose: array<vec4<f32>>;
// the instance's vertices (18 floats each, `Vertex` of gpu_types.rs)
@group(0) @binding(4) var<storage, read_write> now: array<f32>;
@group(0) @binding(5) var<storage, read_write> prev: array<f32>;

const NONE: u32 = 0xffffffffu;
const STRIDE: u32 = 18u;
const NORMAL: u32 = 3u;
const TANGENT: u32 = 10u;

struct Posed {
    p: vec3<f32>,
    n: vec3<f32>,
    t: vec4<f32>,
}

fn weight(frame: u32, k: u32) -> f32 {
    let f = frame * info.targets + k;
    return pose[info.pose_base + 1u + 8u * info.joints + f / 4u][f % 4u];
}

fn joint(frame: u32, j: u32) -> mat4x4<f32> {
    let i = info.pose_base + 1u + 4u * (frame * info.joints + j);
    return mat4x4<f32>(pose[i], pose[i + 1u], pose[i + 2u], pose[i + 3u]);
}

fn morphed(v: u32, frame: u32) -> Posed {
    let r = info.mesh_base + 3u * v;
    var d = Posed(mesh[r].xyz, mesh[r + 1u].xyz, mesh[r + 2u]);
    for (var k = 0u; k < info.targets; k++) {
        let w = weight(frame, k);
        if (w == 0.0) {
            continue;
        }
        let o = targets[info.target_base + k];
        if (o.x != NONE) {
            d.p += w * mesh[o.x + v].xyz;
        }
        if (o.y != NONE) {
            d.n += w * mesh[o.y + v].xyz;
        }
        if (o.z != NONE) {
            d.t = vec4<f32>(d.t.xyz + w * mesh[o.z + v].xyz, d.t.w);
        }
    }
    return d;
}

fn skin_matrix(v: u32, frame: u32) -> mat4x4<f32> {
    let deformed = pose[info.pose_base].x != 0.0;
    if (info.sets == 0u || info.joints == 0u || !deformed) {
        return mat4x4<f32>(
            vec4<f32>(1.0, 0.0, 0.0, 0.0),
            vec4<f32>(0.0, 1.0, 0.0, 0.0),
            vec4<f32>(0.0, 0.0, 1.0, 0.0),
            vec4<f32>(0.0, 0.0, 0.0, 1.0),
        );
    }
    var m = mat4x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var s = 0u; s < info.sets; s++) {
        let i = info.influences + 2u * (v * info.sets + s);
        let j = mesh[i];
        let w = mesh[i + 1u];
        for (var k = 0u; k < 4u; k++) {
            let jk = u32(j[k]);
            if (w[k] != 0.0 && jk < info.joints) {
                m += joint(frame, jk) * w[k];
            }
        }
    }
    return m;
}

// `d` unit length, or as it is where its length is 0 (or not finite).
fn renormalised(d: vec3<f32>, keep: vec3<f32>) -> vec3<f32> {
    let l = length(d);
    if (l > 0.0 && l < 3.0e38) {
        return d / l;
    }
    return keep;
}

fn deformed_position(v: u32, frame: u32) -> vec3<f32> {
    let m = skin_matrix(v, frame);
    return (m * vec4<f32>(morphed(v, frame).p, 1.0)).xyz;
}

fn deformed(v: u32, frame: u32) -> Posed {
    var d = morphed(v, frame);
    let m = skin_matrix(v, frame);
    let a = m[0].xyz;
    let b = m[1].xyz;
    let c = m[2].xyz;
    let m3 = mat3x3<f32>(a, b, c);
    let det = dot(a, cross(b, c));
    var n = m3 * d.n;
    if (det != 0.0) {
        // inverse transpose = cofactor matrix / det
        n = mat3x3<f32>(cross(b, c), cross(c, a), cross(a, b)) * d.n / det;
    }
    var out: Posed;
    out.p = (m * vec4<f32>(d.p, 1.0)).xyz;
    out.n = renormalised(n, d.n);
    let t = m3 * d.t.xyz;
    let l = length(t);
    out.t = d.t;
    if (l > 0.0 && l < 3.0e38) {
        out.t = vec4<f32>(t / l, d.t.w);
    }
    if (info.flat != 0u && v < info.vertices - info.vertices % 3u) {
        let first = v - v % 3u;
        var p: array<vec3<f32>, 3>;
        for (var i = 0u; i < 3u; i++) {
            p[i] = select(deformed_position(first + i, frame), out.p, first + i == v);
        }
        out.n = renormalised(cross(p[1] - p[0], p[2] - p[0]), vec3<f32>(0.0, 1.0, 0.0));
    }
    return out;
}

@compute @workgroup_size(64)
fn fx_cs_skin(@builtin(global_invocation_id) id: vec3<u32>) {
    let v = id.x + id.y * info.row;
    if (v >= info.vertices) {
        return;
    }
    let d = deformed(v, 0u);
    let o = v * STRIDE;
    now[o] = d.p.x;
    now[o + 1u] = d.p.y;
    now[o + 2u] = d.p.z;
    now[o + NORMAL] = d.n.x;
    now[o + NORMAL + 1u] = d.n.y;
    now[o + NORMAL + 2u] = d.n.z;
    now[o + TANGENT] = d.t.x;
    now[o + TANGENT + 1u] = d.t.y;
    now[o + TANGENT + 2u] = d.t.z;
    now[o + TANGENT + 3u] = d.t.w;
    let q = deformed_position(v, 1u);
    prev[o] = q.x;
    prev[o + 1u] = q.y;
    prev[o + 2u] = q.z;
}
