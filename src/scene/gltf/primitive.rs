//! One glTF primitive converted into a [`Mesh`]: its accessors checked, the
//! positions and triangle indices (lists, strips and fans) read, then the
//! normals, texture coordinates, colours, skin attributes and tangents (given,
//! or derived from the texture coordinates the normal map reads).

use super::material::{texture_refs, TexRef};
use super::{skin_attributes, Converter};
use crate::scene::model::Mesh;
use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Reader};

/// A primitive's attribute reader, with its name in messages and its vertex
/// count (POSITION's).
struct Attributes<'p, 'a, 's, F>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    label: &'p str,
    count: usize,
    reader: &'p Reader<'a, 's, F>,
}

impl Converter<'_> {
    /// Converts one primitive; `None` when it is not made of triangles.
    pub(super) fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
    ) -> Result<Option<usize>, String> {
        let label = format!("mesh {} primitive {}", mesh.index(), prim.index());
        let mode = prim.mode();
        if matches!(
            mode,
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            log::warn!("{}: {label}: {mode:?} are not drawn", self.name);
        }
        let count = self.check_primitive_accessors(&label, prim)?;
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let attrs = Attributes {
            label: &label,
            count,
            reader: &reader,
        };
        let positions = attrs.positions()?;
        let Some(indices) = attrs.triangles(mode)? else {
            return Ok(None);
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
        let flat = !attrs.normals(&mut m)?;
        let has_uv = attrs.tex_coords_and_colors(&mut m)?;
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
            Some(t) => m.tangents = Some(attrs.tangents(t)?),
            None => derive_tangents(&mut m, &material, &refs, has_uv),
        }
        self.scene.meshes.push(m);
        Ok(Some(self.scene.meshes.len() - 1))
    }

    /// Checks the accessors of POSITION, the other attributes read (each as
    /// many as POSITION) and the indices; returns the vertex count.
    fn check_primitive_accessors(
        &self,
        label: &str,
        prim: &gltf::Primitive,
    ) -> Result<usize, String> {
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
        Ok(count)
    }
}

impl<'a, 's, F> Attributes<'_, 'a, 's, F>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    /// The positions: `count` of them, all finite.
    fn positions(&self) -> Result<Vec<Vec3>, String> {
        let (label, count) = (self.label, self.count);
        let positions: Vec<Vec3> = self
            .reader
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
        Ok(positions)
    }

    /// The indices (0, 1, 2… without an index accessor), all in range, as a
    /// triangle list; `None` when `mode` is not made of triangles.
    fn triangles(&self, mode: Mode) -> Result<Option<Vec<u32>>, String> {
        let (label, count) = (self.label, self.count);
        let raw_indices: Vec<u32> = match self.reader.read_indices() {
            Some(ri) => ri.into_u32().collect(),
            None => (0..count as u32).collect(),
        };
        if let Some(bad) = raw_indices.iter().position(|&i| i as usize >= count) {
            return Err(format!(
                "{label}: index {} (at {bad}) is out of range: the primitive has {count} vertices",
                raw_indices[bad]
            ));
        }
        Ok(Some(match mode {
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
        }))
    }

    /// The normals, normalised; `false` when there are none (glTF: flat
    /// normals then, and no given tangents).
    fn normals(&self, m: &mut Mesh) -> Result<bool, String> {
        let (label, count) = (self.label, self.count);
        let Some(n) = self.reader.read_normals() else {
            return Ok(false);
        };
        m.normals = n
            .map(|v| Vec3::from(v).try_normalize().unwrap_or(Vec3::Y))
            .collect();
        if m.normals.len() != count {
            return Err(format!("{label}: NORMAL count differs from POSITION"));
        }
        if let Some(bad) = m.normals.iter().position(|n| !n.is_finite()) {
            return Err(format!("{label}: normal {bad} is not finite"));
        }
        Ok(true)
    }

    /// Texture coordinate sets 0 (zeros without it) and 1, and `COLOR_0`;
    /// returns whether set 0 was given.
    fn tex_coords_and_colors(&self, m: &mut Mesh) -> Result<bool, String> {
        let (label, count) = (self.label, self.count);
        let has_uv = match self.reader.read_tex_coords(0) {
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
        if let Some(t) = self.reader.read_tex_coords(1) {
            m.uvs1 = t.into_f32().map(Vec2::from).collect();
            check_vertex_values(label, "TEXCOORD_1", &m.uvs1, count, Vec2::is_finite)?;
        }
        if let Some(c) = self.reader.read_colors(0) {
            // Normalised integers become 0..1, RGB gets alpha 1.
            m.colors = c.into_rgba_f32().map(Vec4::from).collect();
            check_vertex_values(label, "COLOR_0", &m.colors, count, Vec4::is_finite)?;
        }
        Ok(has_uv)
    }

    /// The given tangents: `count` of them, all finite.
    fn tangents(&self, t: impl Iterator<Item = [f32; 4]>) -> Result<Vec<Vec4>, String> {
        let t: Vec<Vec4> = t.map(Vec4::from).collect();
        if t.len() != self.count || t.iter().any(|v| !v.is_finite()) {
            return Err(format!(
                "{}: TANGENT is invalid (count or non-finite)",
                self.label
            ));
        }
        Ok(t)
    }
}

/// Tangents derived from the texture coordinates the normal map reads (a
/// clear coat normal map alone: set 0), when it reads a set the mesh has.
fn derive_tangents(m: &mut Mesh, material: &gltf::Material, refs: &[TexRef], has_uv: bool) {
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
