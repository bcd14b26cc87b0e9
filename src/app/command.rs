//! What the panels and the input ask the editor to do: [`Command`]s, returned as values
//! and carried out in one place (`Editor::apply`). A panel never reaches into the editor.

use std::path::PathBuf;

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;

use super::export::ExportRequest;
use super::jobs::WriteKind;
use super::state::{Action, Shown};
use super::unsaved::UnsavedChoice;

/// A request from a panel, a dialog or the input to the editor.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// A menu entry, button or shortcut ([`Action`]).
    Action(Action),
    /// Open this file.
    Open(PathBuf),
    /// Write the document to this file: save or export, in this colour format.
    Write(PathBuf, ColorFormat, WriteKind),
    /// Carry out File → Export…'s choice.
    Export(ExportRequest),
    /// Find which UVs a bake at this texture size would use (for File → Export…).
    CheckUvs(u32),
    /// Fill the whole mesh, or (`connected`) the part last under the pointer.
    Fill {
        /// Only the part connected to the face last under the pointer.
        connected: bool,
    },
    /// Set the resolution of every face.
    SetResolutionAll(Resolution),
    /// Lower face resolutions while every shown colour stays within this bound.
    Optimize(f32),
    /// Cap the undo memory at this many bytes.
    SetUndoCap(usize),
    /// Build the alternate view `Shown` for the open document, if it is missing.
    PrepareView(Shown),
    /// The answer to "save changes first?".
    Unsaved(UnsavedChoice),
    /// Restore the offered recovery file.
    RestoreRecovery,
    /// Delete the offered recovery file.
    DiscardRecovery,
    /// Start a paint stroke at this point (points, window coordinates).
    BeginStroke(egui::Pos2),
    /// Extend the stroke to this point.
    StrokeTo(egui::Pos2),
    /// End the stroke (closes its undo step).
    EndStroke,
}

impl From<Action> for Command {
    fn from(action: Action) -> Self {
        Command::Action(action)
    }
}
