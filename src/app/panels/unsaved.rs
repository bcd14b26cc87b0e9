//! The "save changes first?" prompt of [`crate::app::unsaved`]: a modal window with Save,
//! Don't save and Cancel (Esc).

use crate::app::command::Command;
use crate::app::unsaved::{Pending, UnsavedChoice};

/// The prompt and the action waiting for its answer.
#[derive(Debug, Default)]
pub struct UnsavedPrompt {
    /// The action that asked, while the prompt is shown.
    pub pending: Option<Pending>,
}

impl UnsavedPrompt {
    /// The prompt for the document `title` while an action waits; returns the answer
    /// (Esc or a click outside: Cancel).
    pub fn ui(&mut self, ctx: &egui::Context, title: &str) -> Vec<Command> {
        let Some(pending) = &self.pending else {
            return Vec::new();
        };
        let mut answer = None;
        let modal = egui::Modal::new(egui::Id::unique("unsaved changes")).show(ctx, |ui| {
            ui.set_max_width(360.0);
            ui.heading(format!("Save changes to {title}?"));
            ui.label(format!("The document has changes that are not saved. Save them before {}?", pending.describe()));
            ui.add_space(8.0);
            ui.horizontal(|ui| {
                if ui.button("Save").clicked() {
                    answer = Some(UnsavedChoice::Save);
                }
                if ui.button("Don't save").clicked() {
                    answer = Some(UnsavedChoice::DontSave);
                }
                if ui.button("Cancel").clicked() {
                    answer = Some(UnsavedChoice::Cancel);
                }
            });
        });
        if answer.is_none() && modal.should_close() {
            answer = Some(UnsavedChoice::Cancel);
        }
        answer.map(Command::Unsaved).into_iter().collect()
    }
}
