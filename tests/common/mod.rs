//! Helpers shared by the integration tests: a deterministic random source and small meshes.
#![allow(dead_code)] // each test file uses a different subset

use meshpaint::colors::format::Rgba;
use meshpaint::mesh::topology::Topology;

/// xorshift64: deterministic, seedable, good enough to scatter test inputs.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A float in `[0, 1)` with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A random colour, alpha included.
    pub fn color(&mut self) -> Rgba {
        [self.unit(), self.unit(), self.unit(), self.unit()]
    }
}

/// Triangles of [`octahedron`]: closed, and a vertex numbering that makes some face edges
/// run against their canonical direction.
pub const OCTAHEDRON_TRIANGLES: [[u32; 3]; 8] =
    [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];

/// The unit octahedron: 6 vertices, 12 edges, 8 faces.
pub fn octahedron() -> (Vec<[f32; 3]>, Topology) {
    let positions =
        vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let topology = Topology::build(6, &OCTAHEDRON_TRIANGLES).expect("the octahedron is a valid mesh");
    (positions, topology)
}
