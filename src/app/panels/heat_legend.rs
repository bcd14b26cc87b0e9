//! The resolution heat map's legend (under the view panel's checkbox while the heat map is
//! on): a swatch per face resolution `R = 1 … 4096` in the colour the shader gives it
//! ([`meshpaint_render::heat_color`], the CPU copy of the shader's table; a test checks the
//! two agree), the resolutions the open mesh has marked.

use meshpaint_core::colors::format::encode_srgb8;
use meshpaint_render::HEAT_COLORS;

/// Side of a swatch, points.
const SWATCH: f32 = 14.0;

/// Each resolution's legend entry: `R` and its colour as the heat map draws it (unlit,
/// sRGB-encoded as the render target stores it).
pub fn legend_entries() -> Vec<(u64, egui::Color32)> {
    HEAT_COLORS
        .iter()
        .enumerate()
        .map(|(log2, rgb)| {
            let [r, g, b] = rgb.map(encode_srgb8);
            (1u64 << log2, egui::Color32::from_rgb(r, g, b))
        })
        .collect()
}

/// `R` as the legend writes it (4096 → "4k").
fn short(r: u64) -> String {
    if r >= 1024 { format!("{}k", r / 1024) } else { r.to_string() }
}

/// The legend; `present` is the range of `log2 R` in the open mesh, if any.
pub fn heat_legend_ui(ui: &mut egui::Ui, present: Option<(u32, u32)>) {
    ui.label(egui::RichText::new("Heat map: face resolution R").small());
    ui.horizontal_wrapped(|ui| {
        ui.spacing_mut().item_spacing.x = 3.0;
        for (log2, (r, color)) in legend_entries().into_iter().enumerate() {
            let here = present.is_some_and(|(lo, hi)| (lo..=hi).contains(&(log2 as u32)));
            let (rect, response) = ui.allocate_exact_size(egui::vec2(SWATCH, SWATCH), egui::Sense::hover());
            response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, format!("Heat map R = {r}")));
            ui.painter().rect_filled(rect, 2.0, color);
            if here {
                let stroke = egui::Stroke::new(1.5, ui.visuals().strong_text_color());
                ui.painter().rect_stroke(rect, 2.0, stroke, egui::StrokeKind::Outside);
            }
            let text = egui::RichText::new(short(r)).small();
            ui.label(if here { text.strong() } else { text.weak() });
            response.on_hover_text(format!("R = {r}{}", if here { " (in this mesh)" } else { "" }));
        }
    });
}
