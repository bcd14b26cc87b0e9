//! The status line: the mode, the last message, and a running job's progress.

use std::time::Duration;

use crate::app::state::{Mode, Severity, Status};

/// A running job as the status line shows it: label, fraction done, stage, age.
pub type JobProgress<'a> = (&'a str, f32, String, Duration);

/// The status line (it shows the editor's [`Status`] and keeps nothing itself).
#[derive(Debug, Default)]
pub struct StatusLine;

impl StatusLine {
    /// The mode, then the running `job`'s progress if there is one (with a Cancel button
    /// when `cancellable`; returns whether it was clicked), else `status`.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        mode: Mode,
        status: &Status,
        job: Option<JobProgress<'_>>,
        cancellable: bool,
    ) -> bool {
        let mut cancel = false;
        ui.horizontal(|ui| {
            let text = egui::RichText::new(format!("{} mode", mode.name())).strong();
            let text = match mode {
                Mode::Paint => text.color(egui::Color32::from_rgb(255, 170, 60)),
                Mode::View => text,
            };
            ui.label(text).on_hover_text("Tab toggles paint mode");
            ui.separator();
            if let Some((label, fraction, stage, elapsed)) = job {
                ui.add(egui::ProgressBar::new(fraction).desired_width(220.0).show_percentage().animate(true));
                if cancellable {
                    cancel = ui.button("Cancel").on_hover_text("Stop; the open document stays").clicked();
                }
                ui.label(format!("{label}: {stage} ({:.1} s)", elapsed.as_secs_f32()));
            } else {
                let color = match status.severity {
                    Severity::Info => ui.visuals().text_color(),
                    Severity::Warning => ui.visuals().warn_fg_color,
                    Severity::Error => ui.visuals().error_fg_color,
                };
                let prefix = match status.severity {
                    Severity::Error => "Error: ",
                    _ => "",
                };
                ui.add(
                    egui::Label::new(egui::RichText::new(format!("{prefix}{}", status.text)).color(color)).truncate(),
                )
                .on_hover_text(&status.text);
            }
        });
        cancel
    }
}
