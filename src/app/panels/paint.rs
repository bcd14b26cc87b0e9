//! The paint panel: enter / leave paint mode, the brush presets ([`super::presets`]), the
//! brush settings (tool, colour with the
//! wheel, hex field and recent colours of [`super::color`], radius, strength, falloff,
//! spacing, blend mode, occlusion, culling, mirror) and the commands eyedropper, fill and
//! "Set R for all". The brush and the recent colours are this panel's state; the editor
//! lends them to paint mode's strokes (which record the colours they paint with).

use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::paint::brush::{
    BlendMode, BrushRadius, BrushSettings, FOLLOW_BRUSH_MAX_RESOLUTION, Falloff, ResolutionOp, Tool,
};

use super::color::ColorPicker;
use super::presets::PresetsPanel;
use crate::app::command::Command;
use crate::app::recent_colors::RecentColors;
use crate::app::state::Action;
use crate::app::widgets::resolution_combo;

/// The paint panel and the settings it edits.
#[derive(Debug)]
pub struct PaintPanel {
    /// The brush settings (kept between paint sessions).
    pub brush: BrushSettings,
    /// The resolution of "Set R for all".
    pub resolution_for_all: Resolution,
    /// The colour wheel and hex field.
    pub picker: ColorPicker,
    /// The last distinct colours strokes painted with.
    pub recent_colors: RecentColors,
    /// The brush presets.
    pub presets: PresetsPanel,
}

impl Default for PaintPanel {
    fn default() -> Self {
        PaintPanel {
            brush: BrushSettings::default(),
            resolution_for_all: Resolution::from_log2(3).unwrap_or(Resolution::ONE),
            picker: ColorPicker::default(),
            recent_colors: RecentColors::default(),
            presets: PresetsPanel::default(),
        }
    }
}

/// What the paint panel reads of the editor.
#[derive(Debug, Clone, Copy)]
pub struct PaintPanelContext {
    /// Paint mode is on (the commands work only then).
    pub painting: bool,
    /// A document is open (paint mode can be entered).
    pub has_document: bool,
    /// The open mesh's bounding radius (scales the world radius slider).
    pub bounds_radius: Option<f64>,
}

impl PaintPanel {
    /// The mode button, the brush settings and the commands.
    pub fn ui(&mut self, ui: &mut egui::Ui, ctx: PaintPanelContext) -> Vec<Command> {
        let mut commands = Vec::new();
        let button = if ctx.painting { "Leave paint mode (Tab)" } else { "Enter paint mode (Tab)" };
        if ui.add_enabled(ctx.has_document, egui::Button::new(button)).clicked() {
            commands.push(Command::Action(Action::TogglePaintMode));
        }
        self.presets.ui(ui, &mut self.brush);
        ui.separator();
        tool_ui(ui, &mut self.brush);
        self.picker.ui(ui, &mut self.brush.color, &self.recent_colors);
        brush_settings_ui(ui, &mut self.brush, ctx.bounds_radius);
        ui.separator();
        ui.add_enabled_ui(ctx.painting, |ui| {
            ui.horizontal_wrapped(|ui| {
                if ui.button("Eyedropper").on_hover_text("S over the mesh").clicked() {
                    commands.push(Command::Action(Action::Eyedropper));
                }
                if ui.button("Fill all").clicked() {
                    commands.push(Command::Fill { connected: false });
                }
                if ui.button("Fill connected").on_hover_text("The part last under the cursor").clicked() {
                    commands.push(Command::Fill { connected: true });
                }
            });
            ui.horizontal(|ui| {
                resolution_combo(ui, "All faces: R", &mut self.resolution_for_all);
                if ui.button("Set R for all").clicked() {
                    commands.push(Command::SetResolutionAll(self.resolution_for_all));
                }
            });
        });
        commands
    }
}

/// The tool row (and the resolution tool's operation).
fn tool_ui(ui: &mut egui::Ui, brush: &mut BrushSettings) {
    ui.horizontal(|ui| {
        ui.label("Tool:");
        ui.selectable_value(&mut brush.tool, Tool::Paint, "Colour");
        ui.selectable_value(&mut brush.tool, Tool::Blur, "Blur");
        let is_resolution = matches!(brush.tool, Tool::Resolution(_));
        if ui.selectable_label(is_resolution, "Resolution").clicked() && !is_resolution {
            brush.tool = Tool::Resolution(ResolutionOp::Raise);
        }
    });
    if let Tool::Resolution(op) = &mut brush.tool {
        ui.horizontal(|ui| {
            ui.radio_value(op, ResolutionOp::Raise, "Raise");
            ui.radio_value(op, ResolutionOp::Lower, "Lower");
            let is_set = matches!(op, ResolutionOp::Set(_));
            if ui.radio(is_set, "Set").clicked() && !is_set {
                *op = ResolutionOp::Set(Resolution::from_log2(3).unwrap_or(Resolution::ONE));
            }
        });
        if let ResolutionOp::Set(r) = op {
            ui.horizontal(|ui| resolution_combo(ui, "To R", r));
        }
    }
}

/// The brush settings after the tool and the colour: radius (pixels or world units;
/// `bounds_radius` of the mesh scales the world slider), strength, spacing, falloff, blend,
/// occlusion, culling, mirror, edited in place.
fn brush_settings_ui(ui: &mut egui::Ui, brush: &mut BrushSettings, bounds_radius: Option<f64>) {
    ui.horizontal(|ui| {
        let mut world = matches!(brush.radius, BrushRadius::World { .. });
        ui.label("Radius in:");
        let pixels_clicked = ui.radio_value(&mut world, false, "pixels").clicked();
        let world_clicked = ui.radio_value(&mut world, true, "world").clicked();
        if pixels_clicked && !matches!(brush.radius, BrushRadius::Pixels { .. }) {
            brush.radius = BrushRadius::Pixels { radius_px: 30.0 };
        }
        if world_clicked && !matches!(brush.radius, BrushRadius::World { .. }) {
            let scale = bounds_radius.unwrap_or(1.0);
            brush.radius = BrushRadius::World { radius_world: scale * 0.05 };
        }
    });
    match &mut brush.radius {
        BrushRadius::Pixels { radius_px } => {
            ui.add(egui::Slider::new(radius_px, 1.0..=500.0).logarithmic(true).text("Radius (px)"))
                .on_hover_text("F: set interactively");
        }
        BrushRadius::World { radius_world } => {
            let max = bounds_radius.map_or(10.0, |r| r * 2.0).max(1e-3);
            ui.add(egui::Slider::new(radius_world, max * 1e-4..=max).logarithmic(true).text("Radius (world)"))
                .on_hover_text("F: set interactively");
        }
    }
    ui.add(egui::Slider::new(&mut brush.strength, 0.0..=1.0).text("Strength")).on_hover_text("Shift+F");
    ui.add(egui::Slider::new(&mut brush.spacing_percent, 1.0..=200.0).text("Spacing (%)"));
    ui.horizontal(|ui| {
        let label = ui.label("Falloff:");
        egui::ComboBox::from_id_salt("falloff")
            .selected_text(brush.falloff.name())
            .show_ui(ui, |ui| {
                for falloff in [Falloff::Smooth, Falloff::Linear, Falloff::Constant, Falloff::Sharp] {
                    ui.selectable_value(&mut brush.falloff, falloff, falloff.name());
                }
            })
            .response
            .labelled_by(label.id);
    });
    ui.horizontal(|ui| {
        let label = ui.label("Blend:");
        egui::ComboBox::from_id_salt("blend")
            .selected_text(blend_name(brush.blend))
            .show_ui(ui, |ui| {
                for blend in BlendMode::ALL {
                    ui.selectable_value(&mut brush.blend, blend, blend_name(blend));
                }
            })
            .response
            .labelled_by(label.id);
    });
    ui.checkbox(&mut brush.occlusion, "Occlusion").on_hover_text("Paint only what the eye sees");
    ui.checkbox(&mut brush.backface_culling, "Backface culling");
    ui.checkbox(&mut brush.mirror_x, "X mirror");
    // Resolution follows the brush: faces under a dab are raised until their sample spacing
    // is at most a quarter of the radius (up to R = 64).
    let mut follow = brush.follow_resolution.is_some();
    ui.checkbox(&mut follow, "Resolution follows the brush")
        .on_hover_text("Raise the faces under each dab to the R that resolves the brush (spacing at most a quarter of the radius, R up to 64)");
    brush.follow_resolution = follow.then_some(FOLLOW_BRUSH_MAX_RESOLUTION);
}

/// The name of a blend mode in the panel.
pub fn blend_name(blend: BlendMode) -> &'static str {
    match blend {
        BlendMode::Mix => "Mix",
        BlendMode::Add => "Add",
        BlendMode::Multiply => "Multiply",
        BlendMode::EraseToBase => "Erase to base",
    }
}
