//! The state of paint mode while it is on: the paint layout, the base snapshot, the brush
//! engine and an interactive gesture; and the result of the repack job that ends it. The
//! editor's paint-mode commands are in [`super::paint`], its panel in `panels::paint`.

use std::sync::Arc;
use std::time::Duration;

use meshpaint_core::colors::store::{ColorStore, DirtyAccumulator};
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::topology::VertexFaces;
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::packing::paint_layout::{EncodedBuffer, PaintLayout};
use meshpaint_core::paint::brush::{self, Painter};
use meshpaint_render::{AtlasWriter, GpuContext, GpuMesh, RenderError};

/// Points of pointer travel for strength 0 → 1 in the Shift+F gesture.
pub const STRENGTH_GESTURE_POINTS: f32 = 200.0;

/// Which brush value an interactive gesture changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GestureKind {
    /// The radius (F).
    Radius,
    /// The strength (Shift+F).
    Strength,
}

/// An interactive radius / strength gesture in progress: the value follows the pointer's
/// distance from `center`; a click or Enter confirms, Esc or a right click cancels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gesture {
    /// What it changes.
    pub kind: GestureKind,
    /// The circle's centre, points.
    pub center: egui::Pos2,
    /// The settings before the gesture (restored on cancel).
    pub before: brush::BrushSettings,
}

/// The state of paint mode while it is on.
#[derive(Debug)]
pub struct PaintSession {
    /// Where every element's samples live in the GPU colour buffer.
    pub layout: PaintLayout,
    /// The encoded paint buffer as the GPU holds it (uploads send merged spans from it);
    /// `None` without a GPU.
    pub encoded: Option<EncodedBuffer>,
    /// `encoded` holds the bytes of [`PaintSession::pack_cache`], lent to paint the mesh the
    /// view showed in place ([`meshpaint_render::Gpu::enter_paint`]); they go back on leaving.
    pub lent_colors: bool,
    /// The colours when paint mode was entered (Erase to base).
    pub base: ColorStore,
    /// The brush engine.
    pub painter: Painter,
    /// A radius / strength gesture in progress.
    pub gesture: Option<Gesture>,
    /// The pointer's last position over the 3D view, points (fill connected, eyedropper).
    pub last_pointer: Option<egui::Pos2>,
    /// The primary button went down to confirm a gesture: no stroke until it is released.
    pub swallow_primary: bool,
    /// Bytes uploaded by the current (or last) stroke.
    pub stroke_upload_bytes: u64,
    /// An upload failed: the GPU mesh stays stale until paint mode ends (reported once).
    pub upload_failed: bool,
    /// Samples changed by the current (or last) stroke.
    pub stroke_samples_changed: u64,
    /// The compact packing from before paint mode (`None` when there was none): leaving
    /// repacks only what [`PaintSession::repack_dirty`] reaches.
    pub pack_cache: Option<PackCache>,
    /// The compact buffers on the GPU from before paint mode, patched in place on leaving.
    pub compact_gpu_mesh: Option<GpuMesh>,
    /// Every element changed during the session (the union of the dirty sets of all dabs).
    pub repack_dirty: DirtyAccumulator,
    /// The faces around each vertex: which faces a dab's changes show on (the 3D view
    /// redraws only those).
    pub vertex_faces: VertexFaces,
}

impl PaintSession {
    /// What the repack on leaving starts from: the packing (its lent bytes given back), every
    /// change of the session, and the compact GPU buffers to patch in place: those kept
    /// aside, or the ones `shown` (the view's mesh) when the session painted them in place.
    pub fn into_repack_inputs(
        mut self,
        shown: Option<&GpuMesh>,
    ) -> (Option<PackCache>, DirtyAccumulator, Option<CompactMesh>) {
        let mut cache = self.pack_cache.take();
        let compact = if self.lent_colors {
            if let (Some(cache), Some(encoded)) = (cache.as_mut(), self.encoded.take()) {
                cache.return_colors(encoded.into_bytes());
            }
            shown.map(|mesh| CompactMesh::Shown(mesh.atlas_writer()))
        } else {
            self.compact_gpu_mesh.take().map(|mesh| CompactMesh::Owned(Box::new(mesh)))
        };
        (cache, self.repack_dirty, compact)
    }
}

/// The compact buffers on the GPU a repack patches in place.
#[derive(Debug)]
pub enum CompactMesh {
    /// Kept aside during paint mode; the view shows it again when the repack is done.
    Owned(Box<GpuMesh>),
    /// The mesh the view shows (paint mode painted it in place): written through its atlas.
    Shown(AtlasWriter),
}

impl CompactMesh {
    /// Overwrites samples `first..` with `encoded`.
    pub fn write_samples(&self, ctx: &GpuContext, first: u64, encoded: &[u8]) -> Result<(), RenderError> {
        match self {
            CompactMesh::Owned(mesh) => mesh.write_samples(ctx, first, encoded),
            CompactMesh::Shown(atlas) => atlas.write_samples(ctx, first, encoded),
        }
    }

    /// The mesh for the view to show afterwards (`None`: keep the one shown).
    pub fn into_mesh(self) -> Option<GpuMesh> {
        match self {
            CompactMesh::Owned(mesh) => Some(*mesh),
            CompactMesh::Shown(_) => None,
        }
    }
}

/// Which repack leaving paint mode ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Repack {
    /// Only the chains the session's edits reach, in place (no resolution changed).
    ChangedChains,
    /// A new layout, the chains no edit reached moved into it (a resolution changed).
    Relayout,
    /// Every chain (no earlier packing, or another format).
    Full,
}

impl Repack {
    /// How the status line says it (empty for a full repack).
    pub fn note(self) -> &'static str {
        match self {
            Repack::ChangedChains => " (changed chains only)",
            Repack::Relayout => " (new layout, unchanged chains moved)",
            Repack::Full => "",
        }
    }
}

/// The result of a repack job (leaving paint mode).
#[derive(Debug)]
pub struct Repacked {
    /// The document that was packed (applied only if it is still the open one).
    pub document: Arc<Document>,
    /// The compact buffers on the GPU (`None` without a GPU, or when the view's mesh was
    /// patched in place).
    pub gpu_mesh: Option<GpuMesh>,
    /// Samples with MIP chains.
    pub samples_with_mips: u64,
    /// Bytes of face records and colours.
    pub packed_bytes: u64,
    /// How long packing took.
    pub pack_time: Duration,
    /// Which repack ran.
    pub how: Repack,
    /// The packing, kept for the next incremental repack.
    pub cache: PackCache,
}
