//! One-shot tools: the eyedropper, fill (all faces, or the faces connected to one) and
//! "set resolution", each written through one [`StoreWriter`] as its own undo step.

use crate::colors::budget::{Budget, SampleCounts};
use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;
use crate::packing::sampler::{self, Filter};
use crate::paint::undo::{StoreWriter, UndoHistory};

use super::error::BrushError;
use super::footprint::Everywhere;
use super::kernels::{DabStats, PaintOp, paint_faces};
use super::painter::{PaintView, check_base};
use super::scratch::Scratch;
use super::settings::BlendMode;

/// The colour under the cursor: the store sampled linearly at the ray's hit (level 0), or
/// `None` off the mesh.
pub fn eyedropper(view: &PaintView, store: &ColorStore, cursor_px: [f64; 2]) -> Option<Rgba> {
    let hit = view.pick(cursor_px)?;
    sampler::sample(store, hit.face, hit.barycentric, Filter::Linear, 0)
}

/// Which faces a fill covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FillScope {
    /// Every face.
    All,
    /// The faces connected to `face` through shared edges.
    Connected {
        /// The seed face (e.g. the face under the cursor).
        face: u32,
    },
}

/// The faces connected to `seed` through shared edges (non-manifold edges connect all their
/// faces), sorted. Empty when `seed` does not exist.
pub fn connected_faces(store: &ColorStore, seed: u32) -> Vec<u32> {
    let topology = store.topology();
    let mut seen = vec![false; topology.face_count() as usize];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    if let Some(flag) = seen.get_mut(seed as usize) {
        *flag = true;
        stack.push(seed);
    }
    while let Some(face) = stack.pop() {
        out.push(face);
        for &edge in &topology.face_edges[face as usize] {
            for &(other, _) in topology.faces_of_edge(edge) {
                if let Some(flag) = seen.get_mut(other as usize)
                    && !*flag
                {
                    *flag = true;
                    stack.push(other);
                }
            }
        }
    }
    out.sort_unstable();
    out
}

/// Fills the faces in `scope` (every sample, shared ones once) with `color` blended by
/// `blend` at weight `strength`, as one undo step labelled "fill".
pub fn fill(
    store: &mut ColorStore,
    history: &mut UndoHistory,
    scope: FillScope,
    color: Rgba,
    blend: BlendMode,
    strength: f32,
    base: Option<&ColorStore>,
) -> Result<DabStats, BrushError> {
    if !(0.0..=1.0).contains(&strength) {
        return Err(BrushError::InvalidSetting(format!("strength {strength} is not in 0..=1")));
    }
    if blend == BlendMode::EraseToBase {
        check_base(base, store)?;
    }
    let faces = match scope {
        FillScope::All => (0..store.topology().face_count()).collect(),
        FillScope::Connected { face } => {
            if face >= store.topology().face_count() {
                return Err(BrushError::NoSuchFace(face));
            }
            connected_faces(store, face)
        }
    };
    let mut scratch = Scratch::default();
    scratch.fit(store);
    scratch.face_masks = vec![1; faces.len()];
    scratch.faces = faces;
    // Positions do not matter: every point has the same weight.
    let positions = vec![[0.0f32; 3]; store.topology().vertex_count as usize];
    history.begin_step(store, "fill")?;
    let op = PaintOp { blend, color, base };
    let stats =
        paint_faces(&Everywhere(strength), &op, &positions, &mut StoreWriter::new(store, history), &mut scratch);
    history.end_step();
    Ok(stats)
}

/// Sets the resolution of `faces` (every face when `None`) to `resolution`, as one undo step
/// labelled "set resolution". Returns the number of faces changed.
///
/// With a `budget` (and the document's colour format), the samples of the result are counted
/// first — closed form for every face, one pass otherwise — and a result past the budget is
/// refused with [`BrushError::Budget`] before any face changes.
pub fn set_resolution(
    store: &mut ColorStore,
    history: &mut UndoHistory,
    faces: Option<&[u32]>,
    resolution: Resolution,
    budget: Option<(&Budget, ColorFormat)>,
) -> Result<u32, BrushError> {
    let face_count = store.topology().face_count();
    if let Some(&bad) = faces.and_then(|list| list.iter().find(|&&f| f >= face_count)) {
        return Err(BrushError::NoSuchFace(bad));
    }
    if let Some((budget, format)) = budget {
        match faces {
            None => {
                let counts = SampleCounts::uniform_on(store.topology(), resolution);
                budget.check(&format!("R = {resolution} on every face"), &counts, format)?;
            }
            Some(list) => {
                let mut resolutions = store.face_resolutions().to_vec();
                for &face in list {
                    resolutions[face as usize] = resolution;
                }
                let what = format!("R = {resolution} on {} faces", list.len());
                budget.check_resolutions(&what, store, &resolutions, format)?;
            }
        }
    }
    history.begin_step(store, "set resolution")?;
    let mut changed = 0;
    let mut writer = StoreWriter::new(store, history);
    let mut run = |face: u32| -> Result<(), BrushError> {
        if writer.set_face_resolution(face, resolution)? {
            changed += 1;
        }
        Ok(())
    };
    let result = match faces {
        Some(list) => list.iter().try_for_each(|&face| run(face)),
        None => (0..face_count).try_for_each(run),
    };
    history.end_step();
    result.map(|()| changed)
}
