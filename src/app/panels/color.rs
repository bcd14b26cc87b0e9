//! The brush colour, always in view: an HSV wheel (hue around, saturation outwards) with
//! brightness and opacity sliders, a hex field (`#ff8800`, `ff8800` or `#f80`; Enter or
//! leaving the field applies it, anything else shows a message and changes nothing) and the
//! recent colours, newest first, each a button that picks it.
//!
//! Drawn with egui's painter, not egui's colour picker: that one sits in a popup and shows a
//! clipboard emoji (U+1F4CB) that the default fonts (without `monochrome_emoji_fonts`) lack,
//! so it rendered as a missing-glyph box.
//!
//! HSV here is of the sRGB-encoded colour (as painting programs and hex codes have it); the
//! brush colour is linear.

use std::f32::consts::TAU;

use meshpaint_core::colors::format::{Rgba, encode_rgba8_srgb, linear_to_srgb, srgb_to_linear};
use meshpaint_core::paint::brush::parse_hex_color;

use crate::app::recent_colors::{RecentColors, hex_of};

/// Largest diameter of the wheel, points.
const WHEEL_DIAMETER: f32 = 150.0;
/// Side of a recent-colour button, points.
const SWATCH: f32 = 20.0;
/// Segments around the wheel's mesh, and rings from its centre out.
const SEGMENTS: usize = 72;
const RINGS: usize = 8;

/// The colour section's state: the HSV being edited and the hex field.
#[derive(Debug, Clone, Default)]
pub struct ColorPicker {
    /// Hue, saturation, value (each `0..=1`) of the colour last seen or set here: kept so
    /// that the hue survives grey and black.
    hsv: [f32; 3],
    /// The brush colour `hsv` belongs to; another colour (eyedropper, preset, recent colour)
    /// resets `hsv` and the hex field.
    seen: Option<Rgba>,
    /// The hex field's text.
    pub hex: String,
    /// Why the last hex entry was refused.
    pub hex_error: Option<String>,
}

impl ColorPicker {
    /// The wheel, sliders, hex field and recent colours editing `color` (linear, straight
    /// alpha). Returns whether `color` changed.
    pub fn ui(&mut self, ui: &mut egui::Ui, color: &mut Rgba, recent: &RecentColors) -> bool {
        if self.seen != Some(*color) {
            self.hsv = hsv_of(*color, self.hsv);
            self.hex = hex_of(encode_rgba8_srgb(*color));
            self.seen = Some(*color);
        }
        let before = *color;
        let mut hsv = self.hsv;
        if hsv_wheel(ui, &mut hsv) | brightness_slider(ui, &mut hsv[2]) {
            *color = linear_of(hsv, color[3]);
        }
        self.hsv = hsv;
        ui.add(egui::Slider::new(&mut color[3], 0.0..=1.0).text("Opacity"))
            .on_hover_text("Alpha of the brush colour (Mix blends it in by this much)");
        let picked = *color;
        self.hex_row(ui, color);
        if let Some(error) = &self.hex_error {
            ui.colored_label(ui.visuals().error_fg_color, error);
        }
        recent_row(ui, color, recent);
        if *color != picked {
            // From the hex field or a recent colour: the wheel follows.
            self.hsv = hsv_of(*color, self.hsv);
        }
        if *color != before {
            self.seen = Some(*color);
            self.hex = hex_of(encode_rgba8_srgb(*color));
        }
        *color != before
    }

    /// The current colour's swatch and the hex field; a valid entry sets the colour (alpha
    /// kept), an invalid one only sets the message.
    fn hex_row(&mut self, ui: &mut egui::Ui, color: &mut Rgba) {
        ui.horizontal(|ui| {
            let [r, g, b, a] = encode_rgba8_srgb(*color);
            egui::color_picker::show_color(
                ui,
                egui::Color32::from_rgba_unmultiplied(r, g, b, a),
                egui::vec2(40.0, 18.0),
            );
            let label = ui.label("Hex");
            let response = ui
                .add(egui::TextEdit::singleline(&mut self.hex).desired_width(72.0).font(egui::TextStyle::Monospace))
                .labelled_by(label.id)
                .on_hover_text("#rrggbb, rrggbb or #rgb (sRGB); Enter applies");
            if response.lost_focus() {
                match parse_hex_color(&self.hex) {
                    Some(parsed) => {
                        *color = [parsed[0], parsed[1], parsed[2], color[3]];
                        self.hex = hex_of(encode_rgba8_srgb(*color));
                        self.hex_error = None;
                    }
                    None => {
                        self.hex_error = Some(format!("\"{}\" is not a colour: type #rrggbb or #rgb", self.hex.trim()));
                    }
                }
            }
        });
    }
}

/// The recent colours: a button each, picking it (alpha included).
fn recent_row(ui: &mut egui::Ui, color: &mut Rgba, recent: &RecentColors) {
    ui.horizontal_wrapped(|ui| {
        ui.label("Recent:");
        if recent.is_empty() {
            ui.weak("none yet (colours you paint with)");
        }
        for (k, &code) in recent.srgba8().iter().enumerate() {
            let name = format!("Recent colour {}", hex_of(code));
            let (rect, response) = ui.allocate_exact_size(egui::vec2(SWATCH, SWATCH), egui::Sense::click());
            response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Button, true, &name));
            let [r, g, b, a] = code;
            egui::color_picker::show_color_at(ui.painter(), egui::Color32::from_rgba_unmultiplied(r, g, b, a), rect);
            let stroke = ui.style().interact(&response).fg_stroke;
            ui.painter().rect_stroke(rect, 2.0, stroke, egui::StrokeKind::Inside);
            if response.on_hover_text(&name).clicked()
                && let Some(picked) = recent.linear(k)
            {
                *color = picked;
            }
        }
    });
}

/// The brightness (HSV value) slider.
fn brightness_slider(ui: &mut egui::Ui, value: &mut f32) -> bool {
    ui.add(egui::Slider::new(value, 0.0..=1.0).text("Brightness")).changed()
}

/// The HSV wheel: hue is the angle (0 = red to the right, counter-clockwise on screen),
/// saturation the distance from the centre; clicking or dragging picks. Returns whether
/// `hsv` changed.
fn hsv_wheel(ui: &mut egui::Ui, hsv: &mut [f32; 3]) -> bool {
    let diameter = ui.available_width().min(WHEEL_DIAMETER);
    let (rect, response) = ui.allocate_exact_size(egui::vec2(diameter, diameter), egui::Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Slider, true, "Colour wheel"));
    let (center, radius) = (rect.center(), diameter * 0.5);
    let mut changed = false;
    if (response.clicked() || response.dragged())
        && let Some(pos) = response.interact_pointer_pos()
        && let Some((hue, saturation)) = hue_saturation_at(pos - center, radius)
    {
        changed = hue != hsv[0] || saturation != hsv[1];
        hsv[0] = hue;
        hsv[1] = saturation;
    }
    if ui.is_rect_visible(rect) {
        let painter = ui.painter();
        painter.add(egui::Shape::mesh(wheel_mesh(center, radius, hsv[2])));
        let angle = hsv[0] * TAU;
        let marker = center + egui::vec2(angle.cos(), -angle.sin()) * (hsv[1] * radius);
        let contrast = if hsv[2] > 0.5 { egui::Color32::BLACK } else { egui::Color32::WHITE };
        painter.circle_stroke(marker, 5.0, egui::Stroke::new(2.0, contrast));
    }
    changed
}

/// Hue and saturation at `offset` from the wheel's centre (points, y down); beyond the rim
/// the saturation is 1. `None` when `radius` is not positive.
pub fn hue_saturation_at(offset: egui::Vec2, radius: f32) -> Option<(f32, f32)> {
    if radius <= 0.0 || !offset.is_finite() {
        return None;
    }
    let hue = (-offset.y).atan2(offset.x).rem_euclid(TAU) / TAU;
    Some((hue.clamp(0.0, 1.0), (offset.length() / radius).min(1.0)))
}

/// The wheel as a mesh of vertex colours at brightness `value`.
fn wheel_mesh(center: egui::Pos2, radius: f32, value: f32) -> egui::Mesh {
    let mut mesh = egui::Mesh::default();
    mesh.colored_vertex(center, color32_of([0.0, 0.0, value]));
    for ring in 1..=RINGS {
        let saturation = ring as f32 / RINGS as f32;
        for segment in 0..SEGMENTS {
            let hue = segment as f32 / SEGMENTS as f32;
            let angle = hue * TAU;
            let pos = center + egui::vec2(angle.cos(), -angle.sin()) * (saturation * radius);
            mesh.colored_vertex(pos, color32_of([hue, saturation, value]));
        }
    }
    let index = |ring: usize, segment: usize| (1 + (ring - 1) * SEGMENTS + segment % SEGMENTS) as u32;
    for segment in 0..SEGMENTS {
        mesh.add_triangle(0, index(1, segment), index(1, segment + 1));
        for ring in 1..RINGS {
            let (a, b) = (index(ring, segment), index(ring, segment + 1));
            let (c, d) = (index(ring + 1, segment), index(ring + 1, segment + 1));
            mesh.add_triangle(a, c, d);
            mesh.add_triangle(a, d, b);
        }
    }
    mesh
}

/// The opaque egui colour of HSV `hsv`.
fn color32_of(hsv: [f32; 3]) -> egui::Color32 {
    let [r, g, b] = rgb_of_hsv(hsv).map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8);
    egui::Color32::from_rgb(r, g, b)
}

/// The linear colour of HSV `hsv` with alpha `alpha`.
pub fn linear_of(hsv: [f32; 3], alpha: f32) -> Rgba {
    let [r, g, b] = rgb_of_hsv(hsv).map(srgb_to_linear);
    [r, g, b, alpha]
}

/// The HSV of a linear colour; `previous` gives the hue where there is none (grey) and the
/// saturation where there is none (black).
pub fn hsv_of(color: Rgba, previous: [f32; 3]) -> [f32; 3] {
    let [r, g, b] = [color[0], color[1], color[2]].map(linear_to_srgb);
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let delta = max - min;
    if max <= 0.0 {
        return [previous[0], previous[1], 0.0];
    }
    if delta <= 0.0 {
        return [previous[0], 0.0, max];
    }
    let sector = if max == r {
        ((g - b) / delta).rem_euclid(6.0)
    } else if max == g {
        (b - r) / delta + 2.0
    } else {
        (r - g) / delta + 4.0
    };
    [sector / 6.0, delta / max, max]
}

/// sRGB-encoded RGB of HSV `[h, s, v]` (each `0..=1`; the hue wraps).
pub fn rgb_of_hsv([h, s, v]: [f32; 3]) -> [f32; 3] {
    let sector = (h.rem_euclid(1.0) * 6.0).min(6.0 - f32::EPSILON);
    let chroma = v * s;
    let x = chroma * (1.0 - ((sector % 2.0) - 1.0).abs());
    let m = v - chroma;
    let [r, g, b] = match sector as u32 {
        0 => [chroma, x, 0.0],
        1 => [x, chroma, 0.0],
        2 => [0.0, chroma, x],
        3 => [0.0, x, chroma],
        4 => [x, 0.0, chroma],
        _ => [chroma, 0.0, x],
    };
    [r + m, g + m, b + m]
}
