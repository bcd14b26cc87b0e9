//! The numbers `meshpaint info` reports about a mesh colored at a uniform resolution.

use crate::colors::layout::{Resolution, uniform_counts};
use crate::mesh::topology::Topology;

/// Counts of a welded mesh and its mesh-colors sample budget at one resolution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeshStats {
    /// Faces kept after welding.
    pub triangles: u64,
    /// Welded vertices used by faces.
    pub vertices: u64,
    /// Unique edges.
    pub edges: u64,
    /// Edges with one face.
    pub boundary_edges: u64,
    /// Edges with three or more faces.
    pub nonmanifold_edges: u64,
    /// Triangles dropped by welding because corners repeated.
    pub degenerate_triangles_dropped: u64,
    /// The uniform resolution the sample counts are for.
    pub resolution: u32,
    /// Level-0 samples: `V + E(R−1) + F(R−1)(R−2)/2`.
    pub samples: u64,
    /// Samples over all MIP levels down to resolution 1.
    pub samples_with_mips: u64,
}

impl MeshStats {
    /// Stats of `topology` at uniform resolution `resolution`.
    pub fn new(topology: &Topology, degenerate_triangles_dropped: u64, resolution: Resolution) -> Self {
        let (vertices, edges, triangles) =
            (u64::from(topology.vertex_count), u64::from(topology.edge_count()), u64::from(topology.face_count()));
        let counts = uniform_counts(resolution, vertices, edges, triangles);
        MeshStats {
            triangles,
            vertices,
            edges,
            boundary_edges: u64::from(topology.boundary_edge_count()),
            nonmanifold_edges: u64::from(topology.nonmanifold_edge_count()),
            degenerate_triangles_dropped,
            resolution: resolution.get(),
            samples: counts.samples,
            samples_with_mips: counts.samples_with_mips,
        }
    }

    /// The stats as a JSON object (keys as documented in docs/CLI.md, "`info` output").
    pub fn to_json(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut map = serde_json::Map::new();
        let mut put = |key: &str, value: u64| {
            map.insert(key.to_owned(), serde_json::Value::from(value));
        };
        put("triangles", self.triangles);
        put("vertices", self.vertices);
        put("edges", self.edges);
        put("boundary_edges", self.boundary_edges);
        put("nonmanifold_edges", self.nonmanifold_edges);
        put("degenerate_triangles_dropped", self.degenerate_triangles_dropped);
        put("resolution", u64::from(self.resolution));
        put("samples", self.samples);
        put("samples_with_mips", self.samples_with_mips);
        map
    }

    /// A short human-readable report, one fact per line.
    pub fn to_text(&self) -> String {
        format!(
            "triangles:                    {}\n\
             vertices (welded):            {}\n\
             edges:                        {}\n\
             boundary edges:               {}\n\
             non-manifold edges:           {}\n\
             degenerate triangles dropped: {}\n\
             resolution:                   {}\n\
             samples (level 0):            {}\n\
             samples (with MIP chains):    {}\n",
            self.triangles,
            self.vertices,
            self.edges,
            self.boundary_edges,
            self.nonmanifold_edges,
            self.degenerate_triangles_dropped,
            self.resolution,
            self.samples,
            self.samples_with_mips
        )
    }
}
