//! Paint mode: the session state (brush, paint layout, base snapshot), strokes from the
//! pointer, the live GPU upload after every dab, undo / redo, eyedropper, fill, resolution
//! commands, the interactive radius / strength gestures (F / Shift+F), the tool panel and
//! the brush cursor.
//!
//! Entering paint mode switches the GPU mesh to the paint layout
//! ([`meshpaint_core::packing::paint_layout::PaintLayout`], level 0 only); leaving repacks the store into the
//! compact layout with MIP chains on a worker thread ([`Editor::leave_paint_mode`]).

use std::sync::Arc;
use std::time::Instant;

use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, DirtyAccumulator};
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::packing::paint_layout::PaintLayout;
use meshpaint_core::paint::brush::{
    self, BlendMode, BrushRadius, BrushSettings, Falloff, FillScope, PaintView, Painter, ResolutionOp, StrokeUpdate,
    Tool,
};
use meshpaint_core::paint::undo::UndoHistory;

use super::editor::{Editor, JobOutput};
use super::jobs::JobKind;
use super::paint_session::{Gesture, GestureKind, PaintSession, Repack, Repacked, STRENGTH_GESTURE_POINTS};
use super::state::{Mode, Severity};
use super::text::{human_bytes, thousands};

/// The egui colour of a linear straight-alpha colour.
fn to_egui(color: [f32; 4]) -> egui::Rgba {
    egui::Rgba::from_rgba_unmultiplied(color[0], color[1], color[2], color[3])
}

impl Editor {
    /// Tab: enters or leaves paint mode.
    pub fn toggle_paint_mode(&mut self) {
        match self.mode {
            Mode::View => self.enter_paint_mode(),
            Mode::Paint => self.leave_paint_mode(),
        }
    }

    /// Enters paint mode: snapshots the base colours, builds the paint layout and uploads it.
    pub fn enter_paint_mode(&mut self) {
        if self.jobs.is_busy() {
            self.set_status(Severity::Warning, "Busy: wait for the running job to finish before painting.");
            return;
        }
        let budget = self.budget();
        let Some(open) = self.document.as_mut() else {
            self.set_status(Severity::Error, "Nothing to paint: no document is open.");
            return;
        };
        let started = Instant::now();
        let document = Arc::make_mut(&mut open.document);
        // Changes from before (none expected) are in the new layout anyway; the compact
        // packing is reused on leaving only if it is still the store's.
        let unpacked_changes = !document.store.take_dirty().is_empty();
        let layout = PaintLayout::new(&document.store);
        let (mut compact_gpu_mesh, mut encoded) = (None, None);
        if let Some(gpu) = &self.gpu {
            match gpu.upload_paint_layout(&layout, &document.store, &document.positions, open.format) {
                Ok(upload) => {
                    self.upload_bytes_this_frame += upload.bytes;
                    compact_gpu_mesh = open.gpu_mesh.replace(upload.mesh);
                    encoded = Some(upload.encoded);
                }
                Err(error) => {
                    let text = format!("Cannot enter paint mode: uploading the paint layout failed: {error}");
                    self.set_status(Severity::Error, text);
                    return;
                }
            }
        }
        let painter = {
            let mut painter = Painter::new(&document.positions);
            painter.set_settings(self.brush);
            painter.set_budget(Some((budget, open.format)));
            painter
        };
        self.paint = Some(PaintSession {
            layout,
            encoded,
            base: document.store.clone(),
            painter,
            gesture: None,
            last_pointer: None,
            swallow_primary: false,
            stroke_upload_bytes: 0,
            stroke_samples_changed: 0,
            upload_failed: false,
            pack_cache: if unpacked_changes { None } else { open.pack_cache.take() },
            compact_gpu_mesh,
            repack_dirty: DirtyAccumulator::new(document.store.topology()),
        });
        self.gpu_paint_layout = true;
        self.mode = Mode::Paint;
        self.scene_generation += 1;
        let ms = started.elapsed().as_secs_f64() * 1000.0;
        self.set_status(Severity::Info, format!("Paint mode (level 0 on the GPU, set up in {ms:.0} ms). Tab leaves."));
    }

    /// Leaves paint mode: repacks the store into compact buffers with MIP chains on a worker
    /// thread (the status line shows its progress) and replaces the GPU buffers when done.
    pub fn leave_paint_mode(&mut self) {
        if self.jobs.is_busy() {
            self.set_status(Severity::Warning, "Busy: wait for the running job to finish before leaving paint mode.");
            return;
        }
        self.end_stroke();
        let session = self.paint.take();
        self.mode = Mode::View;
        let Some(open) = &self.document else {
            return;
        };
        let (cache, mut dirty, compact_gpu_mesh) = match session {
            Some(mut session) => (session.pack_cache.take(), session.repack_dirty, session.compact_gpu_mesh.take()),
            None => (None, DirtyAccumulator::default(), None),
        };
        let document = Arc::clone(&open.document);
        let format = open.format;
        let gpu = self.gpu.clone();
        let started = self.jobs.start(JobKind::Repack, "Repacking", move |job| {
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
                    Some(mesh)
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
            Ok(()) => self.set_status(Severity::Info, "Repacking…"),
            Err(message) => self.set_status(Severity::Error, message),
        }
    }

    /// Pixel coordinates in the 3D view of `pos` (points, window coordinates).
    fn view_px(&self, pos: egui::Pos2) -> [f64; 2] {
        let ppp = f64::from(self.viewport.pixels_per_point);
        let rect = self.viewport.rect;
        [f64::from(pos.x - rect.min.x) * ppp, f64::from(pos.y - rect.min.y) * ppp]
    }

    /// Runs `work` with the paint view, the store, the painter and the history; uploads the
    /// changes afterwards.
    pub(crate) fn with_paint<T>(
        &mut self,
        work: impl FnOnce(&PaintView, &mut ColorStore, &mut Painter, &mut UndoHistory) -> T,
    ) -> Option<T> {
        let viewport_px = self.viewport.size_px();
        let Editor { document, paint, history, camera, .. } = self;
        let (open, session) = (document.as_mut()?, paint.as_mut()?);
        let doc = Arc::make_mut(&mut open.document);
        let PaintSession { base, painter, .. } = session;
        let view =
            PaintView { positions: &doc.positions, bvh: &open.bvh, camera: &*camera, viewport_px, base: Some(base) };
        let result = work(&view, &mut doc.store, painter, history);
        self.sync_gpu();
        Some(result)
    }

    /// Counts a stroke update; reports brush errors.
    fn stroke_result(&mut self, result: Option<Result<StrokeUpdate, brush::BrushError>>) {
        match result {
            Some(Ok(update)) => {
                if let Some(session) = self.paint.as_mut() {
                    session.stroke_samples_changed += update.stats.samples_changed;
                }
                if update.stats.samples_changed > 0 || update.stats.faces_resized > 0 {
                    self.edit_generation += 1;
                }
            }
            Some(Err(error)) => {
                self.end_stroke();
                self.set_status(Severity::Error, format!("Brush: {error}"));
            }
            None => {}
        }
    }

    /// Starts a stroke at `pos` (points).
    pub fn begin_stroke(&mut self, pos: egui::Pos2) {
        let px = self.view_px(pos);
        let settings = self.brush;
        if let Some(session) = self.paint.as_mut() {
            session.painter.set_settings(settings);
            session.stroke_upload_bytes = 0;
            session.stroke_samples_changed = 0;
        }
        let result = self.with_paint(|view, store, painter, history| painter.begin_stroke(view, store, history, px));
        self.stroke_result(result);
    }

    /// Extends the stroke to `pos` (points).
    pub fn stroke_to(&mut self, pos: egui::Pos2) {
        let px = self.view_px(pos);
        let result = self.with_paint(|view, store, painter, history| painter.stroke_to(view, store, history, px));
        self.stroke_result(result);
    }

    /// Ends the stroke (closes its undo step).
    pub fn end_stroke(&mut self) {
        let Editor { paint, history, .. } = self;
        let Some(session) = paint.as_mut() else {
            return;
        };
        if !session.painter.is_stroking() {
            return;
        }
        let summary = session.painter.end_stroke(history);
        let (bytes, changed) = (session.stroke_upload_bytes, session.stroke_samples_changed);
        if let Some(summary) = summary {
            let kept = if summary.kept { "" } else { " (too large for the undo memory cap: not undoable)" };
            self.set_status(
                Severity::Info,
                format!(
                    "{}: {} sample updates, {} uploaded{kept}",
                    summary.label,
                    thousands(changed),
                    human_bytes(bytes)
                ),
            );
        }
    }

    /// Uploads what changed in the store since the last call: the dirty blocks of the paint
    /// layout and the changed face records, or everything when the layout grew.
    pub fn sync_gpu(&mut self) {
        let Editor { document, paint, gpu, .. } = self;
        let (Some(open), Some(session)) = (document.as_mut(), paint.as_mut()) else {
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
        if let (Some(gpu), Some(mesh)) = (gpu.as_ref(), open.gpu_mesh.as_mut()) {
            match session.encoded.as_mut() {
                Some(encoded) if !plan.grown && encoded.format() == open.format => {
                    let spans = encoded.apply(&session.layout, &doc.store, &dirty, &plan);
                    let records = (plan.faces.as_slice(), session.layout.records());
                    match mesh.write_paint_upload(&gpu.ctx, &spans, encoded.bytes(), records) {
                        Ok(written) => bytes += written,
                        Err(e) => error = Some(e.to_string()),
                    }
                }
                _ => match gpu.upload_paint_layout(&session.layout, &doc.store, &doc.positions, open.format) {
                    Ok(upload) => {
                        *mesh = upload.mesh;
                        bytes += upload.bytes;
                        session.encoded = Some(upload.encoded);
                    }
                    Err(e) => error = Some(e.to_string()),
                },
            }
        }
        session.stroke_upload_bytes += bytes;
        self.upload_bytes_this_frame += bytes;
        self.scene_generation += 1;
        if let Some(error) = error {
            session.upload_failed = true;
            self.set_status(
                Severity::Error,
                format!("Uploading the painted samples failed: {error}. The view shows the colours before; leave paint mode (Tab) to upload them again."),
            );
        }
    }

    /// Ctrl+Z: undoes the last stroke (paint mode only).
    pub fn undo(&mut self) {
        self.undo_redo(true);
    }

    /// Ctrl+Shift+Z: redoes the last undone stroke (paint mode only).
    pub fn redo(&mut self) {
        self.undo_redo(false);
    }

    fn undo_redo(&mut self, undo: bool) {
        if self.mode != Mode::Paint {
            self.set_status(Severity::Info, "Undo and redo work in paint mode (Tab).");
            return;
        }
        self.end_stroke();
        let label = if undo { self.history.undo_label() } else { self.history.redo_label() }.map(str::to_owned);
        let result =
            self.with_paint(|_, store, _, history| if undo { history.undo(store) } else { history.redo(store) });
        let verb = if undo { "Undo" } else { "Redo" };
        match result {
            Some(Ok(true)) => {
                self.edit_generation += 1;
                self.set_status(Severity::Info, format!("{verb}: {}", label.unwrap_or_default()));
            }
            Some(Ok(false)) => self.set_status(Severity::Info, format!("Nothing to {}.", verb.to_lowercase())),
            Some(Err(error)) => self.set_status(Severity::Error, format!("{verb} failed: {error}")),
            None => {}
        }
    }

    /// S: picks the colour under the pointer into the brush.
    pub fn eyedropper(&mut self) {
        let Some(pos) = self.viewport_pointer.or_else(|| self.paint.as_ref().and_then(|p| p.last_pointer)) else {
            return;
        };
        let px = self.view_px(pos);
        let picked = self.with_paint(|view, store, _, _| brush::eyedropper(view, store, px)).flatten();
        match picked {
            Some(color) => {
                self.brush.color = color;
                let [r, g, b, _] = color.map(meshpaint_core::colors::format::encode_srgb8);
                self.set_status(Severity::Info, format!("Picked colour #{r:02x}{g:02x}{b:02x}"));
            }
            None => self.set_status(Severity::Info, "Eyedropper: nothing under the cursor."),
        }
    }

    /// Fills the whole mesh, or the part connected to the face last under the pointer.
    pub fn fill(&mut self, connected: bool) {
        let scope = if connected {
            let pos = self.paint.as_ref().and_then(|p| p.last_pointer);
            let face = pos.and_then(|pos| {
                let px = self.view_px(pos);
                self.with_paint(|view, _, _, _| view.pick(px)).flatten().map(|hit| hit.face)
            });
            match face {
                Some(face) => FillScope::Connected { face },
                None => {
                    self.set_status(Severity::Info, "Fill connected: point at the mesh first.");
                    return;
                }
            }
        } else {
            FillScope::All
        };
        let settings = self.brush;
        let result = self.with_paint(|view, store, _, history| {
            brush::fill(store, history, scope, settings.color, settings.blend, settings.strength, view.base)
        });
        match result {
            Some(Ok(stats)) => {
                self.edit_generation += 1;
                self.set_status(Severity::Info, format!("Fill: {} samples changed", thousands(stats.samples_changed)));
            }
            Some(Err(error)) => self.set_status(Severity::Error, format!("Fill: {error}")),
            None => {}
        }
    }

    /// Sets the resolution of every face.
    pub fn set_resolution_all(&mut self, resolution: Resolution) {
        let budget = self.budget();
        let format = self.document.as_ref().map_or_else(Default::default, |open| open.format);
        let result = self.with_paint(|_, store, _, history| {
            brush::set_resolution(store, history, None, resolution, Some((&budget, format)))
        });
        match result {
            Some(Ok(changed)) => {
                self.edit_generation += 1;
                if let Some(open) = self.document.as_mut() {
                    open.samples = open.document.store.sample_count();
                }
                self.set_status(
                    Severity::Info,
                    format!("R = {} on {} faces", resolution.get(), thousands(changed.into())),
                );
            }
            Some(Err(error)) => self.set_status(Severity::Error, format!("Set resolution: {error}")),
            None => self.set_status(Severity::Info, "Set R for all works in paint mode (Tab)."),
        }
    }

    /// Starts the radius (F) or strength (Shift+F) gesture at the pointer.
    pub fn start_gesture(&mut self, kind: GestureKind) {
        let pointer = self.viewport_pointer.unwrap_or_else(|| self.viewport.rect.center());
        let radius_pt = self.brush_radius_points(None);
        let before = self.brush;
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
        self.set_status(Severity::Info, format!("Move to set the {what}; click or Enter confirms, Esc cancels."));
    }

    /// Follows the pointer during a gesture, and confirms or cancels it. Returns whether a
    /// gesture is running (it then owns the pointer).
    pub(crate) fn gesture_input(&mut self, ctx: &egui::Context) -> bool {
        let Some(gesture) = self.paint.as_ref().and_then(|p| p.gesture) else {
            return false;
        };
        let (pointer, primary, secondary) =
            ctx.input(|i| (i.pointer.latest_pos(), i.pointer.primary_pressed(), i.pointer.secondary_pressed()));
        let enter = ctx.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Enter));
        let escape = ctx.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Escape));
        if let Some(pointer) = pointer {
            let distance = (pointer - gesture.center).length();
            match gesture.kind {
                GestureKind::Radius => {
                    let ppp = f64::from(self.viewport.pixels_per_point);
                    let px = (f64::from(distance) * ppp).clamp(1.0, 2000.0);
                    self.brush.radius = match gesture.before.radius {
                        BrushRadius::Pixels { .. } => BrushRadius::Pixels { radius_px: px },
                        BrushRadius::World { radius_world } => {
                            let before = f64::from(self.brush_radius_points(Some(gesture.before))).max(1e-6);
                            BrushRadius::World { radius_world: radius_world * f64::from(distance).max(0.5) / before }
                        }
                    }
                }
                GestureKind::Strength => {
                    self.brush.strength = (distance / STRENGTH_GESTURE_POINTS).clamp(0.0, 1.0);
                }
            }
        }
        if primary || enter || secondary || escape {
            let confirmed = primary || enter;
            if !confirmed {
                self.brush = gesture.before;
            }
            if let Some(session) = self.paint.as_mut() {
                session.gesture = None;
                session.swallow_primary = primary;
            }
            let text = match (confirmed, gesture.kind) {
                (false, _) => "Cancelled.".to_owned(),
                (true, GestureKind::Radius) => format!("Radius {}", radius_text(self.brush.radius)),
                (true, GestureKind::Strength) => format!("Strength {:.2}", self.brush.strength),
            };
            self.set_status(Severity::Info, text);
        }
        ctx.request_repaint();
        true
    }

    /// The brush radius on screen, points (`settings` or the current brush). A world radius
    /// is converted at the depth of the camera's target.
    pub fn brush_radius_points(&self, settings: Option<brush::BrushSettings>) -> f32 {
        let settings = settings.unwrap_or(self.brush);
        let ppp = f64::from(self.viewport.pixels_per_point.max(0.01));
        let px = match settings.radius {
            BrushRadius::Pixels { radius_px } => radius_px,
            BrushRadius::World { radius_world } => {
                let [_, h] = self.viewport.size_px();
                radius_world / self.camera.world_per_pixel(f64::from(h)).max(f64::MIN_POSITIVE)
            }
        };
        (px / ppp) as f32
    }

    /// Draws the brush circle (and the gesture's circle) over the 3D view.
    pub fn brush_cursor_ui(&self, painter: &egui::Painter) {
        let Some(session) = &self.paint else {
            return;
        };
        let stroke = egui::Stroke::new(1.5, egui::Color32::WHITE);
        let shadow = egui::Stroke::new(3.0, egui::Color32::from_black_alpha(140));
        if let Some(gesture) = session.gesture {
            let radius = match gesture.kind {
                GestureKind::Radius => self.brush_radius_points(None),
                GestureKind::Strength => self.brush.strength * STRENGTH_GESTURE_POINTS,
            };
            painter.circle_stroke(gesture.center, radius, shadow);
            painter.circle_stroke(gesture.center, radius, stroke);
            if gesture.kind == GestureKind::Strength {
                let fill = egui::Color32::from_white_alpha((self.brush.strength * 120.0) as u8);
                painter.circle_filled(gesture.center, radius, fill);
            }
            return;
        }
        if let Some(pos) = self.viewport_pointer {
            let radius = self.brush_radius_points(None);
            painter.circle_stroke(pos, radius, shadow);
            painter.circle_stroke(pos, radius, stroke);
            let [r, g, b, _] = self.brush.color.map(meshpaint_core::colors::format::encode_srgb8);
            painter.circle_filled(pos, 2.5, egui::Color32::from_rgb(r, g, b));
        }
    }

    /// The paint tool panel: tool, colour, radius, strength, falloff, spacing, blend mode,
    /// occlusion, culling, mirror, fill, resolution, undo / redo and their memory.
    pub fn paint_panel_ui(&mut self, ui: &mut egui::Ui) {
        let painting = self.mode == Mode::Paint;
        let button = if painting { "Leave paint mode (Tab)" } else { "Enter paint mode (Tab)" };
        if ui.add_enabled(self.document.is_some(), egui::Button::new(button)).clicked() {
            self.toggle_paint_mode();
        }
        let bounds_radius = self.document.as_ref().map(|d| d.bounds.radius);
        brush_settings_ui(ui, &mut self.brush, bounds_radius);
        ui.separator();
        self.paint_commands_ui(ui, painting);
    }

    /// The panel's commands (eyedropper, fill, resolution for all, undo / redo) and the undo
    /// memory.
    fn paint_commands_ui(&mut self, ui: &mut egui::Ui, painting: bool) {
        ui.add_enabled_ui(painting, |ui| {
            ui.horizontal_wrapped(|ui| {
                if ui.button("Eyedropper").on_hover_text("S over the mesh").clicked() {
                    self.eyedropper();
                }
                if ui.button("Fill all").clicked() {
                    self.fill(false);
                }
                if ui.button("Fill connected").on_hover_text("The part last under the cursor").clicked() {
                    self.fill(true);
                }
            });
            ui.horizontal(|ui| {
                let mut r = self.resolution_for_all;
                resolution_combo_ui(ui, "All faces:", &mut r);
                self.resolution_for_all = r;
                if ui.button("Set R for all").clicked() {
                    self.set_resolution_all(r);
                }
            });
            ui.horizontal(|ui| {
                ui.label("Error bound");
                ui.add(egui::DragValue::new(&mut self.optimize_bound).range(0.0..=1.0).speed(0.001).max_decimals(3))
                    .on_hover_text("Largest change of any shown colour channel (linear light, 0..1); 0 = lossless");
                if ui
                    .button("Optimize")
                    .on_hover_text("Lower each face's R while what the mesh shows stays within the bound (undoable)")
                    .clicked()
                {
                    self.optimize_resolutions();
                }
            });
            ui.horizontal(|ui| {
                let undo = ui
                    .add_enabled(self.history.undo_len() > 0, egui::Button::new("Undo"))
                    .on_hover_text(self.history.undo_label().unwrap_or("Ctrl+Z"));
                if undo.clicked() {
                    self.undo();
                }
                let redo = ui
                    .add_enabled(self.history.redo_len() > 0, egui::Button::new("Redo"))
                    .on_hover_text(self.history.redo_label().unwrap_or("Ctrl+Shift+Z"));
                if redo.clicked() {
                    self.redo();
                }
            });
        });
        ui.label(format!(
            "Undo: {} steps, {} / {}",
            self.history.undo_len(),
            human_bytes(self.history.bytes_used() as u64),
            human_bytes(self.history.cap_bytes() as u64)
        ));
        let mut cap_mib = (self.history.cap_bytes() >> 20) as u32;
        if ui.add(egui::Slider::new(&mut cap_mib, 1..=4096).logarithmic(true).text("Undo memory (MiB)")).changed() {
            self.history.set_cap_bytes((cap_mib as usize) << 20);
        }
        if let Some(session) = &self.paint {
            ui.label(
                egui::RichText::new(format!(
                    "Last stroke: {} sample updates, {} uploaded",
                    thousands(session.stroke_samples_changed),
                    human_bytes(session.stroke_upload_bytes)
                ))
                .weak(),
            );
        }
    }
}

/// The brush settings: tool, colour, radius (pixels or world units; `bounds_radius` of the
/// mesh scales the world slider), strength, spacing, falloff, blend, occlusion, culling,
/// mirror. The panel owns nothing else: it edits `brush` in place.
fn brush_settings_ui(ui: &mut egui::Ui, brush: &mut BrushSettings, bounds_radius: Option<f64>) {
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
            ui.horizontal(|ui| resolution_combo_ui(ui, "To:", r));
        }
    }
    ui.horizontal(|ui| {
        ui.label("Colour:");
        let mut color = to_egui(brush.color);
        if egui::color_picker::color_edit_button_rgba(ui, &mut color, egui::color_picker::Alpha::OnlyBlend).changed() {
            brush.color = color.to_rgba_unmultiplied();
        }
        let [r, g, b, _] = brush.color.map(meshpaint_core::colors::format::encode_srgb8);
        ui.label(egui::RichText::new(format!("#{r:02x}{g:02x}{b:02x}")).monospace().weak());
    });
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
    brush.follow_resolution = follow.then_some(meshpaint_core::paint::brush::FOLLOW_BRUSH_MAX_RESOLUTION);
}

/// A labelled combo box of resolutions 1 … 64.
fn resolution_combo_ui(ui: &mut egui::Ui, label: &str, resolution: &mut Resolution) {
    let label = ui.label(label);
    egui::ComboBox::from_id_salt(label.id)
        .selected_text(format!("R = {}", resolution.get()))
        .show_ui(ui, |ui| {
            for log2 in 0..=6 {
                if let Ok(r) = Resolution::from_log2(log2) {
                    ui.selectable_value(resolution, r, format!("R = {}", r.get()));
                }
            }
        })
        .response
        .labelled_by(label.id);
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

/// A radius for messages.
pub fn radius_text(radius: BrushRadius) -> String {
    match radius {
        BrushRadius::Pixels { radius_px } => format!("{radius_px:.0} px"),
        BrushRadius::World { radius_world } => format!("{radius_world:.4} (world)"),
    }
}
