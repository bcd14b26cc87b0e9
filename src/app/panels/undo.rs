//! The undo panel: undo / redo buttons, the undo memory and its cap, the last stroke.

use meshpaint_core::paint::undo::UndoHistory;

use crate::app::command::Command;
use crate::app::state::Action;
use crate::app::text::{human_bytes, thousands};

/// The undo panel (the history is the document's: the panel shows it and asks for changes).
#[derive(Debug, Default)]
pub struct UndoPanel;

/// What the last stroke did: sample updates and bytes uploaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LastStroke {
    /// Samples changed.
    pub samples_changed: u64,
    /// Bytes uploaded to the GPU.
    pub upload_bytes: u64,
}

impl UndoPanel {
    /// Undo / redo (enabled while `painting`), the memory `history` uses and its cap, and
    /// the `last_stroke` of the paint session.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        painting: bool,
        history: &UndoHistory,
        last_stroke: Option<LastStroke>,
    ) -> Vec<Command> {
        let mut commands = Vec::new();
        ui.add_enabled_ui(painting, |ui| {
            ui.horizontal(|ui| {
                let undo = ui
                    .add_enabled(history.undo_len() > 0, egui::Button::new("Undo"))
                    .on_hover_text(history.undo_label().unwrap_or("Ctrl+Z"));
                if undo.clicked() {
                    commands.push(Command::Action(Action::Undo));
                }
                let redo = ui
                    .add_enabled(history.redo_len() > 0, egui::Button::new("Redo"))
                    .on_hover_text(history.redo_label().unwrap_or("Ctrl+Shift+Z"));
                if redo.clicked() {
                    commands.push(Command::Action(Action::Redo));
                }
            });
        });
        ui.label(format!(
            "Undo: {} steps, {} / {}",
            history.undo_len(),
            human_bytes(history.bytes_used() as u64),
            human_bytes(history.cap_bytes() as u64)
        ));
        let mut cap_mib = (history.cap_bytes() >> 20) as u32;
        if ui.add(egui::Slider::new(&mut cap_mib, 1..=4096).logarithmic(true).text("Undo memory (MiB)")).changed() {
            commands.push(Command::SetUndoCap((cap_mib as usize) << 20));
        }
        if let Some(stroke) = last_stroke {
            ui.label(
                egui::RichText::new(format!(
                    "Last stroke: {} samples changed, {} uploaded to the GPU",
                    thousands(stroke.samples_changed),
                    human_bytes(stroke.upload_bytes)
                ))
                .weak(),
            );
        }
        commands
    }
}
