//! The brush presets section of the paint panel: a button per preset (loads it), a name
//! field, "Save preset" (the current brush under that name, replacing one of the same
//! name) and "Delete preset" (the one of that name). Loading a preset puts its name in the
//! field, so saving again updates it and Delete removes it.

use meshpaint_core::paint::brush::BrushSettings;

use crate::app::presets::BrushPresets;

/// The presets and the section's state.
#[derive(Debug, Clone, Default)]
pub struct PresetsPanel {
    /// The presets (remembered in the settings file).
    pub presets: BrushPresets,
    /// The name field.
    pub name: String,
    /// What the last action did, or why it did nothing.
    pub message: Option<String>,
}

impl PresetsPanel {
    /// The section, editing `brush` when a preset is loaded.
    pub fn ui(&mut self, ui: &mut egui::Ui, brush: &mut BrushSettings) {
        ui.horizontal_wrapped(|ui| {
            ui.label("Presets:");
            let mut loaded = None;
            for preset in self.presets.list() {
                let selected = preset.applied_to(brush) == *brush;
                if ui
                    .selectable_label(selected, &preset.name)
                    .on_hover_text(format!("Load the brush \"{}\" (the colour stays)", preset.name))
                    .clicked()
                {
                    *brush = preset.applied_to(brush);
                    loaded = Some(preset.name.clone());
                }
            }
            if let Some(name) = loaded {
                self.message = Some(format!("Loaded \"{name}\"."));
                self.name = name;
            }
        });
        ui.horizontal(|ui| {
            let label = ui.label("Name");
            ui.add(egui::TextEdit::singleline(&mut self.name).desired_width(90.0).hint_text("my brush"))
                .labelled_by(label.id);
            if ui.button("Save preset").on_hover_text("The current brush under this name").clicked() {
                self.message = Some(match self.presets.save(&self.name, *brush) {
                    Ok(true) => format!("Updated \"{}\".", self.name.trim()),
                    Ok(false) => format!("Saved \"{}\".", self.name.trim()),
                    Err(reason) => reason,
                });
            }
            if ui.button("Delete preset").on_hover_text("The preset of this name").clicked() {
                let name = self.name.trim().to_owned();
                self.message = Some(if self.presets.delete(&name) {
                    format!("Deleted \"{name}\".")
                } else {
                    format!("No preset is named \"{name}\".")
                });
            }
        });
        if let Some(message) = &self.message {
            ui.weak(message);
        }
    }
}
