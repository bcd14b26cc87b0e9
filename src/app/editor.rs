//! The editor: everything between the window shell ([`super::window`]) and the library.
//!
//! [`Editor`] keeps the document ([`DocumentState`]: the open
//! [`meshpaint_core::io::document::Document`] with its colour store side by side with its
//! [`meshpaint_render::GpuMesh`], paint mode, the undo history), the camera, the panels
//! ([`Panels`]), the 3D view's state, the status line and the job runner. [`Editor::ui`]
//! draws one frame: the panels draw themselves and return [`Command`]s, input returns
//! [`Action`]s and commands, and [`Editor::apply`] carries every one out here. It needs no
//! window, so `tests/editor/app_ui.rs` drives it with egui_kittest.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use meshpaint_core::camera::{BoundingSphere, DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, OrbitCamera};
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::io::autosave;
use meshpaint_core::io::document::Source;
use meshpaint_render::{DrawItem, FilterMode, Gpu, RenderSettings, Shading};

use super::autosave::{AutosaveTick, Autosaved, Restoring};
use super::command::Command;
use super::document::{self, AlternateView};
use super::file_dialog::DialogPurpose;
use super::input;
use super::job_output::JobOutput;
use super::jobs::{Finished, JobKind, Jobs, Waker, WriteKind};
use super::paint::{PaintContext, draw_brush_cursor};
use super::paint_session::GestureKind;
use super::panels::{
    ExportContext, LastStroke, PaintPanelContext, Panels, SIDE_PANEL_WIDTH, SceneContext, ViewContext, ViewportContext,
};
use super::session::{DocumentState, opened_text};
use super::settings::SettingsFile;
use super::state::{Action, Mode, Representation, Severity, Shown, Status, ViewportState};
use super::text::error_text;
use super::unsaved::{Pending, UnsavedChoice};

/// The editor.
pub struct Editor {
    /// GPU objects shared with jobs (`None` in UI tests without a GPU).
    pub gpu: Option<Arc<Gpu>>,
    /// The open document, paint mode and the undo history.
    pub document: DocumentState,
    /// The camera of the 3D view.
    pub camera: OrbitCamera,
    /// Every panel, each with its own state (view settings, brush, file dialog, autosave …).
    pub panels: Panels,
    /// The 3D view's area, pointer, texture, frame timing and change counter.
    pub viewport: ViewportState,
    /// The status line.
    pub status: Status,
    /// Background work.
    pub jobs: Jobs<JobOutput>,
    /// Set when the user asked to quit (and answered the unsaved-changes prompt).
    pub quit_requested: bool,
    /// What carries on once the running save succeeds ([`super::unsaved`]).
    pub(crate) after_save: Option<Pending>,
    /// A memory budget that replaces the machine's (tests set a small one; `None`:
    /// [`Budget::from_environment`]).
    pub budget_override: Option<Budget>,
    /// A load error to report once the built-in scene has replaced a failed start-up file.
    pub(crate) fallback_error: Option<String>,
    /// The settings file (read and written by [`super::editor_settings`]).
    pub settings_file: SettingsFile,
}

impl std::fmt::Debug for Editor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Editor")
            .field("document", &self.document.open.as_ref().map(|d| &d.title))
            .field("mode", &self.mode())
            .field("status", &self.status)
            .field("jobs", &self.jobs)
            .finish_non_exhaustive()
    }
}

impl Editor {
    /// An editor with no document. `waker` is called from worker threads to request a
    /// repaint (progress, completion).
    pub fn new(gpu: Option<Arc<Gpu>>, waker: Waker) -> Self {
        let sphere = BoundingSphere { center: [0.0; 3], radius: 1.0 };
        Editor {
            gpu,
            document: DocumentState::default(),
            camera: OrbitCamera::framing(sphere, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES),
            panels: Panels::default(),
            viewport: ViewportState::default(),
            status: Status { text: "Welcome to meshpaint. F1 lists the shortcuts.".into(), severity: Severity::Info },
            jobs: Jobs::new(waker),
            quit_requested: false,
            after_save: None,
            budget_override: None,
            fallback_error: None,
            settings_file: SettingsFile::default(),
        }
    }

    /// Sets the status line.
    pub fn set_status(&mut self, severity: Severity, text: impl Into<String>) {
        self.status.set(severity, text);
    }

    /// The interaction mode (paint while paint mode's session is on).
    pub fn mode(&self) -> Mode {
        self.document.mode()
    }

    /// The render settings of the 3D view.
    pub fn render_settings(&self) -> RenderSettings {
        self.panels.view.settings.render_settings(self.camera, self.document.level0_only())
    }

    /// The budget every R-changing operation checks first: this machine's, with the GPU's
    /// limits when there is a GPU.
    pub fn budget(&self) -> Budget {
        let budget = self.budget_override.unwrap_or_else(Budget::from_environment);
        match &self.gpu {
            Some(gpu) => budget.with_gpu(gpu.budget_limits()),
            None => budget,
        }
    }

    /// Opens `source` on a worker thread; the current document stays until the new one
    /// is ready, and stays for good if opening fails.
    pub fn open(&mut self, source: Source) {
        let rule = self.panels.import.rule();
        let budget = self.budget();
        let gpu = self.gpu.clone();
        let name = source.name();
        if let Source::File(path) = &source {
            self.panels.file.remember_directory_of(path);
        }
        let label = format!("Opening {name}");
        let kind = JobKind::Open { built_in: source == Source::BuiltIn };
        let started = self.jobs.start(kind, label.clone(), move |job| {
            document::load(&source, rule, &budget, gpu.as_deref(), job)
                .map(|document| JobOutput::Loaded(Box::new(document)))
                .map_err(|error| error_text(&error))
        });
        self.report_start(started, &label);
    }

    /// Says on the status line that the job `label` started, or why it could not.
    pub(crate) fn report_start(&mut self, started: Result<(), String>, label: &str) {
        match started {
            Ok(()) => self.set_status(Severity::Info, format!("{label}…")),
            Err(message) => self.set_status(Severity::Error, message),
        }
    }

    /// Saves the project to `path` as a packed file in `format`.
    pub fn save_to(&mut self, path: PathBuf, format: ColorFormat) {
        self.write(path, format, WriteKind::Save);
    }

    /// Starts a write job (save or export).
    fn write(&mut self, path: PathBuf, format: ColorFormat, kind: WriteKind) {
        let Some(open) = &self.document.open else {
            self.set_status(Severity::Error, "Nothing to save: no document is open.");
            return;
        };
        let document = Arc::clone(&open.document);
        self.panels.file.remember_directory_of(&path);
        if kind == WriteKind::Save {
            self.document.saving_generation = Some(self.document.edit_generation);
        }
        let label = match kind {
            WriteKind::Save => format!("Saving {}", path.display()),
            WriteKind::ExportPacked => format!("Exporting packed buffers to {}", path.display()),
            // A bake is File → Export…'s (`Command::Export`); the file dialog writes the tessellated glTF.
            WriteKind::ExportGltf | WriteKind::ExportBaked => format!("Exporting glTF to {}", path.display()),
        };
        let started = self.jobs.start(JobKind::Write(kind), label.clone(), move |job| {
            let written = match kind {
                WriteKind::Save | WriteKind::ExportPacked => document::write_packed(&document, format, &path, job),
                WriteKind::ExportGltf | WriteKind::ExportBaked => document::write_gltf(&document, &path, job),
            };
            written.map(|written| JobOutput::Written(written, kind)).map_err(|error| error_text(&error))
        });
        self.report_start(started, &label);
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
        let Finished::Done { value, elapsed } = finished else {
            match finished {
                Finished::Failed(message) => self.finish_failed(kind, message),
                Finished::Cancelled => self.finish_cancelled(kind),
                Finished::Done { .. } => {}
            }
            return;
        };
        match value {
            JobOutput::Loaded(document) => self.finish_loaded(*document, elapsed),
            JobOutput::Written(written, kind) => {
                self.document.written(&written, kind);
                if kind == WriteKind::Save {
                    let generation = self.document.saving_generation.take().unwrap_or(self.document.edit_generation);
                    self.document.saved_generation = generation;
                    self.panels.autosave.state.saved(self.document.open.as_ref(), generation);
                }
                let verb = if kind == WriteKind::Save { "Saved" } else { "Exported" };
                self.set_status(
                    Severity::Info,
                    format!("{verb} {}: {} ({:.2} s)", written.path.display(), written.summary, elapsed.as_secs_f64()),
                );
                if kind == WriteKind::Save {
                    self.after_save_finished(true);
                }
            }
            JobOutput::Repacked(repacked) => {
                self.document.finish_repack(*repacked, elapsed, &mut self.viewport, &mut self.status);
            }
            JobOutput::Autosaved(autosaved) => self.panels.autosave.state.finished(&autosaved),
            JobOutput::UvsChecked(size, choice) => self.panels.export.uv_check = Some((size, choice)),
            JobOutput::Optimized(done) => {
                let (document, mut ctx) = self.paint_parts();
                document.finish_optimize(&mut ctx, *done, elapsed);
            }
            JobOutput::View(path, view) => {
                self.document.finish_view(path, *view, &mut self.viewport, &mut self.status);
            }
        }
    }

    /// A document was opened: it replaces the open one, framed, with the brush and autosave
    /// set up for it.
    fn finish_loaded(&mut self, mut document: document::OpenDocument, elapsed: Duration) {
        let text = opened_text(&document, elapsed);
        self.camera = OrbitCamera::framing(document.bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES);
        self.camera.up = self.panels.import.up_axis;
        let history_budget = (self.budget(), document.format);
        // Untextured meshes start at the lowest R where nothing is painted, and resolution
        // follows the brush there; textured ones keep the chosen R, and a project (packed
        // file) keeps the resolutions it was saved with.
        let project = matches!(document.document.source, meshpaint_core::io::document::SourceKind::Packed(_));
        self.panels.paint.brush.follow_resolution = (!document.document.textured && !project)
            .then_some(meshpaint_core::paint::brush::FOLLOW_BRUSH_MAX_RESOLUTION);
        // A restored recovery file holds colours no file holds yet: unsaved until saved.
        let restored = self.panels.autosave.state.restoring.is_some();
        self.panels.autosave.state.document_opened(&mut document, self.document.edit_generation);
        self.document.replace(document, history_budget);
        self.document.saved_generation = if restored { u64::MAX } else { self.document.edit_generation };
        self.viewport.scene_generation += 1;
        self.frame_all();
        match self.fallback_error.take() {
            Some(error) => self.set_status(Severity::Error, format!("{error} — showing the built-in Duck instead")),
            None => match self.settings_file.problem.take() {
                Some(problem) => self.set_status(Severity::Warning, format!("{text}. {problem}")),
                None => self.set_status(Severity::Info, text),
            },
        }
    }

    /// Shows the file dialog for `purpose` (refused while a job runs).
    pub fn open_dialog(&mut self, purpose: DialogPurpose) {
        if self.jobs.is_busy() && purpose != DialogPurpose::Open {
            self.set_status(Severity::Warning, "Busy: wait for the running job to finish.");
            return;
        }
        if purpose != DialogPurpose::Open && self.document.open.is_none() {
            self.set_status(Severity::Error, "Nothing to save or export: no document is open.");
            return;
        }
        self.panels.file.open_dialog(purpose, self.document.open.as_ref(), self.panels.import);
    }

    /// Frames the whole mesh, keeping the viewing angles; the sphere fits the narrower of
    /// the two fields of view.
    pub fn frame_all(&mut self) {
        if let Some(open) = &self.document.open {
            input::frame_all(&mut self.camera, open.bounds, &self.viewport);
        }
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
        input::frame_under(&mut self.camera, self.document.open.as_ref(), &self.viewport, pos, &mut self.status);
    }

    /// Starts the job that builds the view `shown` needs, when it is missing and no other
    /// job runs (the view panel asks each frame it is shown).
    pub fn prepare_view(&mut self, shown: Shown) {
        let (Some(open), Some(gpu)) = (&self.document.open, &self.gpu) else {
            return;
        };
        if !open.is_missing(shown) || self.jobs.is_busy() {
            return;
        }
        let (source, path) = (open.source(), open.path.clone());
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

    /// Builds the Mesh Color Texture (or packed Ptex, or Htex) of the open document's packed mesh on a
    /// job, when the view shows that representation and it is missing (never in paint mode,
    /// which draws the paint layout; leaving it repacks, and the texture is built again from
    /// the result).
    pub fn prepare_mct(&mut self) {
        let (Some(open), Some(gpu)) = (&self.document.open, &self.gpu) else {
            return;
        };
        let representation = self.panels.view.settings.representation;
        let missing = match representation {
            Representation::MeshColors => false,
            Representation::MeshColorTexture => open.mct_missing(),
            Representation::Htex => open.htex_missing(),
            Representation::PackedPtex => open.ptex_missing(),
        };
        if !missing || self.document.level0_only() || self.jobs.is_busy() {
            return;
        }
        let Some((packed, geometry)) = open.mct_source() else {
            return;
        };
        let (path, generation) = (open.path.clone(), open.mesh_generation);
        let (gpu, budget) = (Arc::clone(gpu), self.budget());
        let name = representation.name();
        let started = self.jobs.start(JobKind::View, format!("Preparing {name}"), move |job| {
            let view = match representation {
                Representation::PackedPtex => AlternateView::Ptex(
                    generation,
                    Box::new(document::build_ptex(&packed, &geometry, &budget, &gpu, job)),
                ),
                Representation::Htex => AlternateView::Htex(
                    generation,
                    Box::new(document::build_htex(&packed, &geometry, &budget, &gpu, job)),
                ),
                _ => AlternateView::Mct(
                    generation,
                    Box::new(document::build_mct(&packed, &geometry, &budget, &gpu, job)),
                ),
            };
            Ok(JobOutput::View(path, Box::new(view)))
        });
        if let Err(message) = started {
            self.set_status(Severity::Error, message);
        }
    }

    /// The representation the 3D view draws the mesh colors in: the chosen one, except
    /// while the GPU holds the paint layout (mesh colors at level 0).
    pub fn shown_representation(&self) -> Representation {
        if self.document.level0_only() { Representation::MeshColors } else { self.panels.view.settings.representation }
    }

    /// What the 3D view draws: the alternate view chosen in the view panel once it is
    /// built, else the mesh colors, in the chosen representation once it is built.
    pub fn shown_item(&self) -> Option<DrawItem<'_>> {
        self.document.open.as_ref()?.shown_item(self.panels.view.settings.shown, self.shown_representation())
    }

    /// GPU memory in use: the mesh's buffers and atlas, a Mesh Color Texture built for it,
    /// plus the view's render targets.
    pub fn gpu_bytes(&self) -> u64 {
        let open = self.document.open.as_ref();
        let mesh = open.and_then(|d| d.gpu_mesh.as_ref()).map_or(0, |m| m.gpu_bytes());
        let mct = open.and_then(|d| d.current_mct()).and_then(Result::ok).map_or(0, |b| b.mct.gpu_bytes());
        let htex = open.and_then(|d| d.current_htex()).and_then(Result::ok).map_or(0, |b| b.htex.gpu_bytes());
        let ptex = open.and_then(|d| d.current_ptex()).and_then(Result::ok).map_or(0, |b| b.ptex.gpu_bytes());
        mesh + mct + ptex + htex + self.viewport.gpu_bytes
    }

    /// The window title.
    pub fn window_title(&self) -> String {
        match &self.document.open {
            Some(open) if self.document.is_modified() => format!("*{} — meshpaint", open.title),
            Some(open) => format!("{} — meshpaint", open.title),
            None => "meshpaint".to_owned(),
        }
    }

    /// The document and what paint mode's commands use besides it (split borrows).
    fn paint_parts(&mut self) -> (&mut DocumentState, PaintContext<'_>) {
        let Editor { gpu, document, camera, panels, viewport, status, jobs, .. } = self;
        let (brush, recent_colors) = (&mut panels.paint.brush, &mut panels.paint.recent_colors);
        let ctx = PaintContext { gpu: gpu.as_ref(), camera, viewport, brush, recent_colors, status, jobs };
        (document, ctx)
    }

    /// Carries out `pending` at once when nothing is unsaved, else asks first.
    pub fn replace_or_close(&mut self, pending: Pending) {
        if !self.document.is_modified() {
            self.carry_on(pending);
            return;
        }
        log::info!("Unsaved changes: asking before {}", pending.describe());
        self.panels.unsaved.pending = Some(pending);
    }

    /// Applies the answer to the prompt.
    pub fn answer_unsaved(&mut self, choice: UnsavedChoice) {
        let Some(pending) = self.panels.unsaved.pending.take() else {
            return;
        };
        match choice {
            UnsavedChoice::Save => {
                self.after_save = Some(pending);
                self.perform(Action::Save);
            }
            UnsavedChoice::DontSave => self.carry_on(pending),
            UnsavedChoice::Cancel => self.set_status(Severity::Info, format!("Cancelled {}.", pending.describe())),
        }
    }

    /// A save finished (`saved`: successfully): the action that waited for it goes on, or is
    /// dropped with a message.
    pub(crate) fn after_save_finished(&mut self, saved: bool) {
        if let Some(pending) = self.after_save.take() {
            if saved {
                self.carry_on(pending);
            } else {
                let text = format!("Not {}: the document was not saved.", pending.describe());
                self.set_status(Severity::Warning, text);
            }
        }
    }

    /// Drops the action that waited for a save when no save is coming: the "Save as" dialog
    /// was closed without a name (called every frame).
    pub(crate) fn drop_abandoned_save(&mut self) {
        if self.after_save.is_some() && self.panels.file.dialog.is_none() && !self.jobs.is_busy() {
            self.after_save_finished(false);
        }
    }

    fn carry_on(&mut self, pending: Pending) {
        match pending {
            Pending::Open(source) => self.open(source),
            Pending::Quit => self.quit_requested = true,
        }
    }

    /// Carries out `action`: the one place every menu entry, button and shortcut ends.
    pub fn perform(&mut self, action: Action) {
        let view = &mut self.panels.view.settings;
        match action {
            Action::Open => self.open_dialog(DialogPurpose::Open),
            Action::Save => match self.document.open.as_ref().and_then(|d| Some((d.project_path.clone()?, d.format))) {
                Some((path, format)) => self.save_to(path, format),
                None => self.open_dialog(DialogPurpose::SaveAs),
            },
            Action::SaveAs => self.open_dialog(DialogPurpose::SaveAs),
            Action::Export => {
                self.panels.export.show_for(self.document.open.as_ref(), &self.panels.file.last_directory)
            }
            Action::ExportGltf => self.open_dialog(DialogPurpose::ExportGltf),
            Action::ExportPacked => self.open_dialog(DialogPurpose::ExportPacked),
            Action::FrameAll => self.frame_all(),
            Action::FrameUnderCursor => {
                if let Some(pos) = self.viewport.pointer {
                    self.frame_under(pos);
                }
            }
            Action::ViewFront => self.set_view_angles(0.0, 0.0),
            Action::ViewBack => self.set_view_angles(180.0, 0.0),
            Action::ViewRight => self.set_view_angles(90.0, 0.0),
            Action::ViewLeft => self.set_view_angles(-90.0, 0.0),
            Action::ViewTop => self.set_view_angles(0.0, 89.0),
            Action::ViewBottom => self.set_view_angles(0.0, -89.0),
            Action::ToggleWireframe => view.overlays.wireframe = !view.overlays.wireframe,
            Action::ToggleHeatmap => view.overlays.heatmap = !view.overlays.heatmap,
            Action::ToggleShading => {
                view.shading = match view.shading {
                    Shading::Lit | Shading::Smooth => Shading::Unlit,
                    Shading::Unlit => Shading::Smooth,
                }
            }
            Action::CycleFilter => {
                view.filter = match view.filter {
                    FilterMode::Nearest | FilterMode::NearestMipLevel(_) => FilterMode::Linear,
                    FilterMode::Linear | FilterMode::MipLevel(_) => FilterMode::Trilinear,
                    FilterMode::Trilinear | FilterMode::Anisotropic => FilterMode::Nearest,
                }
            }
            Action::ToggleRepresentation => {
                view.representation = match view.representation {
                    Representation::MeshColors => Representation::MeshColorTexture,
                    Representation::MeshColorTexture => Representation::PackedPtex,
                    Representation::PackedPtex => Representation::Htex,
                    Representation::Htex => Representation::MeshColors,
                };
                self.prepare_mct();
            }
            Action::ToggleHelp => self.panels.help.open = !self.panels.help.open,
            Action::Quit => self.replace_or_close(Pending::Quit),
            Action::TogglePaintMode => {
                let budget = self.budget();
                self.with_paint_parts(|document, ctx| document.toggle_paint_mode(ctx, budget));
            }
            Action::Undo => self.with_paint_parts(|document, ctx| document.undo(ctx)),
            Action::Redo => self.with_paint_parts(|document, ctx| document.redo(ctx)),
            Action::Eyedropper => self.with_paint_parts(|document, ctx| document.eyedropper(ctx)),
            Action::RadiusGesture => {
                self.with_paint_parts(|document, ctx| document.start_gesture(ctx, GestureKind::Radius));
            }
            Action::StrengthGesture => {
                self.with_paint_parts(|document, ctx| document.start_gesture(ctx, GestureKind::Strength));
            }
        }
    }

    /// Runs a paint-mode command on the document with its [`PaintContext`].
    fn with_paint_parts<T>(&mut self, work: impl FnOnce(&mut DocumentState, &mut PaintContext<'_>) -> T) -> T {
        let (document, mut ctx) = self.paint_parts();
        work(document, &mut ctx)
    }

    /// Carries out what a panel, dialog or the input asked for.
    pub fn apply(&mut self, command: Command) {
        match command {
            Command::Action(action) => self.perform(action),
            Command::Open(path) => self.replace_or_close(Pending::Open(Source::File(path))),
            Command::Unsaved(choice) => self.answer_unsaved(choice),
            Command::Write(path, format, kind) => self.write(path, format, kind),
            Command::Export(request) => {
                self.panels.file.remember_directory_of(&request.path);
                self.export(request);
            }
            Command::CheckUvs(size) => self.check_uvs(size),
            Command::Fill { connected } => self.with_paint_parts(|document, ctx| document.fill(ctx, connected)),
            Command::SetResolutionAll(resolution) => {
                let budget = self.budget();
                self.with_paint_parts(|document, ctx| document.set_resolution_all(ctx, resolution, budget));
            }
            Command::Optimize(bound) => {
                self.with_paint_parts(|document, ctx| document.optimize_resolutions(ctx, bound));
            }
            Command::SetUndoCap(bytes) => self.document.history.set_cap_bytes(bytes),
            Command::PrepareView(shown) => self.prepare_view(shown),
            Command::RestoreRecovery => self.restore_recovery(),
            Command::DiscardRecovery => self.discard_recovery(),
            Command::BeginStroke(pos) => self.with_paint_parts(|document, ctx| document.begin_stroke(ctx, pos)),
            Command::StrokeTo(pos) => self.with_paint_parts(|document, ctx| document.stroke_to(ctx, pos)),
            Command::EndStroke => self.with_paint_parts(|document, ctx| document.end_stroke(ctx)),
        }
    }

    /// Carries out `commands` in order.
    fn apply_all(&mut self, commands: Vec<Command>) {
        for command in commands {
            self.apply(command);
        }
    }

    /// Restores the offered recovery file: it opens in place of the document, keeping the
    /// document's name, paths and format, unsaved.
    fn restore_recovery(&mut self) {
        let Some(offer) = self.panels.autosave.state.offer.clone() else {
            return;
        };
        let Some(open) = &self.document.open else {
            return;
        };
        if self.jobs.is_busy() {
            self.set_status(Severity::Warning, "Busy: try again when the running job has finished.");
            return;
        }
        let autosave = &mut self.panels.autosave.state;
        autosave.restoring = Some(Restoring {
            path: open.path.clone(),
            project_path: open.project_path.clone(),
            title: open.title.clone(),
            format: open.format,
        });
        autosave.offer = None;
        self.open(Source::File(offer.path));
        // Unsaved: the restored colours are not in the document's file yet.
        self.document.edit_generation += 1;
    }

    /// Deletes the offered recovery file.
    fn discard_recovery(&mut self) {
        let Some(offer) = self.panels.autosave.state.offer.take() else {
            return;
        };
        match autosave::discard_recovery(&offer.path) {
            Ok(()) => self.set_status(Severity::Info, "Recovery file discarded."),
            Err(error) => self.set_status(Severity::Error, error.to_string()),
        }
    }

    /// Starts an autosave when one is due (called every frame). Returns how long until the
    /// next one falls due, when one is pending: the editor draws no frame at rest, so the UI
    /// asks to be woken then.
    fn autosave_tick(&mut self) -> Option<Duration> {
        let blocked = self.jobs.is_busy() || self.document.is_stroking();
        let generation = self.document.edit_generation;
        let Some(open) = &self.document.open else {
            return None;
        };
        let path = match self.panels.autosave.state.tick(generation, blocked) {
            AutosaveTick::Wait(after) => return after,
            AutosaveTick::Write(path) => path,
        };
        let document = Arc::clone(&open.document);
        let started = self.jobs.start(JobKind::Autosave, "Autosave", move |job| {
            job.progress(0.1, "writing the recovery file");
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
            }
            let write = autosave::write_recovery(&path, &document).map_err(|e| e.to_string())?;
            Ok(JobOutput::Autosaved(Autosaved { path, write, generation }))
        });
        if let Err(message) = started {
            log::warn!("{message}");
        }
        None
    }

    /// One frame of the editor's UI inside `ui` (the window's root). Afterwards
    /// [`Editor::viewport`] holds the 3D view's area, which the window shell renders.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.viewport.upload_bytes_last_frame = std::mem::take(&mut self.viewport.upload_bytes_this_frame);
        self.poll_jobs();
        let ctx = ui.ctx().clone();
        if let Some(after) = self.autosave_tick() {
            // Nothing else wakes an idle editor: the autosave asks for the frame it needs.
            ctx.request_repaint_after(after);
        }
        self.global_input(&ctx);
        let bounds = self.document.open.as_ref().map(|d| d.bounds);
        input::follow_up_axis(&mut self.camera, self.panels.import.up_axis, bounds, &self.viewport);
        let (has_document, idle) = (self.document.open.is_some(), !self.jobs.is_busy());
        let chosen = egui::Panel::top("menu bar").show(ui, |ui| self.panels.menu.ui(ui, has_document, idle)).inner;
        self.apply_all(chosen);
        egui::Panel::bottom("status line").show(ui, |ui| {
            let mode = self.mode();
            // Opening reads its cancel flag (the conversion stops; the open document stays).
            let cancellable = matches!(self.jobs.kind(), Some(JobKind::Open { .. })) && !self.jobs.is_cancelling();
            if self.panels.status_line.ui(ui, mode, &self.status, self.jobs.status(), cancellable) {
                self.jobs.cancel();
            }
        });
        egui::Panel::left("side panel")
            .resizable(true)
            .default_size(SIDE_PANEL_WIDTH)
            .show(ui, |ui| egui::ScrollArea::vertical().show(ui, |ui| self.side_panel_ui(ui)));
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport_ui(ui));
        self.panels.help.ui(&ctx, self.viewport.rect.center());
        let chosen = self.panels.file.dialog_ui(&ctx, &mut self.panels.import);
        self.apply_all(chosen);
        let (document, generation) = (self.document.open.as_ref(), self.document.edit_generation);
        let chosen = self.panels.export.ui(&ctx, ExportContext { document, generation, idle: !self.jobs.is_busy() });
        self.apply_all(chosen);
        let chosen = self.panels.autosave.recovery_ui(&ctx, self.viewport.rect.center());
        self.apply_all(chosen);
        let title = self.document.open.as_ref().map_or_else(String::new, |open| open.title.clone());
        let chosen = self.panels.unsaved.ui(&ctx, &title);
        self.apply_all(chosen);
        self.drop_abandoned_save();
        // The Mesh Color Texture follows the packed mesh: built again after every repack.
        self.prepare_mct();
        if self.jobs.is_busy() {
            // Animate the progress bar; a finished job wakes the UI by itself.
            ctx.request_repaint_after(Duration::from_millis(100));
        }
        if self.panels.scene.continuous_redraw {
            ctx.request_repaint();
        }
    }

    /// Dropped files, a running brush gesture, and the keyboard shortcuts.
    fn global_input(&mut self, ctx: &egui::Context) {
        if let Some(path) = input::dropped_file(ctx) {
            self.replace_or_close(Pending::Open(Source::File(path)));
        }
        if self.with_paint_parts(|document, paint| document.gesture_input(paint, ctx)) {
            return;
        }
        let dialog_open = self.panels.file.dialog.is_some() || self.panels.export.open;
        for action in input::shortcuts(ctx, self.mode(), dialog_open) {
            self.perform(action);
        }
    }

    /// The side panel's sections: paint (with Optimize and undo), file (with the import
    /// settings and autosave), view, scene. Each section's commands are applied after it.
    fn side_panel_ui(&mut self, ui: &mut egui::Ui) {
        let painting = self.mode() == Mode::Paint;
        egui::CollapsingHeader::new("Paint").default_open(true).show(ui, |ui| {
            let has_document = self.document.open.is_some();
            let bounds_radius = self.document.open.as_ref().map(|d| d.bounds.radius);
            let context = PaintPanelContext { painting, has_document, bounds_radius };
            let mut chosen = self.panels.paint.ui(ui, context);
            chosen.extend(self.panels.optimize.ui(ui, painting));
            let last_stroke = self.document.paint.as_ref().map(|session| LastStroke {
                samples_changed: session.stroke_samples_changed,
                upload_bytes: session.stroke_upload_bytes,
            });
            chosen.extend(self.panels.undo.ui(ui, painting, &self.document.history, last_stroke));
            self.apply_all(chosen);
        });
        egui::CollapsingHeader::new("File").default_open(true).show(ui, |ui| {
            let (has_document, idle) = (self.document.open.is_some(), !self.jobs.is_busy());
            let chosen = self.panels.file.ui(ui, has_document, idle);
            self.panels.import.ui(ui, "Open meshes at:");
            self.panels.autosave.settings_ui(ui);
            self.apply_all(chosen);
        });
        egui::CollapsingHeader::new("View").default_open(true).show(ui, |ui| {
            let context = ViewContext {
                document: self.document.open.as_ref(),
                gpu: self.gpu.as_deref(),
                camera: self.camera,
                level0_only: self.document.level0_only(),
                viewport_px: self.viewport.size_px(),
                scene_generation: self.viewport.scene_generation,
                gpu_bytes: self.gpu_bytes(),
                frame_ms: self.viewport.frame_stats.frame_ms,
            };
            let chosen = self.panels.view.ui(ui, &context);
            self.apply_all(chosen);
        });
        egui::CollapsingHeader::new("Scene").default_open(true).show(ui, |ui| {
            let context = SceneContext {
                document: self.document.open.as_ref(),
                gpu_bytes: self.gpu_bytes(),
                upload_bytes_last_frame: self.viewport.upload_bytes_last_frame,
                frame_stats: &self.viewport.frame_stats,
                gpu_name: self.gpu.as_ref().map(|gpu| gpu.ctx.adapter_info.name.as_str()),
            };
            self.panels.scene.ui(ui, context);
        });
    }

    /// The 3D view's area: its image, its input, and the brush cursor over it.
    fn viewport_ui(&mut self, ui: &mut egui::Ui) {
        let context = ViewportContext {
            texture: self.viewport.texture,
            showing: self.document.open.as_ref().is_some_and(|d| d.gpu_mesh.is_some()),
            busy: self.jobs.is_busy(),
            has_document: self.document.open.is_some(),
            mode: self.mode(),
        };
        let (response, painter) = self.panels.viewport.ui(ui, context);
        self.viewport.rect = response.rect;
        self.viewport.pixels_per_point = ui.ctx().pixels_per_point();
        self.viewport.pointer = response.hover_pos();
        let dialog_open = self.panels.file.dialog.is_some();
        if let Some(session) = self.document.paint.as_mut() {
            let strokes = input::paint_input(ui, &response, session, dialog_open);
            self.apply_all(strokes);
            if self.document.is_stroking() {
                ui.ctx().request_repaint();
            }
        }
        let open = self.document.open.as_ref();
        let zoom_to_cursor = self.panels.view.settings.zoom_to_cursor;
        input::navigate(ui, &response, &mut self.camera, open, &self.viewport, zoom_to_cursor, &mut self.status);
        if let Some(session) = &self.document.paint {
            draw_brush_cursor(&painter, session, &self.panels.paint.brush, &self.viewport, &self.camera);
        }
    }
}
