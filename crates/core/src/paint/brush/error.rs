//! The brushes' error type.

use thiserror::Error;

use crate::colors::store::StoreError;
use crate::paint::undo::UndoError;

/// Errors of the brushes.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BrushError {
    /// Erase-to-base without a base snapshot.
    #[error("erase to base needs the base colours (the snapshot taken when painting started)")]
    NoBase,
    /// The base snapshot belongs to another mesh.
    #[error("the base snapshot has {base_faces} faces but the mesh has {faces}")]
    BaseMismatch {
        /// Faces in the base.
        base_faces: u32,
        /// Faces in the store.
        faces: u32,
    },
    /// A brush setting out of range.
    #[error("invalid brush setting: {0}")]
    InvalidSetting(String),
    /// The positions do not match the store's mesh.
    #[error("{positions} positions for a mesh with {vertices} vertices")]
    PositionCount {
        /// Positions given.
        positions: usize,
        /// Vertices in the mesh.
        vertices: u32,
    },
    /// A face id past the face count.
    #[error("face {0} does not exist")]
    NoSuchFace(u32),
    /// Recording the undo step failed.
    #[error(transparent)]
    Undo(#[from] UndoError),
    /// A resolution change is past the budget (refused before it was made).
    #[error(transparent)]
    Budget(#[from] crate::colors::budget::BudgetError),
    /// The store refused a change.
    #[error(transparent)]
    Store(#[from] StoreError),
}
