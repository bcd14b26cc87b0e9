//! The editor's panels: menu bar, side panel (file, view, scene), status line, help
//! window and the 3D view's area. [`Editor::ui`] lays out one frame.

use meshpaint_render::{FilterMode, RenderSettings, Shading};

use super::editor::{Editor, PsnrKey};
use super::input::{self, POINTER_HELP, SHORTCUTS, shortcut_text};
use super::state::{Action, Severity, Shown};
use super::text::{human_bytes, thousands};

/// Width of the side panel, points.
pub const SIDE_PANEL_WIDTH: f32 = 250.0;

impl Editor {
    /// One frame of the editor's UI inside `ui` (the window's root). Afterwards
    /// [`Editor::viewport`] holds the 3D view's area, which the window shell renders.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.upload_bytes_last_frame = std::mem::take(&mut self.upload_bytes_this_frame);
        self.poll_jobs();
        let autosave_due = self.autosave_tick();
        let ctx = ui.ctx().clone();
        if let Some(after) = autosave_due {
            // Nothing else wakes an idle editor: the autosave asks for the frame it needs.
            ctx.request_repaint_after(after);
        }
        input::global_input(self, &ctx);
        egui::Panel::top("menu bar").show(ui, |ui| self.menu_bar_ui(ui));
        egui::Panel::bottom("status line").show(ui, |ui| self.status_line_ui(ui));
        egui::Panel::left("side panel")
            .resizable(true)
            .default_size(SIDE_PANEL_WIDTH)
            .show(ui, |ui| self.side_panel_ui(ui));
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport_ui(ui));
        if self.show_help {
            self.help_window_ui(&ctx);
        }
        self.dialog_ui(&ctx);
        self.recovery_dialog_ui(&ctx);
        if self.jobs.is_busy() {
            // Animate the progress bar; a finished job wakes the UI by itself.
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        if self.view.continuous_redraw {
            ctx.request_repaint();
        }
    }

    /// A menu entry that performs `action`, showing its shortcut.
    fn action_button_ui(&mut self, ui: &mut egui::Ui, text: &str, action: Action, enabled: bool) {
        let mut button = egui::Button::new(text);
        if let Some(keys) = shortcut_text(action) {
            button = button.shortcut_text(keys);
        }
        if ui.add_enabled(enabled, button).clicked() {
            input::perform(self, action);
            ui.close();
        }
    }

    /// The menu bar: File, View, Help.
    pub fn menu_bar_ui(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            let has_document = self.document.is_some();
            let idle = !self.jobs.is_busy();
            ui.menu_button("File", |ui| {
                self.action_button_ui(ui, "Open…", Action::Open, idle);
                ui.separator();
                self.action_button_ui(ui, "Save", Action::Save, idle && has_document);
                self.action_button_ui(ui, "Save as…", Action::SaveAs, idle && has_document);
                ui.separator();
                self.action_button_ui(ui, "Export glTF…", Action::ExportGltf, idle && has_document);
                self.action_button_ui(ui, "Export packed buffers…", Action::ExportPacked, idle && has_document);
                ui.separator();
                self.action_button_ui(ui, "Quit", Action::Quit, true);
            });
            ui.menu_button("View", |ui| {
                self.action_button_ui(ui, "Frame all", Action::FrameAll, has_document);
                self.action_button_ui(ui, "Front", Action::ViewFront, has_document);
                self.action_button_ui(ui, "Right", Action::ViewRight, has_document);
                self.action_button_ui(ui, "Top", Action::ViewTop, has_document);
                ui.separator();
                self.action_button_ui(ui, "Wireframe on / off", Action::ToggleWireframe, true);
                self.action_button_ui(ui, "Heat map on / off", Action::ToggleHeatmap, true);
                self.action_button_ui(ui, "Lit / unlit", Action::ToggleShading, true);
                self.action_button_ui(ui, "Next filter", Action::CycleFilter, true);
            });
            ui.menu_button("Help", |ui| {
                self.action_button_ui(ui, "Shortcuts", Action::ToggleHelp, true);
            });
        });
    }

    /// The side panel: file, view and scene sections.
    pub fn side_panel_ui(&mut self, ui: &mut egui::Ui) {
        egui::ScrollArea::vertical().show(ui, |ui| {
            egui::CollapsingHeader::new("Paint").default_open(true).show(ui, |ui| self.paint_panel_ui(ui));
            egui::CollapsingHeader::new("File").default_open(true).show(ui, |ui| self.file_panel_ui(ui));
            egui::CollapsingHeader::new("View").default_open(true).show(ui, |ui| self.view_panel_ui(ui));
            egui::CollapsingHeader::new("Scene").default_open(true).show(ui, |ui| self.scene_panel_ui(ui));
        });
    }

    /// Open, save, export, and the resolution given to glTF files.
    pub fn file_panel_ui(&mut self, ui: &mut egui::Ui) {
        let has_document = self.document.is_some();
        let idle = !self.jobs.is_busy();
        ui.horizontal_wrapped(|ui| {
            if ui.add_enabled(idle, egui::Button::new("Open…")).on_hover_text("Ctrl+O").clicked() {
                input::perform(self, Action::Open);
            }
            if ui.add_enabled(idle && has_document, egui::Button::new("Save")).on_hover_text("Ctrl+S").clicked() {
                input::perform(self, Action::Save);
            }
            if ui
                .add_enabled(idle && has_document, egui::Button::new("Save as…"))
                .on_hover_text("Ctrl+Shift+S")
                .clicked()
            {
                input::perform(self, Action::SaveAs);
            }
        });
        ui.horizontal_wrapped(|ui| {
            if ui.add_enabled(idle && has_document, egui::Button::new("Export glTF…")).on_hover_text("Ctrl+E").clicked()
            {
                input::perform(self, Action::ExportGltf);
            }
            if ui
                .add_enabled(idle && has_document, egui::Button::new("Export packed…"))
                .on_hover_text("Ctrl+Shift+E")
                .clicked()
            {
                input::perform(self, Action::ExportPacked);
            }
        });
        self.import.ui(ui, "Open meshes at:");
        self.autosave_settings_ui(ui);
    }

    /// What the view shows (mesh colors, or for comparison the source texture or position
    /// colours), what the current choice costs, and what it loses against the source.
    fn shown_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let label = ui.label("Show:");
            egui::ComboBox::from_id_salt("shown")
                .selected_text(self.view.shown.name())
                .show_ui(ui, |ui| {
                    for shown in Shown::ALL {
                        ui.selectable_value(&mut self.view.shown, shown, shown.name());
                    }
                })
                .response
                .labelled_by(label.id)
                .on_hover_text(
                    "Compare the mesh colors with the source file's UV texture, or show a position colour field",
                );
        });
        if self.view.shown != Shown::MeshColors {
            self.ensure_shown_view();
        }
        let Some(open) = &self.document else {
            return;
        };
        // The cost of the current choice: what the GPU holds and how long a frame takes.
        ui.label(
            egui::RichText::new(format!(
                "Cost: {} samples, {} on the GPU, {:.1} ms per frame",
                thousands(open.samples_with_mips),
                human_bytes(self.gpu_bytes()),
                self.frame_stats.frame_ms
            ))
            .weak(),
        );
        let failed = match self.view.shown {
            Shown::MeshColors => None,
            Shown::SourceTexture => open.alternates.source_texture.as_ref().and_then(|b| b.as_ref().err()),
            Shown::PositionColors => open.alternates.position_colors.as_ref().and_then(|b| b.as_ref().err()),
        };
        if let Some(message) = failed {
            ui.colored_label(ui.visuals().warn_fg_color, format!("Showing the mesh colors: {message}"));
        }
        if self.view.shown != Shown::SourceTexture {
            return;
        }
        // The loss: PSNR of this view against the source texture, measured again whenever the
        // view changes and no button is held (not while orbiting).
        let key: PsnrKey = (self.render_settings(), self.viewport.size_px(), self.scene_generation);
        let dragging = ui.input(|i| i.pointer.any_down());
        if !dragging
            && self.source_psnr.as_ref().is_none_or(|(measured, _)| *measured != key)
            && let Some(result) = self.measure_source_psnr()
        {
            self.source_psnr = Some((key, result));
        }
        match &self.source_psnr {
            Some((_, Ok(db))) => {
                let text = if db.is_finite() { format!("{db:.1} dB") } else { "identical".to_owned() };
                ui.label(format!("Mesh colors vs source texture, this view: PSNR {text}"))
                    .on_hover_text("Both rendered offscreen with the current camera, filter and shading");
            }
            Some((_, Err(message))) => {
                ui.colored_label(ui.visuals().warn_fg_color, format!("PSNR not measured: {message}"));
            }
            None => {
                ui.label(egui::RichText::new("PSNR: preparing the source texture…").weak());
            }
        }
    }

    /// Filter, shading, overlays and camera.
    pub fn view_panel_ui(&mut self, ui: &mut egui::Ui) {
        let max_level = self
            .document
            .as_ref()
            .and_then(|d| d.document.store.face_resolutions().iter().map(|r| r.log2()).max())
            .unwrap_or(0);
        ui.horizontal(|ui| {
            let label = ui.label("Filter:");
            let combo = egui::ComboBox::from_id_salt("filter").selected_text(filter_name(self.view.filter));
            let response = combo.show_ui(ui, |ui| {
                for filter in [
                    FilterMode::Nearest,
                    FilterMode::Linear,
                    FilterMode::Trilinear,
                    FilterMode::MipLevel(1.min(max_level)),
                    FilterMode::NearestMipLevel(1.min(max_level)),
                ] {
                    let selected = std::mem::discriminant(&self.view.filter) == std::mem::discriminant(&filter);
                    if ui.selectable_label(selected, filter_name(filter)).clicked() {
                        self.view.filter = filter;
                    }
                }
            });
            response.response.labelled_by(label.id);
        });
        if self.gpu_paint_layout {
            ui.label(egui::RichText::new("Paint mode shows level 0 (nearest or linear)").weak());
        }
        if let FilterMode::MipLevel(level) | FilterMode::NearestMipLevel(level) = &mut self.view.filter {
            ui.add(egui::Slider::new(level, 0..=max_level.max(1)).text("MIP level"));
        }
        ui.horizontal(|ui| {
            ui.label("Shading:");
            ui.radio_value(&mut self.view.shading, Shading::Smooth, "Smooth")
                .on_hover_text("Lit with vertex normals (edges sharper than 45° stay sharp)");
            ui.radio_value(&mut self.view.shading, Shading::Lit, "Flat").on_hover_text("Lit with face normals");
            ui.radio_value(&mut self.view.shading, Shading::Unlit, "Unlit").on_hover_text("The colours as they are");
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.view.overlays.wireframe, "Wireframe").on_hover_text("W");
            ui.checkbox(&mut self.view.overlays.heatmap, "Resolution heat map")
                .on_hover_text("H — log2 R: dark blue 0, blue, cyan, green, yellow, orange, magenta 12");
        });
        ui.horizontal(|ui| {
            if ui.button("Frame all").on_hover_text("Home").clicked() {
                input::perform(self, Action::FrameAll);
            }
            ui.label(
                egui::RichText::new(format!(
                    "yaw {:.0}°  pitch {:.0}°",
                    self.camera.yaw_degrees, self.camera.pitch_degrees
                ))
                .weak(),
            );
        });
        self.shown_ui(ui);
    }

    /// Triangles, samples, GPU memory, fps, last repack time.
    pub fn scene_panel_ui(&mut self, ui: &mut egui::Ui) {
        let gpu_bytes = self.gpu_bytes();
        egui::Grid::new("scene stats").num_columns(2).spacing([12.0, 4.0]).striped(true).show(ui, |ui| {
            let row = |ui: &mut egui::Ui, name: &str, value: String| {
                ui.label(name);
                ui.label(value);
                ui.end_row();
            };
            match &self.document {
                Some(open) => {
                    let store = &open.document.store;
                    let resolutions = store.face_resolutions();
                    let min = resolutions.iter().map(|r| r.get()).min().unwrap_or(1);
                    let max = resolutions.iter().map(|r| r.get()).max().unwrap_or(1);
                    row(ui, "Document", open.title.clone());
                    row(ui, "Triangles", thousands(u64::from(open.triangles())));
                    row(ui, "Vertices", thousands(open.document.positions.len() as u64));
                    row(ui, "Resolution R", if min == max { min.to_string() } else { format!("{min} … {max}") });
                    row(ui, "Samples", thousands(open.samples));
                    row(ui, "With MIP chains", thousands(open.samples_with_mips));
                    row(ui, "Colour format", open.format.name().to_owned());
                    row(ui, "Packed size", human_bytes(open.packed_bytes));
                    row(ui, "Last repack", format!("{:.1} ms", open.last_repack.as_secs_f64() * 1000.0));
                }
                None => row(ui, "Document", "none".into()),
            }
            row(ui, "GPU memory", human_bytes(gpu_bytes));
            row(ui, "Uploaded last frame", human_bytes(self.upload_bytes_last_frame));
            let fps = if self.frame_stats.fps > 0.0 { format!("{:.1}", self.frame_stats.fps) } else { "–".into() };
            row(ui, "fps", fps);
            row(ui, "Frame time", format!("{:.1} ms", self.frame_stats.frame_ms));
            if let Some(gpu) = &self.gpu {
                row(ui, "GPU", gpu.ctx.adapter_info.name.clone());
            }
        });
        ui.checkbox(&mut self.view.continuous_redraw, "Redraw continuously")
            .on_hover_text("Redraw every frame to measure fps (otherwise only when something changes)");
    }

    /// The status line: mode, last message, and a running job's progress.
    pub fn status_line_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let mode = egui::RichText::new(format!("{} mode", self.mode.name())).strong();
            let mode = match self.mode {
                super::state::Mode::Paint => mode.color(egui::Color32::from_rgb(255, 170, 60)),
                super::state::Mode::View => mode,
            };
            ui.label(mode).on_hover_text("Tab toggles paint mode");
            ui.separator();
            if let Some((label, fraction, stage, elapsed)) = self.jobs.status() {
                ui.add(egui::ProgressBar::new(fraction).desired_width(220.0).show_percentage().animate(true));
                ui.label(format!("{label}: {stage} ({:.1} s)", elapsed.as_secs_f32()));
            } else {
                let color = match self.status.severity {
                    Severity::Info => ui.visuals().text_color(),
                    Severity::Warning => ui.visuals().warn_fg_color,
                    Severity::Error => ui.visuals().error_fg_color,
                };
                let prefix = match self.status.severity {
                    Severity::Error => "Error: ",
                    _ => "",
                };
                ui.add(
                    egui::Label::new(egui::RichText::new(format!("{prefix}{}", self.status.text)).color(color))
                        .truncate(),
                )
                .on_hover_text(&self.status.text);
            }
        });
    }

    /// The shortcut help window (F1).
    pub fn help_window_ui(&mut self, ctx: &egui::Context) {
        let mut open = self.show_help;
        let center = self.viewport.rect.center();
        egui::Window::new("Keyboard and mouse")
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .pivot(egui::Align2::CENTER_CENTER)
            .default_pos(center)
            .show(ctx, |ui| {
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
            });
        self.show_help = open && self.show_help;
    }

    /// The 3D view's area: the rendered image (or a placeholder), and its input.
    pub fn viewport_ui(&mut self, ui: &mut egui::Ui) {
        let rect = ui.max_rect();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        self.viewport.rect = rect;
        self.viewport.pixels_per_point = ui.ctx().pixels_per_point();
        let painter = ui.painter_at(rect);
        let showing = self.document.as_ref().is_some_and(|d| d.gpu_mesh.is_some());
        match (self.viewport_texture, showing) {
            (Some(texture), true) => {
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                painter.image(texture, rect, uv, egui::Color32::WHITE);
            }
            _ => {
                let [r, g, b, _] = RenderSettings::DEFAULT_BACKGROUND.map(meshpaint_core::colors::format::encode_srgb8);
                painter.rect_filled(rect, 0.0, egui::Color32::from_rgb(r, g, b));
                let text = if self.jobs.is_busy() {
                    "Loading…"
                } else if self.document.is_none() {
                    "No document: open a file (Ctrl+O) or drop one here"
                } else {
                    "No GPU: the 3D view is off"
                };
                painter.text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    text,
                    egui::FontId::proportional(16.0),
                    egui::Color32::from_gray(170),
                );
            }
        }
        let hint = match self.mode {
            super::state::Mode::View => {
                "Middle drag: orbit · Shift: pan · Wheel: zoom · Home: frame all · Tab: paint · F1: help"
            }
            super::state::Mode::Paint => {
                "PAINT · Left drag: paint · F / Shift+F: radius / strength · S: pick colour · Ctrl+Z: undo · Tab: leave"
            }
        };
        painter.text(
            rect.left_bottom() + egui::vec2(8.0, -6.0),
            egui::Align2::LEFT_BOTTOM,
            hint,
            egui::FontId::proportional(12.0),
            egui::Color32::from_gray(150),
        );
        input::viewport_input(self, ui, &response);
        self.brush_cursor_ui(&painter);
    }
}

/// The name of a filter in the view panel.
pub fn filter_name(filter: FilterMode) -> String {
    match filter {
        FilterMode::Nearest => "Nearest".into(),
        FilterMode::Linear => "Linear".into(),
        FilterMode::Trilinear => "Trilinear (auto MIP)".into(),
        FilterMode::MipLevel(level) => format!("Linear, MIP level {level}"),
        FilterMode::NearestMipLevel(level) => format!("Nearest, MIP level {level}"),
    }
}
