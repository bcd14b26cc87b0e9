//! What the editor's background jobs produce ([`JobOutput`]); the editor applies each by
//! its [`super::jobs::JobKind`].

use std::path::PathBuf;

use super::autosave::Autosaved;
use super::document::{AlternateView, OpenDocument, Written};
use super::jobs::WriteKind;
use super::paint_session::Repacked;

/// What a job produced.
#[derive(Debug)]
pub enum JobOutput {
    /// A document was opened.
    Loaded(Box<OpenDocument>),
    /// A file was written.
    Written(Written, WriteKind),
    /// The store was repacked after paint mode.
    Repacked(Box<Repacked>),
    /// A recovery file was written.
    Autosaved(Autosaved),
    /// Optimize found its changes (applied if the document did not change meanwhile).
    Optimized(Box<Optimized>),
    /// The UVs a bake of this texture size would use (File → Export…), or why that is
    /// unknown.
    UvsChecked(u32, Result<meshpaint_core::convert::unwrap::UvChoice, String>),
    /// An alternate view was built for the document opened from this path (`None`: built-in).
    View(Option<PathBuf>, Box<AlternateView>),
}

/// What an Optimize job found.
#[derive(Debug)]
pub struct Optimized {
    /// The changes, planned on the store as it was at `generation`.
    pub plan: meshpaint_core::paint::optimize::OptimizePlan,
    /// The document's edit generation (`DocumentState::edit_generation`) when the job started.
    pub generation: u64,
    /// The error bound used.
    pub bound: f32,
}
