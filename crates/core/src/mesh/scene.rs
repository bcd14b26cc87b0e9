//! The imported scene: what a glTF file contributes before welding.
//!
//! Pure data, no parsing and no GPU. The importer (`import.rs`) fills it; welding
//! (`weld.rs`) turns it into one indexed triangle mesh with shared vertices.

use glam::Mat4;

/// One glTF mesh (all of its triangle primitives), in the mesh's local space.
///
/// Vertices are the glTF vertices of every primitive concatenated; they are *not*
/// welded yet. Attribute vectors all have `positions_local.len()` entries, except
/// [`SourceMesh::colors`], which is empty when the mesh has no vertex colours.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SourceMesh {
    /// Name from the glTF file, or `mesh N`.
    pub name: String,
    /// POSITION values exactly as stored in the file (finite, checked by the importer).
    pub positions_local: Vec<[f32; 3]>,
    /// Unit normals in local space (computed from the faces when the file has none).
    pub normals_local: Vec<[f32; 3]>,
    /// TEXCOORD_0, or `[0, 0]` when the primitive has none.
    pub uvs: Vec<[f32; 2]>,
    /// COLOR_0 per vertex as linear RGBA (RGB colours get alpha 1), clamped to `[0, 1]`.
    /// Empty when no primitive of the mesh has COLOR_0; when only some have it, the
    /// vertices of the others are white (glTF's neutral vertex colour).
    pub colors: Vec<[f32; 4]>,
    /// Triangles as indices into the vertex arrays above (strips and fans already expanded).
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the index into [`Scene::materials`] (or `None` for the default material).
    pub triangle_materials: Vec<Option<u32>>,
}

/// One placement of a [`SourceMesh`] reachable from the default scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Index into [`Scene::meshes`].
    pub mesh: u32,
    /// The node's global transform (product of the transforms from the scene root).
    pub world_from_local: Mat4,
}

/// The part of a glTF material the painter uses: the base colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// `baseColorFactor`, linear RGBA.
    pub base_color_factor: [f32; 4],
    /// Index into [`Scene::textures`] of the base-colour texture, if any and decodable.
    pub base_color_texture: Option<u32>,
}

/// A decoded base-colour texture, RGBA8 with sRGB-encoded colour channels.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width * height * 4` bytes, rows top to bottom.
    pub rgba8_srgb: Vec<u8>,
}

/// Everything the importer keeps from one file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// Meshes referenced by at least one instance.
    pub meshes: Vec<SourceMesh>,
    /// Mesh placements (a mesh used by two nodes appears twice).
    pub instances: Vec<Instance>,
    /// Materials referenced by triangles.
    pub materials: Vec<Material>,
    /// Decoded base-colour textures.
    pub textures: Vec<Texture>,
    /// Human-readable notes about what was skipped or ignored (one line each).
    pub warnings: Vec<String>,
}

impl Scene {
    /// Number of triangles over all instances, before welding.
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .filter_map(|instance| self.meshes.get(instance.mesh as usize))
            .map(|mesh| mesh.triangles.len())
            .sum()
    }
}
