//! Meshes: what is read from a file, welded into one indexed mesh, its topology and its
//! orientation (winding consistency, signed volume).
//!
//! `file ─ import ─▶ Scene ─ weld ─▶ WeldedMesh ─ topology ─▶ Topology`; [`subdivide`] splits a
//! scene's triangles 1→4 (how benchmarks reach a million triangles).

pub mod formats;
pub mod import;
pub mod orientation;
pub mod scene;
pub mod subdivide;
pub mod topology;
pub mod weld;

pub use import::{ImportError, import_gltf};
pub use scene::Scene;
pub use topology::Topology;
pub use weld::{WeldedMesh, weld_scene};
