//! Painting: BVH picking, the brushes and their tools, occlusion by a depth map of the view, optimize (lower R where nothing
//! visible changes), undo / redo per stroke, and parallel writes
//! through the undo step (`split`).

pub mod brush;
mod face_state;
pub mod occlusion;
pub mod optimize;
pub mod picking;
pub mod split;
pub mod undo;

pub use brush::{BrushSettings, Painter};
pub use picking::{BvhPreset, MeshBvh};
pub use undo::UndoHistory;
