//! The import settings panel: how the editor gives an opened mesh its face resolutions,
//! the choice in the open dialog (and the file panel's section), turned into one
//! [`ResolutionRule`] of [`meshpaint_core::convert::adaptive`]; and which axis is up (Y or
//! Z: Z-up scans otherwise open lying on their side). The up axis turns the camera
//! ([`OrbitCamera::up`](meshpaint_core::camera::OrbitCamera::up)), never the geometry, so the
//! document and everything exported from it stay as the file had them.

use meshpaint_core::camera::UpAxis;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;

use super::widgets::resolution_combo;

/// The kinds of choice the open dialog offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImportMode {
    /// `R` where textured, the lowest `R` elsewhere (the default; painting raises it).
    Automatic,
    /// The same `R` on every face.
    Uniform,
    /// One sample per texel along each face's longest UV edge (texel density).
    MatchTexture,
    /// The lowest `R` per face whose reconstruction stays within `E` of the texture.
    ErrorBound,
    /// The per-face `R` that shows the texture best with at most `N` samples.
    Budget,
}

impl ImportMode {
    /// Every mode, in the order the dialog lists them.
    pub const ALL: [ImportMode; 5] = [
        ImportMode::Automatic,
        ImportMode::Uniform,
        ImportMode::MatchTexture,
        ImportMode::ErrorBound,
        ImportMode::Budget,
    ];

    /// The name the dialog shows.
    pub fn name(self) -> &'static str {
        match self {
            ImportMode::Automatic => "Automatic",
            ImportMode::Uniform => "Uniform R",
            ImportMode::MatchTexture => "Match texture",
            ImportMode::ErrorBound => "Error ≤ E",
            ImportMode::Budget => "Samples ≤ N",
        }
    }

    /// What the mode does, for the hover text.
    pub fn explanation(self) -> &'static str {
        match self {
            ImportMode::Automatic => {
                "R on textured faces, R = 1 on the others (a flat colour or vertex colours need no more; \
                 resolution follows the brush where you paint)"
            }
            ImportMode::Uniform => "The same R on every face",
            ImportMode::MatchTexture => "About one sample per texel each face covers, up to the largest R",
            ImportMode::ErrorBound => {
                "The lowest R per face whose linear reconstruction stays within E of the texture \
                 (RMS of sRGB-encoded differences, 0..1), up to the largest R"
            }
            ImportMode::Budget => {
                "The per-face R that shows the texture best with at most N samples (level 0, MIP chains \
                 not counted): more where the texture varies, fewer where it is flat, up to the largest R"
            }
        }
    }
}

/// The open dialog's resolution choice; the import settings panel ([`ImportSettings::ui`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImportSettings {
    /// Which rule.
    pub mode: ImportMode,
    /// `R` of [`ImportMode::Automatic`] and [`ImportMode::Uniform`].
    pub resolution: Resolution,
    /// `E` of [`ImportMode::ErrorBound`] (colour units, full range = 1).
    pub error_bound: f32,
    /// `N` of [`ImportMode::Budget`] (level-0 samples).
    pub sample_budget: u64,
    /// The largest `R` of the content-driven modes.
    pub max_resolution: Resolution,
    /// The axis that is up in the 3D view (the open document's view follows a change).
    pub up_axis: UpAxis,
}

impl Default for ImportSettings {
    fn default() -> Self {
        ImportSettings {
            mode: ImportMode::Automatic,
            resolution: Resolution::from_log2(3).unwrap_or(Resolution::ONE),
            error_bound: 0.01,
            sample_budget: 100_000,
            // The layout's largest: faces are held by their texels and the rule, not a cap.
            max_resolution: Resolution::MAX,
            up_axis: UpAxis::Y,
        }
    }
}

impl ImportSettings {
    /// The rule opening applies.
    pub fn rule(&self) -> ResolutionRule {
        match self.mode {
            ImportMode::Automatic => ResolutionRule::WhereTextured(self.resolution),
            ImportMode::Uniform => ResolutionRule::Uniform(self.resolution),
            ImportMode::MatchTexture => ResolutionRule::TexelDensity { max: self.max_resolution },
            ImportMode::ErrorBound => {
                ResolutionRule::ErrorBound { bound: self.error_bound.max(0.0), max: self.max_resolution }
            }
            ImportMode::Budget => ResolutionRule::Budget { samples: self.sample_budget, max: self.max_resolution },
        }
    }

    /// The mode combo and its parameters, one row, after `label`; the up axis below.
    pub fn ui(&mut self, ui: &mut egui::Ui, label: &str) {
        self.resolution_ui(ui, label);
        ui.horizontal(|ui| {
            ui.label("Up axis:");
            ui.radio_value(&mut self.up_axis, UpAxis::Y, "Y up").on_hover_text("glTF and most modelling tools");
            ui.radio_value(&mut self.up_axis, UpAxis::Z, "Z up").on_hover_text(
                "Many scans and CAD files: without it they lie on their side (the view turns, not the mesh)",
            );
        });
    }

    /// The mode combo and its parameters, one row, after `label`.
    fn resolution_ui(&mut self, ui: &mut egui::Ui, label: &str) {
        ui.horizontal_wrapped(|ui| {
            let label = ui.label(label);
            egui::ComboBox::from_id_salt("import mode")
                .selected_text(self.mode.name())
                .show_ui(ui, |ui| {
                    for mode in ImportMode::ALL {
                        ui.selectable_value(&mut self.mode, mode, mode.name()).on_hover_text(mode.explanation());
                    }
                })
                .response
                .labelled_by(label.id)
                .on_hover_text(self.mode.explanation());
            match self.mode {
                ImportMode::Automatic | ImportMode::Uniform => {
                    resolution_combo(ui, "R", &mut self.resolution);
                }
                ImportMode::MatchTexture => {
                    resolution_combo(ui, "R ≤", &mut self.max_resolution);
                }
                ImportMode::ErrorBound => {
                    let label = ui.label("E");
                    ui.add(egui::DragValue::new(&mut self.error_bound).range(0.0..=1.0).speed(0.001).max_decimals(4))
                        .labelled_by(label.id);
                    resolution_combo(ui, "R ≤", &mut self.max_resolution);
                }
                ImportMode::Budget => {
                    let label = ui.label("N");
                    ui.add(egui::DragValue::new(&mut self.sample_budget).range(1..=1u64 << 28).speed(1000.0))
                        .labelled_by(label.id);
                    resolution_combo(ui, "R ≤", &mut self.max_resolution);
                }
            }
        });
    }
}
