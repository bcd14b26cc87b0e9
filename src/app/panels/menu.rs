//! The menu bar: File, View, Help. Every entry is an [`Action`] with its shortcut shown.

use crate::app::command::Command;
use crate::app::input::shortcut_text;
use crate::app::state::Action;

/// The menu bar (it keeps no state: egui remembers which menu is open).
#[derive(Debug, Default)]
pub struct MenuBar;

impl MenuBar {
    /// The menus; returns the action chosen, if any. `has_document`: a document is open;
    /// `idle`: no job runs (files are opened and written one at a time).
    pub fn ui(&mut self, ui: &mut egui::Ui, has_document: bool, idle: bool) -> Vec<Command> {
        let mut chosen = Vec::new();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                action_button(ui, "Open…", Action::Open, idle, &mut chosen);
                ui.separator();
                action_button(ui, "Save", Action::Save, idle && has_document, &mut chosen);
                action_button(ui, "Save as…", Action::SaveAs, idle && has_document, &mut chosen);
                ui.separator();
                action_button(ui, "Export…", Action::Export, idle && has_document, &mut chosen);
                action_button(ui, "Export glTF…", Action::ExportGltf, idle && has_document, &mut chosen);
                action_button(ui, "Export packed buffers…", Action::ExportPacked, idle && has_document, &mut chosen);
                ui.separator();
                action_button(ui, "Quit", Action::Quit, true, &mut chosen);
            });
            ui.menu_button("View", |ui| {
                action_button(ui, "Frame all", Action::FrameAll, has_document, &mut chosen);
                action_button(ui, "Front", Action::ViewFront, has_document, &mut chosen);
                action_button(ui, "Right", Action::ViewRight, has_document, &mut chosen);
                action_button(ui, "Top", Action::ViewTop, has_document, &mut chosen);
                ui.separator();
                action_button(ui, "Wireframe on / off", Action::ToggleWireframe, true, &mut chosen);
                action_button(ui, "Heat map on / off", Action::ToggleHeatmap, true, &mut chosen);
                action_button(ui, "Lit / unlit", Action::ToggleShading, true, &mut chosen);
                action_button(ui, "Next filter", Action::CycleFilter, true, &mut chosen);
                action_button(ui, "Mesh colors / MCT / Ptex / Htex", Action::ToggleRepresentation, true, &mut chosen);
            });
            ui.menu_button("Help", |ui| {
                action_button(ui, "Shortcuts", Action::ToggleHelp, true, &mut chosen);
            });
        });
        chosen
    }
}

/// A menu entry for `action`, showing its shortcut; a click adds the action to `chosen`
/// and closes the menu.
fn action_button(ui: &mut egui::Ui, text: &str, action: Action, enabled: bool, chosen: &mut Vec<Command>) {
    let mut button = egui::Button::new(text);
    if let Some(keys) = shortcut_text(action) {
        button = button.shortcut_text(keys);
    }
    if ui.add_enabled(enabled, button).clicked() {
        chosen.push(Command::Action(action));
        ui.close();
    }
}
