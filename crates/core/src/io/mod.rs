//! Documents on disk: open glTF, OBJ, PLY, STL or packed files into a store ([`document`];
//! for display, packed and with the picking BVH beside: [`display`], the one open path),
//! export glTF (tessellated, fitted to a vertex budget, or textured: baked into the model's UVs
//! or generated ones, [`export_baked`]), autosave and recovery.
//! What turns one signal into another (bakes, adaptive resolution, subdivision) lives in
//! [`crate::convert`]; this folder only reads and writes files.

pub mod autosave;
pub mod display;
pub mod document;
pub mod export_baked;
pub mod export_fit;
pub mod export_gltf;
pub mod export_scene;
pub mod export_textured;

pub use document::{Document, SourceKind};
