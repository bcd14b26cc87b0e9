//! Halfedges of a triangle mesh and their pairing into intrinsic quads (paper §3).
//!
//! Halfedge `h = 3·f + k` runs from corner `k` of face `f` to corner `k + 1`:
//! `Vert(h) = c_k`, `Next(h) = 3f + (k+1) mod 3`, `Prev(h) = 3f + (k+2) mod 3`. Its twin is
//! the halfedge of the other face on the same edge running the other way. A boundary
//! halfedge — and, since a halfedge mesh cannot describe them, every halfedge of a
//! non-manifold edge (three or more faces) or of an edge whose two faces disagree on
//! winding — is paired with itself: its quad holds its own triangle and the mirror of it.
//!
//! Each quad is the pair `[lower, upper]`: `lower` is the halfedge with the larger id
//! (paper, Algorithm 2: `h > Twin(h)` maps `(u, v)` unchanged to the quad's lower-left
//! triangle `x + y ≤ 1`), `upper` the smaller (mapped to `(1 − u, 1 − v)`), [`NONE`] for a
//! halfedge paired with itself. Quads are numbered in order of their lower halfedge.

use crate::mesh::topology::Topology;

/// "No halfedge".
pub const NONE: u32 = u32::MAX;

/// The halfedge pairing of a mesh.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Halfedges {
    /// Twin of each halfedge, or [`NONE`] (boundary, non-manifold or mis-wound edge).
    pub twin: Vec<u32>,
    /// Quad of each halfedge.
    pub quad: Vec<u32>,
    /// Per quad: `[lower, upper]` halfedges (`upper` = [`NONE`] for a self-paired one).
    pub quads: Vec<[u32; 2]>,
}

/// `Next(h)` of a triangle mesh.
pub fn next(h: u32) -> u32 {
    h - h % 3 + (h % 3 + 1) % 3
}

/// `Prev(h)` of a triangle mesh.
pub fn prev(h: u32) -> u32 {
    h - h % 3 + (h % 3 + 2) % 3
}

impl Halfedges {
    /// Pairs the halfedges of `topology`'s faces.
    pub fn of(topology: &Topology) -> Halfedges {
        let count = topology.face_vertices.len() * 3;
        let mut twin = vec![NONE; count];
        for edge in 0..topology.edge_count() {
            if let [(f, k), (g, l)] = *topology.faces_of_edge(edge) {
                // Opposite directions only: a mis-wound pair stays two boundaries.
                if topology.is_reversed(f, usize::from(k)) != topology.is_reversed(g, usize::from(l)) {
                    let (a, b) = (3 * f + u32::from(k), 3 * g + u32::from(l));
                    twin[a as usize] = b;
                    twin[b as usize] = a;
                }
            }
        }
        let mut quad = vec![NONE; count];
        let mut quads = Vec::with_capacity(count / 2 + 1);
        for h in 0..count as u32 {
            let t = twin[h as usize];
            if t == NONE || h > t {
                quad[h as usize] = quads.len() as u32;
                if t != NONE {
                    quad[t as usize] = quads.len() as u32;
                }
                quads.push([h, t]);
            }
        }
        Halfedges { twin, quad, quads }
    }

    /// Whether `h` is its quad's lower-left halfedge (`(x, y) = (u, v)`).
    pub fn is_lower(&self, h: u32) -> bool {
        self.quads[self.quad[h as usize] as usize][0] == h
    }
}

/// The quad point `(x, y)` of point `(u, v)` of halfedge `h`'s intrinsic triangle
/// (paper, Algorithm 2), `lower` being [`Halfedges::is_lower`].
pub fn triangle_to_quad(lower: bool, uv: [f32; 2]) -> [f32; 2] {
    if lower { uv } else { [1.0 - uv[0], 1.0 - uv[1]] }
}

/// Face barycentrics (weights of corners 0, 1, 2) of point `(u, v)` of halfedge `h`'s
/// intrinsic triangle: `u` weighs `Vert(h)`, `v` weighs `Vert(Next(h))`, `w = 1 − u − v`
/// the face's centroid (paper §4.2 (i), (ii); Algorithm 1's `v₁`).
pub fn face_barycentric(h: u32, uv: [f32; 2]) -> [f32; 3] {
    let k = (h % 3) as usize;
    let w = (1.0 - uv[0] - uv[1]) / 3.0;
    let mut b = [w; 3];
    b[k] += uv[0];
    b[(k + 1) % 3] += uv[1];
    b
}

/// The intrinsic triangle (face edge `k`) holding face barycentric `b`, and the point's
/// `(u, v)` in it: the sub-triangle of the face edge opposite the smallest weight.
pub fn intrinsic_point(b: [f32; 3]) -> (u32, [f32; 2]) {
    // Smallest weight: corner m; the edge opposite it is face edge (m + 1) mod 3.
    let m = if b[0] <= b[1] && b[0] <= b[2] {
        0
    } else if b[1] <= b[2] {
        1
    } else {
        2
    };
    let k = (m + 1) % 3;
    (k as u32, [b[k] - b[m], b[(k + 1) % 3] - b[m]])
}
