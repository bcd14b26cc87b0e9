//! The 3D view's area: the rendered image (or a placeholder saying why there is none) and
//! the mode's hint line. Its input is [`crate::app::input`]'s.

use meshpaint_render::RenderSettings;

use crate::app::state::Mode;

/// What the 3D view's area reads of the editor.
#[derive(Debug, Clone, Copy)]
pub struct ViewportContext {
    /// The egui texture the window shell renders the 3D view into (`None` without a window).
    pub texture: Option<egui::TextureId>,
    /// The document is on the GPU (the texture shows it).
    pub showing: bool,
    /// A job runs (a document may be loading).
    pub busy: bool,
    /// A document is open.
    pub has_document: bool,
    /// The interaction mode (the hint line).
    pub mode: Mode,
}

/// The 3D view's area (it keeps nothing: the editor records the area's rectangle).
#[derive(Debug, Default)]
pub struct ViewportArea;

impl ViewportArea {
    /// Fills `ui` with the view; returns its response (clicks and drags) and a painter
    /// clipped to it (for the brush cursor).
    pub fn ui(&mut self, ui: &mut egui::Ui, ctx: ViewportContext) -> (egui::Response, egui::Painter) {
        let rect = ui.max_rect();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        match (ctx.texture, ctx.showing) {
            (Some(texture), true) => {
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                painter.image(texture, rect, uv, egui::Color32::WHITE);
            }
            _ => {
                let [r, g, b, _] = RenderSettings::DEFAULT_BACKGROUND.map(meshpaint_core::colors::format::encode_srgb8);
                painter.rect_filled(rect, 0.0, egui::Color32::from_rgb(r, g, b));
                let text = if ctx.busy {
                    "Loading…"
                } else if !ctx.has_document {
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
        let hint = match ctx.mode {
            Mode::View => "Middle drag: orbit · Shift: pan · Wheel: zoom · Home: frame all · Tab: paint · F1: help",
            Mode::Paint => {
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
        (response, painter)
    }
}
