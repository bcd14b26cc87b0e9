//! Autosave and recovery in the editor, on top of [`crate::io::autosave`]: a periodic recovery
//! write on a worker thread while there are unsaved edits, the recovery offer (restore /
//! discard) when a document with a newer recovery file opens, and the settings.
//!
//! Recovery files of project files sit next to them ([`autosave::recovery_path`]); those of
//! imported glTF files and the built-in scene go to `$XDG_STATE_HOME/meshpaint` (else
//! `~/.local/state/meshpaint`, else the temporary directory).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::colors::format::ColorFormat;
use crate::io::autosave::{self, Autosaver, RecoveryInfo, RecoveryWrite};

use super::editor::{Editor, JobOutput, Severity};
use super::loaded::{OpenDocument, Source, human_bytes};

/// The job label of autosaves.
pub const AUTOSAVE_LABEL: &str = "Autosave";

/// What an autosave job wrote.
#[derive(Debug, Clone)]
pub struct Autosaved {
    /// The recovery file.
    pub path: PathBuf,
    /// Size and time.
    pub write: RecoveryWrite,
    /// The edit generation it holds.
    pub generation: u64,
}

/// The document a restore replaces: what the restored document keeps of it.
#[derive(Debug, Clone)]
struct Restoring {
    path: Option<PathBuf>,
    project_path: Option<PathBuf>,
    title: String,
    format: ColorFormat,
}

/// Autosave settings and state.
#[derive(Debug, Clone)]
pub struct AutosaveState {
    /// Autosave on or off.
    pub enabled: bool,
    /// Seconds between autosaves (while there are unsaved edits).
    pub interval_seconds: u32,
    autosaver: Autosaver,
    /// The open document's recovery file.
    pub recovery_path: Option<PathBuf>,
    /// A recovery file found when the document opened, offered for restoring.
    pub offer: Option<RecoveryInfo>,
    /// When the last autosave finished.
    pub last_saved: Option<Instant>,
    restoring: Option<Restoring>,
}

impl Default for AutosaveState {
    fn default() -> Self {
        AutosaveState {
            enabled: true,
            interval_seconds: autosave::DEFAULT_INTERVAL.as_secs() as u32,
            autosaver: Autosaver::new(autosave::DEFAULT_INTERVAL, 0),
            recovery_path: None,
            offer: None,
            last_saved: None,
            restoring: None,
        }
    }
}

/// Where recovery files of documents without a project file go.
pub fn state_directory() -> PathBuf {
    if let Some(dir) = std::env::var_os("XDG_STATE_HOME").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir).join("meshpaint");
    }
    if let Some(home) = std::env::var_os("HOME").filter(|d| !d.is_empty()) {
        return PathBuf::from(home).join(".local/state/meshpaint");
    }
    std::env::temp_dir().join("meshpaint")
}

/// The recovery file of `open`.
pub fn recovery_path_of(open: &OpenDocument) -> Option<PathBuf> {
    match &open.project_path {
        Some(path) => autosave::recovery_path(path),
        None => Some(autosave::recovery_path_in(&state_directory(), &open.title)),
    }
}

impl AutosaveState {
    /// A document opened: patches a restored one, finds its recovery file, resets the timer.
    pub(crate) fn document_opened(&mut self, open: &mut OpenDocument, generation: u64) {
        if let Some(restoring) = self.restoring.take() {
            open.path = restoring.path;
            open.project_path = restoring.project_path;
            open.title = restoring.title;
            open.format = restoring.format;
            self.offer = None;
        } else {
            self.recovery_path = recovery_path_of(open);
            let document_path = open.project_path.as_deref().or(open.path.as_deref());
            self.offer = self
                .recovery_path
                .as_deref()
                .and_then(|path| autosave::find_recovery_at(path, document_path))
                .filter(|info| info.newer_than_document);
        }
        self.recovery_path = recovery_path_of(open);
        self.autosaver = Autosaver::new(Duration::from_secs(u64::from(self.interval_seconds)), generation);
    }

    /// An autosave failed: try again after another interval.
    pub(crate) fn failed(&mut self) {
        let generation = self.autosaver.saved_generation();
        self.autosaver.mark_saved(Instant::now(), generation);
    }
}

impl Editor {
    /// Starts an autosave when one is due (called every frame).
    pub fn autosave_tick(&mut self) {
        let stroking = self.paint.as_ref().is_some_and(|p| p.painter.is_stroking());
        if !self.autosave.enabled || self.jobs.is_busy() || stroking || self.autosave.offer.is_some() {
            return;
        }
        let (Some(open), Some(path)) = (&self.document, self.autosave.recovery_path.clone()) else {
            return;
        };
        self.autosave.autosaver.interval = Duration::from_secs(u64::from(self.autosave.interval_seconds.max(1)));
        let generation = self.edit_generation;
        if !self.autosave.autosaver.is_due(Instant::now(), generation) {
            return;
        }
        let document = std::sync::Arc::clone(&open.document);
        let started = self.jobs.start(AUTOSAVE_LABEL, move |job| {
            job.progress(0.1, "writing the recovery file");
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
            }
            let write = autosave::write_recovery(&path, &document).map_err(|e| e.to_string())?;
            Ok(JobOutput::Autosaved(Autosaved { path, write, generation }))
        });
        if let Err(message) = started {
            log::warn!("{message}");
        }
    }

    /// Applies a finished autosave.
    pub(crate) fn finish_autosave(&mut self, autosaved: Autosaved) {
        self.autosave.autosaver.mark_saved(Instant::now(), autosaved.generation);
        self.autosave.last_saved = Some(Instant::now());
        log::info!(
            "Autosaved {} ({}, {:.2} s)",
            autosaved.path.display(),
            human_bytes(autosaved.write.bytes),
            autosaved.write.seconds
        );
    }

    /// After a normal save: the recovery file is obsolete; later autosaves go next to the
    /// saved project.
    pub(crate) fn saved_document(&mut self) {
        if let Some(path) = self.autosave.recovery_path.take()
            && let Err(error) = autosave::discard_recovery(&path)
        {
            log::warn!("{error}");
        }
        if let Some(open) = &self.document {
            self.autosave.recovery_path = recovery_path_of(open);
        }
        let generation = self.edit_generation;
        self.autosave.autosaver.mark_saved(Instant::now(), generation);
    }

    /// Autosave settings (file panel).
    pub fn autosave_settings_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.autosave.enabled, "Autosave every");
            ui.add_enabled(
                self.autosave.enabled,
                egui::DragValue::new(&mut self.autosave.interval_seconds).range(5..=3600).suffix(" s"),
            );
        });
        if let Some(at) = self.autosave.last_saved {
            ui.label(egui::RichText::new(format!("Last autosave {:.0} s ago", at.elapsed().as_secs_f64())).weak());
        }
    }

    /// The recovery offer: restore the recovery file or discard it.
    pub fn recovery_dialog_ui(&mut self, ctx: &egui::Context) {
        let Some(offer) = self.autosave.offer.clone() else {
            return;
        };
        let mut choice = None;
        egui::Window::new("Recover unsaved work?")
            .collapsible(false)
            .resizable(false)
            .pivot(egui::Align2::CENTER_CENTER)
            .default_pos(self.viewport.rect.center())
            .show(ctx, |ui| {
                ui.label(format!("A recovery file from an earlier session exists:\n{}", offer.path.display()));
                ui.horizontal(|ui| {
                    if ui.button("Restore").clicked() {
                        choice = Some(true);
                    }
                    if ui.button("Discard").clicked() {
                        choice = Some(false);
                    }
                });
            });
        match choice {
            Some(true) => {
                let Some(open) = &self.document else {
                    return;
                };
                if self.jobs.is_busy() {
                    self.set_status(Severity::Warning, "Busy: try again when the running job has finished.");
                    return;
                }
                self.autosave.restoring = Some(Restoring {
                    path: open.path.clone(),
                    project_path: open.project_path.clone(),
                    title: open.title.clone(),
                    format: open.format,
                });
                self.autosave.offer = None;
                self.open(Source::File(offer.path));
                // Unsaved: the restored colours are not in the document's file yet.
                self.edit_generation += 1;
            }
            Some(false) => {
                self.autosave.offer = None;
                match autosave::discard_recovery(&offer.path) {
                    Ok(()) => self.set_status(Severity::Info, "Recovery file discarded."),
                    Err(error) => self.set_status(Severity::Error, error.to_string()),
                }
            }
            None => {}
        }
    }
}
