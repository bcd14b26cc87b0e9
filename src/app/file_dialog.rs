//! A small in-app file browser (egui only).
//!
//! Native dialog crates (rfd, portals) need GTK or a desktop portal, which a bare X server
//! such as Xvfb lacks; this browser works everywhere the window does, and it can be driven
//! with the keyboard: the path field has the focus, Enter confirms, Escape cancels.

use std::path::{Path, PathBuf};

use meshpaint_core::colors::format::ColorFormat;

use super::import_settings::ImportSettings;

/// What the dialog is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    /// Open a glTF or packed file.
    Open,
    /// Save the project (a packed file).
    SaveAs,
    /// Export the packed buffers in a chosen colour format.
    ExportPacked,
    /// Export a tessellated vertex-colour .glb.
    ExportGltf,
}

impl DialogPurpose {
    /// Window title.
    pub fn title(self) -> &'static str {
        match self {
            DialogPurpose::Open => "Open",
            DialogPurpose::SaveAs => "Save as packed file",
            DialogPurpose::ExportPacked => "Export packed buffers",
            DialogPurpose::ExportGltf => "Export glTF (.glb)",
        }
    }

    /// The confirm button's text.
    pub fn action(self) -> &'static str {
        match self {
            DialogPurpose::Open => "Open",
            DialogPurpose::SaveAs => "Save",
            DialogPurpose::ExportPacked | DialogPurpose::ExportGltf => "Export",
        }
    }

    /// File-name extensions listed (lower case; every file is listed with "all files").
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            DialogPurpose::Open => &["glb", "gltf", "obj", "ply", "stl", "mpk"],
            DialogPurpose::SaveAs | DialogPurpose::ExportPacked => &["mpk"],
            DialogPurpose::ExportGltf => &["glb"],
        }
    }

    /// Whether the dialog writes a file (and so asks before replacing one).
    pub fn writes(self) -> bool {
        self != DialogPurpose::Open
    }
}

/// What the user decided this frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DialogOutcome {
    /// Still choosing.
    Pending,
    /// Closed without a choice.
    Cancelled,
    /// Chose this file (and, for packed exports, this colour format).
    Chosen(PathBuf, ColorFormat),
}

/// One directory entry.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Entry {
    name: String,
    is_dir: bool,
}

/// The dialog's state.
#[derive(Debug, Clone)]
pub struct FileDialog {
    /// What it is for.
    pub purpose: DialogPurpose,
    /// The directory listed.
    pub directory: PathBuf,
    /// The path field: a file name in `directory`, or a path (absolute or relative to it).
    pub file_name: String,
    /// Colour format for packed outputs.
    pub format: ColorFormat,
    /// List every file, not only the purpose's extensions.
    pub show_all: bool,
    /// The mesh resolution choice, shown when opening (the editor copies it in and back).
    pub import: Option<ImportSettings>,
    entries: Vec<Entry>,
    listing_error: Option<String>,
    confirm_replace: Option<PathBuf>,
    focus_pending: bool,
    focus_logged: bool,
}

impl FileDialog {
    /// A dialog for `purpose` listing `directory`, the path field set to `file_name`.
    pub fn new(purpose: DialogPurpose, directory: PathBuf, file_name: String, format: ColorFormat) -> Self {
        let mut dialog = FileDialog {
            purpose,
            directory,
            file_name,
            format,
            show_all: false,
            import: None,
            entries: Vec::new(),
            listing_error: None,
            confirm_replace: None,
            focus_pending: true,
            focus_logged: false,
        };
        dialog.refresh();
        dialog
    }

    /// Re-reads the directory listing.
    pub fn refresh(&mut self) {
        self.entries.clear();
        self.listing_error = None;
        let read = match std::fs::read_dir(&self.directory) {
            Ok(read) => read,
            Err(error) => {
                self.listing_error = Some(format!("{}: {error}", self.directory.display()));
                return;
            }
        };
        let extensions = self.purpose.extensions();
        for entry in read.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') {
                continue;
            }
            let is_dir = entry.path().is_dir();
            let listed = is_dir
                || self.show_all
                || Path::new(&name)
                    .extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| extensions.contains(&e.to_ascii_lowercase().as_str()));
            if listed {
                self.entries.push(Entry { name, is_dir });
            }
        }
        self.entries
            .sort_by(|a, b| b.is_dir.cmp(&a.is_dir).then_with(|| a.name.to_lowercase().cmp(&b.name.to_lowercase())));
    }

    /// Lists `directory` instead.
    pub fn navigate(&mut self, directory: PathBuf) {
        self.directory = directory;
        self.confirm_replace = None;
        self.refresh();
    }

    /// The path the field names.
    pub fn chosen_path(&self) -> PathBuf {
        let typed = expand_home(self.file_name.trim());
        if typed.is_absolute() { typed } else { self.directory.join(typed) }
    }

    /// What confirming (Enter or the action button) does now.
    fn confirm(&mut self) -> DialogOutcome {
        if self.file_name.trim().is_empty() {
            return DialogOutcome::Pending;
        }
        let path = self.chosen_path();
        if path.is_dir() {
            self.navigate(path);
            self.file_name.clear();
            self.focus_pending = true;
            return DialogOutcome::Pending;
        }
        if self.purpose.writes() && path.exists() && self.confirm_replace.as_deref() != Some(path.as_path()) {
            self.confirm_replace = Some(path);
            return DialogOutcome::Pending;
        }
        DialogOutcome::Chosen(path, self.format)
    }

    /// Draws the dialog as a window; returns the user's decision.
    pub fn file_dialog_ui(&mut self, ctx: &egui::Context) -> DialogOutcome {
        let mut outcome = DialogOutcome::Pending;
        let mut open = true;
        let screen = ctx.content_rect();
        egui::Window::new(self.purpose.title())
            .id(egui::Id::unique("file dialog"))
            .open(&mut open)
            .collapsible(false)
            .resizable(true)
            .default_size([520.0, 420.0])
            .max_height((screen.height() - 40.0).max(200.0))
            .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
            .show(ctx, |ui| outcome = self.contents_ui(ui));
        if !open || ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            return DialogOutcome::Cancelled;
        }
        outcome
    }

    fn contents_ui(&mut self, ui: &mut egui::Ui) -> DialogOutcome {
        let mut outcome = DialogOutcome::Pending;
        ui.horizontal(|ui| {
            if ui.button("Up").on_hover_text("Parent directory").clicked()
                && let Some(parent) = self.directory.parent()
            {
                self.navigate(parent.to_owned());
            }
            if ui.button("Home").clicked()
                && let Some(home) = std::env::var_os("HOME")
            {
                self.navigate(PathBuf::from(home));
            }
            ui.label(egui::RichText::new(self.directory.display().to_string()).monospace());
        });
        ui.separator();
        let list_height = (ui.available_height() - if self.import.is_some() { 120.0 } else { 90.0 }).max(80.0);
        let mut navigate_to = None;
        egui::ScrollArea::vertical().max_height(list_height).auto_shrink([false, false]).show(ui, |ui| {
            if let Some(error) = &self.listing_error {
                ui.colored_label(ui.visuals().error_fg_color, error);
            }
            for entry in &self.entries {
                let text = if entry.is_dir { format!("{}/", entry.name) } else { entry.name.clone() };
                let selected = !entry.is_dir && self.file_name == entry.name;
                let response = ui.selectable_label(selected, text);
                if response.clicked() {
                    if entry.is_dir {
                        navigate_to = Some(self.directory.join(&entry.name));
                    } else {
                        self.file_name.clone_from(&entry.name);
                        self.confirm_replace = None;
                    }
                }
                if !entry.is_dir && response.double_clicked() {
                    self.file_name.clone_from(&entry.name);
                    outcome = DialogOutcome::Chosen(self.chosen_path(), self.format);
                }
            }
        });
        if let Some(directory) = navigate_to {
            self.navigate(directory);
        }
        ui.separator();
        ui.horizontal(|ui| {
            ui.label("File:");
            let field = ui.add(
                egui::TextEdit::singleline(&mut self.file_name)
                    .id(egui::Id::unique("file dialog path"))
                    .desired_width(ui.available_width() - 8.0)
                    .hint_text("name or path"),
            );
            if self.focus_pending {
                field.request_focus();
                self.focus_pending = false;
            } else if field.has_focus() && !self.focus_logged {
                // The window tests wait for this line before typing a path.
                log::info!("File dialog \"{}\": the path field has the keyboard focus", self.purpose.title());
                self.focus_logged = true;
            }
            if field.changed() {
                self.confirm_replace = None;
            }
            if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                outcome = self.confirm();
            }
        });
        ui.horizontal(|ui| {
            if self.purpose == DialogPurpose::ExportPacked || self.purpose == DialogPurpose::SaveAs {
                let label = ui.label("Colour format:");
                let combo = egui::ComboBox::from_id_salt("file dialog format").selected_text(self.format.name());
                let response = combo.show_ui(ui, |ui| {
                    for format in ColorFormat::ALL {
                        ui.selectable_value(&mut self.format, format, format.name());
                    }
                });
                response.response.labelled_by(label.id);
            }
            if ui.checkbox(&mut self.show_all, "All files").changed() {
                self.refresh();
            }
        });
        if let Some(import) = self.import.as_mut() {
            import.ui(ui, "Mesh resolution:");
        }
        if let Some(path) = &self.confirm_replace {
            ui.colored_label(
                ui.visuals().warn_fg_color,
                format!("{} exists. Press {} again to replace it.", path.display(), self.purpose.action()),
            );
        }
        ui.horizontal(|ui| {
            if ui.button(self.purpose.action()).clicked() {
                outcome = self.confirm();
            }
            if ui.button("Cancel").clicked() {
                outcome = DialogOutcome::Cancelled;
            }
        });
        outcome
    }
}

/// `~/x` → `$HOME/x`.
fn expand_home(typed: &str) -> PathBuf {
    if let Some(rest) = typed.strip_prefix("~/")
        && let Some(home) = std::env::var_os("HOME")
    {
        return PathBuf::from(home).join(rest);
    }
    PathBuf::from(typed)
}
