//! Documents on disk: open glTF or packed files into a store, export glTF, bake
//! textures into mesh colors, autosave and recovery.

pub mod autosave;
pub mod bake;
pub mod document;
pub mod export_gltf;

pub use document::{Document, SourceKind};
