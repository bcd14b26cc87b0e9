//! Documents on disk: open glTF, OBJ, PLY, STL or packed files into a store, export glTF
//! (tessellated or textured), bake textures into mesh colors (at a per-face resolution chosen by the content, `adaptive`)
//! and back, autosave and recovery; `subdivide` splits an imported scene's triangles 1→4 (how
//! the benchmarks reach a million triangles).

pub mod adaptive;
pub mod autosave;
pub mod bake;
pub mod bake_uv;
pub mod document;
pub mod export_fit;
pub mod export_gltf;
pub mod export_textured;
pub mod least_squares;
pub mod subdivide;

pub use document::{Document, SourceKind};
