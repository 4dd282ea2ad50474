//! glTF 2.0 (`.gltf` / `.glb`) loading with validation.
//!
//! Everything a malformed file could use to crash or mislead the renderer is
//! checked and reported as [`SceneError::Gltf`] naming the file: JSON schema
//! problems (including extension values that are not objects), accessor types and
//! byte ranges, index ranges, vertex counts, non-finite values (positions, normals,
//! transforms, skin weights, morph displacements, key times and values), node
//! cycles, nodes with two parents and hierarchy depth, and every animation channel
//! and skin (`animation.rs`). The `gltf` crate runs behind
//! `crate::unwind::catch_quiet` as a last defence (its panic text never printed).
//!
//! Supported: triangle lists, strips and fans; the node hierarchy, kept in
//! [`Scene::nodes`] (`nodes.rs`) so that instances, lights and cameras move with
//! their nodes; perspective cameras; `KHR_lights_punctual` (`lights_cameras.rs`);
//! metallic-roughness materials mapped exactly onto the `standard` surface and the
//! `cook_torrance` lighting shader (every core factor and texture, alpha mode,
//! double-sided, `KHR_materials_emissive_strength`, `KHR_materials_ior`,
//! `KHR_materials_specular` factors, `KHR_materials_clearcoat` and
//! `KHR_materials_transmission` (`material_layers.rs`), `KHR_texture_transform` on every texture;
//! see [`UvTransform`]); texture coordinate sets 0 and 1 (`TEXCOORD_1` is loaded
//! into [`Mesh::uvs1`]; a texture reading a higher set reads set 0, with a
//! warning) and vertex colours (`COLOR_0` into [`Mesh::colors`]); animations of
//! node translation, rotation, scale and morph weights with STEP, LINEAR and
//! CUBICSPLINE keys (`animation.rs`, played by [`crate::scene::animation`]);
//! skins of up to [`crate::scene::MAX_JOINTS`] joints with 4 or 8 influences
//! (`JOINTS_0/1`, `WEIGHTS_0/1`: unsigned bytes or shorts, float or normalised
//! weights, renormalised to sum 1) and morph targets of `POSITION`, `NORMAL` and
//! `TANGENT` (at most [`crate::scene::MAX_MORPH_TARGETS`]), with the mesh's and
//! the node's default weights (`skin_attributes.rs`). Ignored with a log message:
//! points and lines, orthographic cameras, `KHR_materials_specular` textures,
//! `JOINTS_2`/`WEIGHTS_2` and later sets; ignored silently: morphed `TEXCOORD_n`
//! and `COLOR_n`, tangents of morphed meshes whose tangents are derived (not
//! given), `KHR_animation_pointer` and sampler settings (textures always repeat).
//!
//! This file reads the node tree and the meshes; materials and textures are mapped
//! in `material.rs`, lights and cameras converted in `lights_cameras.rs`, the raw
//! bytes pre-checked in `json_checks.rs`.

mod animation;
mod json_checks;
mod lights_cameras;
mod material;
mod material_layers;
mod nodes;
mod skin_attributes;

use super::model::{Instance, Mesh, Scene, SceneError};
use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
pub use json_checks::MAX_GLTF_FILE_BYTES;
use json_checks::{check_json_schema, check_references, check_uris};
use lights_cameras::{convert_camera, convert_light};
pub use material::UvTransform;
use material::{texture_refs, TexRef};
use std::collections::HashMap;
use std::path::Path;

pub use crate::scene::node::MAX_NODE_DEPTH;
/// Most vertices accepted in one primitive.
const MAX_VERTICES: usize = 1 << 26;

/// Loads a glTF file into a [`Scene`] (without default lights; see [`Scene::load`]).
pub fn load_gltf(path: &Path) -> Result<Scene, SceneError> {
    let name = path.display().to_string();
    let err = |message: String| SceneError::Gltf {
        path: name.clone(),
        message,
    };
    let bytes = crate::io::read_regular_file(path, MAX_GLTF_FILE_BYTES).map_err(|e| match e {
        crate::io::IoError::Decode { message, .. } => err(message),
        other => err(format!(
            "cannot read the file: {}",
            std::error::Error::source(&other).map_or(String::new(), |s| s.to_string())
        )),
    })?;
    check_json_schema(&bytes).map_err(err)?;
    check_uris(path, &bytes).map_err(err)?;
    check_references(&bytes).map_err(err)?;
    let imported = crate::unwind::catch_quiet(|| gltf::import(path))
        .map_err(|p| err(format!("the glTF parser failed: {p}")))?
        .map_err(|e| err(describe_gltf_error(&e)))?;
    let scene = crate::unwind::catch_quiet(|| convert(&name, &imported))
        .map_err(|p| err(format!("internal error while converting: {p}")))?
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
        // (An embedded PNG's error names chunks by their `Debug` form.)
        other => format!(
            "invalid glTF: {}",
            crate::io::tidy_png_message(&other.to_string())
        ),
    }
}

type Imported = (
    gltf::Document,
    Vec<gltf::buffer::Data>,
    Vec<gltf::image::Data>,
);

/// The conversion of one glTF file into a [`Scene`] (its material and texture
/// methods are in `material.rs`).
pub(super) struct Converter<'a> {
    pub(super) name: &'a str,
    pub(super) document: &'a gltf::Document,
    buffers: &'a [gltf::buffer::Data],
    pub(super) images: &'a [gltf::image::Data],
    pub(super) scene: Scene,
    /// glTF (mesh, primitive) → scene mesh index (None: not drawable).
    primitives: HashMap<(usize, usize), Option<usize>>,
    /// glTF material index (None: default material) → scene material.
    pub(super) materials: HashMap<Option<usize>, usize>,
    /// glTF image index → scene texture.
    pub(super) textures: HashMap<usize, usize>,
}

fn convert(name: &str, (doc, buffers, images): &Imported) -> Result<Scene, String> {
    let mut c = Converter {
        name,
        document: doc,
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
    c.scene.skins = c.skins(doc)?;
    let mut stack = Vec::new();
    for node in gscene.nodes() {
        c.visit(&node, Mat4::IDENTITY, &mut stack)?;
    }
    c.scene.nodes = nodes::read_nodes(name, doc)?;
    for inst in &mut c.scene.instances {
        if let Some(node) = inst.node.and_then(|n| c.scene.nodes.get(n)) {
            inst.morph_weights = node.weights.clone();
        }
    }
    c.scene.animations = c.animations(doc)?;
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
        // The same local and world matrices as the rest pose (`Scene::pose`).
        let local = nodes::rest_transform(node).matrix();
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
                    let name = format!("{node_name}/{}", prim.index());
                    let skin = self.instance_skin(node, mesh_index, &name)?;
                    self.scene.instances.push(Instance {
                        name,
                        mesh: mesh_index,
                        material,
                        transform: world,
                        node: Some(index),
                        skin,
                        // from the node's rest weights, once all nodes are read
                        morph_weights: Vec::new(),
                    });
                }
            }
        }
        if let Some(cam) = node.camera() {
            if let Some(camera) = convert_camera(self.name, &cam, &world, index, &node_name)? {
                self.scene.cameras.push(camera);
            }
        }
        if let Some(light) = node.light() {
            self.scene
                .lights
                .push(convert_light(self.name, &light, &world, index)?);
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
        if acc.count() == 0 {
            // (the `gltf` crate's readers underflow on it)
            return Err(format!("{label}: count 0 (glTF requires at least 1)"));
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
                Some(0)
            } else {
                stride
                    .checked_mul(acc.count() - 1)
                    .and_then(|n| n.checked_add(acc.offset()))
                    .and_then(|n| n.checked_add(elem))
            };
            let Some(needed) = needed else {
                return Err(format!(
                    "{label}: offset {} + stride {stride} × {} elements overflows",
                    acc.offset(),
                    acc.count()
                ));
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
            if view
                .offset()
                .checked_add(view.length())
                .is_none_or(|end| end > have)
            {
                return Err(format!(
                    "buffer view {} (bytes {}..{}) is outside buffer {buffer} ({have} bytes)",
                    view.index(),
                    view.offset(),
                    view.offset().saturating_add(view.length())
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
        let mut flat = false;
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
            // glTF: without normals, flat normals (and no given tangents)
            None => flat = true,
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
            check_vertex_values(&label, "TEXCOORD_1", &m.uvs1, count, Vec2::is_finite)?;
        }
        if let Some(c) = reader.read_colors(0) {
            // Normalised integers become 0..1, RGB gets alpha 1.
            m.colors = c.into_rgba_f32().map(Vec4::from).collect();
            check_vertex_values(&label, "COLOR_0", &m.colors, count, Vec4::is_finite)?;
        }
        skin_attributes::SkinReader {
            conv: self,
            label: &label,
            mesh,
            prim,
            reader: &reader,
        }
        .read(&mut m)?;
        if flat {
            m.make_flat();
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
        match reader.read_tangents().filter(|_| !flat) {
            Some(t) => {
                let t: Vec<Vec4> = t.map(Vec4::from).collect();
                if t.len() != count || t.iter().any(|v| !v.is_finite()) {
                    return Err(format!("{label}: TANGENT is invalid (count or non-finite)"));
                }
                m.tangents = Some(t);
            }
            None => {
                // Derived from the texture coordinates the normal map reads (a
                // clear coat normal map alone: set 0).
                let coat_normal = material
                    .extension_value("KHR_materials_clearcoat")
                    .is_some_and(|c| c.get("clearcoatNormalTexture").is_some());
                let normal_set = refs.iter().find(|r| r.var == "normal_map").map(TexRef::set);
                match normal_set.or(coat_normal.then_some(0)) {
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
}

/// Checks an optional attribute read for every vertex: `count` values, all finite.
fn check_vertex_values<T: Copy>(
    label: &str,
    what: &str,
    values: &[T],
    count: usize,
    finite: fn(T) -> bool,
) -> Result<(), String> {
    if values.len() != count {
        return Err(format!("{label}: {what} count differs from POSITION"));
    }
    if !values.iter().all(|&v| finite(v)) {
        return Err(format!("{label}: {what} has non-finite values"));
    }
    Ok(())
}
