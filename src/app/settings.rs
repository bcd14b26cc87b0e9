//! The settings remembered between runs, in `settings.toml` in the platform's config
//! directory (`$XDG_CONFIG_HOME/meshpaint` or `~/.config/meshpaint` on Linux, from the
//! `dirs` crate), or in `$MESHPAINT_CONFIG_DIR` when that is set (tests point it at a
//! temporary directory, so they never touch the real one).
//!
//! What is remembered: the brush presets, the recent colours, the up axis, and the view
//! preferences an artist sets once (zoom to the pointer, shading). Each has one home in the
//! editor (the panels' state); this file only reads and writes them. The file is written
//! atomically ([`meshpaint_core::atomic_write`]); a file that cannot be read, is not TOML,
//! holds a value this version does not know or comes from a newer version gives a message
//! and the defaults, never an error that stops the editor. Keys this version does not know
//! are ignored.

use std::path::{Path, PathBuf};

use meshpaint_core::camera::UpAxis;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::paint::brush::{
    BlendMode, BrushRadius, BrushSettings, Falloff, PressureResponse, ResolutionOp, Tool,
};
use meshpaint_render::Shading;
use serde::{Deserialize, Serialize};

use super::presets::{BrushPreset, BrushPresets};
use super::recent_colors::RecentColors;

/// The environment variable naming the directory of the settings file (overrides the
/// platform's config directory).
pub const CONFIG_DIR_ENV: &str = "MESHPAINT_CONFIG_DIR";
/// The settings file's name.
pub const FILE_NAME: &str = "settings.toml";
/// The version this editor writes.
pub const VERSION: u32 = 1;

/// What is remembered between runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// The brush presets.
    pub presets: BrushPresets,
    /// The recent colours, newest first.
    pub recent_colors: RecentColors,
    /// The up axis of the 3D view.
    pub up_axis: UpAxis,
    /// The wheel zooms towards the pointer.
    pub zoom_to_cursor: bool,
    /// Lit (smooth or flat) or unlit.
    pub shading: Shading,
}

/// Where the editor's settings live and what was last read or written there.
#[derive(Debug, Clone, Default)]
pub struct SettingsFile {
    /// The file (`None`: settings are not remembered, as in UI tests).
    pub path: Option<PathBuf>,
    /// The settings as last read or written: nothing is written while they stay so.
    pub saved: Option<Settings>,
    /// Why the file could not be used, for the status line once the first document opened.
    pub problem: Option<String>,
}

/// The settings file: `$MESHPAINT_CONFIG_DIR/settings.toml` when the variable is set and not
/// empty, else `settings.toml` in the platform's config directory under `meshpaint`; `None`
/// when there is no config directory (no home).
pub fn settings_path() -> Option<PathBuf> {
    settings_path_with(std::env::var_os(CONFIG_DIR_ENV))
}

/// [`settings_path`] with `override_dir` as the value of `$MESHPAINT_CONFIG_DIR`.
pub fn settings_path_with(override_dir: Option<std::ffi::OsString>) -> Option<PathBuf> {
    if let Some(dir) = override_dir.filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(dir).join(FILE_NAME));
    }
    dirs::config_dir().map(|dir| dir.join("meshpaint").join(FILE_NAME))
}

/// Reads the settings at `path`: `Ok(None)` when there is no file, `Err` with a message for
/// the status line when it cannot be used.
pub fn load(path: &Path) -> Result<Option<Settings>, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(error) => return Err(format!("Could not read the settings file {}: {error}", path.display())),
    };
    let problem = |what: String| format!("The settings file {} {what}: using the defaults.", path.display());
    let file: FileLayout =
        toml::from_str(&text).map_err(|error| problem(format!("is not valid ({})", error.message())))?;
    if file.version > VERSION {
        return Err(problem(format!("is from a newer meshpaint (version {})", file.version)));
    }
    file.settings().map(Some).map_err(problem)
}

/// Writes `settings` to `path` atomically, creating its directory.
pub fn save(path: &Path, settings: &Settings) -> Result<(), String> {
    let text =
        toml::to_string(&FileLayout::of(settings)).map_err(|error| format!("Could not write the settings: {error}"))?;
    let text = format!("# meshpaint's settings, written by the editor (unknown keys are ignored).\n{text}");
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|error| format!("Could not create {}: {error}", dir.display()))?;
    }
    meshpaint_core::atomic_write::write_atomically(path, text.as_bytes()).map_err(|error| error.to_string())
}

/// The file's layout.
#[derive(Debug, Serialize, Deserialize)]
#[serde(default)]
struct FileLayout {
    version: u32,
    /// `y` or `z`.
    up_axis: String,
    /// `#rrggbbaa`, newest first.
    recent_colors: Vec<String>,
    view: ViewFile,
    presets: Vec<PresetFile>,
}

impl Default for FileLayout {
    fn default() -> Self {
        let settings = Settings {
            presets: BrushPresets::default(),
            recent_colors: RecentColors::default(),
            up_axis: UpAxis::Y,
            zoom_to_cursor: true,
            shading: Shading::Smooth,
        };
        FileLayout::of(&settings)
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(default)]
struct ViewFile {
    zoom_to_cursor: bool,
    /// `smooth`, `flat` or `unlit`.
    shading: String,
}

impl Default for ViewFile {
    fn default() -> Self {
        ViewFile { zoom_to_cursor: true, shading: "smooth".into() }
    }
}

/// One preset; the radius is `radius_px` or `radius_world`.
#[derive(Debug, Serialize, Deserialize)]
struct PresetFile {
    name: String,
    /// `paint`, `blur`, `raise`, `lower` or `set` (with `target_resolution`).
    tool: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    target_resolution: Option<u64>,
    blend: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    radius_px: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    radius_world: Option<f64>,
    strength: f32,
    falloff: String,
    spacing_percent: f64,
    occlusion: bool,
    backface_culling: bool,
    mirror_x: bool,
    /// `radius`, `strength`, `both` or `none`.
    pressure: String,
}

impl FileLayout {
    fn of(settings: &Settings) -> Self {
        let shading = match settings.shading {
            Shading::Smooth => "smooth",
            Shading::Lit => "flat",
            Shading::Unlit => "unlit",
        };
        FileLayout {
            version: VERSION,
            up_axis: settings.up_axis.name().to_owned(),
            recent_colors: settings
                .recent_colors
                .srgba8()
                .iter()
                .map(|[r, g, b, a]| format!("#{r:02x}{g:02x}{b:02x}{a:02x}"))
                .collect(),
            view: ViewFile { zoom_to_cursor: settings.zoom_to_cursor, shading: shading.to_owned() },
            presets: settings.presets.list().iter().map(PresetFile::of).collect(),
        }
    }

    /// The settings, or what is wrong with the first value that is not understood.
    fn settings(&self) -> Result<Settings, String> {
        let up_axis =
            UpAxis::from_name(&self.up_axis).ok_or_else(|| format!("has an unknown up axis \"{}\"", self.up_axis))?;
        let shading = match self.view.shading.as_str() {
            "smooth" => Shading::Smooth,
            "flat" => Shading::Lit,
            "unlit" => Shading::Unlit,
            other => return Err(format!("has an unknown shading \"{other}\"")),
        };
        let recent = self
            .recent_colors
            .iter()
            .map(|text| {
                parse_rgba8(text).ok_or_else(|| format!("has a recent colour \"{text}\" that is not #rrggbbaa"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let presets = self.presets.iter().map(PresetFile::preset).collect::<Result<Vec<_>, _>>()?;
        Ok(Settings {
            presets: BrushPresets::from_list(presets),
            recent_colors: RecentColors::from_srgba8(recent),
            up_axis,
            zoom_to_cursor: self.view.zoom_to_cursor,
            shading,
        })
    }
}

impl PresetFile {
    fn of(preset: &BrushPreset) -> Self {
        let brush = &preset.brush;
        let (tool, target_resolution) = match brush.tool {
            Tool::Paint => ("paint", None),
            Tool::Blur => ("blur", None),
            Tool::Resolution(ResolutionOp::Raise) => ("raise", None),
            Tool::Resolution(ResolutionOp::Lower) => ("lower", None),
            Tool::Resolution(ResolutionOp::Set(r)) => ("set", Some(r.get().into())),
        };
        let (radius_px, radius_world) = match brush.radius {
            BrushRadius::Pixels { radius_px } => (Some(radius_px), None),
            BrushRadius::World { radius_world } => (None, Some(radius_world)),
        };
        PresetFile {
            name: preset.name.clone(),
            tool: tool.to_owned(),
            target_resolution,
            blend: brush.blend.name().to_owned(),
            radius_px,
            radius_world,
            strength: brush.strength,
            falloff: brush.falloff.name().to_owned(),
            spacing_percent: brush.spacing_percent,
            occlusion: brush.occlusion,
            backface_culling: brush.backface_culling,
            mirror_x: brush.mirror_x,
            pressure: brush.pressure.name().to_owned(),
        }
    }

    fn preset(&self) -> Result<BrushPreset, String> {
        let bad =
            |what: &str, value: &str| format!("has a preset \"{}\" with an unknown {what} \"{value}\"", self.name);
        let tool = match (self.tool.as_str(), self.target_resolution) {
            ("paint", _) => Tool::Paint,
            ("blur", _) => Tool::Blur,
            ("raise", _) => Tool::Resolution(ResolutionOp::Raise),
            ("lower", _) => Tool::Resolution(ResolutionOp::Lower),
            ("set", Some(r)) => Tool::Resolution(ResolutionOp::Set(
                Resolution::new(r).map_err(|_| bad("target resolution", &r.to_string()))?,
            )),
            (other, _) => return Err(bad("tool", other)),
        };
        let radius = match (self.radius_px, self.radius_world) {
            (_, Some(radius_world)) => BrushRadius::World { radius_world },
            (Some(radius_px), None) => BrushRadius::Pixels { radius_px },
            (None, None) => return Err(format!("has a preset \"{}\" without a radius", self.name)),
        };
        let brush = BrushSettings {
            tool,
            blend: BlendMode::from_name(&self.blend).ok_or_else(|| bad("blend mode", &self.blend))?,
            radius,
            strength: self.strength,
            falloff: Falloff::from_name(&self.falloff).ok_or_else(|| bad("falloff", &self.falloff))?,
            spacing_percent: self.spacing_percent,
            occlusion: self.occlusion,
            backface_culling: self.backface_culling,
            mirror_x: self.mirror_x,
            pressure: PressureResponse::from_name(&self.pressure)
                .ok_or_else(|| bad("pressure response", &self.pressure))?,
            ..BrushSettings::default()
        };
        brush.validate().map_err(|error| format!("has a preset \"{}\" that is not valid: {error}", self.name))?;
        Ok(BrushPreset { name: self.name.clone(), brush })
    }
}

/// Parses `#rrggbbaa`.
fn parse_rgba8(text: &str) -> Option<[u8; 4]> {
    let hex = text.strip_prefix('#')?;
    if hex.len() != 8 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let byte = |k: usize| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).ok();
    Some([byte(0)?, byte(1)?, byte(2)?, byte(3)?])
}
