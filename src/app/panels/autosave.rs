//! The autosave panel: the settings (on / off, interval, last autosave) and the recovery
//! offer (restore / discard) shown when a document with a newer recovery file opens. It
//! owns the autosave state ([`AutosaveState`]); the editor writes recovery files as jobs.

use crate::app::autosave::AutosaveState;
use crate::app::command::Command;

/// The autosave panel and the autosave state.
#[derive(Debug, Default)]
pub struct AutosavePanel {
    /// Settings, timer, recovery file and offer.
    pub state: AutosaveState,
}

impl AutosavePanel {
    /// The settings (in the file section).
    pub fn settings_ui(&mut self, ui: &mut egui::Ui) {
        let state = &mut self.state;
        ui.horizontal(|ui| {
            ui.checkbox(&mut state.enabled, "Autosave every");
            ui.add_enabled(
                state.enabled,
                // Not clamped while shown: MESHPAINT_AUTOSAVE_SECONDS may ask for less than 5 s.
                egui::DragValue::new(&mut state.interval_seconds)
                    .range(5..=3600)
                    .clamp_existing_to_range(false)
                    .suffix(" s"),
            );
        });
        if let Some(at) = state.last_saved {
            ui.label(egui::RichText::new(format!("Last autosave {:.0} s ago", at.elapsed().as_secs_f64())).weak());
        }
    }

    /// The recovery offer, while there is one, centred on `center` (points): returns the
    /// choice (restore or discard).
    pub fn recovery_ui(&mut self, ctx: &egui::Context, center: egui::Pos2) -> Vec<Command> {
        let Some(path) = self.state.offer.as_ref().map(|offer| offer.path.clone()) else {
            return Vec::new();
        };
        let mut choice = Vec::new();
        let mut restore_at = None;
        egui::Window::new("Recover unsaved work?")
            .collapsible(false)
            .resizable(false)
            .pivot(egui::Align2::CENTER_CENTER)
            .default_pos(center)
            .show(ctx, |ui| {
                ui.label(format!("A recovery file from an earlier session exists:\n{}", path.display()));
                ui.horizontal(|ui| {
                    let restore = ui.button("Restore");
                    if restore.clicked() {
                        choice.push(Command::RestoreRecovery);
                    }
                    restore_at = Some(restore.rect.center());
                    if ui.button("Discard").clicked() {
                        choice.push(Command::DiscardRecovery);
                    }
                });
            });
        // A log line the window tests wait for (and click at).
        if let Some(at) = restore_at {
            let ppp = ctx.pixels_per_point();
            let px = [(at.x * ppp).round() as i32, (at.y * ppp).round() as i32];
            if self.state.logged_restore_button != Some(px) {
                log::info!("Recovery offered for {}: Restore button at {},{} px", path.display(), px[0], px[1]);
                self.state.logged_restore_button = Some(px);
            }
        }
        choice
    }
}
