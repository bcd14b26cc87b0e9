//! Midpoint subdivision of an imported scene: every triangle becomes four.
//!
//! How the benchmarks get a million-triangle mesh without shipping one: `--subdivide N`
//! on the bench commands turns Bunny144k (144 046 triangles) into 576 184 (N = 1) or
//! 2 304 736 (N = 2). The shape does not change (new vertices lie on the old edges, so
//! the surface and its silhouette are the same), only the triangle count.
//!
//! Each edge of a source mesh gets one midpoint vertex, shared by the triangles on both
//! sides (keyed by the unordered index pair), so a welded input stays welded and the
//! topology of the result is that of a regular 1→4 split: `V' = V + E`, `F' = 4F`.
//! Attributes are interpolated at the midpoint (normals renormalised); triangle `[a, b, c]`
//! with midpoints `ab, bc, ca` becomes `[a, ab, ca]`, `[ab, b, bc]`, `[ca, bc, c]`,
//! `[ab, bc, ca]`, keeping its winding and its material.

use std::collections::HashMap;

use crate::colors::budget::{Budget, BudgetError};
use crate::mesh::scene::{Scene, SourceMesh};

/// Splits every triangle of `scene` into four, `levels` times, after checking that the
/// resulting triangle count fits `budget` (nothing is allocated past it).
pub fn subdivide_scene(scene: &Scene, levels: u32, budget: &Budget) -> Result<Scene, BudgetError> {
    let triangles = scene.instanced_triangle_count() as u64;
    let factor = 4u64.checked_pow(levels).unwrap_or(u64::MAX);
    budget.check_triangles("the subdivided mesh", triangles.saturating_mul(factor))?;
    let mut out = scene.clone();
    for _ in 0..levels {
        for mesh in &mut out.meshes {
            *mesh = subdivide_mesh(mesh);
        }
    }
    Ok(out)
}

/// One 1→4 split of one source mesh.
fn subdivide_mesh(mesh: &SourceMesh) -> SourceMesh {
    let mut out = SourceMesh {
        name: mesh.name.clone(),
        positions_local: mesh.positions_local.clone(),
        normals_local: mesh.normals_local.clone(),
        uvs: mesh.uvs.clone(),
        colors: mesh.colors.clone(),
        triangles: Vec::with_capacity(mesh.triangles.len() * 4),
        triangle_materials: Vec::with_capacity(mesh.triangle_materials.len() * 4),
    };
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.triangles.len() * 3 / 2);
    let mut midpoint = |out: &mut SourceMesh, a: u32, b: u32| -> u32 {
        let key = (a.min(b), a.max(b));
        *midpoints.entry(key).or_insert_with(|| {
            let (a, b) = (key.0 as usize, key.1 as usize);
            let index = out.positions_local.len() as u32;
            let mid3 = |p: [f32; 3], q: [f32; 3]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])];
            out.positions_local.push(mid3(mesh.positions_local[a], mesh.positions_local[b]));
            let n = mid3(mesh.normals_local[a], mesh.normals_local[b]);
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            out.normals_local.push(if length > 0.0 {
                [n[0] / length, n[1] / length, n[2] / length]
            } else {
                mesh.normals_local[a]
            });
            let (u, v) = (mesh.uvs[a], mesh.uvs[b]);
            out.uvs.push([0.5 * (u[0] + v[0]), 0.5 * (u[1] + v[1])]);
            if !mesh.colors.is_empty() {
                let (p, q) = (mesh.colors[a], mesh.colors[b]);
                out.colors.push(std::array::from_fn(|i| 0.5 * (p[i] + q[i])));
            }
            index
        })
    };
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        let ab = midpoint(&mut out, a, b);
        let bc = midpoint(&mut out, b, c);
        let ca = midpoint(&mut out, c, a);
        out.triangles.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        let material = mesh.triangle_materials.get(t).copied().flatten();
        out.triangle_materials.extend_from_slice(&[material; 4]);
    }
    out
}
