//! The document as the editor edits it: the open document, paint mode's session, the undo
//! history and the edit generation ([`DocumentState`]), and how finished jobs that produce
//! or change a document are applied to it. Paint mode's commands are in [`super::paint`].

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::paint::undo::{DEFAULT_CAP_BYTES, UndoHistory};

use super::document::{AlternateView, OpenDocument, Written};
use super::jobs::WriteKind;
use super::paint_session::{PaintSession, Repacked};
use super::state::{Mode, Severity, Status, ViewportState};
use super::text::{human_bytes, thousands};

/// The open document and what editing it keeps: paint mode, undo history, edit generation.
#[derive(Debug)]
pub struct DocumentState {
    /// The open document, if any.
    pub open: Option<OpenDocument>,
    /// Paint mode's state while it is on (paint mode is on exactly while this is `Some`).
    pub paint: Option<PaintSession>,
    /// Undo / redo of paint mode, one step per stroke (cleared when another document opens).
    pub history: UndoHistory,
    /// Counts edits of the colours (autosave and Optimize compare it).
    pub edit_generation: u64,
    /// The edit generation the document's file holds: set when it opens and when a save
    /// finishes ([`u64::MAX`] for a restored recovery file, whose colours no file holds yet).
    pub saved_generation: u64,
    /// The edit generation a running save writes.
    pub saving_generation: Option<u64>,
    /// The GPU mesh holds the paint layout (level 0 only): the filter is limited to level 0.
    pub gpu_paint_layout: bool,
}

impl Default for DocumentState {
    fn default() -> Self {
        DocumentState {
            open: None,
            paint: None,
            history: UndoHistory::new(DEFAULT_CAP_BYTES),
            edit_generation: 0,
            saved_generation: 0,
            saving_generation: None,
            gpu_paint_layout: false,
        }
    }
}

impl DocumentState {
    /// The interaction mode: paint while a paint session is on.
    pub fn mode(&self) -> Mode {
        if self.paint.is_some() { Mode::Paint } else { Mode::View }
    }

    /// Whether the 3D view shows level 0 only (the paint layout is, or is still, on the GPU).
    pub fn level0_only(&self) -> bool {
        self.gpu_paint_layout || self.paint.is_some()
    }

    /// Whether the colours changed since the document was opened or last saved.
    pub fn is_modified(&self) -> bool {
        self.open.is_some() && self.edit_generation != self.saved_generation
    }

    /// Whether a paint stroke is in progress.
    pub fn is_stroking(&self) -> bool {
        self.paint.as_ref().is_some_and(|p| p.painter.is_stroking())
    }

    /// A new document replaces the open one: paint mode, its GPU layout and the undo
    /// history end; the history checks `budget` (memory, colour format) from now on.
    pub fn replace(&mut self, document: OpenDocument, budget: (Budget, ColorFormat)) {
        self.paint = None;
        self.gpu_paint_layout = false;
        self.history.clear();
        self.history.set_budget(Some(budget));
        self.open = Some(document);
    }

    /// Applies a finished write: a save makes the written file the project (Save writes
    /// there, in its format, from now on).
    pub fn written(&mut self, written: &Written, kind: WriteKind) {
        let Some(open) = self.open.as_mut() else {
            return;
        };
        if let Some(repack) = written.repack {
            open.last_repack = repack;
        }
        if kind == WriteKind::Save {
            open.project_path = Some(written.path.clone());
            open.title = written
                .path
                .file_name()
                .map_or_else(|| written.path.display().to_string(), |n| n.to_string_lossy().into_owned());
            if let Some(format) = written.format {
                open.format = format;
            }
        }
    }

    /// Keeps a built alternate view if the document is still the one it was built for
    /// (opened from `path`); a view that cannot be shown is reported on `status`.
    pub fn finish_view(
        &mut self,
        path: Option<PathBuf>,
        view: AlternateView,
        viewport: &mut ViewportState,
        status: &mut Status,
    ) {
        let Some(open) = self.open.as_mut().filter(|open| open.path == path) else {
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
            AlternateView::Mct(generation, built) => {
                if generation != open.mesh_generation {
                    log::info!("a Mesh Color Texture finished for colours that changed since; ignored");
                    return;
                }
                let failed = match built.as_ref() {
                    Ok(built) => {
                        let [w, h] = built.mct.atlas_size;
                        status.set(
                            Severity::Info,
                            format!(
                                "Built the Mesh Color Texture: {w} × {h} atlas, {} ({:.2}× the mesh colors) in {:.0} ms",
                                human_bytes(built.mct.gpu_bytes()),
                                built.bytes_over_mesh_colors,
                                built.build.as_secs_f64() * 1000.0
                            ),
                        );
                        None
                    }
                    Err(message) => Some(message.clone()),
                };
                open.alternates.mct = Some((generation, *built));
                failed
            }
            AlternateView::Htex(generation, built) => {
                if generation != open.mesh_generation {
                    log::info!("an Htex finished for colours that changed since; ignored");
                    return;
                }
                let failed = built.as_ref().as_ref().err().cloned();
                if let Ok(built) = built.as_ref() {
                    let (e, f) = built.textures;
                    status.set(
                        Severity::Info,
                        format!(
                            "Built the Htex: {e} edge textures for {f} faces, {} ({:.2}× the mesh colors) in {:.0} ms",
                            human_bytes(built.htex.gpu_bytes()),
                            built.bytes_over_mesh_colors,
                            built.build.as_secs_f64() * 1000.0
                        ),
                    );
                }
                open.alternates.htex = Some((generation, *built));
                failed
            }
            AlternateView::Ptex(generation, built) => {
                if generation != open.mesh_generation {
                    log::info!("a packed Ptex finished for colours that changed since; ignored");
                    return;
                }
                let failed = match built.as_ref() {
                    Ok(built) => {
                        let [w, h] = built.ptex.size;
                        let text = format!(
                            "Built the packed Ptex: {w} × {h} texture, {} ({:.2}× the mesh colors) in {:.0} ms",
                            human_bytes(built.ptex.gpu_bytes()),
                            built.bytes_over_mesh_colors,
                            built.build.as_secs_f64() * 1000.0
                        );
                        status.set(Severity::Info, text);
                        None
                    }
                    Err(message) => Some(message.clone()),
                };
                open.alternates.ptex = Some((generation, *built));
                failed
            }
        };
        if let Some(message) = failed {
            status.set(Severity::Warning, format!("Cannot show it: {message}"));
        }
        viewport.scene_generation += 1;
    }

    /// Applies a finished repack (if the document is still the one packed and paint mode
    /// is off).
    pub fn finish_repack(
        &mut self,
        repacked: Repacked,
        elapsed: Duration,
        viewport: &mut ViewportState,
        status: &mut Status,
    ) {
        let painting = self.paint.is_some();
        let Some(open) = self.open.as_mut() else {
            return;
        };
        if !Arc::ptr_eq(&open.document, &repacked.document) || painting {
            log::info!("a repack finished for a document that changed since; ignored");
            return;
        }
        if let Some(mesh) = repacked.gpu_mesh {
            open.gpu_mesh = Some(mesh);
        }
        // The colours on the GPU changed: a Mesh Color Texture of the old ones is stale.
        open.mesh_generation += 1;
        open.alternates.mct = None;
        open.alternates.htex = None;
        open.alternates.ptex = None;
        open.samples_with_mips = repacked.samples_with_mips;
        open.packed_bytes = repacked.packed_bytes;
        open.samples = open.document.store.sample_count();
        open.last_repack = repacked.pack_time;
        open.pack_cache = Some(repacked.cache);
        self.gpu_paint_layout = false;
        viewport.scene_generation += 1;
        open.last_repack_how = Some(repacked.how);
        log::info!(
            "Repacked{}: {} samples with MIP chains in {:.1} ms ({:.2} s with the upload)",
            repacked.how.note(),
            thousands(repacked.samples_with_mips),
            repacked.pack_time.as_secs_f64() * 1000.0,
            elapsed.as_secs_f64()
        );
        status.set(
            Severity::Info,
            format!("Left paint mode: the colours are ready to view ({:.2} s)", elapsed.as_secs_f64()),
        );
    }
}

/// The status line's report of an opened document: size, time and its import notes (also
/// logged).
pub fn opened_text(document: &OpenDocument, elapsed: Duration) -> String {
    let mut text = format!(
        "Opened {}: {} triangles, {} samples ({:.2} s)",
        document.title,
        thousands(u64::from(document.triangles())),
        thousands(document.samples),
        elapsed.as_secs_f64()
    );
    // The conversion's rule and PSNR against the texture, and the faces the budget held.
    if let Some(conversion) = document.document.conversion.as_ref().filter(|c| c.texture_psnr_db.is_some()) {
        text.push_str(&format!("; {}", conversion.summary()));
    }
    let notes = &document.document.warnings;
    match notes.as_slice() {
        [] => {}
        [note] => text.push_str(&format!("; note: {note}")),
        [first, ..] => text.push_str(&format!("; {} notes, first: {first}", notes.len())),
    }
    for note in notes {
        log::info!("{}: {note}", document.title);
    }
    text
}
