//! The editor's side of a job that did not finish: a failure is reported (a failed
//! start-up file falls back to the built-in scene), a cancel keeps the open document.

use meshpaint_core::io::document::Source;

use super::editor::Editor;
use super::jobs::{JobKind, WriteKind};
use super::state::Severity;

impl Editor {
    /// A job was cancelled: the open document stays (with nothing open, the built-in scene
    /// opens, as after a failed start).
    pub(super) fn finish_cancelled(&mut self, kind: JobKind) {
        if kind == JobKind::Write(WriteKind::Save) {
            self.document.saving_generation = None;
            self.after_save_finished(false);
        }
        match &self.document.open {
            Some(open) => {
                let text = format!("Cancelled; still showing {}", open.title);
                self.set_status(Severity::Info, text);
            }
            None if matches!(kind, JobKind::Open { built_in: false }) => {
                self.set_status(Severity::Info, "Cancelled; showing the built-in Duck");
                self.open(Source::BuiltIn);
            }
            None => self.set_status(Severity::Info, "Cancelled"),
        }
    }

    /// A job failed: reported; a failed start-up file falls back to the built-in scene.
    pub(super) fn finish_failed(&mut self, kind: JobKind, message: String) {
        if kind == JobKind::Write(WriteKind::Save) {
            self.document.saving_generation = None;
            self.after_save_finished(false);
        }
        if kind == JobKind::Autosave {
            self.panels.autosave.state.failed();
            self.set_status(Severity::Warning, format!("Autosave failed: {message}"));
            return;
        }
        if kind == JobKind::Repack {
            self.document.gpu_paint_layout = true;
        }
        let is_open = matches!(kind, JobKind::Open { .. });
        if kind == (JobKind::Open { built_in: false }) && self.document.open.is_none() {
            // Nothing was open (a bad file on the command line): show the Duck.
            self.fallback_error = Some(format!("Could not open: {message}"));
            self.set_status(Severity::Error, format!("Could not open: {message}"));
            self.open(Source::BuiltIn);
            return;
        }
        let kept = match &self.document.open {
            Some(open) => format!(" (still showing {})", open.title),
            None => String::new(),
        };
        let what = if is_open { "Could not open" } else { "Failed" };
        self.set_status(Severity::Error, format!("{what}: {message}{kept}"));
    }
}
