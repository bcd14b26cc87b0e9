//! Documents on disk: open glTF or packed files into a store, export glTF, bake
//! textures into mesh colors (at a per-face resolution chosen by the content, `adaptive`),
//! autosave and recovery.

pub mod adaptive;
pub mod autosave;
pub mod bake;
pub mod document;
pub mod export_gltf;

pub use document::{Document, SourceKind};
