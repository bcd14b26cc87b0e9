//! Paint mode's commands on the document ([`DocumentState`]): entering and leaving it,
//! strokes from the pointer, the live GPU upload after every dab, undo / redo, eyedropper,
//! fill, resolution commands, Optimize, the interactive radius / strength gestures
//! (F / Shift+F) and the brush cursor. The brush settings and the tool panel are the paint
//! panel's (`panels::paint`); what the commands need besides the document comes in a
//! [`PaintContext`].
//!
//! Entering paint mode switches the GPU mesh to the paint layout
//! ([`meshpaint_core::packing::paint_layout::PaintLayout`], level 0 only); leaving repacks the store into the
//! compact layout with MIP chains on a worker thread ([`DocumentState::leave_paint_mode`]).
//! Optimize plans on a worker thread too (`paint::optimize::plan`); its changes are applied
//! as one undo step when it is done, if the colours did not change meanwhile.

use std::sync::Arc;
use std::time::{Duration, Instant};

use meshpaint_core::camera::OrbitCamera;
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, DirtyAccumulator};
use meshpaint_core::mesh::topology::VertexFaces;
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::packing::paint_layout::PaintLayout;
use meshpaint_core::paint::brush::{
    self, BrushRadius, BrushSettings, FillScope, PaintView, Painter, StrokePoint, StrokeUpdate,
};
use meshpaint_core::paint::optimize;
use meshpaint_core::paint::undo::{StepSummary, UndoHistory};
use meshpaint_render::Gpu;

use super::job_output::{JobOutput, Optimized};
use super::jobs::{JobKind, Jobs};
use super::paint_session::{Gesture, GestureKind, PaintSession, Repack, Repacked, STRENGTH_GESTURE_POINTS};
use super::recent_colors::RecentColors;
use super::session::DocumentState;
use super::state::{Mode, Severity, Status, ViewportState};
use super::text::{human_bytes, thousands};

/// What paint mode's commands use besides the document: the GPU, the view, the brush, the
/// status line and the job runner (the editor lends them).
pub struct PaintContext<'a> {
    /// GPU objects (`None` in UI tests without a GPU).
    pub gpu: Option<&'a Arc<Gpu>>,
    /// The camera of the 3D view.
    pub camera: &'a OrbitCamera,
    /// The 3D view: its area and pointer; uploads and scene changes are counted here.
    pub viewport: &'a mut ViewportState,
    /// The brush settings (the paint panel's).
    pub brush: &'a mut BrushSettings,
    /// The colours strokes painted with (the paint panel's row).
    pub recent_colors: &'a mut RecentColors,
    /// The status line.
    pub status: &'a mut Status,
    /// Background work (repack, Optimize).
    pub jobs: &'a mut Jobs<JobOutput>,
}

impl DocumentState {
    /// Tab: enters or leaves paint mode.
    pub fn toggle_paint_mode(&mut self, ctx: &mut PaintContext<'_>, budget: Budget) {
        match self.mode() {
            Mode::View => self.enter_paint_mode(ctx, budget),
            Mode::Paint => self.leave_paint_mode(ctx),
        }
    }

    /// Enters paint mode: snapshots the base colours, builds the paint layout and uploads it.
    pub fn enter_paint_mode(&mut self, ctx: &mut PaintContext<'_>, budget: Budget) {
        if ctx.jobs.is_busy() {
            ctx.status.set(Severity::Warning, "Busy: wait for the running job to finish before painting.");
            return;
        }
        let Some(open) = self.open.as_mut() else {
            ctx.status.set(Severity::Error, "Nothing to paint: no document is open.");
            return;
        };
        let started = Instant::now();
        let document = Arc::make_mut(&mut open.document);
        // Changes from before (none expected) are in the new layout anyway; the compact
        // packing is reused on leaving only if it is still the store's.
        let unpacked_changes = !document.store.take_dirty().is_empty();
        let mut pack_cache = if unpacked_changes { None } else { open.pack_cache.take() };
        let (mut layout, mut compact_gpu_mesh, mut encoded, mut lent_colors) = (None, None, None, false);
        // Painted in place when the view shows the packing (no wait); else uploaded anew. The
        // base snapshot (copy-on-write) and the session's tables are made meanwhile.
        let compact = if open.gpu_mesh.is_some() { pack_cache.as_mut() } else { None };
        let (store, positions, format) = (&document.store, &document.positions, open.format);
        let (entered, (base, vertex_faces, repack_dirty)) = rayon::join(
            || ctx.gpu.map(|gpu| gpu.enter_paint(store, positions, format, compact)),
            || (store.clone(), VertexFaces::of(store.topology()), DirtyAccumulator::new(store.topology())),
        );
        if let Some(entered) = entered {
            match entered {
                Ok(start) => {
                    ctx.viewport.upload_bytes_this_frame += start.bytes;
                    match start.mesh {
                        Some(mesh) => compact_gpu_mesh = open.gpu_mesh.replace(mesh),
                        None => lent_colors = true,
                    }
                    // Paint mode draws mesh colors; the Mesh Color Texture is rebuilt after it.
                    open.mesh_generation += 1;
                    open.alternates.mct = None;
                    open.alternates.htex = None;
                    open.alternates.ptex = None;
                    encoded = Some(start.encoded);
                    layout = Some(start.layout);
                }
                Err(error) => {
                    open.pack_cache = pack_cache;
                    let text = format!("Cannot enter paint mode: uploading the paint layout failed: {error}");
                    ctx.status.set(Severity::Error, text);
                    return;
                }
            }
        }
        let layout = layout.unwrap_or_else(|| PaintLayout::new(&document.store));
        let painter = {
            let mut painter = Painter::new(&document.positions);
            painter.set_settings(*ctx.brush);
            painter.set_budget(Some((budget, open.format)));
            painter
        };
        self.paint = Some(PaintSession {
            layout,
            encoded,
            lent_colors,
            base,
            painter,
            gesture: None,
            last_pointer: None,
            swallow_primary: false,
            stroke_upload_bytes: 0,
            stroke_samples_changed: 0,
            upload_failed: false,
            pack_cache,
            compact_gpu_mesh,
            repack_dirty,
            vertex_faces,
        });
        self.gpu_paint_layout = true;
        ctx.viewport.scene_generation += 1;
        let ms = started.elapsed().as_secs_f64() * 1000.0;
        ctx.status.set(Severity::Info, format!("Paint mode (level 0 on the GPU, set up in {ms:.0} ms). Tab leaves."));
    }

    /// Leaves paint mode: repacks the store into compact buffers with MIP chains on a worker
    /// thread (the status line shows its progress) and replaces the GPU buffers when done.
    pub fn leave_paint_mode(&mut self, ctx: &mut PaintContext<'_>) {
        if ctx.jobs.is_busy() {
            ctx.status.set(Severity::Warning, "Busy: wait for the running job to finish before leaving paint mode.");
            return;
        }
        self.end_stroke(ctx);
        let session = self.paint.take();
        let Some(open) = &self.open else {
            return;
        };
        let (cache, mut dirty, compact_gpu_mesh) = match session {
            Some(session) => session.into_repack_inputs(open.gpu_mesh.as_ref()),
            None => (None, DirtyAccumulator::default(), None),
        };
        let document = Arc::clone(&open.document);
        let format = open.format;
        let gpu = ctx.gpu.cloned();
        let started = ctx.jobs.start(JobKind::Repack, "Repacking", move |job| {
            job.progress(0.1, "packing colours with MIP chains");
            let started = Instant::now();
            let dirty = dirty.take();
            // Only the chains the session changed when no resolution changed; else a new
            // layout in the old packing's buffers, with the chains no edit reached moved
            // into it; all of them when the format changed.
            let failed = |error: meshpaint_core::packing::PackError| format!("repacking failed: {error}");
            let (store, positions) = (&document.store, &document.positions);
            let (cache, ranges, how) = match cache {
                Some(mut cache) if cache.packed().format == format => match cache.update(store, &dirty) {
                    Some(ranges) => (cache, Some(ranges), Repack::ChangedChains),
                    None => (cache.relayout(store, positions, &dirty).map_err(failed)?, None, Repack::Relayout),
                },
                Some(cache) => (cache.rebuild(store, positions, format).map_err(failed)?, None, Repack::Full),
                None => (PackCache::build(store, positions, format).map_err(failed)?, None, Repack::Full),
            };
            let pack_time = started.elapsed();
            job.progress(0.7, "uploading to the GPU");
            let packed = cache.packed();
            let upload_error =
                |error: meshpaint_render::RenderError| format!("uploading the repacked buffers failed: {error}");
            let gpu_mesh = match (gpu, compact_gpu_mesh, &ranges) {
                (Some(gpu), Some(mesh), Some(ranges)) => {
                    let size = packed.format.bytes_per_sample();
                    for &(first, count) in ranges {
                        let bytes = &packed.colors[first as usize * size..(first + count) as usize * size];
                        mesh.write_samples(&gpu.ctx, first, bytes).map_err(upload_error)?;
                    }
                    mesh.into_mesh()
                }
                (Some(gpu), _, _) => Some(gpu.upload(packed).map_err(upload_error)?),
                (None, _, _) => None,
            };
            Ok(JobOutput::Repacked(Box::new(Repacked {
                document,
                gpu_mesh,
                samples_with_mips: packed.sample_count(),
                packed_bytes: packed.face_record_bytes() + packed.color_bytes(),
                pack_time,
                how,
                cache,
            })))
        });
        match started {
            Ok(()) => ctx.status.set(Severity::Info, "Repacking…"),
            Err(message) => ctx.status.set(Severity::Error, message),
        }
    }

    /// Runs `work` with the paint view, the store, the painter and the history; uploads the
    /// changes afterwards.
    pub(crate) fn with_paint<T>(
        &mut self,
        ctx: &mut PaintContext<'_>,
        work: impl FnOnce(&PaintView, &mut ColorStore, &mut Painter, &mut UndoHistory) -> T,
    ) -> Option<T> {
        let viewport_px = ctx.viewport.size_px();
        let DocumentState { open, paint, history, .. } = self;
        let (open, session) = (open.as_mut()?, paint.as_mut()?);
        let doc = Arc::make_mut(&mut open.document);
        let PaintSession { base, painter, .. } = session;
        let view =
            PaintView { positions: &doc.positions, bvh: &open.bvh, camera: ctx.camera, viewport_px, base: Some(base) };
        let result = work(&view, &mut doc.store, painter, history);
        self.sync_gpu(ctx);
        Some(result)
    }

    /// Counts a stroke update; reports brush errors.
    fn stroke_result(&mut self, ctx: &mut PaintContext<'_>, result: Option<Result<StrokeUpdate, brush::BrushError>>) {
        match result {
            Some(Ok(update)) => {
                if let Some(session) = self.paint.as_mut() {
                    session.stroke_samples_changed += update.stats.samples_changed;
                }
                if update.stats.samples_changed > 0 || update.stats.faces_resized > 0 {
                    self.edit_generation += 1;
                }
                // A colour counts as used once a stroke changed samples with it.
                let painting = ctx.brush.tool == brush::Tool::Paint && ctx.brush.blend != brush::BlendMode::EraseToBase;
                if painting && update.stats.samples_changed > 0 {
                    ctx.recent_colors.push(ctx.brush.color);
                }
            }
            Some(Err(error)) => {
                self.end_stroke(ctx);
                ctx.status.set(Severity::Error, format!("Brush: {error}"));
            }
            None => {}
        }
    }

    /// Starts a stroke at `pos` (points). The pointer is a mouse: full pressure (winit has no
    /// tablet pressure yet).
    pub fn begin_stroke(&mut self, ctx: &mut PaintContext<'_>, pos: egui::Pos2) {
        let px = StrokePoint::mouse(ctx.viewport.view_px(pos));
        let settings = *ctx.brush;
        if let Some(session) = self.paint.as_mut() {
            session.painter.set_settings(settings);
            session.stroke_upload_bytes = 0;
            session.stroke_samples_changed = 0;
        }
        let result =
            self.with_paint(ctx, |view, store, painter, history| painter.begin_stroke(view, store, history, px));
        self.stroke_result(ctx, result);
    }

    /// Extends the stroke to `pos` (points).
    pub fn stroke_to(&mut self, ctx: &mut PaintContext<'_>, pos: egui::Pos2) {
        let px = StrokePoint::mouse(ctx.viewport.view_px(pos));
        let result = self.with_paint(ctx, |view, store, painter, history| painter.stroke_to(view, store, history, px));
        self.stroke_result(ctx, result);
    }

    /// Ends the stroke (closes its undo step).
    pub fn end_stroke(&mut self, ctx: &mut PaintContext<'_>) {
        let DocumentState { paint, history, .. } = self;
        let Some(session) = paint.as_mut() else {
            return;
        };
        if !session.painter.is_stroking() {
            return;
        }
        let summary = session.painter.end_stroke(history);
        let (bytes, changed) = (session.stroke_upload_bytes, session.stroke_samples_changed);
        if let Some(summary) = summary {
            log::info!("{}: {} sample updates, {} uploaded", summary.label, thousands(changed), human_bytes(bytes));
            ctx.status.set(Severity::Info, stroke_message(&summary, changed));
        }
    }

    /// Uploads what changed in the store since the last call: the dirty blocks of the paint
    /// layout and the changed face records, or everything when the layout grew.
    pub fn sync_gpu(&mut self, ctx: &mut PaintContext<'_>) {
        let DocumentState { open, paint, .. } = self;
        let (Some(open), Some(session)) = (open.as_mut(), paint.as_mut()) else {
            return;
        };
        let doc = Arc::make_mut(&mut open.document);
        let dirty = doc.store.take_dirty();
        // Everything the session changed is repacked on leaving, uploaded or not.
        session.repack_dirty.add(&dirty);
        if dirty.is_empty() || session.upload_failed {
            // After a failed upload the GPU mesh is stale until paint mode ends (the repack
            // uploads everything): reported once, not retried on every change.
            return;
        }
        let plan = session.layout.sync(&doc.store, &dirty);
        let mut bytes = 0u64;
        let mut error = None;
        // The faces these changes show on, for a partial redraw (`None`: all of them).
        let mut shown = None;
        if let (Some(gpu), Some(mesh)) = (ctx.gpu, open.gpu_mesh.as_mut()) {
            if plan.grown
                && let Some(encoded) = session.encoded.as_mut()
                && let Err(e) = gpu.grow_paint_buffer(mesh, encoded, &session.layout)
            {
                error = Some(e.to_string());
            }
            match session.encoded.as_mut() {
                Some(encoded) if error.is_none() && encoded.format() == open.format => {
                    let spans = encoded.apply(&session.layout, &doc.store, &dirty, &plan);
                    let records = (plan.faces.as_slice(), session.layout.records());
                    match mesh.write_paint_upload(&gpu.ctx, &spans, encoded.bytes(), records) {
                        Ok(written) => {
                            bytes += written;
                            shown = Some(dirty.faces_shown(doc.store.topology(), &session.vertex_faces));
                        }
                        Err(e) => error = Some(e.to_string()),
                    }
                }
                _ => match gpu.upload_paint_layout(&session.layout, &doc.store, &doc.positions, open.format) {
                    Ok(upload) => {
                        *mesh = upload.mesh;
                        bytes += upload.bytes;
                        session.encoded = Some(upload.encoded);
                        // The packing's bytes are gone with the mesh: leaving packs in full.
                        session.lent_colors = false;
                        error = None;
                    }
                    Err(e) => error = Some(e.to_string()),
                },
            }
        }
        session.stroke_upload_bytes += bytes;
        ctx.viewport.upload_bytes_this_frame += bytes;
        ctx.viewport.scene_changed(shown);
        if let Some(error) = error {
            session.upload_failed = true;
            ctx.status.set(
                Severity::Error,
                format!("Uploading the painted samples failed: {error}. The view shows the colours before; leave paint mode (Tab) to upload them again."),
            );
        }
    }

    /// Ctrl+Z: undoes the last stroke (paint mode only).
    pub fn undo(&mut self, ctx: &mut PaintContext<'_>) {
        self.undo_redo(ctx, true);
    }

    /// Ctrl+Shift+Z: redoes the last undone stroke (paint mode only).
    pub fn redo(&mut self, ctx: &mut PaintContext<'_>) {
        self.undo_redo(ctx, false);
    }

    fn undo_redo(&mut self, ctx: &mut PaintContext<'_>, undo: bool) {
        if self.mode() != Mode::Paint {
            ctx.status.set(Severity::Info, "Undo and redo work in paint mode (Tab).");
            return;
        }
        self.end_stroke(ctx);
        let label = if undo { self.history.undo_label() } else { self.history.redo_label() }.map(str::to_owned);
        let result =
            self.with_paint(ctx, |_, store, _, history| if undo { history.undo(store) } else { history.redo(store) });
        let verb = if undo { "Undo" } else { "Redo" };
        match result {
            Some(Ok(true)) => {
                self.edit_generation += 1;
                ctx.status.set(Severity::Info, format!("{verb}: {}", label.unwrap_or_default()));
            }
            Some(Ok(false)) => ctx.status.set(Severity::Info, format!("Nothing to {}.", verb.to_lowercase())),
            Some(Err(error)) => ctx.status.set(Severity::Error, format!("{verb} failed: {error}")),
            None => {}
        }
    }

    /// S: picks the colour under the pointer into the brush.
    pub fn eyedropper(&mut self, ctx: &mut PaintContext<'_>) {
        let Some(pos) = ctx.viewport.pointer.or_else(|| self.paint.as_ref().and_then(|p| p.last_pointer)) else {
            return;
        };
        let px = ctx.viewport.view_px(pos);
        let picked = self.with_paint(ctx, |view, store, _, _| brush::eyedropper(view, store, px)).flatten();
        match picked {
            Some(color) => {
                ctx.brush.color = color;
                let [r, g, b, _] = color.map(meshpaint_core::colors::format::encode_srgb8);
                ctx.status.set(Severity::Info, format!("Picked colour #{r:02x}{g:02x}{b:02x}"));
            }
            None => ctx.status.set(Severity::Info, "Eyedropper: nothing under the cursor."),
        }
    }

    /// Fills the whole mesh, or the part connected to the face last under the pointer.
    pub fn fill(&mut self, ctx: &mut PaintContext<'_>, connected: bool) {
        let scope = if connected {
            let pos = self.paint.as_ref().and_then(|p| p.last_pointer);
            let face = pos.and_then(|pos| {
                let px = ctx.viewport.view_px(pos);
                self.with_paint(ctx, |view, _, _, _| view.pick(px)).flatten().map(|hit| hit.face)
            });
            match face {
                Some(face) => FillScope::Connected { face },
                None => {
                    ctx.status.set(Severity::Info, "Fill connected: point at the mesh first.");
                    return;
                }
            }
        } else {
            FillScope::All
        };
        let settings = *ctx.brush;
        let result = self.with_paint(ctx, |view, store, _, history| {
            brush::fill(store, history, scope, settings.color, settings.blend, settings.strength, view.base)
        });
        match result {
            Some(Ok(stats)) => {
                self.edit_generation += 1;
                ctx.status.set(Severity::Info, format!("Fill: {} samples changed", thousands(stats.samples_changed)));
            }
            Some(Err(error)) => ctx.status.set(Severity::Error, format!("Fill: {error}")),
            None => {}
        }
    }

    /// Sets the resolution of every face.
    pub fn set_resolution_all(&mut self, ctx: &mut PaintContext<'_>, resolution: Resolution, budget: Budget) {
        let format = self.open.as_ref().map_or_else(Default::default, |open| open.format);
        let result = self.with_paint(ctx, |_, store, _, history| {
            brush::set_resolution(store, history, None, resolution, Some((&budget, format)))
        });
        match result {
            Some(Ok(changed)) => {
                self.edit_generation += 1;
                if let Some(open) = self.open.as_mut() {
                    open.samples = open.document.store.sample_count();
                }
                ctx.status
                    .set(Severity::Info, format!("R = {} on {} faces", resolution.get(), thousands(changed.into())));
            }
            Some(Err(error)) => ctx.status.set(Severity::Error, format!("Set resolution: {error}")),
            None => ctx.status.set(Severity::Info, "Set R for all works in paint mode (Tab)."),
        }
    }

    /// Starts the radius (F) or strength (Shift+F) gesture at the pointer.
    pub fn start_gesture(&mut self, ctx: &mut PaintContext<'_>, kind: GestureKind) {
        let pointer = ctx.viewport.pointer.unwrap_or_else(|| ctx.viewport.rect.center());
        let radius_pt = brush_radius_points(ctx.brush, ctx.viewport, ctx.camera);
        let before = *ctx.brush;
        let Some(session) = self.paint.as_mut() else {
            return;
        };
        let offset = match kind {
            GestureKind::Radius => radius_pt,
            GestureKind::Strength => before.strength * STRENGTH_GESTURE_POINTS,
        };
        session.gesture = Some(Gesture { kind, center: pointer - egui::vec2(offset, 0.0), before });
        let what = match kind {
            GestureKind::Radius => "radius",
            GestureKind::Strength => "strength",
        };
        ctx.status.set(Severity::Info, format!("Move to set the {what}; click or Enter confirms, Esc cancels."));
    }

    /// Follows the pointer during a gesture, and confirms or cancels it. Returns whether a
    /// gesture is running (it then owns the pointer).
    pub(crate) fn gesture_input(&mut self, ctx: &mut PaintContext<'_>, input: &egui::Context) -> bool {
        let Some(gesture) = self.paint.as_ref().and_then(|p| p.gesture) else {
            return false;
        };
        let (pointer, primary, secondary) =
            input.input(|i| (i.pointer.latest_pos(), i.pointer.primary_pressed(), i.pointer.secondary_pressed()));
        let enter = input.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Enter));
        let escape = input.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Escape));
        if let Some(pointer) = pointer {
            let distance = (pointer - gesture.center).length();
            match gesture.kind {
                GestureKind::Radius => {
                    let ppp = f64::from(ctx.viewport.pixels_per_point);
                    let px = (f64::from(distance) * ppp).clamp(1.0, 2000.0);
                    ctx.brush.radius = match gesture.before.radius {
                        BrushRadius::Pixels { .. } => BrushRadius::Pixels { radius_px: px },
                        BrushRadius::World { radius_world } => {
                            let before =
                                f64::from(brush_radius_points(&gesture.before, ctx.viewport, ctx.camera)).max(1e-6);
                            BrushRadius::World { radius_world: radius_world * f64::from(distance).max(0.5) / before }
                        }
                    }
                }
                GestureKind::Strength => {
                    ctx.brush.strength = (distance / STRENGTH_GESTURE_POINTS).clamp(0.0, 1.0);
                }
            }
        }
        if primary || enter || secondary || escape {
            let confirmed = primary || enter;
            if !confirmed {
                *ctx.brush = gesture.before;
            }
            if let Some(session) = self.paint.as_mut() {
                session.gesture = None;
                session.swallow_primary = primary;
            }
            let text = match (confirmed, gesture.kind) {
                (false, _) => "Cancelled.".to_owned(),
                (true, GestureKind::Radius) => format!("Radius {}", radius_text(ctx.brush.radius)),
                (true, GestureKind::Strength) => format!("Strength {:.2}", ctx.brush.strength),
            };
            ctx.status.set(Severity::Info, text);
        }
        input.request_repaint();
        true
    }

    /// Lowers face resolutions while every shown colour stays within `bound`
    /// (`paint::optimize`): plans the changes on a worker thread (the status line shows its
    /// progress), then applies them as one undo step and reports the memory before and after.
    pub fn optimize_resolutions(&mut self, ctx: &mut PaintContext<'_>, bound: f32) {
        if self.paint.is_none() {
            ctx.status.set(Severity::Info, "Optimize works in paint mode (Tab).");
            return;
        }
        if ctx.jobs.is_busy() {
            ctx.status.set(Severity::Warning, "Busy: wait for the running job to finish before optimizing.");
            return;
        }
        self.end_stroke(ctx);
        let Some(open) = &self.open else {
            return;
        };
        let document = Arc::clone(&open.document);
        let generation = self.edit_generation;
        let started = ctx.jobs.start(JobKind::Optimize, "Optimizing", move |job| {
            let plan =
                optimize::plan(&document.store, bound, &|fraction| job.progress(fraction, "trying lower resolutions"))
                    .map_err(|error| error.to_string())?;
            Ok(JobOutput::Optimized(Box::new(Optimized { plan, generation, bound })))
        });
        match started {
            Ok(()) => ctx.status.set(Severity::Info, format!("Optimizing (E = {bound})…")),
            Err(message) => ctx.status.set(Severity::Error, message),
        }
    }

    /// Applies a finished Optimize plan if the document is still the one planned on.
    pub(crate) fn finish_optimize(&mut self, ctx: &mut PaintContext<'_>, optimized: Optimized, elapsed: Duration) {
        let Optimized { plan, generation, bound } = optimized;
        if generation != self.edit_generation || self.paint.is_none() {
            ctx.status.set(
                Severity::Warning,
                "The colours changed while Optimize ran (or paint mode ended); nothing was changed. Run it again.",
            );
            return;
        }
        let result = self.with_paint(ctx, |_, store, _, history| optimize::apply(store, history, &plan));
        match result {
            Some(Ok(report)) => {
                if report.step.is_some() {
                    self.edit_generation += 1;
                }
                if let Some(open) = self.open.as_mut() {
                    open.samples = open.document.store.sample_count();
                }
                // The store keeps RGBA32F samples: 16 bytes each.
                let bytes = |samples: u64| human_bytes(samples.saturating_mul(16));
                ctx.status.set(
                    Severity::Info,
                    format!(
                        "Optimize (E = {bound}): {} faces lowered, samples {} to {} ({} to {}), largest change {:.2e} ({:.2} s)",
                        thousands(report.faces_lowered.into()),
                        thousands(report.samples_before),
                        thousands(report.samples_after),
                        bytes(report.samples_before),
                        bytes(report.samples_after),
                        report.max_error,
                        elapsed.as_secs_f64()
                    ),
                );
            }
            Some(Err(error)) => ctx.status.set(Severity::Error, format!("Optimize: {error}")),
            None => ctx.status.set(Severity::Info, "Optimize works in paint mode (Tab)."),
        }
    }
}

/// The radius of `brush` on screen, points. A world radius is converted at the depth of
/// the camera's target.
pub fn brush_radius_points(brush: &BrushSettings, viewport: &ViewportState, camera: &OrbitCamera) -> f32 {
    let ppp = f64::from(viewport.pixels_per_point.max(0.01));
    let px = match brush.radius {
        BrushRadius::Pixels { radius_px } => radius_px,
        BrushRadius::World { radius_world } => {
            let [_, h] = viewport.size_px();
            radius_world / camera.world_per_pixel(f64::from(h)).max(f64::MIN_POSITIVE)
        }
    };
    (px / ppp) as f32
}

/// Draws the brush circle (and the gesture's circle) of paint mode's `session` over the
/// 3D view.
pub fn draw_brush_cursor(
    painter: &egui::Painter,
    session: &PaintSession,
    brush: &BrushSettings,
    viewport: &ViewportState,
    camera: &OrbitCamera,
) {
    let stroke = egui::Stroke::new(1.5, egui::Color32::WHITE);
    let shadow = egui::Stroke::new(3.0, egui::Color32::from_black_alpha(140));
    if let Some(gesture) = session.gesture {
        let radius = match gesture.kind {
            GestureKind::Radius => brush_radius_points(brush, viewport, camera),
            GestureKind::Strength => brush.strength * STRENGTH_GESTURE_POINTS,
        };
        painter.circle_stroke(gesture.center, radius, shadow);
        painter.circle_stroke(gesture.center, radius, stroke);
        if gesture.kind == GestureKind::Strength {
            let fill = egui::Color32::from_white_alpha((brush.strength * 120.0) as u8);
            painter.circle_filled(gesture.center, radius, fill);
        }
        return;
    }
    if let Some(pos) = viewport.pointer {
        let radius = brush_radius_points(brush, viewport, camera);
        painter.circle_stroke(pos, radius, shadow);
        painter.circle_stroke(pos, radius, stroke);
        let [r, g, b, _] = brush.color.map(meshpaint_core::colors::format::encode_srgb8);
        painter.circle_filled(pos, 2.5, egui::Color32::from_rgb(r, g, b));
    }
}

/// A radius for messages.
pub fn radius_text(radius: BrushRadius) -> String {
    match radius {
        BrushRadius::Pixels { radius_px } => format!("{radius_px:.0} px"),
        BrushRadius::World { radius_world } => format!("{radius_world:.4} (world)"),
    }
}

/// What the status line says after a stroke: what changed, in plain words, and whether it
/// can be undone.
pub fn stroke_message(summary: &StepSummary, samples_changed: u64) -> String {
    let mut label = summary.label.clone();
    if let Some(first) = label.get(..1) {
        label.replace_range(..1, &first.to_uppercase());
    }
    if summary.samples == 0 && summary.resolution_changes == 0 {
        return format!("{label}: nothing changed (the stroke missed the mesh, or the colour was already there)");
    }
    let mut parts = Vec::new();
    if summary.resolution_changes > 0 {
        let faces = summary.resolution_changes;
        parts.push(format!("resolution changed on {} {}", thousands(faces), if faces == 1 { "face" } else { "faces" }));
    }
    if samples_changed > 0 {
        parts.push(format!("{} samples changed", thousands(samples_changed)));
    }
    let undo = if summary.kept { "" } else { "; too large for the undo memory, so it cannot be undone" };
    format!("{label}: {}{undo}", parts.join(", "))
}
