//! glTF 2.0 (`.gltf` / `.glb`) loading with validation.
//!
//! Everything a malformed file could use to crash or mislead the renderer is
//! checked and reported as [`SceneError::Gltf`] naming the file: JSON schema
//! problems (including extension values that are not objects), accessor types and
//! byte ranges, index ranges, vertex counts, non-finite values (positions, normals,
//! transforms), node cycles and hierarchy depth. The `gltf` crate runs behind
//! `catch_unwind` as a last defence.
//!
//! Supported: triangle lists, strips and fans; node hierarchy transforms;
//! perspective cameras; `KHR_lights_punctual` (see `convert_light`);
//! metallic-roughness materials mapped exactly onto the `standard` surface and the
//! `cook_torrance` lighting shader (every core factor and texture, alpha mode,
//! double-sided, `KHR_materials_emissive_strength`, `KHR_materials_ior`,
//! `KHR_materials_specular` factors, `KHR_texture_transform` on every texture;
//! see [`UvTransform`]); texture coordinate sets 0 and 1 (`TEXCOORD_1` is loaded
//! into [`Mesh::uvs1`]; a texture reading a higher set reads set 0, with a
//! warning) and vertex colours (`COLOR_0` into [`Mesh::colors`]). Ignored with a
//! log message: points and lines, orthographic cameras, `KHR_materials_specular`
//! textures; ignored silently: skins, morph targets, animations and sampler
//! settings (textures always repeat).

use super::scene::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, NamedCamera, Scene, SceneError,
    TextureImage,
};
use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

/// Deepest node hierarchy accepted.
pub const MAX_NODE_DEPTH: usize = 64;
/// Most vertices accepted in one primitive.
const MAX_VERTICES: usize = 1 << 26;

/// Loads a glTF file into a [`Scene`] (without default lights; see [`Scene::load`]).
pub fn load_gltf(path: &Path) -> Result<Scene, SceneError> {
    let name = path.display().to_string();
    let err = |message: String| SceneError::Gltf {
        path: name.clone(),
        message,
    };
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read the file: {e}")))?;
    check_json_schema(&bytes).map_err(err)?;
    let imported = catch_unwind(AssertUnwindSafe(|| gltf::import(path)))
        .map_err(|p| err(format!("the glTF parser failed: {}", panic_message(&p))))?
        .map_err(|e| err(describe_gltf_error(&e)))?;
    let scene = catch_unwind(AssertUnwindSafe(|| convert(&name, &imported)))
        .map_err(|p| {
            err(format!(
                "internal error while converting: {}",
                panic_message(&p)
            ))
        })?
        .map_err(err)?;
    if scene.triangle_count() == 0 {
        return Err(err("the scene has no triangles to draw".into()));
    }
    log::info!(
        "{name}: {} meshes, {} instances, {} triangles, {} materials, {} textures, {} lights, {} cameras",
        scene.meshes.len(),
        scene.instances.len(),
        scene.triangle_count(),
        scene.materials.len(),
        scene.textures.len(),
        scene.lights.len(),
        scene.cameras.len()
    );
    Ok(scene)
}

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".to_string())
}

fn describe_gltf_error(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Io(io) => format!("cannot read a referenced file: {io}"),
        gltf::Error::Validation(list) => {
            let items: Vec<String> = list
                .iter()
                .take(8)
                .map(|(path, kind)| format!("{}: {kind}", path.as_str()))
                .collect();
            format!("invalid glTF: {}", items.join("; "))
        }
        other => format!("invalid glTF: {other}"),
    }
}

/// The JSON chunk of a `.glb`, or the whole file.
fn json_bytes(bytes: &[u8]) -> Result<&[u8], String> {
    if bytes.len() >= 4 && &bytes[..4] == b"glTF" {
        if bytes.len() < 20 {
            return Err("truncated GLB header".into());
        }
        let len = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
        let kind = &bytes[16..20];
        if kind != b"JSON" {
            return Err("the first GLB chunk is not JSON".into());
        }
        bytes
            .get(20..20usize.saturating_add(len))
            .ok_or_else(|| "truncated GLB JSON chunk".to_string())
    } else {
        Ok(bytes)
    }
}

/// Schema checks the `gltf` crate does not make: every `extensions` member is an
/// object whose values are objects (glTF `extension.schema.json`).
fn check_json_schema(bytes: &[u8]) -> Result<(), String> {
    let json = json_bytes(bytes)?;
    let value: serde_json::Value =
        serde_json::from_slice(json).map_err(|e| format!("invalid JSON: {e}"))?;
    fn walk(v: &serde_json::Value, path: &mut Vec<String>, depth: usize) -> Result<(), String> {
        if depth > 256 {
            return Err("JSON nested too deeply".into());
        }
        match v {
            serde_json::Value::Object(map) => {
                for (k, child) in map {
                    if k == "extras" {
                        continue;
                    }
                    if k == "extensions" {
                        let serde_json::Value::Object(exts) = child else {
                            return Err(format!("{}/extensions must be an object", path.join("/")));
                        };
                        for (name, ext) in exts {
                            if !ext.is_object() {
                                return Err(format!(
                                    "{}/extensions/{name} must be an object, found {ext}",
                                    path.join("/")
                                ));
                            }
                        }
                    }
                    path.push(k.clone());
                    walk(child, path, depth + 1)?;
                    path.pop();
                }
            }
            serde_json::Value::Array(items) => {
                for (i, child) in items.iter().enumerate() {
                    path.push(i.to_string());
                    walk(child, path, depth + 1)?;
                    path.pop();
                }
            }
            _ => {}
        }
        Ok(())
    }
    walk(&value, &mut vec![String::new()], 0)
}

type Imported = (
    gltf::Document,
    Vec<gltf::buffer::Data>,
    Vec<gltf::image::Data>,
);

struct Converter<'a> {
    name: &'a str,
    buffers: &'a [gltf::buffer::Data],
    images: &'a [gltf::image::Data],
    scene: Scene,
    /// glTF (mesh, primitive) → scene mesh index (None: not drawable).
    primitives: HashMap<(usize, usize), Option<usize>>,
    /// glTF material index (None: default material) → scene material.
    materials: HashMap<Option<usize>, usize>,
    /// glTF image index → scene texture.
    textures: HashMap<usize, usize>,
}

fn convert(name: &str, (doc, buffers, images): &Imported) -> Result<Scene, String> {
    let mut c = Converter {
        name,
        buffers,
        images,
        scene: Scene {
            name: name.to_string(),
            ..Default::default()
        },
        primitives: HashMap::new(),
        materials: HashMap::new(),
        textures: HashMap::new(),
    };
    let gscene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| "the file has no scene".to_string())?;
    let mut stack = Vec::new();
    for node in gscene.nodes() {
        c.visit(&node, Mat4::IDENTITY, &mut stack)?;
    }
    Ok(c.scene)
}

impl Converter<'_> {
    fn visit(
        &mut self,
        node: &gltf::Node,
        parent: Mat4,
        stack: &mut Vec<usize>,
    ) -> Result<(), String> {
        let index = node.index();
        if stack.contains(&index) {
            return Err(format!(
                "node {index} is its own ancestor (cycle {} -> {index})",
                stack
                    .iter()
                    .map(|i| i.to_string())
                    .collect::<Vec<_>>()
                    .join(" -> ")
            ));
        }
        if stack.len() >= MAX_NODE_DEPTH {
            return Err(format!(
                "node hierarchy deeper than {MAX_NODE_DEPTH} levels at node {index}"
            ));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(format!("node {index} has a non-finite transform"));
        }
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!("node {index}: the world transform overflows"));
        }
        let node_name = node
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {index}"));
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let key = (mesh.index(), prim.index());
                let mesh_index = match self.primitives.get(&key) {
                    Some(m) => *m,
                    None => {
                        let m = self.primitive(&mesh, &prim)?;
                        self.primitives.insert(key, m);
                        m
                    }
                };
                if let Some(mesh_index) = mesh_index {
                    let material = self.material(prim.material())?;
                    self.scene.instances.push(Instance {
                        name: format!("{node_name}/{}", prim.index()),
                        mesh: mesh_index,
                        material,
                        transform: world,
                    });
                }
            }
        }
        if let Some(cam) = node.camera() {
            match cam.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    let eye = world.transform_point3(Vec3::ZERO);
                    let fwd = world
                        .transform_vector3(Vec3::NEG_Z)
                        .normalize_or(Vec3::NEG_Z);
                    let up = world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
                    let near = p.znear();
                    let far = p.zfar().unwrap_or(near * 1e5);
                    let yfov = p.yfov();
                    if !(near > 0.0 && far > near && yfov > 0.0 && yfov < 3.1) {
                        return Err(format!(
                            "camera {}: invalid perspective (znear {near}, zfar {far}, yfov {yfov})",
                            cam.index()
                        ));
                    }
                    self.scene.cameras.push(NamedCamera {
                        name: cam
                            .name()
                            .map(str::to_string)
                            .unwrap_or_else(|| node_name.clone()),
                        camera: Camera {
                            eye,
                            target: eye + fwd,
                            up,
                            fov_y: yfov,
                            near,
                            far,
                        },
                    });
                }
                gltf::camera::Projection::Orthographic(_) => {
                    log::warn!("{}: orthographic camera {} ignored", self.name, cam.index())
                }
            }
        }
        if let Some(light) = node.light() {
            self.scene
                .lights
                .push(convert_light(self.name, &light, &world)?);
        }
        stack.push(index);
        for child in node.children() {
            self.visit(&child, world, stack)?;
        }
        stack.pop();
        Ok(())
    }

    /// Checks an accessor's type and that its bytes lie inside its view and buffer.
    fn check_accessor(
        &self,
        what: &str,
        acc: &gltf::Accessor,
        dims: &[Dimensions],
        types: &[DataType],
    ) -> Result<(), String> {
        let label = format!("accessor {} ({what})", acc.index());
        if !dims.contains(&acc.dimensions()) {
            return Err(format!(
                "{label}: type {:?}, expected {}",
                acc.dimensions(),
                dims.iter()
                    .map(|d| format!("{d:?}"))
                    .collect::<Vec<_>>()
                    .join(" or ")
            ));
        }
        if !types.contains(&acc.data_type()) {
            return Err(format!(
                "{label}: component type {:?}, expected {}",
                acc.data_type(),
                types
                    .iter()
                    .map(|d| format!("{d:?}"))
                    .collect::<Vec<_>>()
                    .join(" or ")
            ));
        }
        if acc.count() > MAX_VERTICES {
            return Err(format!("{label}: {} elements is too many", acc.count()));
        }
        if let Some(view) = acc.view() {
            let elem = acc.size();
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "{label}: byte stride {stride} < element size {elem}"
                ));
            }
            let needed = if acc.count() == 0 {
                0
            } else {
                acc.offset() + stride * (acc.count() - 1) + elem
            };
            if needed > view.length() {
                return Err(format!(
                    "{label}: needs {needed} bytes but buffer view {} has {}",
                    view.index(),
                    view.length()
                ));
            }
            let buffer = view.buffer().index();
            let have = self.buffers.get(buffer).map_or(0, |b| b.len());
            if view.offset() + view.length() > have {
                return Err(format!(
                    "buffer view {} (bytes {}..{}) is outside buffer {buffer} ({have} bytes)",
                    view.index(),
                    view.offset(),
                    view.offset() + view.length()
                ));
            }
        } else if acc.sparse().is_none() {
            log::warn!("{}: {label} has no data (all zeros)", self.name);
        }
        Ok(())
    }

    /// Converts one primitive; `None` when it is not made of triangles.
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
    ) -> Result<Option<usize>, String> {
        use gltf::mesh::Mode;
        let label = format!("mesh {} primitive {}", mesh.index(), prim.index());
        let mode = prim.mode();
        if matches!(
            mode,
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            log::warn!("{}: {label}: {mode:?} are not drawn", self.name);
        }
        let pos_acc = prim
            .get(&gltf::Semantic::Positions)
            .ok_or_else(|| format!("{label}: no POSITION attribute"))?;
        self.check_accessor(
            &format!("{label} POSITION"),
            &pos_acc,
            &[Dimensions::Vec3],
            &[DataType::F32],
        )?;
        let count = pos_acc.count();
        for (semantic, acc) in prim.attributes() {
            let (dims, types): (&[Dimensions], &[DataType]) = match semantic {
                gltf::Semantic::Normals => (&[Dimensions::Vec3], &[DataType::F32]),
                gltf::Semantic::Tangents => (&[Dimensions::Vec4], &[DataType::F32]),
                gltf::Semantic::TexCoords(_) => (
                    &[Dimensions::Vec2],
                    &[DataType::F32, DataType::U8, DataType::U16],
                ),
                gltf::Semantic::Colors(_) => (
                    &[Dimensions::Vec3, Dimensions::Vec4],
                    &[DataType::F32, DataType::U8, DataType::U16],
                ),
                _ => continue,
            };
            self.check_accessor(&format!("{label} {semantic:?}"), &acc, dims, types)?;
            if acc.count() != count {
                return Err(format!(
                    "{label}: attribute {semantic:?} has {} elements, POSITION has {count}",
                    acc.count()
                ));
            }
        }
        if let Some(idx) = prim.indices() {
            self.check_accessor(
                &format!("{label} indices"),
                &idx,
                &[Dimensions::Scalar],
                &[DataType::U8, DataType::U16, DataType::U32],
            )?;
        }
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| format!("{label}: POSITION data is unreadable"))?
            .map(Vec3::from)
            .collect();
        if positions.len() != count {
            return Err(format!(
                "{label}: read {} positions, accessor says {count}",
                positions.len()
            ));
        }
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "{label}: position {bad} is not finite ({})",
                positions[bad]
            ));
        }
        let raw_indices: Vec<u32> = match reader.read_indices() {
            Some(ri) => ri.into_u32().collect(),
            None => (0..count as u32).collect(),
        };
        if let Some(bad) = raw_indices.iter().position(|&i| i as usize >= count) {
            return Err(format!(
                "{label}: index {} (at {bad}) is out of range: the primitive has {count} vertices",
                raw_indices[bad]
            ));
        }
        let indices: Vec<u32> = match mode {
            Mode::Triangles => {
                if raw_indices.len() % 3 != 0 {
                    return Err(format!(
                        "{label}: a triangle list needs a multiple of 3 indices, has {}",
                        raw_indices.len()
                    ));
                }
                raw_indices
            }
            Mode::TriangleStrip => (2..raw_indices.len())
                .flat_map(|i| {
                    let (a, b, c) = (raw_indices[i - 2], raw_indices[i - 1], raw_indices[i]);
                    if i % 2 == 0 {
                        [a, b, c]
                    } else {
                        [b, a, c]
                    }
                })
                .collect(),
            Mode::TriangleFan => (2..raw_indices.len())
                .flat_map(|i| [raw_indices[0], raw_indices[i - 1], raw_indices[i]])
                .collect(),
            _ => return Ok(None),
        };
        let mut m = Mesh {
            name: format!(
                "{}/{}",
                mesh.name()
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("mesh {}", mesh.index())),
                prim.index()
            ),
            positions,
            indices,
            ..Default::default()
        };
        match reader.read_normals() {
            Some(n) => {
                m.normals = n
                    .map(|v| Vec3::from(v).try_normalize().unwrap_or(Vec3::Y))
                    .collect();
                if m.normals.len() != count {
                    return Err(format!("{label}: NORMAL count differs from POSITION"));
                }
                if let Some(bad) = m.normals.iter().position(|n| !n.is_finite()) {
                    return Err(format!("{label}: normal {bad} is not finite"));
                }
            }
            None => m.compute_normals(),
        }
        let has_uv = match reader.read_tex_coords(0) {
            Some(t) => {
                m.uvs = t.into_f32().map(Vec2::from).collect();
                if m.uvs.len() != count {
                    return Err(format!("{label}: TEXCOORD_0 count differs from POSITION"));
                }
                if m.uvs.iter().any(|u| !u.is_finite()) {
                    return Err(format!("{label}: TEXCOORD_0 has non-finite values"));
                }
                true
            }
            None => {
                m.uvs = vec![Vec2::ZERO; count];
                false
            }
        };
        if let Some(t) = reader.read_tex_coords(1) {
            m.uvs1 = t.into_f32().map(Vec2::from).collect();
            if m.uvs1.len() != count {
                return Err(format!("{label}: TEXCOORD_1 count differs from POSITION"));
            }
            if m.uvs1.iter().any(|u| !u.is_finite()) {
                return Err(format!("{label}: TEXCOORD_1 has non-finite values"));
            }
        }
        if let Some(c) = reader.read_colors(0) {
            // Normalised integers become 0..1, RGB gets alpha 1.
            m.colors = c.into_rgba_f32().map(Vec4::from).collect();
            if m.colors.len() != count {
                return Err(format!("{label}: COLOR_0 count differs from POSITION"));
            }
            if m.colors.iter().any(|c| !c.is_finite()) {
                return Err(format!("{label}: COLOR_0 has non-finite values"));
            }
        }
        let material = prim.material();
        let refs = texture_refs(&material).unwrap_or_default();
        if m.uvs1.is_empty() && refs.iter().any(|r| r.set() == 1) {
            log::warn!(
                "{}: {label}: its material reads TEXCOORD_1, which the primitive lacks \
                 (zeros)",
                self.name
            );
        }
        match reader.read_tangents() {
            Some(t) => {
                let t: Vec<Vec4> = t.map(Vec4::from).collect();
                if t.len() != count || t.iter().any(|v| !v.is_finite()) {
                    return Err(format!("{label}: TANGENT is invalid (count or non-finite)"));
                }
                m.tangents = Some(t);
            }
            None => {
                // Derived from the texture coordinates the normal map reads.
                match refs.iter().find(|r| r.var == "normal_map").map(TexRef::set) {
                    Some(1) if !m.uvs1.is_empty() => {
                        std::mem::swap(&mut m.uvs, &mut m.uvs1);
                        m.compute_tangents();
                        std::mem::swap(&mut m.uvs, &mut m.uvs1);
                    }
                    Some(_) if has_uv => m.compute_tangents(),
                    _ => {}
                }
            }
        }
        self.scene.meshes.push(m);
        Ok(Some(self.scene.meshes.len() - 1))
    }

    fn texture(&mut self, tex: gltf::Texture, what: &str) -> Result<usize, String> {
        let image = tex.source().index();
        if let Some(&t) = self.textures.get(&image) {
            return Ok(t);
        }
        let data = self
            .images
            .get(image)
            .ok_or_else(|| format!("texture {} refers to missing image {image}", tex.index()))?;
        let rgba8 = to_rgba8(data).map_err(|e| format!("image {image} ({what}): {e}"))?;
        let source = tex.source();
        let name = match (source.name(), source.source()) {
            (Some(n), _) => n.to_string(),
            (None, gltf::image::Source::Uri { uri, .. }) if !uri.starts_with("data:") => {
                uri.to_string()
            }
            _ => format!("image {image}"),
        };
        self.scene.textures.push(TextureImage {
            name,
            width: data.width,
            height: data.height,
            rgba8,
        });
        let t = self.scene.textures.len() - 1;
        self.textures.insert(image, t);
        Ok(t)
    }

    /// Binds one texture reference to the standard surface: the texture variable,
    /// `VAR_uv` (the KHR_texture_transform matrix, columns) and `VAR_uv_offset`
    /// (offset, texture coordinate set).
    fn bind_map(&mut self, m: &mut Material, r: &TexRef) -> Result<(), String> {
        let t = self.texture(r.texture.clone(), r.what)?;
        let set = self.uv_set(&m.name, r);
        let [c0x, c0y, c1x, c1y] = r.transform.matrix_columns();
        let [ox, oy] = r.transform.offset;
        m.surface.set_texture(r.var, t);
        m.surface.set(
            &format!("{}_uv", r.var),
            &[c0x, c0y, c1x, c1y].map(f64::from),
        );
        m.surface.set(
            &format!("{}_uv_offset", r.var),
            &[f64::from(ox), f64::from(oy), f64::from(set), 0.0],
        );
        Ok(())
    }

    /// The texture coordinate set a reference reads (0 or 1; larger sets are read
    /// as set 0 with a warning: only `TEXCOORD_0` and `TEXCOORD_1` are loaded).
    fn uv_set(&self, material: &str, r: &TexRef) -> u32 {
        let set = r.set();
        if set > 1 {
            log::warn!(
                "{}: {material}: the {} texture uses TEXCOORD_{set}; only sets 0 and 1 are \
                 supported, reading TEXCOORD_0",
                self.name,
                r.what
            );
            0
        } else {
            set
        }
    }

    /// Maps a glTF material onto the `standard` surface lit by `cook_torrance`
    /// (glTF 2.0 section 3.9 and Appendix B):
    ///
    /// - `base_color` = baseColorFactor, `base_color_map` = baseColorTexture (sRGB;
    ///   the surface multiplies factor, texture and `COLOR_0`);
    /// - `metallic` / `roughness` = metallicFactor / roughnessFactor,
    ///   `metallic_roughness_map` = metallicRoughnessTexture (B = metallic,
    ///   G = roughness, linear);
    /// - `normal_map` = normalTexture with `normal_scale` = its scale;
    /// - `occlusion_map` = occlusionTexture (R) with `occlusion_strength` = its
    ///   strength;
    /// - `emissive` = emissiveFactor × `KHR_materials_emissive_strength`,
    ///   `emissive_map` = emissiveTexture (sRGB);
    /// - `specular` = the dielectric F0: 0.04, or from `KHR_materials_ior`
    ///   (((ior − 1)/(ior + 1))²) and `KHR_materials_specular` factors
    ///   (min(F0_ior · specularColorFactor, 1) · specularFactor; the extension's
    ///   textures and its scaling of F90 are not supported and logged);
    /// - every map's texCoord and `KHR_texture_transform` become `MAP_uv` and
    ///   `MAP_uv_offset` (see [`UvTransform`]);
    /// - alphaMode, alphaCutoff, doubleSided.
    fn material(&mut self, mat: gltf::Material) -> Result<usize, String> {
        if let Some(&m) = self.materials.get(&mat.index()) {
            return Ok(m);
        }
        let name = mat
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| match mat.index() {
                Some(i) => format!("material {i}"),
                None => "default material".into(),
            });
        let pbr = mat.pbr_metallic_roughness();
        let base = Vec4::from(pbr.base_color_factor());
        let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
        if !base.is_finite() || !metallic.is_finite() || !roughness.is_finite() {
            return Err(format!("{name}: non-finite material factors"));
        }
        let mut m = Material::metallic_roughness(&name, base, metallic, roughness);
        let f0 = self.dielectric_f0(&mat, &name)?;
        m.surface.set("specular", &f0.to_array().map(f64::from));
        let strength = mat.emissive_strength().unwrap_or(1.0);
        let emissive = Vec3::from(mat.emissive_factor()) * strength;
        if !emissive.is_finite() || strength < 0.0 {
            return Err(format!(
                "{name}: invalid emissive (factor {:?}, strength {strength})",
                mat.emissive_factor()
            ));
        }
        m.surface
            .set("emissive", &emissive.to_array().map(f64::from));
        for r in texture_refs(&mat).map_err(|e| format!("{name}: {e}"))? {
            self.bind_map(&mut m, &r)?;
        }
        if let Some(n) = mat.normal_texture() {
            if !n.scale().is_finite() {
                return Err(format!("{name}: non-finite normalTexture scale"));
            }
            m.surface.set("normal_scale", &[f64::from(n.scale())]);
        }
        if let Some(o) = mat.occlusion_texture() {
            if !o.strength().is_finite() {
                return Err(format!("{name}: non-finite occlusionTexture strength"));
            }
            m.surface
                .set("occlusion_strength", &[f64::from(o.strength())]);
        }
        m.alpha_mode = match mat.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        m.alpha_cutoff = mat.alpha_cutoff().unwrap_or(0.5);
        if !(m.alpha_cutoff.is_finite() && m.alpha_cutoff >= 0.0) {
            return Err(format!(
                "{name}: alphaCutoff {} must be a number >= 0",
                m.alpha_cutoff
            ));
        }
        m.double_sided = mat.double_sided();
        self.scene.materials.push(m);
        let index = self.scene.materials.len() - 1;
        self.materials.insert(mat.index(), index);
        Ok(index)
    }

    /// The dielectric specular reflectance F0: 0.04 (ior 1.5) unless
    /// `KHR_materials_ior` / `KHR_materials_specular` say otherwise.
    fn dielectric_f0(&self, mat: &gltf::Material, name: &str) -> Result<Vec3, String> {
        let ior = mat.ior().unwrap_or(1.5);
        if !(ior.is_finite() && (ior == 0.0 || ior >= 1.0)) {
            return Err(format!(
                "{name}: KHR_materials_ior ior {ior} must be 0 or >= 1"
            ));
        }
        // (The extension allows ior = 0, which gives F0 = 1.)
        let f0_ior = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let Some(s) = mat.specular() else {
            return Ok(Vec3::splat(f0_ior));
        };
        let color = Vec3::from(s.specular_color_factor());
        let factor = s.specular_factor();
        if !color.is_finite() || !factor.is_finite() || factor < 0.0 || color.min_element() < 0.0 {
            return Err(format!("{name}: invalid KHR_materials_specular factors"));
        }
        if s.specular_texture().is_some() || s.specular_color_texture().is_some() {
            log::warn!(
                "{}: {name}: KHR_materials_specular textures are not supported (factors only)",
                self.name
            );
        }
        Ok((color * f0_ior).min(Vec3::ONE) * factor)
    }
}

/// A `KHR_lights_punctual` light placed by the node's world transform: colour and
/// intensity as given (directional: lux; point, spot: candela), falling off with
/// the inverse square of the distance (attenuation `[0, 0, 1]`; the renderer keeps
/// `d` away from 0) inside the optional `range`, spot cones as given (half-angles).
/// A negative or non-finite intensity or colour, or a range that is not positive,
/// is an error; a light of intensity 0 is kept with a warning.
fn convert_light(
    file: &str,
    light: &gltf::khr_lights_punctual::Light,
    world: &Mat4,
) -> Result<Light, String> {
    let name = light
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("light {}", light.index()));
    let label = format!("light {} ({name})", light.index());
    let color = Vec3::from(light.color());
    let intensity = light.intensity();
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(format!(
            "{label}: colour {color} must be finite and not negative"
        ));
    }
    if !intensity.is_finite() || intensity < 0.0 {
        return Err(format!(
            "{label}: intensity {intensity} must be finite and not negative"
        ));
    }
    if intensity == 0.0 || color.max_element() == 0.0 {
        log::warn!("{file}: {label} has intensity 0 (it lights nothing)");
    }
    let range = match light.range() {
        Some(r) if !(r.is_finite() && r > 0.0) => {
            return Err(format!("{label}: range {r} must be a positive number"))
        }
        r => r,
    };
    let kind = match light.kind() {
        gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
        gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            if !(inner_cone_angle.is_finite() && outer_cone_angle.is_finite()) {
                return Err(format!("{label}: non-finite spot cone angles"));
            }
            let outer = outer_cone_angle.clamp(1e-3, std::f32::consts::FRAC_PI_2);
            let inner = inner_cone_angle.clamp(0.0, outer);
            if inner != inner_cone_angle || outer != outer_cone_angle || inner >= outer {
                log::warn!(
                    "{file}: {label}: spot cone angles (inner {inner_cone_angle}, outer \
                     {outer_cone_angle}) outside 0 <= inner < outer <= pi/2; using inner \
                     {inner}, outer {outer}"
                );
            }
            LightKind::Spot { inner, outer }
        }
    };
    let range = match kind {
        LightKind::Point | LightKind::Spot { .. } => range,
        _ => None,
    };
    Ok(Light {
        name,
        kind,
        color,
        intensity,
        position: world.transform_point3(Vec3::ZERO),
        direction: world
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z),
        attenuation: [0.0, 0.0, 1.0],
        range,
    })
}

/// A `KHR_texture_transform` (identity when absent): `uv' = M · uv + offset` with
/// `M = R(rotation) · S(scale)`.
///
/// The rotation turns the UVs by `rotation` radians "counter-clockwise" as seen in
/// glTF's UV space, whose V axis points *down*:
///
/// ```text
/// R = | cos r   sin r |      u' = cos r · sx · u + sin r · sy · v + offset.x
///     |-sin r   cos r |      v' = −sin r · sx · u + cos r · sy · v + offset.y
/// ```
///
/// This is the matrix of the extension's published example (offset (0, 1),
/// rotation π/2, scale 0.5 selects the lower-left quadrant of the image, rotated
/// clockwise 90°), of its sample model `TextureTransformTest` and of the common
/// implementations (three.js, Babylon.js, Blender). The GLSL listing in the
/// extension's README builds the transpose (a known mistake in the text,
/// KhronosGroup/glTF issue #1563), which would rotate the other way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UvTransform {
    pub offset: [f32; 2],
    /// Radians.
    pub rotation: f32,
    pub scale: [f32; 2],
    /// The extension's `texCoord` override.
    pub tex_coord: Option<u32>,
}

impl UvTransform {
    /// No transform.
    pub const IDENTITY: UvTransform = UvTransform {
        offset: [0.0, 0.0],
        rotation: 0.0,
        scale: [1.0, 1.0],
        tex_coord: None,
    };

    /// `M = R · S` as its columns: `[m00, m10, m01, m11]` (first column in x, y,
    /// second in z, w).
    pub fn matrix_columns(&self) -> [f32; 4] {
        let (s, c) = self.rotation.sin_cos();
        let [sx, sy] = self.scale;
        [c * sx, -s * sx, s * sy, c * sy]
    }

    /// Applies the transform to one texture coordinate.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [a, b, c, d] = self.matrix_columns();
        Vec2::new(a * uv.x + c * uv.y, b * uv.x + d * uv.y) + Vec2::from(self.offset)
    }

    fn check(self, what: &str) -> Result<UvTransform, String> {
        let finite = self.offset.iter().chain(&self.scale).all(|v| v.is_finite())
            && self.rotation.is_finite();
        if finite {
            Ok(self)
        } else {
            Err(format!(
                "{what}: KHR_texture_transform has non-finite values"
            ))
        }
    }

    /// From a texture info's typed extension.
    fn from_info(info: &gltf::texture::Info, what: &str) -> Result<UvTransform, String> {
        match info.texture_transform() {
            None => Ok(UvTransform::IDENTITY),
            Some(t) => UvTransform {
                offset: t.offset(),
                rotation: t.rotation(),
                scale: t.scale(),
                tex_coord: t.tex_coord(),
            }
            .check(what),
        }
    }

    /// From the raw JSON of the extension (normal and occlusion texture infos,
    /// which the `gltf` crate leaves untyped).
    fn from_json(value: Option<&serde_json::Value>, what: &str) -> Result<UvTransform, String> {
        let Some(value) = value else {
            return Ok(UvTransform::IDENTITY);
        };
        let obj = value
            .as_object()
            .ok_or_else(|| format!("{what}: KHR_texture_transform must be an object"))?;
        let pair = |key: &str, default: [f32; 2]| -> Result<[f32; 2], String> {
            match obj.get(key) {
                None => Ok(default),
                Some(v) => match v.as_array().map(|a| a.as_slice()) {
                    Some([x, y]) => match (x.as_f64(), y.as_f64()) {
                        (Some(x), Some(y)) => Ok([x as f32, y as f32]),
                        _ => Err(format!(
                            "{what}: KHR_texture_transform {key} must be two numbers"
                        )),
                    },
                    _ => Err(format!(
                        "{what}: KHR_texture_transform {key} must be two numbers"
                    )),
                },
            }
        };
        let rotation = match obj.get("rotation") {
            None => 0.0,
            Some(v) => v
                .as_f64()
                .ok_or_else(|| format!("{what}: KHR_texture_transform rotation must be a number"))?
                as f32,
        };
        let tex_coord =
            match obj.get("texCoord") {
                None => None,
                Some(v) => Some(v.as_u64().and_then(|n| u32::try_from(n).ok()).ok_or_else(
                    || format!("{what}: KHR_texture_transform texCoord must be an integer >= 0"),
                )?),
            };
        UvTransform {
            offset: pair("offset", [0.0, 0.0])?,
            rotation,
            scale: pair("scale", [1.0, 1.0])?,
            tex_coord,
        }
        .check(what)
    }
}

/// One texture reference of a material.
struct TexRef<'a> {
    /// The standard surface's texture variable.
    var: &'static str,
    /// For messages.
    what: &'static str,
    texture: gltf::Texture<'a>,
    /// The texture info's `texCoord`.
    tex_coord: u32,
    transform: UvTransform,
}

impl TexRef<'_> {
    /// The set read: the extension's override, else the info's `texCoord`.
    fn set(&self) -> u32 {
        self.transform.tex_coord.unwrap_or(self.tex_coord)
    }
}

/// The texture references of a material that the standard surface uses.
fn texture_refs<'a>(mat: &gltf::Material<'a>) -> Result<Vec<TexRef<'a>>, String> {
    let mut out = Vec::new();
    let pbr = mat.pbr_metallic_roughness();
    let infos = [
        (
            "base_color_map",
            "baseColorTexture",
            pbr.base_color_texture(),
        ),
        (
            "metallic_roughness_map",
            "metallicRoughnessTexture",
            pbr.metallic_roughness_texture(),
        ),
        ("emissive_map", "emissiveTexture", mat.emissive_texture()),
    ];
    for (var, what, info) in infos {
        if let Some(info) = info {
            out.push(TexRef {
                var,
                what,
                texture: info.texture(),
                tex_coord: info.tex_coord(),
                transform: UvTransform::from_info(&info, what)?,
            });
        }
    }
    if let Some(n) = mat.normal_texture() {
        let what = "normalTexture";
        out.push(TexRef {
            var: "normal_map",
            what,
            texture: n.texture(),
            tex_coord: n.tex_coord(),
            transform: UvTransform::from_json(n.extension_value("KHR_texture_transform"), what)?,
        });
    }
    if let Some(o) = mat.occlusion_texture() {
        let what = "occlusionTexture";
        out.push(TexRef {
            var: "occlusion_map",
            what,
            texture: o.texture(),
            tex_coord: o.tex_coord(),
            transform: UvTransform::from_json(o.extension_value("KHR_texture_transform"), what)?,
        });
    }
    Ok(out)
}

/// Any decoded glTF image as RGBA8 (16-bit and float channels are scaled/clamped).
fn to_rgba8(d: &gltf::image::Data) -> Result<Vec<u8>, String> {
    use gltf::image::Format as F;
    let px = d.width as usize * d.height as usize;
    let (channels, bytes_per): (usize, usize) = match d.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    if d.pixels.len() < px * channels * bytes_per {
        return Err(format!(
            "{}x{} {:?} needs {} bytes, decoded {}",
            d.width,
            d.height,
            d.format,
            px * channels * bytes_per,
            d.pixels.len()
        ));
    }
    let sample = |i: usize| -> u8 {
        match bytes_per {
            1 => d.pixels[i],
            2 => d.pixels[i * 2 + 1],
            _ => {
                let b = &d.pixels[i * 4..i * 4 + 4];
                let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                (v.clamp(0.0, 1.0) * 255.0).round() as u8
            }
        }
    };
    let mut out = Vec::with_capacity(px * 4);
    for p in 0..px {
        let base = p * channels;
        let rgba = match channels {
            1 => {
                let v = sample(base);
                [v, v, v, 255]
            }
            2 => {
                let v = sample(base);
                [v, v, v, sample(base + 1)]
            }
            3 => [sample(base), sample(base + 1), sample(base + 2), 255],
            _ => [
                sample(base),
                sample(base + 1),
                sample(base + 2),
                sample(base + 3),
            ],
        };
        out.extend_from_slice(&rgba);
    }
    Ok(out)
}
