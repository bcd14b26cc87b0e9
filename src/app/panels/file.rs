//! The file panel: open, save and export buttons, and the file dialog they show (with the
//! directory it starts in).

use std::path::{Path, PathBuf};

use meshpaint_core::colors::format::ColorFormat;

use crate::app::command::Command;
use crate::app::document::OpenDocument;
use crate::app::file_dialog::{DialogOutcome, DialogPurpose, FileDialog};
use crate::app::import_settings::ImportSettings;
use crate::app::jobs::WriteKind;
use crate::app::state::Action;

/// The file panel and its dialog.
#[derive(Debug)]
pub struct FilePanel {
    /// The open file dialog, if any.
    pub dialog: Option<FileDialog>,
    /// Where file dialogs start (the directory of the last file opened or written).
    pub last_directory: PathBuf,
}

impl Default for FilePanel {
    fn default() -> Self {
        FilePanel { dialog: None, last_directory: std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")) }
    }
}

impl FilePanel {
    /// Open, save, export. `has_document`: a document is open; `idle`: no job runs.
    pub fn ui(&mut self, ui: &mut egui::Ui, has_document: bool, idle: bool) -> Vec<Command> {
        let mut chosen = Vec::new();
        let writable = idle && has_document;
        let mut button = |ui: &mut egui::Ui, enabled: bool, text: &str, keys: &str, action: Action| {
            if ui.add_enabled(enabled, egui::Button::new(text)).on_hover_text(keys).clicked() {
                chosen.push(Command::Action(action));
            }
        };
        ui.horizontal_wrapped(|ui| {
            button(ui, idle, "Open…", "Ctrl+O", Action::Open);
            button(ui, writable, "Save", "Ctrl+S", Action::Save);
            button(ui, writable, "Save as…", "Ctrl+Shift+S", Action::SaveAs);
        });
        ui.horizontal_wrapped(|ui| {
            button(ui, writable, "Export…", "baked texture, glTF or packed", Action::Export);
            button(ui, writable, "Export glTF…", "Ctrl+E", Action::ExportGltf);
            button(ui, writable, "Export packed…", "Ctrl+Shift+E", Action::ExportPacked);
        });
        chosen
    }

    /// Remembers the directory of `path` (a file opened or written) for the next dialog.
    pub fn remember_directory_of(&mut self, path: &Path) {
        if let Some(parent) = path.parent().filter(|p| p.is_dir()) {
            self.last_directory = parent.to_owned();
        }
    }

    /// Shows the dialog for `purpose`, its name field filled after `document` (the open
    /// one, if any); an Open dialog offers `import`.
    pub fn open_dialog(&mut self, purpose: DialogPurpose, document: Option<&OpenDocument>, import: ImportSettings) {
        let stem = document
            .and_then(|d| d.path.as_deref().and_then(Path::file_stem).map(|s| s.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "duck".to_owned());
        let file_name = match purpose {
            DialogPurpose::Open => String::new(),
            DialogPurpose::SaveAs => format!("{stem}.mpk"),
            DialogPurpose::ExportPacked => format!("{stem}_export.mpk"),
            DialogPurpose::ExportGltf => format!("{stem}_meshcolors.glb"),
        };
        let format = document.map_or_else(ColorFormat::default, |d| d.format);
        let mut dialog = FileDialog::new(purpose, self.last_directory.clone(), file_name, format);
        if purpose == DialogPurpose::Open {
            dialog.import = Some(import);
        }
        self.dialog = Some(dialog);
    }

    /// Draws the dialog, if one is open; the import choice made in it becomes `import`.
    /// Returns what the chosen file is for.
    pub fn dialog_ui(&mut self, ctx: &egui::Context, import: &mut ImportSettings) -> Vec<Command> {
        let Some(dialog) = self.dialog.as_mut() else {
            return Vec::new();
        };
        let purpose = dialog.purpose;
        let outcome = dialog.file_dialog_ui(ctx);
        if let Some(chosen) = dialog.import {
            *import = chosen;
        }
        match outcome {
            DialogOutcome::Pending => Vec::new(),
            DialogOutcome::Cancelled => {
                self.dialog = None;
                Vec::new()
            }
            DialogOutcome::Chosen(path, format) => {
                self.dialog = None;
                vec![match purpose {
                    DialogPurpose::Open => Command::Open(path),
                    DialogPurpose::SaveAs => Command::Write(path, format, WriteKind::Save),
                    DialogPurpose::ExportPacked => Command::Write(path, format, WriteKind::ExportPacked),
                    DialogPurpose::ExportGltf => Command::Write(path, format, WriteKind::ExportGltf),
                }]
            }
        }
    }
}
