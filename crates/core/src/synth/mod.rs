//! Synthetic inputs shared by the tests, the benchmarks and the fuzzer: deterministic
//! random sources ([`rng`]), small meshes built in code ([`shapes`]) and production-like
//! test assets written as glTF ([`production`]). One copy of each, so a seed draws the
//! same inputs wherever it is used.

pub mod production;
pub mod rng;
pub mod shapes;

pub use rng::{SplitMix64, XorShift64};
pub use shapes::{OCTAHEDRON_POSITIONS, OCTAHEDRON_TRIANGLES, icosphere, octahedron_positions};
