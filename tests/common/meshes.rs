//! Small meshes built in code.

use std::collections::HashMap;

use glam::DVec3;
use meshpaint::mesh::topology::Topology;

/// Positions and triangles.
pub type Mesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// Triangles of [`octahedron`]: closed, and a vertex numbering that makes some face edges
/// run against their canonical direction.
pub const OCTAHEDRON_TRIANGLES: [[u32; 3]; 8] =
    [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];

/// Vertices of the unit octahedron.
pub fn octahedron_positions() -> Vec<[f32; 3]> {
    vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]
}

/// The unit octahedron: 6 vertices, 12 edges, 8 faces.
pub fn octahedron() -> (Vec<[f32; 3]>, Topology) {
    let topology = Topology::build(6, &OCTAHEDRON_TRIANGLES).expect("the octahedron is a valid mesh");
    (octahedron_positions(), topology)
}

/// The unit octahedron as positions and triangles.
pub fn octahedron_mesh() -> Mesh {
    (octahedron_positions(), OCTAHEDRON_TRIANGLES.to_vec())
}

/// Two meshes in one (indices of the second shifted).
pub fn join((mut positions, mut triangles): Mesh, (p2, t2): Mesh) -> Mesh {
    let offset = positions.len() as u32;
    positions.extend(p2);
    triangles.extend(t2.into_iter().map(|t| t.map(|v| v + offset)));
    (positions, triangles)
}

/// Icosahedron subdivided `levels` times, vertices on the unit sphere, outward winding.
/// Symmetric under x → −x (vertices and faces), bit for bit.
pub fn icosphere(levels: u32) -> Mesh {
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
