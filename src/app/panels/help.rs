//! The shortcut help window (F1): the pointer gestures and every keyboard shortcut.

use crate::app::input::{POINTER_HELP, SHORTCUTS};

/// The help window.
#[derive(Debug, Default)]
pub struct HelpWindow {
    /// Whether it is shown.
    pub open: bool,
}

impl HelpWindow {
    /// Draws the window when it is open, centred on `center` (points) the first time, never
    /// taller than the window (its lists scroll, so the close button stays on screen); its
    /// close button and Esc hide it.
    pub fn ui(&mut self, ctx: &egui::Context, center: egui::Pos2) {
        if !self.open {
            return;
        }
        let mut open = self.open;
        egui::Window::new("Keyboard and mouse")
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .pivot(egui::Align2::CENTER_CENTER)
            .default_pos(center)
            .constrain(true)
            .max_height((ctx.content_rect().height() - 80.0).max(120.0))
            .show(ctx, |ui| {
                egui::ScrollArea::vertical().show(ui, Self::lists);
            });
        if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            open = false;
        }
        self.open = open && self.open;
    }

    /// The pointer gestures and the keyboard shortcuts.
    fn lists(ui: &mut egui::Ui) {
        egui::Grid::new("pointer help").num_columns(2).spacing([16.0, 4.0]).striped(true).show(ui, |ui| {
            for (gesture, what) in POINTER_HELP {
                ui.label(egui::RichText::new(*gesture).strong());
                ui.label(*what);
                ui.end_row();
            }
        });
        ui.separator();
        egui::Grid::new("key help").num_columns(3).spacing([16.0, 4.0]).striped(true).show(ui, |ui| {
            for shortcut in SHORTCUTS {
                ui.label(egui::RichText::new(shortcut.keys).strong().monospace());
                ui.label(shortcut.description);
                ui.label(egui::RichText::new(shortcut.scope.name()).weak());
                ui.end_row();
            }
        });
    }
}
