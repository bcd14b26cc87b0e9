//! The optimize panel: the error bound and the Optimize button (lower each face's `R` while
//! what the mesh shows stays within the bound; runs as a job, undoable).

use crate::app::command::Command;

/// The optimize panel and its error bound.
#[derive(Debug, Default)]
pub struct OptimizePanel {
    /// The error bound of "Optimize" (0 = lossless; colour units, 0..1).
    pub bound: f32,
}

impl OptimizePanel {
    /// The bound and the button (enabled while `painting`).
    pub fn ui(&mut self, ui: &mut egui::Ui, painting: bool) -> Vec<Command> {
        let mut commands = Vec::new();
        ui.add_enabled_ui(painting, |ui| {
            ui.horizontal(|ui| {
                ui.label("Error bound");
                ui.add(egui::DragValue::new(&mut self.bound).range(0.0..=1.0).speed(0.001).max_decimals(3))
                    .on_hover_text("Largest change of any shown colour channel (linear light, 0..1); 0 = lossless");
                if ui
                    .button("Optimize")
                    .on_hover_text("Lower each face's R while what the mesh shows stays within the bound (undoable)")
                    .clicked()
                {
                    commands.push(Command::Optimize(self.bound));
                }
            });
        });
        commands
    }
}
