//! Autosave and recovery in the editor: a periodic recovery write on a worker thread while
//! there are unsaved edits, the recovery offer (restore / discard) when a document with a
//! newer recovery file opens, and the settings. The state is [`super::autosave`].

use std::time::{Duration, Instant};

use meshpaint_core::io::autosave;
use meshpaint_core::io::document::Source;

use super::autosave::{Autosaved, Restoring};
use super::editor::{Editor, JobOutput};
use super::jobs::JobKind;
use super::state::Severity;

impl Editor {
    /// Starts an autosave when one is due (called every frame). Returns how long until the
    /// next one falls due, when one is pending: the editor draws no frame at rest, so the UI
    /// asks to be woken then.
    pub fn autosave_tick(&mut self) -> Option<Duration> {
        let stroking = self.paint.as_ref().is_some_and(|p| p.painter.is_stroking());
        if !self.autosave.enabled || self.jobs.is_busy() || stroking || self.autosave.offer.is_some() {
            return None;
        }
        let (Some(open), Some(path)) = (&self.document, self.autosave.recovery_path.clone()) else {
            return None;
        };
        self.autosave.autosaver.interval = Duration::from_secs(u64::from(self.autosave.interval_seconds.max(1)));
        let generation = self.edit_generation;
        let now = Instant::now();
        if !self.autosave.autosaver.is_due(now, generation) {
            return self.autosave.autosaver.due_at(generation).map(|at| at.saturating_duration_since(now));
        }
        let document = std::sync::Arc::clone(&open.document);
        let started = self.jobs.start(JobKind::Autosave, "Autosave", move |job| {
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
        None
    }

    /// Autosave settings (file panel).
    pub fn autosave_settings_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.autosave.enabled, "Autosave every");
            ui.add_enabled(
                self.autosave.enabled,
                // Not clamped while shown: MESHPAINT_AUTOSAVE_SECONDS may ask for less than 5 s.
                egui::DragValue::new(&mut self.autosave.interval_seconds)
                    .range(5..=3600)
                    .clamp_existing_to_range(false)
                    .suffix(" s"),
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
        let mut restore_at = None;
        egui::Window::new("Recover unsaved work?")
            .collapsible(false)
            .resizable(false)
            .pivot(egui::Align2::CENTER_CENTER)
            .default_pos(self.viewport.rect.center())
            .show(ctx, |ui| {
                ui.label(format!("A recovery file from an earlier session exists:\n{}", offer.path.display()));
                ui.horizontal(|ui| {
                    let restore = ui.button("Restore");
                    if restore.clicked() {
                        choice = Some(true);
                    }
                    restore_at = Some(restore.rect.center());
                    if ui.button("Discard").clicked() {
                        choice = Some(false);
                    }
                });
            });
        // A log line the window tests wait for (and click at).
        if let Some(at) = restore_at {
            let ppp = ctx.pixels_per_point();
            let px = [(at.x * ppp).round() as i32, (at.y * ppp).round() as i32];
            if self.autosave.logged_restore_button != Some(px) {
                log::info!("Recovery offered for {}: Restore button at {},{} px", offer.path.display(), px[0], px[1]);
                self.autosave.logged_restore_button = Some(px);
            }
        }
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
