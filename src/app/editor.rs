//! The editor's state and its per-frame UI: everything between the window shell
//! ([`super::window`]) and the library.
//!
//! The editor holds the open document (the [`meshpaint_core::io::document::Document`] with its colour
//! store side by side with its [`meshpaint_render::GpuMesh`]), the camera, the view settings,
//! the mode, the job runner and the status line. [`Editor::ui`] draws one frame of panels
//! and the 3D view's area; input is handled in one place, [`super::input`]. It needs no
//! window, so `tests/app_ui.rs` drives it with egui_kittest.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use glam::DVec3;

use meshpaint_core::camera::{DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, OrbitCamera};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_render::{DrawItem, FilterMode, RenderSettings};

use meshpaint_core::io::document::Source;
use meshpaint_render::Gpu;

use super::autosave::{AutosaveState, Autosaved};
use super::document::{self, AlternateView, OpenDocument, Written};
use super::file_dialog::{DialogOutcome, DialogPurpose, FileDialog};
use super::import_settings::ImportSettings;
use super::jobs::{Finished, JobKind, Jobs, Waker, WriteKind};
use super::paint_session::{PaintSession, Repacked};
use super::state::{FrameStats, Mode, Severity, Shown, Status, ViewSettings, ViewportInfo};
use super::text::{error_text, thousands};

/// What a job produced.
#[derive(Debug)]
pub enum JobOutput {
    /// A document was opened.
    Loaded(Box<OpenDocument>),
    /// A file was written.
    Written(Written, WriteKind),
    /// The store was repacked after paint mode.
    Repacked(Box<Repacked>),
    /// A recovery file was written.
    Autosaved(Autosaved),
    /// Optimize found its changes (applied if the document did not change meanwhile).
    Optimized(Box<Optimized>),
    /// An alternate view was built for the document opened from this path (`None`: built-in).
    View(Option<PathBuf>, Box<AlternateView>),
}

/// The view a PSNR was measured in: render settings, 3D view size in pixels, scene generation.
pub type PsnrKey = (RenderSettings, [u32; 2], u64);

/// What an Optimize job found.
#[derive(Debug)]
pub struct Optimized {
    /// The changes, planned on the store as it was at `generation`.
    pub plan: meshpaint_core::paint::optimize::OptimizePlan,
    /// [`Editor::edit_generation`] when the job started.
    pub generation: u64,
    /// The error bound used.
    pub bound: f32,
}

/// The editor.
pub struct Editor {
    /// GPU objects shared with jobs (`None` in UI tests without a GPU).
    pub gpu: Option<Arc<Gpu>>,
    /// The open document, if any.
    pub document: Option<OpenDocument>,
    /// The camera of the 3D view.
    pub camera: OrbitCamera,
    /// Filter, shading, overlays.
    pub view: ViewSettings,
    /// The interaction mode.
    pub mode: Mode,
    /// The status line.
    pub status: Status,
    /// Background work.
    pub jobs: Jobs<JobOutput>,
    /// The open file dialog, if any.
    pub dialog: Option<FileDialog>,
    /// Whether the shortcut help window is shown.
    pub show_help: bool,
    /// How meshes opened next get their face resolutions (the open dialog's choice).
    pub import: ImportSettings,
    /// The 3D view's area (set by [`Editor::ui`]).
    pub viewport: ViewportInfo,
    /// The egui texture showing the 3D view (registered by the window shell).
    pub viewport_texture: Option<egui::TextureId>,
    /// GPU memory of the 3D view's render targets (set by the window shell).
    pub viewport_gpu_bytes: u64,
    /// Frame timing (recorded by the window shell).
    pub frame_stats: FrameStats,
    /// Counts changes of what the GPU mesh shows (a new document; later, paint uploads):
    /// the window shell redraws the 3D view only when this, the size or the settings change.
    pub scene_generation: u64,
    /// The pointer over the 3D view (points), if it is there.
    pub viewport_pointer: Option<egui::Pos2>,
    /// Set when the user asked to quit.
    pub quit_requested: bool,
    /// The brush settings (kept between paint sessions).
    pub brush: meshpaint_core::paint::brush::BrushSettings,
    /// Paint mode's state while it is on.
    pub paint: Option<PaintSession>,
    /// Undo / redo of paint mode, one step per stroke (cleared when another document opens).
    pub history: meshpaint_core::paint::undo::UndoHistory,
    /// The GPU mesh holds the paint layout (level 0 only): the filter is limited to level 0.
    pub gpu_paint_layout: bool,
    /// Bytes uploaded to the GPU during the previous frame.
    pub upload_bytes_last_frame: u64,
    /// Bytes uploaded to the GPU so far this frame.
    pub upload_bytes_this_frame: u64,
    /// Counts edits of the colours (autosave compares it).
    pub edit_generation: u64,
    /// The resolution of "Set R for all".
    pub resolution_for_all: Resolution,
    /// The error bound of "Optimize" (0 = lossless; colour units, 0..1).
    pub optimize_bound: f32,
    /// The last PSNR of the mesh colors against the source texture, with the view it was
    /// measured in (render settings, view size, scene generation).
    pub source_psnr: Option<(PsnrKey, Result<f64, String>)>,
    /// A memory budget that replaces the machine's (tests set a small one; `None`:
    /// [`meshpaint_core::colors::budget::Budget::from_environment`]).
    pub budget_override: Option<meshpaint_core::colors::budget::Budget>,
    /// Autosave settings and state.
    pub autosave: AutosaveState,
    /// A load error to report once the built-in scene has replaced a failed start-up file.
    fallback_error: Option<String>,
    /// Where file dialogs start.
    last_directory: PathBuf,
}

impl std::fmt::Debug for Editor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Editor")
            .field("document", &self.document.as_ref().map(|d| &d.title))
            .field("mode", &self.mode)
            .field("status", &self.status)
            .field("jobs", &self.jobs)
            .finish_non_exhaustive()
    }
}

impl Editor {
    /// An editor with no document. `waker` is called from worker threads to request a
    /// repaint (progress, completion).
    pub fn new(gpu: Option<Arc<Gpu>>, waker: Waker) -> Self {
        let sphere = meshpaint_core::camera::BoundingSphere { center: [0.0; 3], radius: 1.0 };
        Editor {
            gpu,
            document: None,
            camera: OrbitCamera::framing(sphere, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES),
            view: ViewSettings::default(),
            mode: Mode::default(),
            status: Status { text: "Welcome to meshpaint. F1 lists the shortcuts.".into(), severity: Severity::Info },
            jobs: Jobs::new(waker),
            dialog: None,
            show_help: false,
            import: ImportSettings::default(),
            viewport: ViewportInfo {
                rect: egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1.0, 1.0)),
                pixels_per_point: 1.0,
            },
            viewport_texture: None,
            viewport_gpu_bytes: 0,
            frame_stats: FrameStats::default(),
            scene_generation: 0,
            viewport_pointer: None,
            quit_requested: false,
            brush: meshpaint_core::paint::brush::BrushSettings::default(),
            paint: None,
            history: meshpaint_core::paint::undo::UndoHistory::new(meshpaint_core::paint::undo::DEFAULT_CAP_BYTES),
            gpu_paint_layout: false,
            upload_bytes_last_frame: 0,
            upload_bytes_this_frame: 0,
            edit_generation: 0,
            resolution_for_all: Resolution::from_log2(3).unwrap_or(Resolution::ONE),
            optimize_bound: 0.0,
            source_psnr: None,
            budget_override: None,
            autosave: AutosaveState::default(),
            fallback_error: None,
            last_directory: std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
        }
    }

    /// Sets the status line.
    pub fn set_status(&mut self, severity: Severity, text: impl Into<String>) {
        let text = text.into();
        match severity {
            Severity::Info => log::info!("{text}"),
            Severity::Warning => log::warn!("{text}"),
            Severity::Error => log::error!("{text}"),
        }
        self.status = Status { text, severity };
    }

    /// The render settings of the 3D view.
    pub fn render_settings(&self) -> RenderSettings {
        let mut settings = RenderSettings::new(self.camera);
        settings.filter = self.view.filter;
        if self.gpu_paint_layout || self.mode == Mode::Paint {
            // The paint layout holds level 0 only.
            settings.filter = match self.view.filter {
                FilterMode::Nearest | FilterMode::NearestMipLevel(_) => FilterMode::Nearest,
                FilterMode::Linear | FilterMode::MipLevel(_) | FilterMode::Trilinear => FilterMode::Linear,
            };
        }
        settings.shading = self.view.shading;
        settings.overlays = self.view.overlays;
        settings
    }

    /// Opens `source` on a worker thread; the current document stays until the new one
    /// is ready, and stays for good if opening fails.
    pub fn open(&mut self, source: Source) {
        let rule = self.import.rule();
        let budget = self.budget();
        let gpu = self.gpu.clone();
        let name = source.name();
        if let Source::File(path) = &source
            && let Some(parent) = path.parent().filter(|p| p.is_dir())
        {
            self.last_directory = parent.to_owned();
        }
        let label = format!("Opening {name}");
        let kind = JobKind::Open { built_in: source == Source::BuiltIn };
        let started = self.jobs.start(kind, label.clone(), move |job| {
            document::load(&source, rule, &budget, gpu.as_deref(), job)
                .map(|document| JobOutput::Loaded(Box::new(document)))
                .map_err(|error| error_text(&error))
        });
        match started {
            Ok(()) => self.set_status(Severity::Info, format!("{label}…")),
            Err(message) => self.set_status(Severity::Error, message),
        }
    }

    /// The budget every R-changing operation checks first: this machine's, with the GPU's
    /// limits when there is a GPU.
    pub fn budget(&self) -> meshpaint_core::colors::budget::Budget {
        let budget = self.budget_override.unwrap_or_else(meshpaint_core::colors::budget::Budget::from_environment);
        match &self.gpu {
            Some(gpu) => budget.with_gpu(gpu.budget_limits()),
            None => budget,
        }
    }

    /// Saves the project to `path` as a packed file in `format`.
    pub fn save_to(&mut self, path: PathBuf, format: ColorFormat) {
        self.write(path, format, WriteKind::Save);
    }

    /// Starts a write job (save or export).
    fn write(&mut self, path: PathBuf, format: ColorFormat, kind: WriteKind) {
        let Some(open) = &self.document else {
            self.set_status(Severity::Error, "Nothing to save: no document is open.");
            return;
        };
        let document = Arc::clone(&open.document);
        if let Some(parent) = path.parent().filter(|p| p.is_dir()) {
            self.last_directory = parent.to_owned();
        }
        let label = match kind {
            WriteKind::Save => format!("Saving {}", path.display()),
            WriteKind::ExportPacked => format!("Exporting packed buffers to {}", path.display()),
            WriteKind::ExportGltf => format!("Exporting glTF to {}", path.display()),
        };
        let started = self.jobs.start(JobKind::Write(kind), label.clone(), move |job| {
            let written = match kind {
                WriteKind::Save | WriteKind::ExportPacked => document::write_packed(&document, format, &path, job),
                WriteKind::ExportGltf => document::write_gltf(&document, &path, job),
            };
            written.map(|written| JobOutput::Written(written, kind)).map_err(|error| error_text(&error))
        });
        match started {
            Ok(()) => self.set_status(Severity::Info, format!("{label}…")),
            Err(message) => self.set_status(Severity::Error, message),
        }
    }

    /// Applies a finished job, if any (called every frame).
    pub fn poll_jobs(&mut self) {
        if let Some((kind, finished)) = self.jobs.poll() {
            self.finish_job(kind, finished);
        }
    }

    /// Waits up to `timeout` for the running job and applies it (tests, scripted runs).
    pub fn wait_for_job(&mut self, timeout: Duration) -> bool {
        match self.jobs.wait(timeout) {
            Some((kind, finished)) => {
                self.finish_job(kind, finished);
                true
            }
            None => !self.jobs.is_busy(),
        }
    }

    fn finish_job(&mut self, kind: JobKind, finished: Finished<JobOutput>) {
        match finished {
            Finished::Done { value: JobOutput::Loaded(document), elapsed } => {
                let mut document = *document;
                let mut text = format!(
                    "Opened {}: {} triangles, {} samples ({:.2} s)",
                    document.title,
                    thousands(u64::from(document.triangles())),
                    thousands(document.samples),
                    elapsed.as_secs_f64()
                );
                let notes = &document.document.warnings;
                match notes.as_slice() {
                    [] => {}
                    [note] => text.push_str(&format!("; note: {note}")),
                    [first, ..] => text.push_str(&format!("; {} notes, first: {first}", notes.len())),
                }
                for note in notes {
                    log::info!("{}: {note}", document.title);
                }
                self.camera = OrbitCamera::framing(document.bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES);
                // A new document: paint mode, its GPU layout and the undo history end.
                self.paint = None;
                self.mode = Mode::View;
                self.gpu_paint_layout = false;
                self.history.clear();
                self.history.set_budget(Some((self.budget(), document.format)));
                // Untextured documents start at the lowest R where nothing is painted, and
                // resolution follows the brush there; textured ones keep the chosen R.
                self.brush.follow_resolution =
                    (!document.document.textured).then_some(meshpaint_core::paint::brush::FOLLOW_BRUSH_MAX_RESOLUTION);
                self.autosave.document_opened(&mut document, self.edit_generation);
                self.document = Some(document);
                self.scene_generation += 1;
                self.frame_all();
                match self.fallback_error.take() {
                    Some(error) => {
                        self.set_status(Severity::Error, format!("{error} — showing the built-in Duck instead"))
                    }
                    None => self.set_status(Severity::Info, text),
                }
            }
            Finished::Done { value: JobOutput::Written(written, kind), elapsed } => {
                if let (Some(repack), Some(open)) = (written.repack, self.document.as_mut()) {
                    open.last_repack = repack;
                }
                if kind == WriteKind::Save
                    && let Some(open) = self.document.as_mut()
                {
                    // Save now writes here, in this format.
                    open.project_path = Some(written.path.clone());
                    open.title = written
                        .path
                        .file_name()
                        .map_or_else(|| written.path.display().to_string(), |n| n.to_string_lossy().into_owned());
                    if let Some(format) = written.format {
                        open.format = format;
                    }
                }
                if kind == WriteKind::Save {
                    self.autosave.saved(self.document.as_ref(), self.edit_generation);
                }
                let verb = match kind {
                    WriteKind::Save => "Saved",
                    WriteKind::ExportPacked | WriteKind::ExportGltf => "Exported",
                };
                self.set_status(
                    Severity::Info,
                    format!("{verb} {}: {} ({:.2} s)", written.path.display(), written.summary, elapsed.as_secs_f64()),
                );
            }
            Finished::Done { value: JobOutput::Repacked(repacked), elapsed } => self.finish_repack(*repacked, elapsed),
            Finished::Done { value: JobOutput::Autosaved(autosaved), .. } => self.autosave.finished(&autosaved),
            Finished::Done { value: JobOutput::Optimized(done), elapsed } => self.finish_optimize(*done, elapsed),
            Finished::Done { value: JobOutput::View(path, view), .. } => self.finish_view(path, *view),
            Finished::Failed(message) if kind == JobKind::Autosave => {
                self.autosave.failed();
                self.set_status(Severity::Warning, format!("Autosave failed: {message}"));
            }
            Finished::Failed(message) => {
                if kind == JobKind::Repack {
                    self.gpu_paint_layout = true;
                }
                let is_open = matches!(kind, JobKind::Open { .. });
                if kind == (JobKind::Open { built_in: false }) && self.document.is_none() {
                    // Nothing was open (a bad file on the command line): show the Duck.
                    self.fallback_error = Some(format!("Could not open: {message}"));
                    self.set_status(Severity::Error, format!("Could not open: {message}"));
                    self.open(Source::BuiltIn);
                    return;
                }
                let kept = match &self.document {
                    Some(open) => format!(" (still showing {})", open.title),
                    None => String::new(),
                };
                let what = if is_open { "Could not open" } else { "Failed" };
                self.set_status(Severity::Error, format!("{what}: {message}{kept}"));
            }
        }
    }

    /// Keeps a built alternate view if the document is still the one it was built for.
    fn finish_view(&mut self, path: Option<PathBuf>, view: AlternateView) {
        let Some(open) = self.document.as_mut().filter(|open| open.path == path) else {
            return;
        };
        let failed = match view {
            AlternateView::SourceTexture(built) => {
                let failed = built.as_ref().as_ref().err().cloned();
                open.alternates.source_texture = Some(*built);
                failed
            }
            AlternateView::PositionColors(built) => {
                let failed = built.as_ref().as_ref().err().cloned();
                open.alternates.position_colors = Some(*built);
                failed
            }
        };
        if let Some(message) = failed {
            self.set_status(Severity::Warning, format!("Cannot show it: {message}"));
        }
        self.scene_generation += 1;
    }

    /// Applies a finished repack (if the document is still the one packed).
    pub(crate) fn finish_repack(&mut self, repacked: Repacked, elapsed: Duration) {
        let Some(open) = self.document.as_mut() else {
            return;
        };
        if !Arc::ptr_eq(&open.document, &repacked.document) || self.mode == Mode::Paint {
            log::info!("a repack finished for a document that changed since; ignored");
            return;
        }
        if let Some(mesh) = repacked.gpu_mesh {
            open.gpu_mesh = Some(mesh);
        }
        open.samples_with_mips = repacked.samples_with_mips;
        open.packed_bytes = repacked.packed_bytes;
        open.samples = open.document.store.sample_count();
        open.last_repack = repacked.pack_time;
        open.pack_cache = Some(repacked.cache);
        self.gpu_paint_layout = false;
        self.scene_generation += 1;
        self.set_status(
            Severity::Info,
            format!(
                "Repacked{}: {} samples with MIP chains in {:.1} ms ({:.2} s with the upload)",
                repacked.how.note(),
                thousands(repacked.samples_with_mips),
                repacked.pack_time.as_secs_f64() * 1000.0,
                elapsed.as_secs_f64()
            ),
        );
    }

    /// Shows the file dialog for `purpose` (refused while a job runs).
    pub fn open_dialog(&mut self, purpose: DialogPurpose) {
        if self.jobs.is_busy() && purpose != DialogPurpose::Open {
            self.set_status(Severity::Warning, "Busy: wait for the running job to finish.");
            return;
        }
        if purpose != DialogPurpose::Open && self.document.is_none() {
            self.set_status(Severity::Error, "Nothing to save or export: no document is open.");
            return;
        }
        let stem = self
            .document
            .as_ref()
            .and_then(|d| d.path.as_deref().and_then(Path::file_stem).map(|s| s.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "duck".to_owned());
        let file_name = match purpose {
            DialogPurpose::Open => String::new(),
            DialogPurpose::SaveAs | DialogPurpose::ExportPacked => format!("{stem}.mpk"),
            DialogPurpose::ExportGltf => format!("{stem}_meshcolors.glb"),
        };
        let format = self.document.as_ref().map_or_else(ColorFormat::default, |d| d.format);
        let mut dialog = FileDialog::new(purpose, self.last_directory.clone(), file_name, format);
        if purpose == DialogPurpose::Open {
            dialog.import = Some(self.import);
        }
        self.dialog = Some(dialog);
    }

    /// Handles the dialog's decision.
    pub(crate) fn dialog_ui(&mut self, ctx: &egui::Context) {
        let Some(dialog) = self.dialog.as_mut() else {
            return;
        };
        let purpose = dialog.purpose;
        let outcome = dialog.file_dialog_ui(ctx);
        if let Some(import) = dialog.import {
            self.import = import;
        }
        match outcome {
            DialogOutcome::Pending => {}
            DialogOutcome::Cancelled => self.dialog = None,
            DialogOutcome::Chosen(path, format) => {
                self.dialog = None;
                match purpose {
                    DialogPurpose::Open => self.open(Source::File(path)),
                    DialogPurpose::SaveAs => self.write(path, format, WriteKind::Save),
                    DialogPurpose::ExportPacked => self.write(path, format, WriteKind::ExportPacked),
                    DialogPurpose::ExportGltf => self.write(path, format, WriteKind::ExportGltf),
                }
            }
        }
    }

    /// Frames the whole mesh, keeping the viewing angles; the sphere fits the narrower of
    /// the two fields of view.
    pub fn frame_all(&mut self) {
        let Some(open) = &self.document else {
            return;
        };
        let (yaw, pitch) = (self.camera.yaw_degrees, self.camera.pitch_degrees);
        let mut camera = OrbitCamera::framing(open.bounds, yaw, pitch);
        let [w, h] = self.viewport.size_px();
        let aspect = f64::from(w) / f64::from(h.max(1));
        if aspect < 1.0 {
            let half_y = (camera.fov_y_degrees.to_radians() * 0.5).tan();
            let half_x = (half_y * aspect).atan();
            camera.distance = open.bounds.radius / half_x.sin() * 1.1;
        }
        self.camera = camera;
    }

    /// Looks at the mesh from `yaw`/`pitch`, framing it.
    pub fn set_view_angles(&mut self, yaw: f64, pitch: f64) {
        self.camera.yaw_degrees = yaw;
        self.camera.pitch_degrees = pitch;
        self.frame_all();
    }

    /// Centres the view on the surface point under `pos` (points, window coordinates) and
    /// halves the distance to it. Reports a miss on the status line.
    pub fn frame_under(&mut self, pos: egui::Pos2) {
        let Some(hit) = self.pick(pos) else {
            self.set_status(Severity::Info, "Nothing under the cursor to frame.");
            return;
        };
        let distance = (self.camera.eye() - hit).length() * 0.5;
        self.camera.look_at_point(hit, distance);
        if let Some(open) = &self.document {
            self.camera.fit_depth_to(open.bounds);
        }
    }

    /// The surface point under `pos` (points, window coordinates), if the ray hits the mesh.
    pub fn pick(&self, pos: egui::Pos2) -> Option<DVec3> {
        let open = self.document.as_ref()?;
        let rect = self.viewport.rect;
        if !rect.contains(pos) {
            return None;
        }
        let ppp = f64::from(self.viewport.pixels_per_point);
        let [w, h] = self.viewport.size_px();
        let x = f64::from(pos.x - rect.min.x) * ppp;
        let y = f64::from(pos.y - rect.min.y) * ppp;
        let (origin, direction) = self.camera.ray_through_pixel(x, y, w, h);
        let hit = open.bvh.cast(origin, direction, f64::INFINITY)?;
        Some(DVec3::from_array(hit.position_world))
    }

    /// Starts the job that builds what [`ViewSettings::shown`] needs, when it is missing and
    /// no other job runs (called by the view panel each frame it is shown).
    pub fn ensure_shown_view(&mut self) {
        let shown = self.view.shown;
        let (Some(open), Some(gpu)) = (&self.document, &self.gpu) else {
            return;
        };
        let missing = match shown {
            Shown::MeshColors => false,
            Shown::SourceTexture => open.alternates.source_texture.is_none(),
            Shown::PositionColors => open.alternates.position_colors.is_none(),
        };
        if !missing || self.jobs.is_busy() {
            return;
        }
        let source = open.path.clone().map_or(Source::BuiltIn, Source::File);
        let path = open.path.clone();
        let document = Arc::clone(&open.document);
        let (gpu, budget) = (Arc::clone(gpu), self.budget());
        let started = self.jobs.start(JobKind::View, format!("Preparing {}", shown.name()), move |job| {
            let view = document::build_alternate(shown, &source, &document, &budget, &gpu, job)
                .ok_or_else(|| "nothing to build".to_owned())?;
            Ok(JobOutput::View(path, Box::new(view)))
        });
        if let Err(message) = started {
            self.set_status(Severity::Error, message);
        }
    }

    /// What the 3D view draws: the alternate view chosen in [`ViewSettings::shown`] once it is
    /// built, else the mesh colors.
    pub fn shown_item(&self) -> Option<DrawItem<'_>> {
        let open = self.document.as_ref()?;
        let alternate = match self.view.shown {
            Shown::MeshColors => None,
            Shown::SourceTexture => match &open.alternates.source_texture {
                Some(Ok(mesh)) => Some(DrawItem::Baseline(mesh)),
                _ => None,
            },
            Shown::PositionColors => match &open.alternates.position_colors {
                Some(Ok(mesh)) => Some(DrawItem::MeshColors(mesh)),
                _ => None,
            },
        };
        alternate.or_else(|| open.gpu_mesh.as_ref().map(DrawItem::MeshColors))
    }

    /// PSNR (dB, RGB of covered pixels) of the mesh colors against the source texture as the
    /// 3D view shows them now, rendered offscreen at the view's aspect (at most 512 px on
    /// the long side). `None` until the source texture is built.
    pub fn measure_source_psnr(&self) -> Option<Result<f64, String>> {
        let open = self.document.as_ref()?;
        let (Some(gpu), Some(mesh), Some(Ok(baseline))) =
            (&self.gpu, open.gpu_mesh.as_ref(), open.alternates.source_texture.as_ref())
        else {
            return None;
        };
        let [w, h] = self.viewport.size_px();
        let scale = (512.0 / f64::from(w.max(h).max(1))).min(1.0);
        let (w, h) = (((f64::from(w) * scale) as u32).max(16), ((f64::from(h) * scale) as u32).max(16));
        let settings = self.render_settings();
        let render = |item| gpu.render_image(item, &settings, w, h).map_err(|error| error.to_string());
        Some(render(DrawItem::MeshColors(mesh)).and_then(|ours| {
            render(DrawItem::Baseline(baseline)).map(|theirs| meshpaint_core::colors::psnr::psnr(&ours, &theirs))
        }))
    }

    /// GPU memory in use: the mesh's buffers and atlas plus the view's render targets.
    pub fn gpu_bytes(&self) -> u64 {
        let mesh = self.document.as_ref().and_then(|d| d.gpu_mesh.as_ref()).map_or(0, |m| m.gpu_bytes());
        mesh + self.viewport_gpu_bytes
    }

    /// The window title.
    pub fn window_title(&self) -> String {
        match &self.document {
            Some(open) => format!("{} — meshpaint", open.title),
            None => "meshpaint".to_owned(),
        }
    }
}
