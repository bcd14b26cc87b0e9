//! Meshes: each triangle primitive's attributes (POSITION, indices, NORMAL, TEXCOORD_0,
//! COLOR_0) read and checked, then joined into one [`SourceMesh`] per glTF mesh.

use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;

use crate::mesh::scene::SourceMesh;

use super::accessor::{
    Decode, Expect, FLOAT, FLOAT_OR_UNORM, UNSIGNED, decode_color, decode_index, decode_vec2, decode_vec3, type_name,
};
use super::geometry::{assemble_triangles, computed_normals, normalise_or_fill};
use super::{Fail, Importer, invalid};

/// glTF's neutral vertex colour, used where a primitive has no COLOR_0.
const WHITE: [f32; 4] = [1.0; 4];

/// The primitive being read: its label in messages and its vertex (POSITION) count.
#[derive(Clone, Copy)]
struct Vertices<'l> {
    label: &'l str,
    count: usize,
}

/// One triangle primitive, read and checked, before it joins its mesh.
struct ReadPrimitive {
    /// Where its vertices start in the mesh.
    base: u32,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    colors: Option<Vec<[f32; 4]>>,
    material: Option<u32>,
    /// Triangles, indexing the primitive's own vertices.
    triangles: Vec<[u32; 3]>,
}

impl ReadPrimitive {
    /// Appends the primitive's vertices and triangles to `mesh`.
    fn append_to(self, mesh: &mut SourceMesh) {
        let base = mesh.positions_local.len();
        let vertex_count = self.positions.len();
        mesh.positions_local.extend_from_slice(&self.positions);
        mesh.normals_local.extend_from_slice(&self.normals);
        mesh.uvs.extend_from_slice(&self.uvs);
        match self.colors {
            Some(colors) => {
                // Earlier primitives without COLOR_0 get glTF's neutral white.
                mesh.colors.resize(base, WHITE);
                mesh.colors.extend_from_slice(&colors);
            }
            None if !mesh.colors.is_empty() => mesh.colors.resize(base + vertex_count, WHITE),
            None => {}
        }
        mesh.triangle_materials.extend(std::iter::repeat_n(self.material, self.triangles.len()));
        mesh.triangles.extend(self.triangles.iter().map(|t| t.map(|i| i + self.base)));
    }
}

impl Importer<'_, '_> {
    /// The scene mesh for glTF mesh `index`, built on first use.
    pub(super) fn mesh_for(&mut self, index: usize, non_triangle: &mut usize) -> Result<Option<u32>, Fail> {
        if let Some(&known) = self.mesh_map.get(&index) {
            return Ok(known);
        }
        let mesh = self.build_mesh(index, non_triangle)?;
        let result = if mesh.triangles.is_empty() {
            None
        } else {
            let Ok(slot) = u32::try_from(self.scene.meshes.len()) else {
                return invalid("too many meshes");
            };
            self.scene.meshes.push(mesh);
            Some(slot)
        };
        self.mesh_map.insert(index, result);
        Ok(result)
    }

    /// The triangle primitives of glTF mesh `index` joined into one mesh; point and line
    /// primitives are only counted in `non_triangle`.
    fn build_mesh(&mut self, index: usize, non_triangle: &mut usize) -> Result<SourceMesh, Fail> {
        let root = self.root;
        let Some(gltf_mesh) = root.meshes.get(index) else {
            return invalid(format!("mesh {index} does not exist"));
        };
        let mut mesh = SourceMesh {
            name: gltf_mesh.name.clone().unwrap_or_else(|| format!("mesh {index}")),
            ..SourceMesh::default()
        };
        for (p, primitive) in gltf_mesh.primitives.iter().enumerate() {
            let label = format!("mesh {index} primitive {p}");
            let Checked::Valid(mode) = primitive.mode else {
                return invalid(format!("{label}: invalid mode"));
            };
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                *non_triangle += 1;
                continue;
            }
            let read = self.read_primitive(primitive, mode, &label, mesh.positions_local.len())?;
            read.append_to(&mut mesh);
        }
        Ok(mesh)
    }

    /// Reads one triangle primitive whose vertices will start at `base` in its mesh.
    fn read_primitive(
        &mut self,
        primitive: &json::mesh::Primitive,
        mode: Mode,
        label: &str,
        base: usize,
    ) -> Result<ReadPrimitive, Fail> {
        let attribute = |semantic: Semantic| primitive.attributes.get(&Checked::Valid(semantic)).map(|a| a.value());
        let Some(position_accessor) = attribute(Semantic::Positions) else {
            return invalid(format!("{label}: no POSITION attribute"));
        };
        let positions = self.read_positions(position_accessor, label)?;
        let vertices = Vertices { label, count: positions.len() };
        let Some(base) = u32::try_from(base)
            .ok()
            .filter(|b| u32::try_from(vertices.count).is_ok_and(|n| b.checked_add(n).is_some()))
        else {
            return invalid(format!("{label}: the mesh has more than 2^32 vertices"));
        };
        let corners: Vec<u32> = match primitive.indices {
            Some(indices_accessor) => self.read_indices(indices_accessor.value(), vertices)?,
            None => (0..u32::try_from(vertices.count).unwrap_or(0)).collect(),
        };
        let (triangles, leftover) = assemble_triangles(&corners, mode);
        if leftover > 0 {
            self.scene
                .warnings
                .push(format!("{label}: {leftover} trailing index(es) do not form a whole triangle and were ignored"));
        }
        let normals = match attribute(Semantic::Normals) {
            Some(accessor) => self.read_normals(accessor, vertices, &positions, &triangles)?,
            None => computed_normals(&positions, &triangles),
        };
        let uvs = match attribute(Semantic::TexCoords(0)) {
            Some(accessor) => self.read_uvs(accessor, vertices)?,
            None => vec![[0.0, 0.0]; vertices.count],
        };
        let colors = match attribute(Semantic::Colors(0)) {
            Some(accessor) => Some(self.read_colors(accessor, vertices)?),
            None => None,
        };
        let material = match primitive.material {
            Some(material) => Some(self.material_for(material.value())?),
            None => None,
        };
        Ok(ReadPrimitive { base, positions, normals, uvs, colors, material, triangles })
    }

    /// Reads POSITION (float VEC3), refusing non-finite positions.
    fn read_positions(&mut self, index: usize, label: &str) -> Result<Vec<[f32; 3]>, Fail> {
        let expect = Expect { purpose: format!("{label} POSITION"), ty: Type::Vec3, components: FLOAT };
        let positions = self.read_accessor(index, &expect, decode_vec3)?;
        if let Some(bad) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return invalid(format!(
                "{label}: POSITION (accessor {index}) of vertex {bad} is non-finite (NaN or infinite)"
            ));
        }
        Ok(positions)
    }

    /// Reads the indices (unsigned scalars), refusing any out of the vertex range.
    fn read_indices(&mut self, index: usize, vertices: Vertices<'_>) -> Result<Vec<u32>, Fail> {
        let Vertices { label, count } = vertices;
        let expect = Expect { purpose: format!("{label} indices"), ty: Type::Scalar, components: UNSIGNED };
        let indices = self.read_accessor(index, &expect, decode_index)?;
        if let Some((k, &bad)) = indices.iter().enumerate().find(|&(_, &i)| i as usize >= count) {
            return invalid(format!(
                "{label}: index {bad} at position {k} of accessor {index} is out of range (the primitive has {count} vertices)"
            ));
        }
        Ok(indices)
    }

    /// Reads vertex attribute `name` (accessor `index`), which must have one element per
    /// vertex.
    fn read_vertex_attribute<T: Copy + Default>(
        &mut self,
        index: usize,
        vertices: Vertices<'_>,
        name: &str,
        ty: Type,
        components: &'static [(ComponentType, bool)],
        decode: Decode<T>,
    ) -> Result<Vec<T>, Fail> {
        let Vertices { label, count } = vertices;
        let values =
            self.read_accessor(index, &Expect { purpose: format!("{label} {name}"), ty, components }, decode)?;
        if values.len() != count {
            return invalid(format!("{label}: {name} has {} elements but POSITION has {count}", values.len()));
        }
        Ok(values)
    }

    /// Reads NORMAL (float VEC3) normalised; zero or non-finite normals are replaced by
    /// ones computed from the faces (with one warning).
    fn read_normals(
        &mut self,
        index: usize,
        vertices: Vertices<'_>,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<Vec<[f32; 3]>, Fail> {
        let normals = self.read_vertex_attribute(index, vertices, "NORMAL", Type::Vec3, FLOAT, decode_vec3)?;
        let (normals, replaced) = normalise_or_fill(&normals, positions, triangles);
        if replaced > 0 {
            self.scene
                .warnings
                .push(format!("{}: {replaced} zero or non-finite normal(s) replaced by computed ones", vertices.label));
        }
        Ok(normals)
    }

    /// Reads TEXCOORD_0 (float or normalized unsigned byte/short VEC2); non-finite
    /// coordinates become (0, 0) (with one warning).
    fn read_uvs(&mut self, index: usize, vertices: Vertices<'_>) -> Result<Vec<[f32; 2]>, Fail> {
        let mut uvs =
            self.read_vertex_attribute(index, vertices, "TEXCOORD_0", Type::Vec2, FLOAT_OR_UNORM, decode_vec2)?;
        let mut replaced = 0usize;
        for uv in &mut uvs {
            if !uv.iter().all(|c| c.is_finite()) {
                *uv = [0.0, 0.0];
                replaced += 1;
            }
        }
        if replaced > 0 {
            self.scene
                .warnings
                .push(format!("{}: {replaced} non-finite texture coordinate(s) replaced by (0, 0)", vertices.label));
        }
        Ok(uvs)
    }

    /// Reads COLOR_0 (float VEC3/VEC4 or normalized unsigned byte/short) as linear RGBA:
    /// RGB gets alpha 1, non-finite colours become white and values outside `[0, 1]` are
    /// clamped (each with one warning per primitive).
    fn read_colors(&mut self, index: usize, vertices: Vertices<'_>) -> Result<Vec<[f32; 4]>, Fail> {
        let label = vertices.label;
        let ty = match self.root.accessors.get(index).map(|accessor| accessor.type_) {
            Some(Checked::Valid(Type::Vec3)) => Type::Vec3,
            Some(Checked::Valid(Type::Vec4)) | None | Some(Checked::Invalid) => Type::Vec4,
            Some(Checked::Valid(other)) => {
                return invalid(format!(
                    "{label} COLOR_0 (accessor {index}): wrong accessor type {} (expected VEC3 or VEC4)",
                    type_name(other)
                ));
            }
        };
        let mut colors = self.read_vertex_attribute(index, vertices, "COLOR_0", ty, FLOAT_OR_UNORM, decode_color)?;
        let (mut replaced, mut clamped) = (0usize, 0usize);
        for color in &mut colors {
            if !color.iter().all(|c| c.is_finite()) {
                *color = WHITE;
                replaced += 1;
            } else if color.iter().any(|c| !(0.0..=1.0).contains(c)) {
                *color = color.map(|c| c.clamp(0.0, 1.0));
                clamped += 1;
            }
        }
        if replaced > 0 {
            self.scene.warnings.push(format!("{label}: {replaced} non-finite vertex colour(s) replaced by white"));
        }
        if clamped > 0 {
            self.scene.warnings.push(format!("{label}: {clamped} vertex colour(s) outside [0, 1] clamped"));
        }
        Ok(colors)
    }
}
