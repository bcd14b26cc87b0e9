//! Welding: the imported scene becomes one indexed triangle mesh in world space.
//!
//! Within one glTF mesh (all of its primitives) vertices whose POSITION values are
//! bitwise equal become one vertex, so UV seams and hard-normal splits no longer cut the
//! surface and painting across them is seamless (BoxTextured's 24 glTF vertices are 8).
//! Every node instance is its own copy. Triangles whose welded corners repeat are dropped
//! and counted; vertices no kept triangle uses are dropped too.

use glam::{Mat3, Mat4, Vec3};

use crate::mesh::scene::Scene;

/// One indexed triangle mesh, every instance of the scene concatenated, in world space.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WeldedMesh {
    /// World-space position of each welded vertex.
    pub positions_world: Vec<[f32; 3]>,
    /// Triangles as welded vertex ids, corners in the file's winding order.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, the TEXCOORD_0 of each corner (faces keep their own UVs across seams).
    pub corner_uvs: Vec<[[f32; 2]; 3]>,
    /// Per triangle, the unit world-space normal of each corner.
    pub corner_normals_world: Vec<[[f32; 3]; 3]>,
    /// Per triangle, its material index into the scene's materials.
    pub triangle_materials: Vec<Option<u32>>,
    /// Triangles dropped because two or more welded corners were the same vertex.
    pub degenerate_triangles_dropped: u64,
    /// COLOR_0 of each welded vertex (linear RGBA; the first glTF vertex welded into it
    /// decides), or empty when no mesh of the scene has vertex colours.
    pub vertex_colors: Vec<[f32; 4]>,
}

/// One source mesh welded in its local space (shared by all of its instances).
struct LocalWeld {
    /// Local positions of the welded vertices that kept triangles use.
    positions_local: Vec<Vec3>,
    /// For each of those, the first source vertex welded into it.
    source_vertex: Vec<u32>,
    /// Kept triangles as local welded ids, with the index of the source triangle.
    triangles: Vec<([u32; 3], usize)>,
    /// Source triangles dropped as degenerate.
    dropped: u64,
}

fn weld_local(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> LocalWeld {
    // Bitwise key: -0.0 and 0.0 stay distinct, exactly as "bitwise-equal" says.
    let mut id_of_key: rustc_hash::FxHashMap<[u32; 3], u32> =
        rustc_hash::FxHashMap::with_capacity_and_hasher(positions.len(), Default::default());
    let mut welded_of_source = Vec::with_capacity(positions.len());
    let mut welded_positions: Vec<Vec3> = Vec::new();
    let mut first_source: Vec<u32> = Vec::new();
    for (source, position) in positions.iter().enumerate() {
        let key = position.map(f32::to_bits);
        let next = welded_positions.len() as u32;
        let id = *id_of_key.entry(key).or_insert(next);
        if id == next {
            welded_positions.push(Vec3::from_array(*position));
            first_source.push(source as u32);
        }
        welded_of_source.push(id);
    }
    let mut kept = Vec::with_capacity(triangles.len());
    let mut dropped = 0u64;
    for (source_triangle, corners) in triangles.iter().enumerate() {
        let welded = corners.map(|c| welded_of_source.get(c as usize).copied());
        let [Some(a), Some(b), Some(c)] = welded else {
            // The importer validated indices; a bad one here is dropped, not trusted.
            dropped += 1;
            continue;
        };
        if a == b || b == c || c == a {
            dropped += 1;
            continue;
        }
        kept.push(([a, b, c], source_triangle));
    }
    // Compact: only vertices used by kept triangles, numbered in first-use order.
    let mut compact_of_welded = vec![u32::MAX; welded_positions.len()];
    let mut positions_local = Vec::new();
    let mut source_vertex = Vec::new();
    for (corners, _) in &mut kept {
        for corner in corners.iter_mut() {
            let slot = &mut compact_of_welded[*corner as usize];
            if *slot == u32::MAX {
                *slot = positions_local.len() as u32;
                positions_local.push(welded_positions[*corner as usize]);
                source_vertex.push(first_source[*corner as usize]);
            }
            *corner = *slot;
        }
    }
    LocalWeld { positions_local, source_vertex, triangles: kept, dropped }
}

/// Welds every instance of `scene` and concatenates them into one mesh.
pub fn weld_scene(scene: &Scene) -> WeldedMesh {
    let locals: Vec<LocalWeld> =
        scene.meshes.iter().map(|mesh| weld_local(&mesh.positions_local, &mesh.triangles)).collect();
    let mut out = WeldedMesh::default();
    let any_colors = scene.meshes.iter().any(|mesh| !mesh.colors.is_empty());
    for instance in &scene.instances {
        let (Some(mesh), Some(local)) = (scene.meshes.get(instance.mesh as usize), locals.get(instance.mesh as usize))
        else {
            continue;
        };
        let world_from_local: Mat4 = instance.world_from_local;
        let normal_world_from_local = Mat3::from_mat4(world_from_local).inverse().transpose();
        let base = out.positions_world.len() as u32;
        if any_colors {
            out.vertex_colors
                .extend(local.source_vertex.iter().map(|&v| mesh.colors.get(v as usize).copied().unwrap_or([1.0; 4])));
        }
        out.positions_world
            .extend(local.positions_local.iter().map(|&p| world_from_local.transform_point3(p).to_array()));
        for &(corners, source_triangle) in &local.triangles {
            out.triangles.push(corners.map(|c| c + base));
            let source = mesh.triangles.get(source_triangle).copied().unwrap_or([0; 3]);
            let uv = |c: u32| mesh.uvs.get(c as usize).copied().unwrap_or([0.0; 2]);
            let normal = |c: u32| {
                let local_normal = mesh.normals_local.get(c as usize).map_or(Vec3::Z, |&n| Vec3::from_array(n));
                let world = (normal_world_from_local * local_normal).normalize_or_zero();
                if world == Vec3::ZERO { Vec3::Z } else { world }.to_array()
            };
            out.corner_uvs.push(source.map(uv));
            out.corner_normals_world.push(source.map(normal));
            out.triangle_materials.push(mesh.triangle_materials.get(source_triangle).copied().flatten());
        }
        out.degenerate_triangles_dropped += local.dropped;
    }
    out
}

/// Errors of building a mesh from raw triangles.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WeldError {
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} uses vertex {vertex}, but there are only {vertex_count} vertices")]
    IndexOutOfRange {
        /// The triangle's index.
        triangle: usize,
        /// The offending vertex index.
        vertex: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
}

impl WeldedMesh {
    /// A mesh from world positions and triangles that are already welded (tests, packed
    /// files): no attributes beyond defaults; triangles with repeated corners are dropped
    /// and counted; an out-of-range index is an error.
    pub fn from_triangles(positions_world: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self, WeldError> {
        let vertex_count = positions_world.len();
        let mut out = WeldedMesh { positions_world, ..WeldedMesh::default() };
        for (triangle, [a, b, c]) in triangles.into_iter().enumerate() {
            if let Some(&vertex) = [a, b, c].iter().find(|&&v| v as usize >= vertex_count) {
                return Err(WeldError::IndexOutOfRange { triangle, vertex, vertex_count });
            }
            if a == b || b == c || c == a {
                out.degenerate_triangles_dropped += 1;
                continue;
            }
            out.triangles.push([a, b, c]);
            out.corner_uvs.push([[0.0; 2]; 3]);
            out.corner_normals_world.push([[0.0, 0.0, 1.0]; 3]);
            out.triangle_materials.push(None);
        }
        Ok(out)
    }
}
