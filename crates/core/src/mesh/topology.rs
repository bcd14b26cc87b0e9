//! Welded topology: unique edges with a canonical direction, face → edge incidence,
//! edge → face adjacency, boundary and non-manifold edges, vertex valence.
//!
//! Struct-of-arrays with `u32` ids; [`INVALID`] marks "no element". Edge ids are
//! assigned in lexicographic order of `(lower vertex, higher vertex)`, so they are
//! deterministic. An edge's canonical direction runs from its lower to its higher
//! vertex id; a face whose edge runs the other way sees it *reversed*. Every face
//! incident to an edge — two on a manifold edge, one on a boundary edge, three or more
//! on a non-manifold edge — shares the edge's samples.

use thiserror::Error;

/// The "no element" id.
pub const INVALID: u32 = u32::MAX;

/// Errors of building or validating a topology.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TopologyError {
    /// A face uses a vertex id past the vertex count.
    #[error("face {face} uses vertex {vertex}, but there are {vertex_count} vertices")]
    VertexOutOfRange {
        /// Face id.
        face: u32,
        /// Offending vertex id.
        vertex: u32,
        /// Number of vertices.
        vertex_count: u32,
    },
    /// A face repeats a vertex (it should have been dropped by welding).
    #[error("face {face} repeats a vertex: {corners:?}")]
    DegenerateFace {
        /// Face id.
        face: u32,
        /// Its corners.
        corners: [u32; 3],
    },
    /// The mesh has more elements than `u32` ids can name.
    #[error("too many {what} for 32-bit ids: {count}")]
    TooMany {
        /// What overflowed.
        what: &'static str,
        /// How many there were.
        count: usize,
    },
    /// `validate` found an inconsistency (a bug, never bad input).
    #[error("topology is inconsistent: {0}")]
    Inconsistent(String),
}

/// Welded connectivity of a triangle mesh.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Topology {
    /// Number of vertices (ids `0..vertex_count`).
    pub vertex_count: u32,
    /// Corners of each face, in winding order.
    pub face_vertices: Vec<[u32; 3]>,
    /// Edge id of each face edge: 0 = c0→c1, 1 = c1→c2, 2 = c2→c0.
    pub face_edges: Vec<[u32; 3]>,
    /// Bit `k` set when face edge `k` runs against its edge's canonical direction.
    pub face_edge_reversed_bits: Vec<u8>,
    /// Endpoints of each edge in canonical order (`[0] < [1]`).
    pub edge_vertices: Vec<[u32; 2]>,
    /// Start of each edge's faces in [`Topology::edge_faces`]; `edge_count + 1` entries.
    pub edge_face_offsets: Vec<u32>,
    /// Faces incident to each edge, as `(face id, face-edge index 0..3)`, in face order.
    pub edge_faces: Vec<(u32, u8)>,
    /// Number of distinct edges incident to each vertex.
    pub vertex_valence: Vec<u32>,
}

impl Topology {
    /// Builds the topology of `triangles` over `vertex_count` vertices.
    pub fn build(vertex_count: u32, triangles: &[[u32; 3]]) -> Result<Self, TopologyError> {
        let face_count = u32::try_from(triangles.len())
            .map_err(|_| TopologyError::TooMany { what: "faces", count: triangles.len() })?;
        // Keys for every face edge: (lower, higher, face, face edge). Sorting groups edges.
        let mut half_edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(triangles.len() * 3);
        for (face, &corners) in (0..face_count).zip(triangles) {
            if let Some(&vertex) = corners.iter().find(|&&v| v >= vertex_count) {
                return Err(TopologyError::VertexOutOfRange { face, vertex, vertex_count });
            }
            let [a, b, c] = corners;
            if a == b || b == c || c == a {
                return Err(TopologyError::DegenerateFace { face, corners });
            }
            for k in 0..3u8 {
                let from = corners[usize::from(k)];
                let to = corners[usize::from((k + 1) % 3)];
                half_edges.push((from.min(to), from.max(to), face, k));
            }
        }
        // Keys are unique (one per face edge), so the parallel sort's order is the total order.
        rayon::slice::ParallelSliceMut::par_sort_unstable(&mut half_edges[..]);

        let mut topology = Topology {
            vertex_count,
            face_vertices: triangles.to_vec(),
            face_edges: vec![[INVALID; 3]; triangles.len()],
            face_edge_reversed_bits: vec![0; triangles.len()],
            edge_vertices: Vec::new(),
            edge_face_offsets: vec![0],
            edge_faces: Vec::with_capacity(half_edges.len()),
            vertex_valence: vec![0; vertex_count as usize],
        };
        let mut start = 0;
        while start < half_edges.len() {
            let (lower, higher, _, _) = half_edges[start];
            let mut end = start;
            while end < half_edges.len() && half_edges[end].0 == lower && half_edges[end].1 == higher {
                end += 1;
            }
            let edge = u32::try_from(topology.edge_vertices.len())
                .map_err(|_| TopologyError::TooMany { what: "edges", count: topology.edge_vertices.len() })?;
            topology.edge_vertices.push([lower, higher]);
            topology.vertex_valence[lower as usize] += 1;
            topology.vertex_valence[higher as usize] += 1;
            for &(_, _, face, k) in &half_edges[start..end] {
                topology.face_edges[face as usize][usize::from(k)] = edge;
                let from = triangles[face as usize][usize::from(k)];
                if from != lower {
                    topology.face_edge_reversed_bits[face as usize] |= 1 << k;
                }
                topology.edge_faces.push((face, k));
            }
            topology.edge_face_offsets.push(topology.edge_faces.len() as u32);
            start = end;
        }
        Ok(topology)
    }

    /// Number of faces.
    pub fn face_count(&self) -> u32 {
        self.face_vertices.len() as u32
    }

    /// Heap bytes of the connectivity's arrays.
    pub fn heap_bytes(&self) -> u64 {
        (std::mem::size_of_val(self.face_vertices.as_slice())
            + std::mem::size_of_val(self.face_edges.as_slice())
            + std::mem::size_of_val(self.face_edge_reversed_bits.as_slice())
            + std::mem::size_of_val(self.edge_vertices.as_slice())
            + std::mem::size_of_val(self.edge_face_offsets.as_slice())
            + std::mem::size_of_val(self.edge_faces.as_slice())
            + std::mem::size_of_val(self.vertex_valence.as_slice())) as u64
    }

    /// Number of unique edges.
    pub fn edge_count(&self) -> u32 {
        self.edge_vertices.len() as u32
    }

    /// Whether face edge `k` of `face` runs against the edge's canonical direction.
    pub fn is_reversed(&self, face: u32, k: usize) -> bool {
        self.face_edge_reversed_bits.get(face as usize).is_some_and(|bits| bits & (1 << k) != 0)
    }

    /// The three reversed flags of `face`.
    pub fn reversed(&self, face: u32) -> [bool; 3] {
        [0, 1, 2].map(|k| self.is_reversed(face, k))
    }

    /// Faces incident to `edge`, as `(face, face-edge index)`.
    pub fn faces_of_edge(&self, edge: u32) -> &[(u32, u8)] {
        let e = edge as usize;
        match (self.edge_face_offsets.get(e), self.edge_face_offsets.get(e + 1)) {
            (Some(&start), Some(&end)) => self.edge_faces.get(start as usize..end as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Number of edges with exactly one incident face.
    pub fn boundary_edge_count(&self) -> u32 {
        (0..self.edge_count()).filter(|&e| self.faces_of_edge(e).len() == 1).count() as u32
    }

    /// Number of edges with three or more incident faces.
    pub fn nonmanifold_edge_count(&self) -> u32 {
        (0..self.edge_count()).filter(|&e| self.faces_of_edge(e).len() >= 3).count() as u32
    }

    /// Checks every invariant; used by tests. Cost is linear in the mesh size.
    pub fn validate(&self) -> Result<(), TopologyError> {
        let bad = |message: String| Err(TopologyError::Inconsistent(message));
        let faces = self.face_vertices.len();
        if self.face_edges.len() != faces || self.face_edge_reversed_bits.len() != faces {
            return bad("per-face arrays differ in length".into());
        }
        if self.edge_face_offsets.len() != self.edge_vertices.len() + 1 {
            return bad("edge_face_offsets must have edge_count + 1 entries".into());
        }
        if self.vertex_valence.len() != self.vertex_count as usize {
            return bad("vertex_valence must have vertex_count entries".into());
        }
        let mut valence = vec![0u32; self.vertex_count as usize];
        for (edge, pair) in self.edge_vertices.iter().enumerate() {
            let [lower, higher] = *pair;
            if lower >= higher || higher >= self.vertex_count {
                return bad(format!("edge {edge} is not canonical or out of range: {pair:?}"));
            }
            if edge > 0 && self.edge_vertices[edge - 1] >= *pair {
                return bad(format!("edge {edge} is out of order or duplicated"));
            }
            valence[lower as usize] += 1;
            valence[higher as usize] += 1;
            let incident = self.faces_of_edge(edge as u32);
            if incident.is_empty() {
                return bad(format!("edge {edge} has no face"));
            }
            for &(face, k) in incident {
                if self.face_edges.get(face as usize).map(|e| e[usize::from(k)]) != Some(edge as u32) {
                    return bad(format!("edge {edge} lists face {face}:{k}, which does not list it back"));
                }
            }
        }
        if valence != self.vertex_valence {
            return bad("vertex_valence disagrees with the edge list".into());
        }
        for face in 0..faces {
            let corners = self.face_vertices[face];
            for k in 0..3 {
                let (from, to) = (corners[k], corners[(k + 1) % 3]);
                let edge = self.face_edges[face][k];
                let Some(&[lower, higher]) = self.edge_vertices.get(edge as usize) else {
                    return bad(format!("face {face} edge {k} has no valid edge id"));
                };
                if [from.min(to), from.max(to)] != [lower, higher] {
                    return bad(format!("face {face} edge {k} points at the wrong edge {edge}"));
                }
                if self.is_reversed(face as u32, k) != (from != lower) {
                    return bad(format!("face {face} edge {k} has the wrong orientation"));
                }
                if !self.faces_of_edge(edge).contains(&(face as u32, k as u8)) {
                    return bad(format!("face {face} edge {k} missing from edge {edge}'s faces"));
                }
            }
        }
        if self.edge_faces.len() != faces * 3 {
            return bad("every face edge must appear once in edge_faces".into());
        }
        Ok(())
    }
}

/// The faces around each vertex (compressed rows: `faces[offsets[v]..offsets[v + 1]]`, in
/// face order), built once where the faces an edit shows on are needed (the editor's partial
/// redraw after a dab).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VertexFaces {
    offsets: Vec<u32>,
    faces: Vec<u32>,
}

impl VertexFaces {
    /// The vertex → face incidence of `topology` (a face listed once per corner at `v`).
    pub fn of(topology: &Topology) -> Self {
        let vertices = topology.vertex_count as usize;
        let mut offsets = vec![0u32; vertices + 1];
        for corners in &topology.face_vertices {
            for &v in corners {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..vertices {
            offsets[v + 1] += offsets[v];
        }
        let mut next = offsets.clone();
        let mut faces = vec![0u32; topology.face_vertices.len() * 3];
        for (face, corners) in topology.face_vertices.iter().enumerate() {
            for &v in corners {
                faces[next[v as usize] as usize] = face as u32;
                next[v as usize] += 1;
            }
        }
        VertexFaces { offsets, faces }
    }

    /// The faces with a corner at `vertex` (empty for an unknown vertex).
    pub fn faces(&self, vertex: u32) -> &[u32] {
        let v = vertex as usize;
        match (self.offsets.get(v), self.offsets.get(v + 1)) {
            (Some(&start), Some(&end)) => self.faces.get(start as usize..end as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Bytes held.
    pub fn heap_bytes(&self) -> u64 {
        4 * (self.offsets.capacity() + self.faces.capacity()) as u64
    }
}
