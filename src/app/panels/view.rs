//! The view panel: filter, shading, overlays, the camera's angles, what the 3D view
//! shows (mesh colors, or for comparison the source texture or position colours) with its
//! cost and, against the source texture, its PSNR, and the representation the mesh colors
//! are drawn in (mesh colors, or Mesh Color Textures with their bytes, build time and PSNR
//! against the mesh colors).

use meshpaint_core::camera::OrbitCamera;
use meshpaint_render::{DrawItem, FilterMode, Gpu, Shading};

use crate::app::command::Command;
use crate::app::document::{BuiltMct, OpenDocument};
use crate::app::state::{Action, PsnrKey, Representation, Shown, ViewSettings};
use crate::app::text::{human_bytes, thousands};

/// What the view panel reads of the editor.
#[derive(Debug, Clone, Copy)]
pub struct ViewContext<'a> {
    /// The open document, if any.
    pub document: Option<&'a OpenDocument>,
    /// GPU objects (the PSNR renders offscreen; `None` in UI tests without a GPU).
    pub gpu: Option<&'a Gpu>,
    /// The camera of the 3D view.
    pub camera: OrbitCamera,
    /// The GPU mesh holds the paint layout (level 0 only).
    pub level0_only: bool,
    /// The 3D view's size in physical pixels.
    pub viewport_px: [u32; 2],
    /// Changes of what the GPU mesh shows (a new PSNR is measured when it changes).
    pub scene_generation: u64,
    /// GPU memory in use.
    pub gpu_bytes: u64,
    /// CPU time of the last frame, milliseconds.
    pub frame_ms: f32,
}

/// The view panel and the settings it edits.
#[derive(Debug, Default)]
pub struct ViewPanel {
    /// Filter, shading, overlays, what is shown.
    pub settings: ViewSettings,
    /// The last PSNR of the mesh colors against the source texture, with the view it was
    /// measured in (render settings, view size, scene generation).
    pub source_psnr: Option<(PsnrKey, Result<f64, String>)>,
    /// The last PSNR of the Mesh Color Texture against the mesh colors, likewise.
    pub mct_psnr: Option<(PsnrKey, Result<f64, String>)>,
}

impl ViewPanel {
    /// Filter, shading, overlays and camera, then what is shown. Returns "Frame all" when
    /// clicked, and asks for the shown view to be built while it is not the mesh colors.
    pub fn ui(&mut self, ui: &mut egui::Ui, ctx: &ViewContext<'_>) -> Vec<Command> {
        let mut commands = Vec::new();
        let max_level =
            ctx.document.and_then(|d| d.document.store.face_resolutions().iter().map(|r| r.log2()).max()).unwrap_or(0);
        self.filter_ui(ui, max_level);
        if ctx.level0_only {
            ui.label(egui::RichText::new("Paint mode shows level 0 (nearest or linear)").weak());
        }
        if let FilterMode::MipLevel(level) | FilterMode::NearestMipLevel(level) = &mut self.settings.filter {
            ui.add(egui::Slider::new(level, 0..=max_level.max(1)).text("MIP level"));
        }
        let view = &mut self.settings;
        ui.horizontal(|ui| {
            ui.label("Shading:");
            ui.radio_value(&mut view.shading, Shading::Smooth, "Smooth")
                .on_hover_text("Lit with vertex normals (edges sharper than 45° stay sharp)");
            ui.radio_value(&mut view.shading, Shading::Lit, "Flat").on_hover_text("Lit with face normals");
            ui.radio_value(&mut view.shading, Shading::Unlit, "Unlit").on_hover_text("The colours as they are");
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut view.overlays.wireframe, "Wireframe").on_hover_text("W");
            ui.checkbox(&mut view.overlays.heatmap, "Resolution heat map")
                .on_hover_text("H — log2 R: dark blue 0, blue, cyan, green, yellow, orange, magenta 12");
        });
        if view.overlays.heatmap {
            let levels = ctx.document.map(|d| d.document.store.face_resolutions().iter().map(|r| r.log2()));
            let present = levels.and_then(|levels| Some((levels.clone().min()?, levels.max()?)));
            super::heat_legend::heat_legend_ui(ui, present);
        }
        ui.horizontal(|ui| {
            if ui.button("Frame all").on_hover_text("Home").clicked() {
                commands.push(Command::Action(Action::FrameAll));
            }
            ui.checkbox(&mut view.zoom_to_cursor, "Zoom to pointer")
                .on_hover_text("The wheel zooms towards the point under the pointer, else towards the orbit centre");
            let camera = &ctx.camera;
            let angles = format!("yaw {:.0}°  pitch {:.0}°", camera.yaw_degrees, camera.pitch_degrees);
            ui.label(egui::RichText::new(angles).weak());
        });
        commands.extend(self.shown_ui(ui, ctx));
        self.representation_ui(ui, ctx);
        commands
    }

    /// The filter combo box (the MIP-level filters at level 1, or 0 when there is no other).
    fn filter_ui(&mut self, ui: &mut egui::Ui, max_level: u32) {
        let view = &mut self.settings;
        ui.horizontal(|ui| {
            let label = ui.label("Filter:");
            let combo = egui::ComboBox::from_id_salt("filter").selected_text(filter_name(view.filter));
            // Anisotropic only for Mesh Color Textures (the GPU's sampler; mesh colors would
            // draw it as trilinear).
            let mct = view.representation == Representation::MeshColorTexture;
            let response = combo.show_ui(ui, |ui| {
                for filter in [
                    FilterMode::Nearest,
                    FilterMode::Linear,
                    FilterMode::Trilinear,
                    FilterMode::MipLevel(1.min(max_level)),
                    FilterMode::NearestMipLevel(1.min(max_level)),
                ]
                .into_iter()
                .chain(mct.then_some(FilterMode::Anisotropic))
                {
                    let selected = std::mem::discriminant(&view.filter) == std::mem::discriminant(&filter);
                    if ui.selectable_label(selected, filter_name(filter)).clicked() {
                        view.filter = filter;
                    }
                }
            });
            response.response.labelled_by(label.id);
        });
    }

    /// What the view shows, what the current choice costs, and what it loses against the
    /// source.
    fn shown_ui(&mut self, ui: &mut egui::Ui, ctx: &ViewContext<'_>) -> Vec<Command> {
        let view = &mut self.settings;
        ui.horizontal(|ui| {
            let label = ui.label("Show:");
            egui::ComboBox::from_id_salt("shown")
                .selected_text(view.shown.name())
                .show_ui(ui, |ui| {
                    for shown in Shown::ALL {
                        ui.selectable_value(&mut view.shown, shown, shown.name());
                    }
                })
                .response
                .labelled_by(label.id)
                .on_hover_text(
                    "Compare the mesh colors with the source file's UV texture, or show a position colour field",
                );
        });
        let shown = view.shown;
        let commands = if shown == Shown::MeshColors { Vec::new() } else { vec![Command::PrepareView(shown)] };
        let Some(open) = ctx.document else {
            return commands;
        };
        // The cost of the current choice: what the GPU holds and how long a frame takes.
        ui.label(
            egui::RichText::new(format!(
                "Cost: {} samples, {} on the GPU, {:.1} ms per frame",
                thousands(open.samples_with_mips),
                human_bytes(ctx.gpu_bytes),
                ctx.frame_ms
            ))
            .weak(),
        );
        if let Some(message) = open.failure(shown) {
            ui.colored_label(ui.visuals().warn_fg_color, format!("Showing the mesh colors: {message}"));
        }
        if shown == Shown::SourceTexture {
            self.psnr_ui(ui, ctx, open);
        }
        commands
    }

    /// The loss: PSNR of this view against the source texture, measured again whenever the
    /// view changes and no button is held (not while orbiting).
    fn psnr_ui(&mut self, ui: &mut egui::Ui, ctx: &ViewContext<'_>, open: &OpenDocument) {
        let settings = self.settings.render_settings(ctx.camera, ctx.level0_only);
        let key: PsnrKey = (settings, ctx.viewport_px, ctx.scene_generation);
        let measure = || measure_source_psnr(ctx, open, &key);
        let line = ("Mesh colors vs source texture", "preparing the source texture");
        psnr_line(ui, &mut self.source_psnr, key, measure, line);
    }

    /// The representation the mesh colors are drawn in and, for Mesh Color Textures, what
    /// the texture costs and how far this view is from the mesh colors' own filter.
    fn representation_ui(&mut self, ui: &mut egui::Ui, ctx: &ViewContext<'_>) {
        let view = &mut self.settings;
        ui.horizontal(|ui| {
            let label = ui.label("Representation:");
            egui::ComboBox::from_id_salt("representation")
                .selected_text(view.representation.name())
                .show_ui(ui, |ui| {
                    for representation in Representation::ALL {
                        ui.selectable_value(&mut view.representation, representation, representation.name());
                    }
                })
                .response
                .labelled_by(label.id)
                .on_hover_text(
                    "T — how the GPU draws the painted colours: mesh colors filtered in the shader (exact), \
                     Mesh Color Textures (one 2D atlas the GPU's own sampler filters), packed Ptex \
                     (per-pair blocks with borders, the GPU's sampler too) or Htex (one texture per edge, three \
                     hardware fetches)",
                );
        });
        let Some(open) = ctx.document else {
            return;
        };
        if view.representation == Representation::MeshColors || view.shown != Shown::MeshColors {
            return;
        }
        if view.representation == Representation::PackedPtex {
            ptex_status(ui, open, ctx.level0_only);
            return;
        }
        if ctx.level0_only {
            ui.label(egui::RichText::new("Paint mode draws mesh colors; the texture follows when it ends").weak());
            return;
        }
        if view.representation == Representation::Htex {
            htex_ui(ui, open);
            return;
        }
        let built = match open.current_mct() {
            None => {
                ui.label(egui::RichText::new("Building the Mesh Color Texture…").weak());
                return;
            }
            Some(Err(message)) => {
                ui.colored_label(ui.visuals().warn_fg_color, format!("Showing the mesh colors: {message}"));
                return;
            }
            Some(Ok(built)) => built,
        };
        let [w, h] = built.mct.atlas_size;
        ui.label(
            egui::RichText::new(format!(
                "Atlas {w} × {h}: {} ({:.2}× the mesh colors' buffers), built in {:.0} ms",
                human_bytes(built.mct.gpu_bytes()),
                built.bytes_over_mesh_colors,
                built.build.as_secs_f64() * 1000.0
            ))
            .weak(),
        );
        if matches!(view.filter, FilterMode::Nearest | FilterMode::NearestMipLevel(_)) {
            ui.label(egui::RichText::new("No nearest filter in a Mesh Color Texture: drawn bilinear").weak());
        }
        let settings = view.render_settings(ctx.camera, ctx.level0_only);
        let key: PsnrKey = (settings, ctx.viewport_px, ctx.scene_generation);
        let measure = || measure_mct_psnr(ctx, open, built, &key);
        let line = ("Mesh Color Texture vs mesh colors", "rendering both");
        psnr_line(ui, &mut self.mct_psnr, key, measure, line);
    }
}

/// What the Htex costs (or why it is not shown yet).
fn htex_ui(ui: &mut egui::Ui, open: &OpenDocument) {
    match open.current_htex() {
        None => {
            ui.label(egui::RichText::new("Building the Htex…").weak());
        }
        Some(Err(message)) => {
            ui.colored_label(ui.visuals().warn_fg_color, format!("Showing the mesh colors: {message}"));
        }
        Some(Ok(built)) => {
            let ((e, f), ([w, h], pages)) = (built.textures, built.pages);
            ui.label(
                egui::RichText::new(format!(
                    "{e} edge textures for {f} faces (E/F {:.2}) in {pages} page(s) of {w} × {h}: {} ({:.2}× the mesh \
                     colors' buffers), built in {:.0} ms",
                    e as f64 / f.max(1) as f64,
                    human_bytes(built.htex.gpu_bytes()),
                    built.bytes_over_mesh_colors,
                    built.build.as_secs_f64() * 1000.0
                ))
                .weak(),
            );
        }
    }
}

/// The packed Ptex's state under the representation choice: building, why it cannot be
/// shown, or its size and cost.
fn ptex_status(ui: &mut egui::Ui, open: &OpenDocument, level0_only: bool) {
    if level0_only {
        ui.label(egui::RichText::new("Paint mode draws mesh colors; the texture follows when it ends").weak());
        return;
    }
    match open.current_ptex() {
        None => {
            ui.label(egui::RichText::new("Building the packed Ptex…").weak());
        }
        Some(Err(message)) => {
            ui.colored_label(ui.visuals().warn_fg_color, format!("Showing the mesh colors: {message}"));
        }
        Some(Ok(built)) => {
            let [w, h] = built.ptex.size;
            let text = format!(
                "Texture {w} × {h}: {} ({:.2}× the mesh colors' buffers), built in {:.0} ms",
                human_bytes(built.ptex.gpu_bytes()),
                built.bytes_over_mesh_colors,
                built.build.as_secs_f64() * 1000.0
            );
            ui.label(egui::RichText::new(text).weak());
        }
    }
}

/// One PSNR line: `slot` measured again by `measure` whenever the view `key` changes and no
/// button is held (not while orbiting); `what` names the comparison and what a missing
/// measurement waits for.
fn psnr_line(
    ui: &mut egui::Ui,
    slot: &mut Option<(PsnrKey, Result<f64, String>)>,
    key: PsnrKey,
    measure: impl FnOnce() -> Option<Result<f64, String>>,
    (what, pending): (&str, &str),
) {
    let dragging = ui.input(|i| i.pointer.any_down());
    if !dragging
        && slot.as_ref().is_none_or(|(measured, _)| *measured != key)
        && let Some(result) = measure()
    {
        *slot = Some((key, result));
    }
    match slot {
        Some((_, Ok(db))) => {
            let text = if db.is_finite() { format!("{db:.1} dB") } else { "identical".to_owned() };
            ui.label(format!("{what}, this view: PSNR {text}"))
                .on_hover_text("Both rendered offscreen with the current camera, filter and shading");
        }
        Some((_, Err(message))) => {
            ui.colored_label(ui.visuals().warn_fg_color, format!("PSNR not measured: {message}"));
        }
        None => {
            ui.label(egui::RichText::new(format!("PSNR: {pending}…")).weak());
        }
    }
}

/// PSNR (dB, RGB of covered pixels) of the Mesh Color Texture `built` of `open` against the
/// mesh colors' own filter, both as the 3D view shows them in `key`'s view (offscreen, at
/// most 512 px on the long side).
fn measure_mct_psnr(
    ctx: &ViewContext<'_>,
    open: &OpenDocument,
    built: &BuiltMct,
    key: &PsnrKey,
) -> Option<Result<f64, String>> {
    let (Some(gpu), Some(mesh)) = (ctx.gpu, open.gpu_mesh.as_ref()) else {
        return None;
    };
    Some(compare_renders(gpu, key, DrawItem::Mct(&built.mct), DrawItem::MeshColors(mesh)))
}

/// PSNR of `ours` against `theirs`, both rendered with `key`'s settings at the view's aspect
/// (at most 512 px on the long side).
fn compare_renders(gpu: &Gpu, key: &PsnrKey, ours: DrawItem<'_>, theirs: DrawItem<'_>) -> Result<f64, String> {
    let (settings, [w, h], _) = key;
    let scale = (512.0 / f64::from((*w).max(*h).max(1))).min(1.0);
    let (w, h) = (((f64::from(*w) * scale) as u32).max(16), ((f64::from(*h) * scale) as u32).max(16));
    let render = |item| gpu.render_image(item, settings, w, h).map_err(|error| error.to_string());
    let ours = render(ours)?;
    render(theirs).map(|theirs| meshpaint_core::colors::psnr::psnr(&ours, &theirs))
}

/// PSNR (dB, RGB of covered pixels) of the mesh colors of `open` against its source texture
/// as the 3D view shows them in `key`'s view, rendered offscreen at the view's aspect (at
/// most 512 px on the long side). `None` until the source texture is built.
fn measure_source_psnr(ctx: &ViewContext<'_>, open: &OpenDocument, key: &PsnrKey) -> Option<Result<f64, String>> {
    let (Some(gpu), Some(mesh), Some(Ok(baseline))) =
        (ctx.gpu, open.gpu_mesh.as_ref(), open.alternates.source_texture.as_ref())
    else {
        return None;
    };
    Some(compare_renders(gpu, key, DrawItem::MeshColors(mesh), DrawItem::Baseline(baseline)))
}

/// The name of a filter in the view panel.
pub fn filter_name(filter: FilterMode) -> String {
    match filter {
        FilterMode::Nearest => "Nearest".into(),
        FilterMode::Linear => "Linear".into(),
        FilterMode::Trilinear => "Trilinear (auto MIP)".into(),
        FilterMode::Anisotropic => "Anisotropic (MCT, hardware)".into(),
        FilterMode::MipLevel(level) => format!("Linear, MIP level {level}"),
        FilterMode::NearestMipLevel(level) => format!("Nearest, MIP level {level}"),
    }
}
