//! Small meshes built in code: the octahedron and the icosphere.

use std::collections::HashMap;

use glam::DVec3;

/// Vertices of the unit octahedron: ±x, ±y, ±z.
pub const OCTAHEDRON_POSITIONS: [[f64; 3]; 6] =
    [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];

/// Triangles of the octahedron: closed, outward, and a vertex numbering that makes some
/// face edges run against their canonical direction.
pub const OCTAHEDRON_TRIANGLES: [[u32; 3]; 8] =
    [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];

/// [`OCTAHEDRON_POSITIONS`] in `f32`.
pub fn octahedron_positions() -> Vec<[f32; 3]> {
    OCTAHEDRON_POSITIONS.iter().map(|p| p.map(|c| c as f32)).collect()
}

/// Icosahedron subdivided `levels` times, vertices on the unit sphere, outward winding.
/// Symmetric under x → −x (vertices and faces), bit for bit.
pub fn icosphere(levels: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints = HashMap::new();
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<DVec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push(((vertices[a as usize] + vertices[b as usize]) * 0.5).normalize());
                vertices.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut vertices);
            let bc = midpoint(b, c, &mut vertices);
            let ca = midpoint(c, a, &mut vertices);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    (vertices.iter().map(|v| v.as_vec3().to_array()).collect(), triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Euler's formula and closure: V − E + F = 2 and every edge in exactly two faces,
    /// counted by brute force over the triangles.
    fn check_closed_sphere(positions: usize, triangles: &[[u32; 3]]) {
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for t in triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2));
        assert_eq!(positions as i64 - edges.len() as i64 + triangles.len() as i64, 2);
    }

    #[test]
    fn the_shapes_are_closed_spheres() {
        check_closed_sphere(6, &OCTAHEDRON_TRIANGLES);
        for levels in 0..3 {
            let (positions, triangles) = icosphere(levels);
            assert_eq!(triangles.len(), 20 * 4usize.pow(levels));
            check_closed_sphere(positions.len(), &triangles);
            assert!(positions.iter().all(|p| (glam::Vec3::from_array(*p).length() - 1.0).abs() < 1e-6));
        }
    }
}
