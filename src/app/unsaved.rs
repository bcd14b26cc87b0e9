//! Never lose work: every action that replaces or closes the document — open (dialog, drop),
//! quit (key, menu, window close) — is a [`Pending`] action that goes through
//! `Editor::replace_or_close`, which asks Save / Don't save / Cancel ([`crate::app::panels::UnsavedPrompt`]) while the
//! document has unsaved changes ([`super::session::DocumentState::is_modified`]). "Save"
//! saves (asking for a name when the document has no project file yet) and carries on only
//! once the save has succeeded; a failed or cancelled save carries on with nothing.

use meshpaint_core::io::document::Source;

/// What waits for the answer to "save changes first?".
#[derive(Debug, Clone, PartialEq)]
pub enum Pending {
    /// Open this source (a file chosen in the dialog or dropped on the window).
    Open(Source),
    /// Quit the application.
    Quit,
}

impl Pending {
    /// What the prompt says the action is, e.g. "opening Fox.glb".
    pub fn describe(&self) -> String {
        match self {
            Pending::Open(source) => format!("opening {}", source.name()),
            Pending::Quit => "quitting".to_owned(),
        }
    }
}

/// The answer to the prompt.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnsavedChoice {
    /// Save, then carry on.
    Save,
    /// Carry on; the changes are lost (the autosave's recovery file stays).
    DontSave,
    /// Do nothing; everything stays as it is, undo history included.
    Cancel,
}
