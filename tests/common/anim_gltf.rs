//! Animated glTF files for the animation tests, and an independent reader of
//! glTF accessors (for the corpus tests: key times, values, inverse bind
//! matrices, joints and weights read straight from the file's base64 buffers,
//! not through fxgraph's loader).
//!
//! [`GltfBuilder`] packs accessors into one embedded buffer; [`node_scene`] makes
//! the usual file: one triangle mesh (optionally skinned or morphed) on node 0,
//! more nodes as given, and animations.

use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};
use std::path::PathBuf;

/// The interpolated value at `tc` from the formulas of glTF 2.0 Appendix C, in
/// f64: `values` holds `width` floats per element, one element per key (three —
/// in-tangent, value, out-tangent — for CUBICSPLINE). Before the first key the
/// first value, after the last the last (§3.11).
pub fn appendix_c(
    interp: &str,
    times: &[f32],
    values: &[f32],
    width: usize,
    rotation: bool,
    tc: f64,
) -> Vec<f64> {
    let per_key = if interp == "CUBICSPLINE" { 3 } else { 1 };
    let elem = |k: usize, e: usize| -> Vec<f64> {
        let i = (k * per_key + e) * width;
        values[i..i + width].iter().map(|&v| v as f64).collect()
    };
    let value = |k: usize| elem(k, if per_key == 3 { 1 } else { 0 });
    let n = times.len();
    let t = |k: usize| times[k] as f64;
    if tc <= t(0) {
        return value(0);
    }
    if tc >= t(n - 1) {
        return value(n - 1);
    }
    // t_k <= t_c < t_{k+1}
    let k = (0..n - 1).find(|&k| t(k) <= tc && tc < t(k + 1)).unwrap();
    if tc == t(k) {
        return value(k);
    }
    let td = t(k + 1) - t(k);
    let s = (tc - t(k)) / td;
    let mut out: Vec<f64> = match interp {
        "STEP" => value(k),
        "LINEAR" if rotation => {
            let (vk, vk1) = (value(k), value(k + 1));
            let dot: f64 = vk.iter().zip(&vk1).map(|(a, b)| a * b).sum();
            let a = dot.abs().min(1.0).acos();
            let sign = dot.signum();
            if a < 1e-9 {
                vk.iter()
                    .zip(&vk1)
                    .map(|(x, y)| (1.0 - s) * x + s * sign * y)
                    .collect()
            } else {
                vk.iter()
                    .zip(&vk1)
                    .map(|(x, y)| {
                        (a * (1.0 - s)).sin() / a.sin() * x + sign * (a * s).sin() / a.sin() * y
                    })
                    .collect()
            }
        }
        "LINEAR" => value(k)
            .iter()
            .zip(value(k + 1))
            .map(|(x, y)| (1.0 - s) * x + s * y)
            .collect(),
        "CUBICSPLINE" => {
            let (vk, bk, vk1, ak1) = (elem(k, 1), elem(k, 2), elem(k + 1, 1), elem(k + 1, 0));
            (0..width)
                .map(|i| {
                    (2.0 * s.powi(3) - 3.0 * s * s + 1.0) * vk[i]
                        + td * (s.powi(3) - 2.0 * s * s + s) * bk[i]
                        + (-2.0 * s.powi(3) + 3.0 * s * s) * vk1[i]
                        + td * (s.powi(3) - s * s) * ak1[i]
                })
                .collect()
        }
        other => panic!("{other}"),
    };
    if rotation {
        let len = out.iter().map(|v| v * v).sum::<f64>().sqrt();
        out.iter_mut().for_each(|v| *v /= len);
    }
    out
}

/// The animated corpus model `NAME/NAME.gltf` (../shared/corpus/gltf/animated);
/// panics with a clear message when the corpus is absent.
pub fn animated_corpus(name: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/corpus/gltf/animated")
        .join(name)
        .join(format!("{name}.gltf"));
    assert!(
        path.is_file(),
        "the animated glTF corpus file {} is missing (the corpus lives in ../shared/corpus; \
         see its README.md)",
        path.display()
    );
    path
}

/// Accessors packed into one buffer (each in its own 4-aligned buffer view).
#[derive(Default)]
pub struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl GltfBuilder {
    fn push(&mut self, bytes: &[u8], component: u32, count: usize, ty: &str) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()
        }));
        self.bin.extend_from_slice(bytes);
        self.accessors.push(json!({
            "bufferView": self.views.len() - 1, "componentType": component,
            "count": count, "type": ty
        }));
        self.accessors.len() - 1
    }

    /// A float accessor of type `ty` (`SCALAR`, `VEC3`, `VEC4`, `MAT4`) with
    /// `min`/`max` (NaN ignored).
    pub fn f32s(&mut self, data: &[f32], ty: &str) -> usize {
        let n = components(ty);
        assert_eq!(data.len() % n, 0);
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let i = self.push(&bytes, 5126, data.len() / n, ty);
        let mut min = vec![f32::INFINITY; n];
        let mut max = vec![f32::NEG_INFINITY; n];
        for e in data.chunks(n) {
            for k in 0..n {
                if !e[k].is_nan() {
                    min[k] = min[k].min(e[k]);
                    max[k] = max[k].max(e[k]);
                }
            }
        }
        self.accessors[i]["min"] = json!(min);
        self.accessors[i]["max"] = json!(max);
        i
    }

    /// An unsigned short accessor (`JOINTS_n`, or normalised weights when
    /// `normalized`).
    pub fn u16s(&mut self, data: &[u16], ty: &str, normalized: bool) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let i = self.push(&bytes, 5123, data.len() / components(ty), ty);
        if normalized {
            self.accessors[i]["normalized"] = json!(true);
        }
        i
    }

    /// An unsigned byte accessor.
    pub fn u8s(&mut self, data: &[u8], ty: &str, normalized: bool) -> usize {
        let i = self.push(data, 5121, data.len() / components(ty), ty);
        if normalized {
            self.accessors[i]["normalized"] = json!(true);
        }
        i
    }

    /// The glTF document: `doc` (nodes, meshes, scenes, animations, ...) plus the
    /// asset, buffer, views and accessors.
    pub fn finish(self, mut doc: Value) -> Value {
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{
            "byteLength": self.bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}",
                super::gltf_gen::base64(&self.bin))
        }]);
        doc["bufferViews"] = json!(self.views);
        doc["accessors"] = json!(self.accessors);
        doc
    }
}

fn components(ty: &str) -> usize {
    match ty {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT4" => 16,
        other => panic!("type {other}"),
    }
}

/// One animation channel to write: `path` of `node`, keys and flattened values.
pub struct ChannelSpec<'a> {
    pub node: usize,
    pub path: &'a str,
    pub interpolation: &'a str,
    pub times: &'a [f32],
    pub values: &'a [f32],
}

/// The rest positions of the test triangle (node 0's mesh).
pub const TRIANGLE: [Vec3; 3] = [
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
];

/// A file: node 0 holds the triangle (with the extra primitive attributes and
/// `targets` given), `extra_nodes` follow (indices 1..), node 0 and the nodes in
/// `roots` are the scene's roots, and one animation (named `anim`) per list of
/// channels.
pub fn node_scene(
    b: &mut GltfBuilder,
    attributes: Value,
    targets: Option<Value>,
    extra_nodes: Vec<Value>,
    roots: &[usize],
    animations: &[Vec<ChannelSpec>],
) -> Value {
    let pos: Vec<f32> = TRIANGLE.iter().flat_map(|p| p.to_array()).collect();
    let normals: Vec<f32> = [0.0, 0.0, 1.0].repeat(3);
    let mut attrs = json!({
        "POSITION": b.f32s(&pos, "VEC3"),
        "NORMAL": b.f32s(&normals, "VEC3"),
    });
    for (k, v) in attributes.as_object().unwrap() {
        attrs[k] = v.clone();
    }
    let mut prim = json!({"attributes": attrs});
    if let Some(t) = targets {
        prim["targets"] = t;
    }
    let mut nodes = vec![json!({"mesh": 0, "name": "triangle"})];
    nodes.extend(extra_nodes);
    let mut scene_roots = vec![0];
    scene_roots.extend_from_slice(roots);
    let anims: Vec<Value> = animations
        .iter()
        .enumerate()
        .map(|(a, channels)| {
            let mut samplers = Vec::new();
            let mut chans = Vec::new();
            for (i, c) in channels.iter().enumerate() {
                let width = match c.path {
                    "rotation" => "VEC4",
                    "weights" => "SCALAR",
                    _ => "VEC3",
                };
                samplers.push(json!({
                    "input": b.f32s(c.times, "SCALAR"),
                    "output": b.f32s(c.values, width),
                    "interpolation": c.interpolation,
                }));
                chans.push(json!({"sampler": i, "target": {"node": c.node, "path": c.path}}));
            }
            json!({"name": format!("anim{a}"), "samplers": samplers, "channels": chans})
        })
        .collect();
    let mut doc = json!({
        "scene": 0,
        "scenes": [{"nodes": scene_roots}],
        "nodes": nodes,
        "meshes": [{"primitives": [prim]}],
    });
    if !anims.is_empty() {
        doc["animations"] = json!(anims);
    }
    doc
}

/// Writes `doc` to a new temporary folder; the folder lives as long as the guard.
pub fn write(doc: &Value, name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = super::gltf_gen::write_gltf(dir.path(), name, doc);
    (dir, path)
}

/// A glTF file read independently of fxgraph: the JSON and its decoded buffers.
pub struct RawGltf {
    pub json: Value,
    buffers: Vec<Vec<u8>>,
}

impl RawGltf {
    /// Reads a `.gltf` whose buffers are base64 `data:` URIs.
    pub fn read(path: &std::path::Path) -> RawGltf {
        let json: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
        let buffers = json["buffers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                let uri = b["uri"].as_str().unwrap();
                let data = uri.split_once(";base64,").expect("a base64 data URI").1;
                base64::decode(data).unwrap()
            })
            .collect();
        RawGltf { json, buffers }
    }

    /// Accessor `index` as rows of floats: float components as stored, integer
    /// ones as their values (divided by 255 / 65535 when `normalized`).
    pub fn accessor(&self, index: usize) -> Vec<Vec<f32>> {
        let a = &self.json["accessors"][index];
        let n = components(a["type"].as_str().unwrap());
        let ct = a["componentType"].as_u64().unwrap();
        let size = match ct {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let view = &self.json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let buf = &self.buffers[view["buffer"].as_u64().unwrap() as usize];
        let base = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let stride = view["byteStride"].as_u64().unwrap_or((size * n) as u64) as usize;
        let normalized = a["normalized"].as_bool().unwrap_or(false);
        (0..a["count"].as_u64().unwrap() as usize)
            .map(|i| {
                (0..n)
                    .map(|k| {
                        let o = base + i * stride + k * size;
                        let b = &buf[o..o + size];
                        match ct {
                            5126 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                            5121 if normalized => b[0] as f32 / 255.0,
                            5121 => b[0] as f32,
                            5123 if normalized => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
                            5123 => u16::from_le_bytes([b[0], b[1]]) as f32,
                            other => panic!("component type {other} not read here"),
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// A float array of node `i`'s JSON (`default` when absent).
    fn node_floats(&self, i: usize, key: &str, default: &[f32]) -> Vec<f32> {
        self.json["nodes"][i]
            .get(key)
            .map_or(default.to_vec(), |v| {
                v.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap() as f32)
                    .collect()
            })
    }

    /// Node `i`'s translation, rotation and scale from its JSON (defaults where
    /// absent).
    pub fn trs(&self, i: usize) -> (Vec3, Quat, Vec3) {
        (
            Vec3::from_slice(&self.node_floats(i, "translation", &[0.0; 3])),
            Quat::from_slice(&self.node_floats(i, "rotation", &[0.0, 0.0, 0.0, 1.0])),
            Vec3::from_slice(&self.node_floats(i, "scale", &[1.0; 3])),
        )
    }

    /// Node `i`'s local matrix from its JSON (`matrix`, or T · R · S).
    pub fn local(&self, i: usize) -> Mat4 {
        if self.json["nodes"][i].get("matrix").is_some() {
            return Mat4::from_cols_slice(&self.node_floats(i, "matrix", &[]));
        }
        let (t, r, s) = self.trs(i);
        Mat4::from_translation(t) * Mat4::from_quat(r) * Mat4::from_scale(s)
    }

    /// The parent of node `i` from the `children` lists.
    pub fn parent(&self, i: usize) -> Option<usize> {
        self.json["nodes"].as_array().unwrap().iter().position(|n| {
            n["children"]
                .as_array()
                .is_some_and(|c| c.iter().any(|x| x.as_u64() == Some(i as u64)))
        })
    }

    /// Node `i`'s global matrix with the local matrices `local` gives.
    pub fn global(&self, i: usize, local: &dyn Fn(usize) -> Mat4) -> Mat4 {
        match self.parent(i) {
            Some(p) => self.global(p, local) * local(i),
            None => local(i),
        }
    }
}
