//! Meshes: what is read from a file, welded into one indexed mesh, its topology and its
//! orientation (winding consistency, signed volume).
//!
//! `file ─ import ─▶ Scene ─ weld ─▶ WeldedMesh ─ topology ─▶ Topology`

pub mod formats;
pub mod import;
pub mod normals;
pub mod orientation;
pub mod scene;
pub mod topology;
pub mod weld;

pub use import::{ImportError, import_gltf};
pub use scene::Scene;
pub use topology::Topology;
pub use weld::{WeldedMesh, weld_scene};
