//! What undo keeps of a face before a resolution change ([`FaceState`]), and undo's errors.

use thiserror::Error;

use crate::colors::budget::BudgetError;
use crate::colors::format::Rgba;
use crate::colors::layout::Resolution;
use crate::colors::store::{ColorStore, SampleRef, StoreError};

/// Errors of recording, undoing and redoing.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum UndoError {
    /// [`UndoHistory::begin_step`] while a step is open.
    #[error("an undo step is already open (end the stroke first)")]
    StepOpen,
    /// Undo or redo while a step is open.
    #[error("cannot undo or redo during a stroke")]
    Busy,
    /// The store changed outside the history; the history was cleared.
    #[error("the colours changed outside the undo history ({0}); the history was cleared")]
    Mismatch(String),
    /// The step would take the store past the budget; nothing changed and the step is kept.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// The store refused a change.
    #[error(transparent)]
    Store(#[from] StoreError),
}

/// The saved state of one face and its three edges (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FaceState {
    pub(super) face: u32,
    pub(super) resolution: Resolution,
    interior: Vec<Rgba>,
    /// `(edge, resolution, samples)` of face edges 0, 1, 2.
    pub(super) edges: [(u32, Resolution, Vec<Rgba>); 3],
}

impl FaceState {
    pub(super) fn capture(store: &ColorStore, face: u32) -> Result<Self, UndoError> {
        let no_face = || StoreError::NoSuchFace { face, face_count: store.topology().face_count() };
        let resolution = store.face_resolution(face).ok_or_else(no_face)?;
        let face_edges = *store.topology().face_edges.get(face as usize).ok_or_else(no_face)?;
        let edge = |edge: u32| -> Result<(u32, Resolution, Vec<Rgba>), UndoError> {
            let r = store.edge_resolution(edge).ok_or_else(no_face)?;
            Ok((edge, r, store.edge_samples(edge).to_vec()))
        };
        Ok(FaceState {
            face,
            resolution,
            interior: store.interior_samples(face).to_vec(),
            edges: [edge(face_edges[0])?, edge(face_edges[1])?, edge(face_edges[2])?],
        })
    }

    /// Puts the state back: resolution first (which resizes the elements), then samples.
    pub(super) fn restore(&self, store: &mut ColorStore) -> Result<(), UndoError> {
        store.set_face_resolution(self.face, self.resolution)?;
        for (edge, resolution, _) in &self.edges {
            if store.edge_resolution(*edge) != Some(*resolution) {
                return Err(UndoError::Mismatch(format!(
                    "edge {edge} should be at resolution {resolution} after restoring face {}",
                    self.face
                )));
            }
        }
        if store.interior_samples(self.face).len() != self.interior.len() {
            return Err(UndoError::Mismatch(format!("face {} interior size", self.face)));
        }
        for (offset, &color) in (0u32..).zip(&self.interior) {
            store.set(SampleRef::Interior { face: self.face, offset }, color);
        }
        for (edge, _, samples) in &self.edges {
            for (offset, &color) in (0u32..).zip(samples) {
                store.set(SampleRef::Edge { edge: *edge, offset }, color);
            }
        }
        Ok(())
    }

    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + (self.interior.len() + self.edges.iter().map(|(_, _, s)| s.len()).sum::<usize>())
                * std::mem::size_of::<Rgba>()
    }
}
