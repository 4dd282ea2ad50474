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
//! This file reads the node tree and the meshes (each primitive in
//! `primitive.rs`); materials and textures are mapped
//! in `material.rs`, lights and cameras converted in `lights_cameras.rs`, the raw
//! bytes pre-checked in `json_checks.rs`.

mod animation;
mod json_checks;
mod lights_cameras;
mod material;
mod material_layers;
mod nodes;
mod primitive;
mod skin_attributes;

use super::model::{Instance, Scene, SceneError};
use glam::Mat4;
use gltf::accessor::{DataType, Dimensions};
pub use json_checks::MAX_GLTF_FILE_BYTES;
use json_checks::{check_json_schema, check_references, check_uris};
use lights_cameras::{convert_camera, convert_light};
pub use material::UvTransform;
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
        check_accessor_type(&label, acc, dims, types)?;
        if let Some(view) = acc.view() {
            self.check_accessor_bytes(&label, acc, &view)?;
        } else if acc.sparse().is_none() {
            log::warn!("{}: {label} has no data (all zeros)", self.name);
        }
        Ok(())
    }

    /// Checks that an accessor's elements fit its buffer view, and the view
    /// its buffer.
    fn check_accessor_bytes(
        &self,
        label: &str,
        acc: &gltf::Accessor,
        view: &gltf::buffer::View,
    ) -> Result<(), String> {
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
        Ok(())
    }
}

/// Checks an accessor's element type, component type and count.
fn check_accessor_type(
    label: &str,
    acc: &gltf::Accessor,
    dims: &[Dimensions],
    types: &[DataType],
) -> Result<(), String> {
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
    Ok(())
}
