//! Brush presets: named brushes (tool, radius, strength, falloff, spacing, blend, occlusion,
//! culling, mirror, pressure response) to save, load and delete; three defaults (hard round,
//! soft airbrush, blur brush). A preset never holds the colour (the colour wheel and the recent
//! colours do) nor "resolution follows the brush" (a property of the document being
//! painted): loading one keeps both. Remembered in the settings file.

use meshpaint_core::paint::brush::{BlendMode, BrushRadius, BrushSettings, Falloff, PressureResponse, Tool};

/// One named brush.
#[derive(Debug, Clone, PartialEq)]
pub struct BrushPreset {
    /// The name shown on its button (unique in [`BrushPresets`]).
    pub name: String,
    /// The brush; its colour and `follow_resolution` are ignored.
    pub brush: BrushSettings,
}

impl BrushPreset {
    /// `current` with this preset's settings, keeping `current`'s colour and resolution
    /// following.
    pub fn applied_to(&self, current: &BrushSettings) -> BrushSettings {
        BrushSettings { color: current.color, follow_resolution: current.follow_resolution, ..self.brush }
    }
}

/// The presets, in the order they were saved.
#[derive(Debug, Clone, PartialEq)]
pub struct BrushPresets {
    presets: Vec<BrushPreset>,
}

impl Default for BrushPresets {
    fn default() -> Self {
        BrushPresets { presets: default_presets() }
    }
}

/// The presets a new user starts with.
pub fn default_presets() -> Vec<BrushPreset> {
    let base = BrushSettings::default();
    let preset = |name: &str, brush: BrushSettings| BrushPreset { name: name.to_owned(), brush };
    vec![
        preset(
            "Hard round",
            BrushSettings {
                tool: Tool::Paint,
                blend: BlendMode::Mix,
                radius: BrushRadius::Pixels { radius_px: 20.0 },
                strength: 1.0,
                falloff: Falloff::Constant,
                spacing_percent: 10.0,
                ..base
            },
        ),
        preset(
            "Soft airbrush",
            BrushSettings {
                tool: Tool::Paint,
                blend: BlendMode::Mix,
                radius: BrushRadius::Pixels { radius_px: 60.0 },
                strength: 0.15,
                falloff: Falloff::Smooth,
                spacing_percent: 5.0,
                pressure: PressureResponse { radius: false, strength: true },
                ..base
            },
        ),
        preset(
            "Blur brush",
            BrushSettings {
                tool: Tool::Blur,
                radius: BrushRadius::Pixels { radius_px: 40.0 },
                strength: 0.5,
                falloff: Falloff::Smooth,
                spacing_percent: 10.0,
                ..base
            },
        ),
    ]
}

impl BrushPresets {
    /// These presets (the first of several with one name kept).
    pub fn from_list(list: Vec<BrushPreset>) -> Self {
        let mut presets = BrushPresets { presets: Vec::with_capacity(list.len()) };
        for preset in list {
            if presets.get(&preset.name).is_none() {
                presets.presets.push(preset);
            }
        }
        presets
    }

    /// Every preset, in order.
    pub fn list(&self) -> &[BrushPreset] {
        &self.presets
    }

    /// The preset named `name`.
    pub fn get(&self, name: &str) -> Option<&BrushPreset> {
        self.presets.iter().find(|p| p.name == name)
    }

    /// Saves `brush` as `name` (trimmed), replacing a preset of that name in place.
    /// Returns whether one was replaced; `Err` with the reason when the name is empty.
    pub fn save(&mut self, name: &str, brush: BrushSettings) -> Result<bool, String> {
        let name = name.trim();
        if name.is_empty() {
            return Err("Type a name for the preset first.".to_owned());
        }
        let preset = BrushPreset { name: name.to_owned(), brush };
        match self.presets.iter_mut().find(|p| p.name == name) {
            Some(existing) => {
                *existing = preset;
                Ok(true)
            }
            None => {
                self.presets.push(preset);
                Ok(false)
            }
        }
    }

    /// Deletes the preset named `name`; returns whether there was one.
    pub fn delete(&mut self, name: &str) -> bool {
        let before = self.presets.len();
        self.presets.retain(|p| p.name != name.trim());
        self.presets.len() != before
    }
}
