//! File → Export…: a window offering the baked-texture glTF (texture size; the model's own
//! UVs or generated ones, with the reason for the automatic choice), the tessellated glTF
//! (a level or a vertex budget; smooth normals) and the packed file (colour format), each
//! with its cost shown before anything is written ([`crate::app::export::estimate`]).

use std::path::{Path, PathBuf};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::convert::unwrap::UvChoice;
use meshpaint_core::io::export_baked::UvSource;

use crate::app::command::Command;
use crate::app::document::OpenDocument;
use crate::app::export::{Estimate, ExportRequest, ExportWhat, estimate};

/// Which file the dialog writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExportKind {
    /// A textured glTF.
    #[default]
    Baked,
    /// The tessellated vertex-colour glTF.
    Tessellated,
    /// The packed file.
    Packed,
}

/// Texture sides offered.
pub const TEXTURE_SIZES: [u32; 6] = [256, 512, 1024, 2048, 4096, 8192];

/// The dialog's state.
#[derive(Debug)]
pub struct ExportPanel {
    /// Whether the window is shown.
    pub open: bool,
    /// What is written.
    pub kind: ExportKind,
    /// Texture side of a bake.
    pub size: u32,
    /// UVs of a bake.
    pub uvs: UvSource,
    /// Tessellated: limit the vertices instead of choosing a level.
    pub by_vertices: bool,
    /// Tessellated: the level.
    pub level: u32,
    /// Tessellated: the vertex budget.
    pub max_vertices: u64,
    /// Packed: the colour format.
    pub format: ColorFormat,
    /// The output file.
    pub path: String,
    /// The automatic UV choice at a texture size, once checked (a job, [`Command::CheckUvs`]).
    pub uv_check: Option<(u32, Result<UvChoice, String>)>,
    /// The texture size whose UV check was asked for and has not come back.
    pub uv_check_requested: Option<u32>,
    /// The cost of the current choice, for the document edit generation it was measured at.
    estimate: Option<(ExportWhat, u64, Estimate)>,
}

impl Default for ExportPanel {
    fn default() -> Self {
        ExportPanel {
            open: false,
            kind: ExportKind::Baked,
            size: 1024,
            uvs: UvSource::Auto,
            by_vertices: false,
            level: 0,
            max_vertices: 100_000,
            format: ColorFormat::default(),
            path: String::new(),
            uv_check: None,
            uv_check_requested: None,
            estimate: None,
        }
    }
}

/// What the dialog reads of the editor.
#[derive(Debug, Clone, Copy)]
pub struct ExportContext<'a> {
    /// The open document.
    pub document: Option<&'a OpenDocument>,
    /// Its edit generation (costs are measured again after edits).
    pub generation: u64,
    /// No job runs.
    pub idle: bool,
}

impl ExportPanel {
    /// Shows the window for `document` (none: nothing to export), the file named after it in
    /// `directory`.
    pub fn show_for(&mut self, document: Option<&OpenDocument>, directory: &Path) {
        let Some(document) = document else {
            return;
        };
        let stem = document
            .path
            .as_deref()
            .and_then(Path::file_stem)
            .map_or_else(|| "duck".to_owned(), |s| s.to_string_lossy().into_owned());
        self.path = directory.join(format!("{stem}_export.glb")).display().to_string();
        self.set_extension();
        self.uv_check = None;
        self.uv_check_requested = None;
        self.estimate = None;
        self.open = true;
    }

    /// What the dialog would write now.
    pub fn what(&self) -> ExportWhat {
        match self.kind {
            ExportKind::Baked => ExportWhat::Baked { size: self.size, uvs: self.uvs },
            ExportKind::Tessellated => ExportWhat::Tessellated {
                level: self.level,
                max_vertices: self.by_vertices.then_some(self.max_vertices),
            },
            ExportKind::Packed => ExportWhat::Packed { format: self.format },
        }
    }

    /// The file's extension follows the kind: .glb or .mpk.
    fn set_extension(&mut self) {
        let extension = if self.kind == ExportKind::Packed { "mpk" } else { "glb" };
        self.path = PathBuf::from(&self.path).with_extension(extension).display().to_string();
    }

    /// The window, while open; returns the export to carry out or the UV check to run.
    pub fn ui(&mut self, ctx: &egui::Context, context: ExportContext<'_>) -> Vec<Command> {
        let Some(open_document) = context.document.filter(|_| self.open) else {
            return Vec::new();
        };
        let mut chosen = Vec::new();
        let mut shown = true;
        egui::Window::new("Export the document").open(&mut shown).collapsible(false).resizable(false).show(ctx, |ui| {
            ui.set_max_width(460.0);
            let kind = self.kind;
            ui.radio_value(&mut self.kind, ExportKind::Baked, "Baked-texture glTF (.glb) — for any engine");
            ui.radio_value(&mut self.kind, ExportKind::Tessellated, "Tessellated glTF (.glb) — vertex colours");
            ui.radio_value(&mut self.kind, ExportKind::Packed, "Packed file (.mpk) — mesh colors");
            if self.kind != kind {
                self.set_extension();
            }
            ui.separator();
            match self.kind {
                ExportKind::Baked => self.baked_ui(ui, context.idle, &mut chosen),
                ExportKind::Tessellated => self.tessellated_ui(ui),
                ExportKind::Packed => self.packed_ui(ui),
            }
            ui.separator();
            let what = self.what();
            let stale = self.estimate.as_ref().is_none_or(|(w, g, _)| *w != what || *g != context.generation);
            if stale {
                self.estimate = Some((what, context.generation, estimate(&open_document.document, what)));
            }
            if let Some((_, _, cost)) = &self.estimate {
                ui.label(format!("Cost: {}", cost.text));
            }
            ui.horizontal(|ui| {
                ui.label("File:");
                ui.add(egui::TextEdit::singleline(&mut self.path).desired_width(380.0));
            });
            ui.horizontal(|ui| {
                let ready = context.idle && !self.path.trim().is_empty();
                if ui.add_enabled(ready, egui::Button::new("Export")).clicked() {
                    chosen.push(Command::Export(ExportRequest { path: PathBuf::from(self.path.trim()), what }));
                    self.open = false;
                }
                if ui.button("Cancel").clicked() {
                    self.open = false;
                }
            });
        });
        if !shown {
            self.open = false;
        }
        chosen
    }

    /// Texture size and UVs, with the reason for the automatic choice (checked by a job).
    fn baked_ui(&mut self, ui: &mut egui::Ui, idle: bool, chosen: &mut Vec<Command>) {
        egui::ComboBox::from_label("Texture size").selected_text(format!("{0} × {0}", self.size)).show_ui(ui, |ui| {
            for size in TEXTURE_SIZES {
                ui.selectable_value(&mut self.size, size, format!("{size} × {size}"));
            }
        });
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.uvs, UvSource::Auto, "Automatic UVs");
            ui.radio_value(&mut self.uvs, UvSource::New, "New UVs");
            ui.radio_value(&mut self.uvs, UvSource::Own, "Model's own UVs");
        });
        let checked = self.uv_check.as_ref().filter(|(size, _)| *size == self.size).map(|(_, choice)| choice);
        let text = match (self.uvs, checked) {
            (UvSource::New, _) => "New UVs: a generated atlas where no two faces share a texel.".to_owned(),
            (UvSource::Own, _) => "The model's own UVs, even where islands overlap (paint there is lost).".to_owned(),
            (UvSource::Auto, Some(Ok(choice))) => format!("Automatic: {}.", choice.reason()),
            (UvSource::Auto, Some(Err(error))) => format!("Automatic: the model's UVs cannot be read ({error})."),
            (UvSource::Auto, None) => {
                if idle && self.uv_check_requested != Some(self.size) {
                    self.uv_check_requested = Some(self.size);
                    chosen.push(Command::CheckUvs(self.size));
                }
                "Automatic: checking the model's UVs…".to_owned()
            }
        };
        ui.label(text);
    }

    /// A level, or the finest level within a vertex budget.
    fn tessellated_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.by_vertices, false, "Level");
            ui.add_enabled(!self.by_vertices, egui::DragValue::new(&mut self.level).range(0..=8));
            ui.radio_value(&mut self.by_vertices, true, "At most");
            ui.add_enabled(self.by_vertices, egui::DragValue::new(&mut self.max_vertices).range(3..=u32::MAX as u64));
            ui.label("vertices");
        });
        ui.label("Level L tessellates each face at R / 2^L; vertices get smooth normals.");
    }

    /// The packed file's colour format.
    fn packed_ui(&mut self, ui: &mut egui::Ui) {
        egui::ComboBox::from_label("Colour format").selected_text(self.format.name()).show_ui(ui, |ui| {
            for format in ColorFormat::ALL {
                ui.selectable_value(&mut self.format, format, format.name());
            }
        });
    }
}
