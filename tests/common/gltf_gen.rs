//! A generator of small test glTF files: UV spheres with metallic-roughness
//! materials, one `KHR_lights_punctual` light and a perspective camera, in one
//! `.gltf` with its buffer and images embedded as base64 data URIs.
//!
//! The default scene ([`write_spheres_gltf`]): three spheres of radius
//! [`SPHERE_RADIUS`] at [`SPHERE_CENTRES`] with the materials of
//! [`SPHERE_MATERIALS`] (a rough dielectric, a smooth dielectric, a metal), lit by
//! [`DIRECTIONAL`], seen by the camera [`CAMERA_EYE`] → [`CAMERA_TARGET`] with a
//! vertical field of view [`CAMERA_FOV_Y`]. [`SpheresGltf::textured`] adds a fourth
//! sphere at [`TEXTURED_CENTRE`] whose material ([`textured`]) uses every core
//! texture, `KHR_texture_transform`, `TEXCOORD_1` and `COLOR_0`.

use fxgraph::scene::Camera;
use glam::{Quat, Vec2, Vec3};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Radius of every sphere.
pub const SPHERE_RADIUS: f32 = 1.0;
/// Centres of the three untextured spheres (left to right).
pub const SPHERE_CENTRES: [Vec3; 3] = [
    Vec3::new(-2.2, 0.0, 0.0),
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(2.2, 0.0, 0.0),
];
/// Centre of the textured sphere (below the middle one).
pub const TEXTURED_CENTRE: Vec3 = Vec3::new(0.0, -2.2, 0.0);
/// Longitude segments and latitude rings of the UV spheres.
pub const SEGMENTS: u32 = 64;
pub const RINGS: u32 = 32;

/// The camera node: at `CAMERA_EYE` looking at `CAMERA_TARGET` (+Y up).
pub const CAMERA_EYE: Vec3 = Vec3::new(0.0, 0.0, 8.0);
pub const CAMERA_TARGET: Vec3 = Vec3::ZERO;
/// Vertical field of view of the camera, radians (45°).
pub const CAMERA_FOV_Y: f32 = std::f32::consts::FRAC_PI_4;
pub const CAMERA_ZNEAR: f32 = 0.1;
pub const CAMERA_ZFAR: f32 = 100.0;

/// The file's camera as the renderer's [`Camera`].
pub fn camera() -> Camera {
    Camera {
        eye: CAMERA_EYE,
        target: CAMERA_TARGET,
        up: Vec3::Y,
        fov_y: CAMERA_FOV_Y,
        near: CAMERA_ZNEAR,
        far: CAMERA_ZFAR,
    }
}

/// A metallic-roughness material of a sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereMaterial {
    pub name: &'static str,
    pub base_color: [f32; 4],
    pub metallic: f32,
    pub roughness: f32,
}

/// The materials of the spheres at [`SPHERE_CENTRES`].
pub const SPHERE_MATERIALS: [SphereMaterial; 3] = [
    SphereMaterial {
        name: "rough_dielectric",
        base_color: [0.8, 0.2, 0.2, 1.0],
        metallic: 0.0,
        roughness: 0.9,
    },
    SphereMaterial {
        name: "smooth_dielectric",
        base_color: [0.2, 0.45, 0.8, 1.0],
        metallic: 0.0,
        roughness: 0.2,
    },
    SphereMaterial {
        name: "metal",
        base_color: [1.0, 0.78, 0.34, 1.0],
        metallic: 1.0,
        roughness: 0.35,
    },
];

/// The light of a generated file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GltfLight {
    /// Travelling along `direction` (the node is rotated so that its −Z is it);
    /// `intensity` in lux.
    Directional {
        direction: Vec3,
        color: Vec3,
        intensity: f32,
    },
    /// At `position`; `intensity` in candela.
    Point {
        position: Vec3,
        color: Vec3,
        intensity: f32,
        range: Option<f32>,
    },
}

/// The default light: from the camera's side, above and to the left.
pub const DIRECTIONAL: GltfLight = GltfLight::Directional {
    direction: Vec3::new(0.4, -0.6, -0.7),
    color: Vec3::new(1.0, 0.95, 0.9),
    intensity: 3.0,
};

/// The point-light variant ([`write_spheres_gltf_point`]).
pub const POINT: GltfLight = GltfLight::Point {
    position: Vec3::new(1.5, 2.5, 3.5),
    color: Vec3::new(1.0, 1.0, 1.0),
    intensity: 40.0,
    range: Some(12.0),
};

/// The textured material's settings (fourth sphere), as written to the file.
pub mod textured {
    /// Name of the material.
    pub const NAME: &str = "textured";
    pub const BASE_COLOR: [f32; 4] = [1.0, 1.0, 1.0, 0.8];
    pub const METALLIC: f32 = 0.5;
    pub const ROUGHNESS: f32 = 0.6;
    pub const EMISSIVE: [f32; 3] = [1.0, 0.5, 0.25];
    pub const EMISSIVE_STRENGTH: f32 = 4.0;
    pub const NORMAL_SCALE: f32 = 0.7;
    pub const OCCLUSION_STRENGTH: f32 = 0.5;
    pub const ALPHA_CUTOFF: f32 = 0.3;
    /// baseColorTexture: texture 0, texCoord 0 overridden to 1 by its
    /// KHR_texture_transform (offset, rotation, scale).
    pub const BASE_OFFSET: [f32; 2] = [0.25, 0.5];
    pub const BASE_ROTATION: f32 = std::f32::consts::FRAC_PI_6;
    pub const BASE_SCALE: [f32; 2] = [2.0, 3.0];
    /// normalTexture: texture 1, texCoord 1, KHR_texture_transform rotation only.
    pub const NORMAL_ROTATION: f32 = std::f32::consts::FRAC_PI_2;
    /// metallicRoughnessTexture: texture 1 (the same image as occlusion),
    /// texCoord 0, KHR_texture_transform offset only.
    pub const MR_OFFSET: [f32; 2] = [0.5, 0.0];
    /// COLOR_0 of the textured sphere: unsigned-byte normalised RGB.
    pub const COLOR_0_U8: [u8; 3] = [255, 204, 51];
    /// Names of the two embedded images.
    pub const IMAGE_NAMES: [&str; 2] = ["checker", "orm"];
}

/// What [`spheres_gltf_json`] writes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpheresGltf {
    pub light: GltfLight,
    /// Adds the textured fourth sphere.
    pub textured: bool,
}

impl Default for SpheresGltf {
    fn default() -> Self {
        SpheresGltf {
            light: DIRECTIONAL,
            textured: false,
        }
    }
}

/// `dir/spheres.gltf`: the three spheres under [`DIRECTIONAL`].
pub fn write_spheres_gltf(dir: &Path) -> PathBuf {
    write_gltf(
        dir,
        "spheres.gltf",
        &spheres_gltf_json(&SpheresGltf::default()),
    )
}

/// `dir/spheres_point.gltf`: the three spheres under [`POINT`] (with a range).
pub fn write_spheres_gltf_point(dir: &Path) -> PathBuf {
    write_gltf(
        dir,
        "spheres_point.gltf",
        &spheres_gltf_json(&SpheresGltf {
            light: POINT,
            textured: false,
        }),
    )
}

/// `dir/spheres_textured.gltf`: the three spheres plus the textured one, under
/// [`DIRECTIONAL`].
pub fn write_spheres_gltf_textured(dir: &Path) -> PathBuf {
    write_gltf(
        dir,
        "spheres_textured.gltf",
        &spheres_gltf_json(&SpheresGltf {
            light: DIRECTIONAL,
            textured: true,
        }),
    )
}

/// Writes `json` to `dir/name` and returns the path.
pub fn write_gltf(dir: &Path, name: &str, json: &Value) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_vec_pretty(json).unwrap()).unwrap();
    path
}

/// The vertices of a UV sphere of radius 1 around the origin, pole on +Y:
/// positions (= normals) and texture coordinates `u = j / SEGMENTS` (longitude),
/// `v = i / RINGS` (0 at the top), and CCW (outside) triangle indices.
pub fn uv_sphere() -> (Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
    let (mut pos, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=RINGS {
        let theta = std::f32::consts::PI * i as f32 / RINGS as f32;
        for j in 0..=SEGMENTS {
            let phi = std::f32::consts::TAU * j as f32 / SEGMENTS as f32;
            pos.push(Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            ));
            uv.push(Vec2::new(
                j as f32 / SEGMENTS as f32,
                i as f32 / RINGS as f32,
            ));
        }
    }
    let row = SEGMENTS + 1;
    for i in 0..RINGS {
        for j in 0..SEGMENTS {
            let (a, b) = (i * row + j, i * row + j + 1);
            let (c, d) = (a + row, b + row);
            if i != 0 {
                idx.extend_from_slice(&[a, c, b]);
            }
            if i != RINGS - 1 {
                idx.extend_from_slice(&[b, c, d]);
            }
        }
    }
    (pos, uv, idx)
}

/// The texture coordinates of set 1 of the textured sphere: `(v, u)` of set 0.
pub fn uv1_of(uv0: Vec2) -> Vec2 {
    Vec2::new(uv0.y, uv0.x)
}

/// The scene of [`write_spheres_gltf`] (`textured`: of
/// [`write_spheres_gltf_textured`]) loaded by the renderer from a temporary file.
pub fn load_spheres(textured: bool) -> fxgraph::scene::Scene {
    let dir = tempfile::tempdir().unwrap();
    let path = if textured {
        write_spheres_gltf_textured(dir.path())
    } else {
        write_spheres_gltf(dir.path())
    };
    fxgraph::scene::Scene::load(path.to_str().unwrap()).unwrap()
}

/// The little-endian bytes of float vectors (a glTF buffer's data).
fn le_bytes<const N: usize>(vectors: impl IntoIterator<Item = [f32; N]>) -> Vec<u8> {
    vectors
        .into_iter()
        .flatten()
        .flat_map(f32::to_le_bytes)
        .collect()
}

/// The glTF document (see [`SpheresGltf`]); change it and write it with
/// [`write_gltf`] to make variants.
pub fn spheres_gltf_json(opts: &SpheresGltf) -> Value {
    let (pos, uv, idx) = uv_sphere();
    let n = pos.len();
    let mut buf = Bytes::default();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut add =
        |buf: &mut Bytes, data: Vec<u8>, stride: Option<usize>, target: u32, acc: Value| {
            let offset = buf.append(&data);
            let mut view = json!({
                "buffer": 0, "byteOffset": offset, "byteLength": data.len(), "target": target
            });
            if let Some(s) = stride {
                view["byteStride"] = json!(s);
            }
            views.push(view);
            let mut acc = acc;
            acc["bufferView"] = json!(views.len() - 1);
            accessors.push(acc);
            accessors.len() - 1
        };
    const ARRAY: u32 = 34962;
    const ELEMENTS: u32 = 34963;
    // The accessor of `n` float vectors of `kind`.
    let floats = |kind: &str| json!({"componentType": 5126, "count": n, "type": kind});
    let mut bounded = floats("VEC3");
    bounded["min"] = json!([-1.0, -1.0, -1.0]);
    bounded["max"] = json!([1.0, 1.0, 1.0]);
    // The normals of a unit sphere at the origin are its positions.
    let points = le_bytes(pos.iter().map(|p| p.to_array()));
    let positions = add(&mut buf, points.clone(), None, ARRAY, bounded);
    let normals = add(&mut buf, points, None, ARRAY, floats("VEC3"));
    let set0 = le_bytes(uv.iter().map(|p| p.to_array()));
    let uv0 = add(&mut buf, set0, None, ARRAY, floats("VEC2"));
    let indices = add(
        &mut buf,
        idx.iter().flat_map(|i| i.to_le_bytes()).collect(),
        None,
        ELEMENTS,
        json!({"componentType": 5125, "count": idx.len(), "type": "SCALAR"}),
    );
    let mut materials: Vec<Value> = SPHERE_MATERIALS
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": m.base_color,
                    "metallicFactor": m.metallic,
                    "roughnessFactor": m.roughness
                }
            })
        })
        .collect();
    let attributes = json!({"POSITION": positions, "NORMAL": normals, "TEXCOORD_0": uv0});
    let mut meshes: Vec<Value> = SPHERE_MATERIALS
        .iter()
        .enumerate()
        .map(|(i, m)| {
            json!({
                "name": m.name,
                "primitives": [{"attributes": attributes, "indices": indices, "material": i}]
            })
        })
        .collect();
    let mut nodes: Vec<Value> = SPHERE_CENTRES
        .iter()
        .zip(SPHERE_MATERIALS)
        .enumerate()
        .map(|(i, (c, m))| json!({"name": m.name, "mesh": i, "translation": c.to_array()}))
        .collect();
    let mut root = json!({
        "asset": {"version": "2.0", "generator": "fxgraph tests/common/gltf_gen.rs"},
        "extensionsUsed": ["KHR_lights_punctual"],
    });
    if opts.textured {
        use textured as t;
        let set1 = le_bytes(uv.iter().map(|p| uv1_of(*p).to_array()));
        let uv1 = add(&mut buf, set1, None, ARRAY, floats("VEC2"));
        // Unsigned-byte RGB colours, each element padded to 4 bytes (stride 4).
        let colors = add(
            &mut buf,
            (0..n)
                .flat_map(|_| {
                    let [r, g, b] = t::COLOR_0_U8;
                    [r, g, b, 0]
                })
                .collect(),
            Some(4),
            ARRAY,
            json!({"componentType": 5121, "normalized": true, "count": n, "type": "VEC3"}),
        );
        materials.push(json!({
            "name": t::NAME,
            "pbrMetallicRoughness": {
                "baseColorFactor": t::BASE_COLOR,
                "metallicFactor": t::METALLIC,
                "roughnessFactor": t::ROUGHNESS,
                "baseColorTexture": {"index": 0, "texCoord": 0, "extensions": {
                    "KHR_texture_transform": {
                        "offset": t::BASE_OFFSET, "rotation": t::BASE_ROTATION,
                        "scale": t::BASE_SCALE, "texCoord": 1
                    }
                }},
                "metallicRoughnessTexture": {"index": 1, "extensions": {
                    "KHR_texture_transform": {"offset": t::MR_OFFSET}
                }}
            },
            "normalTexture": {"index": 1, "texCoord": 1, "scale": t::NORMAL_SCALE,
                "extensions": {"KHR_texture_transform": {"rotation": t::NORMAL_ROTATION}}},
            "occlusionTexture": {"index": 1, "texCoord": 1, "strength": t::OCCLUSION_STRENGTH},
            "emissiveTexture": {"index": 0},
            "emissiveFactor": t::EMISSIVE,
            "alphaMode": "MASK",
            "alphaCutoff": t::ALPHA_CUTOFF,
            "doubleSided": true,
            "extensions": {"KHR_materials_emissive_strength": {
                "emissiveStrength": t::EMISSIVE_STRENGTH
            }}
        }));
        meshes.push(json!({
            "name": t::NAME,
            "primitives": [{
                "attributes": {"POSITION": positions, "NORMAL": normals, "TEXCOORD_0": uv0,
                               "TEXCOORD_1": uv1, "COLOR_0": colors},
                "indices": indices,
                "material": 3
            }]
        }));
        nodes.push(json!({"name": t::NAME, "mesh": 3, "translation": TEXTURED_CENTRE.to_array()}));
        let checker = png_data_uri(4, 4, |x, y| {
            if (x + y) % 2 == 0 {
                [230, 230, 230, 255]
            } else {
                [40, 90, 200, 255]
            }
        });
        let orm = png_data_uri(2, 2, |x, y| [255, 60 + 120 * x as u8, 200 * y as u8, 255]);
        root["images"] = json!([
            {"name": t::IMAGE_NAMES[0], "uri": checker},
            {"name": t::IMAGE_NAMES[1], "uri": orm}
        ]);
        root["samplers"] = json!([{"magFilter": 9729, "minFilter": 9987}]);
        root["textures"] = json!([{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}]);
        root["extensionsUsed"] = json!([
            "KHR_lights_punctual",
            "KHR_texture_transform",
            "KHR_materials_emissive_strength"
        ]);
    }
    let light = match opts.light {
        GltfLight::Directional {
            direction,
            color,
            intensity,
        } => {
            let rot = Quat::from_rotation_arc(Vec3::NEG_Z, direction.normalize());
            nodes.push(json!({"name": "light", "rotation": rot.to_array(),
                              "extensions": {"KHR_lights_punctual": {"light": 0}}}));
            json!({"name": "sun", "type": "directional", "color": color.to_array(),
                   "intensity": intensity})
        }
        GltfLight::Point {
            position,
            color,
            intensity,
            range,
        } => {
            nodes.push(json!({"name": "light", "translation": position.to_array(),
                              "extensions": {"KHR_lights_punctual": {"light": 0}}}));
            let mut l = json!({"name": "bulb", "type": "point", "color": color.to_array(),
                               "intensity": intensity});
            if let Some(r) = range {
                l["range"] = json!(r);
            }
            l
        }
    };
    // The camera looks along −Z from CAMERA_EYE (CAMERA_TARGET is straight ahead).
    nodes.push(json!({"name": "camera", "camera": 0, "translation": CAMERA_EYE.to_array()}));
    let buffer_len = buf.0.len();
    root["buffers"] = json!([{
        "byteLength": buffer_len,
        "uri": format!("data:application/octet-stream;base64,{}", base64(&buf.0))
    }]);
    root["bufferViews"] = json!(views);
    root["accessors"] = json!(accessors);
    root["materials"] = json!(materials);
    root["meshes"] = json!(meshes);
    root["scenes"] = json!([{"nodes": (0..nodes.len()).collect::<Vec<_>>()}]);
    root["scene"] = json!(0);
    root["nodes"] = json!(nodes);
    root["cameras"] = json!([{"type": "perspective", "perspective": {
        "yfov": CAMERA_FOV_Y, "znear": CAMERA_ZNEAR, "zfar": CAMERA_ZFAR
    }}]);
    root["extensions"] = json!({"KHR_lights_punctual": {"lights": [light]}});
    root
}

/// The binary buffer, every piece 4-byte aligned.
#[derive(Default)]
struct Bytes(Vec<u8>);

impl Bytes {
    fn append(&mut self, data: &[u8]) -> usize {
        while self.0.len() % 4 != 0 {
            self.0.push(0);
        }
        let offset = self.0.len();
        self.0.extend_from_slice(data);
        offset
    }
}

/// An RGBA8 PNG as a `data:image/png;base64,` URI.
pub fn png_data_uri(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> String {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().unwrap();
        let data: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| f(x, y))
            .collect();
        writer.write_image_data(&data).unwrap();
    }
    format!("data:image/png;base64,{}", base64(&bytes))
}

/// Standard base64 with padding.
pub fn base64(data: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The bytes of standard base64 text (the inverse of [`base64`]).
pub fn base64_decode(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=').map(value).collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let mut n = 0u32;
        for (i, &b) in chunk.iter().enumerate() {
            n |= u32::from(b) << (18 - 6 * i);
        }
        for i in 0..chunk.len() - 1 {
            out.push((n >> (16 - 8 * i)) as u8);
        }
    }
    out
}
