//! The autosave panel: the settings (on / off, interval, last autosave) and the recovery
//! offer (restore / discard, with when the file was written and what it holds) shown when a
//! document with a newer recovery file opens. It
//! owns the autosave state ([`AutosaveState`]); the editor writes recovery files as jobs.

use meshpaint_core::io::autosave::RecoveryInfo;

use crate::app::autosave::AutosaveState;
use crate::app::command::Command;
use crate::app::text::{human_bytes, thousands};

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
        let Some(offer) = self.state.offer.as_ref() else {
            return Vec::new();
        };
        let (path, described) = (offer.path.clone(), describe_recovery(offer, std::time::SystemTime::now()));
        let mut choice = Vec::new();
        let mut restore_at = None;
        egui::Window::new("Recover unsaved work?")
            .collapsible(false)
            .resizable(false)
            .pivot(egui::Align2::CENTER_CENTER)
            .default_pos(center)
            .show(ctx, |ui| {
                ui.label(format!("A recovery file from an earlier session exists:\n{}", path.display()));
                ui.label(described);
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

/// When the recovery file `offer` was written (how long before `now`, and the UTC time) and
/// what it holds, for the recovery prompt.
pub fn describe_recovery(offer: &RecoveryInfo, now: std::time::SystemTime) -> String {
    let written = match offer.modified {
        Some(modified) => {
            let ago = now.duration_since(modified).unwrap_or_default().as_secs();
            let since_epoch = modified.duration_since(std::time::UNIX_EPOCH).unwrap_or_default().as_secs();
            let (h, m) = ((since_epoch / 3600) % 24, (since_epoch / 60) % 60);
            let ago = match ago {
                0..60 => "less than a minute ago".to_owned(),
                60..7200 => format!("{} min ago", ago / 60),
                7200..172_800 => format!("{} hours ago", ago / 3600),
                _ => format!("{} days ago", ago / 86_400),
            };
            format!("Written {ago} ({h:02}:{m:02} UTC)")
        }
        None => "Written at an unknown time".to_owned(),
    };
    match &offer.holds {
        Some(holds) => format!(
            "{written}: {} triangles, {} samples, {}.",
            thousands(u64::from(holds.face_count)),
            thousands(holds.sample_count),
            human_bytes(holds.file_size)
        ),
        None => format!("{written}; its header cannot be read (restoring will say why)."),
    }
}
