//! Orientation: how consistently a mesh's triangles are wound, and which side faces out.
//!
//! Two faces sharing a manifold edge are *consistently wound* when they walk the edge in
//! opposite directions. [`face_flips`] orients every connected component (faces joined by
//! manifold edges) by a breadth-first walk from its lowest face, flipping a neighbour that
//! walks the shared edge the same way; flipping a face means reading its winding reversed.
//! [`Orientation::of`] counts the edges whose two faces disagree, and for every *closed*
//! component (all of its edges manifold) its signed volume with the file's winding
//! (`Σ p0 · (p1 × p2) / 6`): positive when the triangles are wound counter-clockwise seen
//! from outside (glTF's front), negative for an inside-out mesh.

use crate::mesh::topology::Topology;

/// What `meshpaint info` reports about orientation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Orientation {
    /// Connected components (faces joined by manifold edges).
    pub components: u64,
    /// Components whose every edge is manifold (closed surfaces).
    pub closed_components: u64,
    /// Closed components with a negative signed volume (wound inside out).
    pub inverted_components: u64,
    /// Sum of the signed volumes of the closed components, with the file's winding.
    pub closed_signed_volume: f64,
    /// Manifold edges whose two faces walk them in the same direction.
    pub inconsistent_edges: u64,
}

/// Whether the two faces of manifold `edge` walk it in the same direction.
fn same_direction(topology: &Topology, edge: u32) -> Option<(u32, u32, bool)> {
    match topology.faces_of_edge(edge) {
        &[(a, ka), (b, kb)] => {
            Some((a, b, topology.is_reversed(a, usize::from(ka)) == topology.is_reversed(b, usize::from(kb))))
        }
        _ => None,
    }
}

/// Per face: `(component, flipped)` — the component id (in order of the lowest face) and
/// whether the face must be read reversed to agree with the first face of its component.
pub fn face_flips(topology: &Topology) -> Vec<(u32, bool)> {
    const UNSEEN: u32 = u32::MAX;
    let faces = topology.face_count() as usize;
    let mut out = vec![(UNSEEN, false); faces];
    let mut queue = std::collections::VecDeque::new();
    let mut component = 0u32;
    for seed in 0..faces {
        if out[seed].0 != UNSEEN {
            continue;
        }
        out[seed] = (component, false);
        queue.push_back(seed as u32);
        while let Some(face) = queue.pop_front() {
            let flipped = out[face as usize].1;
            for &edge in &topology.face_edges[face as usize] {
                let Some((a, b, same)) = same_direction(topology, edge) else {
                    continue;
                };
                let other = if a == face { b } else { a };
                if out[other as usize].0 == UNSEEN {
                    out[other as usize] = (component, flipped ^ same);
                    queue.push_back(other);
                }
            }
        }
        component += 1;
    }
    out
}

impl Orientation {
    /// The orientation of `topology` over `positions` (one per vertex).
    pub fn of(topology: &Topology, positions: &[[f32; 3]]) -> Self {
        let flips = face_flips(topology);
        let components = flips.iter().map(|&(c, _)| c + 1).max().unwrap_or(0) as usize;
        let mut open = vec![false; components];
        let mut volume = vec![0.0f64; components];
        let mut inconsistent_edges = 0;
        for edge in 0..topology.edge_count() {
            match same_direction(topology, edge) {
                Some((_, _, true)) => inconsistent_edges += 1,
                Some(_) => {}
                None => {
                    for &(face, _) in topology.faces_of_edge(edge) {
                        open[flips[face as usize].0 as usize] = true;
                    }
                }
            }
        }
        for (face, corners) in topology.face_vertices.iter().enumerate() {
            let p = |k: usize| {
                let q = positions.get(corners[k] as usize).copied().unwrap_or([0.0; 3]);
                glam::DVec3::new(f64::from(q[0]), f64::from(q[1]), f64::from(q[2]))
            };
            volume[flips[face].0 as usize] += p(0).dot(p(1).cross(p(2))) / 6.0;
        }
        let mut orientation =
            Orientation { components: components as u64, inconsistent_edges, ..Orientation::default() };
        for c in 0..components {
            if !open[c] {
                orientation.closed_components += 1;
                orientation.closed_signed_volume += volume[c];
                if volume[c] < 0.0 {
                    orientation.inverted_components += 1;
                }
            }
        }
        orientation
    }

    /// The counts as JSON keys (documented in docs/CLI.md, "`info` output").
    pub fn to_json(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut map = serde_json::Map::new();
        map.insert("components".into(), self.components.into());
        map.insert("closed_components".into(), self.closed_components.into());
        map.insert("inverted_components".into(), self.inverted_components.into());
        map.insert("closed_signed_volume".into(), self.closed_signed_volume.into());
        map.insert("inconsistent_edges".into(), self.inconsistent_edges.into());
        map
    }

    /// One line for `meshpaint info`.
    pub fn to_text(&self) -> String {
        let verdict = if self.inverted_components > 0 {
            "inside out (negative volume)"
        } else if self.inconsistent_edges > 0 {
            "mixed winding"
        } else {
            "consistent"
        };
        format!(
            "orientation:                  {verdict}: {} components, {} closed ({} inverted, signed volume {:.6e}), {} inconsistently wound edges\n",
            self.components,
            self.closed_components,
            self.inverted_components,
            self.closed_signed_volume,
            self.inconsistent_edges
        )
    }
}
