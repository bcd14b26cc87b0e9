//! Painting: BVH picking, the brushes and their tools, occlusion by a depth map of the view, optimize (lower R where nothing
//! visible changes), and undo / redo per stroke.

pub mod brush;
pub mod occlusion;
pub mod optimize;
pub mod picking;
pub mod undo;

pub use brush::{BrushSettings, Painter};
pub use picking::{BvhPreset, MeshBvh};
pub use undo::UndoHistory;
