//! The editor's small shared types: mode, status, view settings, the [`Action`]s every
//! menu and shortcut maps to, the 3D view's area and frame timing. They depend on nothing
//! else in the app, so every other file may use them.

use std::time::{Duration, Instant};

use meshpaint_core::camera::OrbitCamera;
use meshpaint_render::{FilterMode, Overlays, RenderSettings, Shading};

/// What the editor is doing with the pointer in the 3D view. Paint mode (Tab) slots in
/// here: its tools get the pointer in [`super::input::paint_input`], edit the document's
/// store and upload dirty samples to its GPU mesh. The editor derives it from the paint
/// session (`DocumentState::mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// Look at the mesh: navigation only.
    #[default]
    View,
    /// Paint on the mesh: the left button paints with the brush ([`super::paint`]).
    Paint,
}

impl Mode {
    /// Name for the status line.
    pub fn name(self) -> &'static str {
        match self {
            Mode::View => "View",
            Mode::Paint => "Paint",
        }
    }
}

/// How bad a status message is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    /// Progress and results.
    Info,
    /// Something worked, with caveats.
    Warning,
    /// Something failed; nothing was changed.
    Error,
}

/// The status line's message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Status {
    /// The message.
    pub text: String,
    /// Its severity.
    pub severity: Severity,
}

impl Status {
    /// Replaces the message, and logs it at its severity's level.
    pub fn set(&mut self, severity: Severity, text: impl Into<String>) {
        let text = text.into();
        match severity {
            Severity::Info => log::info!("{text}"),
            Severity::Warning => log::warn!("{text}"),
            Severity::Error => log::error!("{text}"),
        }
        *self = Status { text, severity };
    }
}

/// What the 3D view shows of the document.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Shown {
    /// The mesh colors (what is painted and saved).
    #[default]
    MeshColors,
    /// The source file drawn the conventional way, with its UVs and base-colour texture
    /// (the UV baseline): what the conversion to mesh colors is compared with.
    SourceTexture,
    /// A colour field of the position (shows the shape and the sample lattice; a view only,
    /// never the document's colours).
    PositionColors,
}

impl Shown {
    /// Every choice, in the order the view panel lists them.
    pub const ALL: [Shown; 3] = [Shown::MeshColors, Shown::SourceTexture, Shown::PositionColors];

    /// The name the view panel shows.
    pub fn name(self) -> &'static str {
        match self {
            Shown::MeshColors => "Mesh colors",
            Shown::SourceTexture => "Source texture",
            Shown::PositionColors => "Position colours",
        }
    }
}

/// How the 3D view draws the mesh colors: the one representation of the document, or one
/// built from it for the GPU's own filtering.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Representation {
    /// The packed mesh colors, filtered in the shader (exact: the reference sampler's filters).
    #[default]
    MeshColors,
    /// Mesh Color Textures (Yuksel 2017): the packed colours laid out in one 2D atlas with
    /// the shared vertex and edge colours duplicated, filtered by the GPU's bilinear sampler
    /// (crates/core/src/mct; built from the packed mesh when shown, again after each repack).
    MeshColorTexture,
    /// Htex (Barbier & Dupuy 2022): one square texture per edge in atlas pages, three
    /// hardware bilinear fetches per pixel (crates/core/src/htex; built like MCT).
    Htex,
    /// Packed Ptex (Kim, Hillesland, Hensley 2011): per-pair square blocks with their MIP
    /// chains and one-texel borders from the neighbours in one texture, filtered by the
    /// GPU's bilinear sampler (crates/core/src/ptex; built as Mesh Color Textures are).
    PackedPtex,
}

impl Representation {
    /// Every choice, in the order the view panel lists them.
    pub const ALL: [Representation; 4] = [
        Representation::MeshColors,
        Representation::MeshColorTexture,
        Representation::PackedPtex,
        Representation::Htex,
    ];

    /// The name the view panel shows.
    pub fn name(self) -> &'static str {
        match self {
            Representation::MeshColors => "Mesh colors (software filter)",
            Representation::MeshColorTexture => "Mesh Color Textures (hardware filter)",
            Representation::Htex => "Htex (per-edge textures, hardware filter)",
            Representation::PackedPtex => "Packed Ptex (hardware filter)",
        }
    }
}

/// Everything that decides how the 3D view looks, besides the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSettings {
    /// What is drawn: the mesh colors, or for comparison the source texture or position colours.
    pub shown: Shown,
    /// How the mesh colors are drawn (paint mode always draws mesh colors at level 0).
    pub representation: Representation,
    /// Mesh-colors reconstruction filter.
    pub filter: FilterMode,
    /// Lit or unlit.
    pub shading: Shading,
    /// Wireframe and resolution heat map.
    pub overlays: Overlays,
    /// The wheel zooms towards the pointer (Blender's "zoom to mouse position"), else
    /// towards the orbit centre.
    pub zoom_to_cursor: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            shown: Shown::MeshColors,
            representation: Representation::MeshColors,
            filter: FilterMode::Trilinear,
            shading: Shading::Smooth,
            overlays: Overlays::default(),
            zoom_to_cursor: true,
        }
    }
}

impl ViewSettings {
    /// The render settings of the 3D view seen through `camera`. `level0_only`: the GPU mesh
    /// holds the paint layout (level 0 only), so the filter is limited to level 0.
    pub fn render_settings(&self, camera: OrbitCamera, level0_only: bool) -> RenderSettings {
        let mut settings = RenderSettings::new(camera);
        settings.filter = self.filter;
        if level0_only {
            settings.filter = match self.filter {
                FilterMode::Nearest | FilterMode::NearestMipLevel(_) => FilterMode::Nearest,
                FilterMode::Linear | FilterMode::MipLevel(_) | FilterMode::Trilinear | FilterMode::Anisotropic => {
                    FilterMode::Linear
                }
            };
        }
        settings.shading = self.shading;
        settings.overlays = self.overlays;
        settings
    }
}

/// The view a PSNR was measured in: render settings, 3D view size in pixels, scene generation.
pub type PsnrKey = (RenderSettings, [u32; 2], u64);

/// Every command the UI offers: shortcuts and menus map to these
/// ([`super::input::SHORTCUTS`]), and `Editor::perform` carries them out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// Show the Open dialog.
    Open,
    /// Save the project (packed file); asks for a name the first time.
    Save,
    /// Save under a new name.
    SaveAs,
    /// Show File → Export…: baked-texture glTF, tessellated glTF or packed file, each with
    /// its cost.
    Export,
    /// Export a tessellated vertex-colour .glb.
    ExportGltf,
    /// Export the packed buffers in a chosen colour format.
    ExportPacked,
    /// Frame the whole mesh.
    FrameAll,
    /// Centre on the surface point under the cursor and move halfway towards it.
    FrameUnderCursor,
    /// Look from the front (+Z).
    ViewFront,
    /// Look from the back (−Z).
    ViewBack,
    /// Look from the right (+X).
    ViewRight,
    /// Look from the left (−X).
    ViewLeft,
    /// Look from above.
    ViewTop,
    /// Look from below.
    ViewBottom,
    /// Toggle the wireframe overlay.
    ToggleWireframe,
    /// Toggle the resolution heat map.
    ToggleHeatmap,
    /// Toggle lit / unlit shading.
    ToggleShading,
    /// Cycle the filter: nearest, linear, trilinear.
    CycleFilter,
    /// Switch the representation: mesh colors → Mesh Color Textures → Htex.
    ToggleRepresentation,
    /// Show or hide the shortcut help window.
    ToggleHelp,
    /// Close the application.
    Quit,
    /// Enter or leave paint mode.
    TogglePaintMode,
    /// Undo the last stroke (paint mode).
    Undo,
    /// Redo the last undone stroke (paint mode).
    Redo,
    /// Pick the colour under the cursor into the brush (paint mode).
    Eyedropper,
    /// Set the brush radius by moving the mouse (paint mode).
    RadiusGesture,
    /// Set the brush strength by moving the mouse (paint mode).
    StrengthGesture,
}

/// The 3D view: its area as the last `Editor::ui` laid it out, the pointer over it, and
/// what the window shell and the GPU uploads record about it.
#[derive(Debug, Clone)]
pub struct ViewportState {
    /// The area in points.
    pub rect: egui::Rect,
    /// Physical pixels per point.
    pub pixels_per_point: f32,
    /// The pointer over the 3D view (points), if it is there.
    pub pointer: Option<egui::Pos2>,
    /// The egui texture showing the 3D view (registered by the window shell).
    pub texture: Option<egui::TextureId>,
    /// GPU memory of the 3D view's render targets (set by the window shell).
    pub gpu_bytes: u64,
    /// Frame timing (recorded by the window shell).
    pub frame_stats: FrameStats,
    /// Counts changes of what the GPU mesh shows (a new document, paint uploads, a repack,
    /// an alternate view): the window shell redraws the 3D view only when this, the size or
    /// the settings change.
    pub scene_generation: u64,
    /// Bytes uploaded to the GPU during the previous frame.
    pub upload_bytes_last_frame: u64,
    /// Bytes uploaded to the GPU so far this frame.
    pub upload_bytes_this_frame: u64,
    /// What changed since scene generation `from` when only colours of known faces did
    /// (paint uploads): the window shell then redraws only those faces, if the view last
    /// drew generation `from` ([`ViewportState::scene_changed`]).
    pub partial: Option<PartialChange>,
}

/// Colour changes of some faces, from scene generation `from` to `to` (the geometry, the
/// camera and everything else as at `from`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartialChange {
    /// The generation the changes start from.
    pub from: u64,
    /// The generation after the last of them.
    pub to: u64,
    /// The faces whose colours changed (sorted and unique per change; may repeat across).
    pub faces: Vec<u32>,
}

impl Default for ViewportState {
    fn default() -> Self {
        ViewportState {
            rect: egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1.0, 1.0)),
            pixels_per_point: 1.0,
            pointer: None,
            texture: None,
            gpu_bytes: 0,
            frame_stats: FrameStats::default(),
            scene_generation: 0,
            upload_bytes_last_frame: 0,
            upload_bytes_this_frame: 0,
            partial: None,
        }
    }
}

impl ViewportState {
    /// Counts a change of what the GPU mesh shows: `Some(faces)` when only those faces'
    /// colours changed (they join the pending [`PartialChange`] if it ends at the current
    /// generation), `None` for anything else (the next frame is drawn whole).
    pub fn scene_changed(&mut self, faces: Option<Vec<u32>>) {
        let from = self.scene_generation;
        self.scene_generation += 1;
        self.partial = match (self.partial.take(), faces) {
            (Some(mut pending), Some(faces)) if pending.to == from => {
                pending.faces.extend(faces);
                pending.to = self.scene_generation;
                Some(pending)
            }
            (_, Some(faces)) => Some(PartialChange { from, to: self.scene_generation, faces }),
            (_, None) => None,
        };
    }

    /// The area's size in physical pixels (at least 1×1).
    pub fn size_px(&self) -> [u32; 2] {
        let w = (self.rect.width() * self.pixels_per_point).round().max(1.0) as u32;
        let h = (self.rect.height() * self.pixels_per_point).round().max(1.0) as u32;
        [w, h]
    }

    /// The area's top-left corner in physical pixels.
    pub fn min_px(&self) -> [i32; 2] {
        [
            (self.rect.min.x * self.pixels_per_point).round() as i32,
            (self.rect.min.y * self.pixels_per_point).round() as i32,
        ]
    }

    /// Pixel coordinates in the 3D view of `pos` (points, window coordinates).
    pub fn view_px(&self, pos: egui::Pos2) -> [f64; 2] {
        let ppp = f64::from(self.pixels_per_point);
        [f64::from(pos.x - self.rect.min.x) * ppp, f64::from(pos.y - self.rect.min.y) * ppp]
    }
}

/// Frame timing for the scene panel.
#[derive(Debug, Clone, Default)]
pub struct FrameStats {
    /// Frames drawn in the current one-second window.
    frames: u32,
    window_start: Option<Instant>,
    /// Frames per second over the last full second of redrawing.
    pub fps: f32,
    /// CPU time of the last frame (UI, 3D and egui recording, submit), milliseconds.
    pub frame_ms: f32,
}

impl FrameStats {
    /// Records one drawn frame that took `cpu_time`.
    pub fn record(&mut self, cpu_time: Duration) {
        let now = Instant::now();
        self.frame_ms = cpu_time.as_secs_f32() * 1000.0;
        let start = *self.window_start.get_or_insert(now);
        self.frames += 1;
        let elapsed = now.duration_since(start).as_secs_f32();
        if elapsed >= 1.0 {
            self.fps = self.frames as f32 / elapsed;
            self.frames = 0;
            self.window_start = Some(now);
        }
    }
}
