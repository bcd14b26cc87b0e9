//! Optimize: lower each face's resolution while what the mesh shows stays within a bound.
//!
//! # The rule
//!
//! The **error** of a change is the largest absolute difference, over the four channels
//! (linear light, alpha included; colour units, full range = 1), between what the CPU
//! reference sampler (linear filter, level 0) returns **before optimizing** and after, at
//! the *test points* of every face the change touches. Test points of a face, taken at
//! its resolution and its edges' resolutions before optimizing (the finest the face has
//! shown): every lattice point, the centroid of every sub-triangle and the midpoints of
//! its sides, and every edge sample with the midpoints between consecutive ones. The
//! reconstruction is linear on each sub-triangle (on each fan triangle next to a finer
//! edge, sampler module docs), so this set holds the points where the difference of two
//! such functions can peak on the finer lattice; on the fans of the coarser one it is a
//! dense sample, not a proof — the tests measure at random points, independently.
//!
//! Faces are visited in id order, round after round; each visit tries to halve the face's
//! `R` ([`ColorStore::set_face_resolution`], the exact lifting reduction). Lowering a face
//! can lower the shared edges (an edge holds the larger `R` of its faces), so the faces
//! across those edges are tested too. A change whose error exceeds `bound` is undone
//! exactly (the face's and its edges' samples are restored). Errors are measured against
//! the state before optimizing, never against the last accepted change, so they do not
//! add up beyond `bound`. Rounds stop when no face changes.
//!
//! `bound = 0` is lossless: a change is kept only if every test point returns the same
//! colour within float rounding ([`LOSSLESS_TOLERANCE`]). Flat-coloured regions collapse
//! to `R = 1` (the lifting reduction of a constant is that constant).
//!
//! The trials run on a copy of the store ([`plan`], which the editor runs on a worker
//! thread); the accepted changes are then replayed on the store through [`StoreWriter`],
//! the one write path, as one undo step labelled "optimize" ([`apply`]).

use rayon::prelude::*;

use crate::colors::format::Rgba;
use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;
use crate::packing::sampler::{Filter, sample};
use crate::paint::brush::BrushError;
use crate::paint::face_state::FaceState;
use crate::paint::undo::{StepSummary, StoreWriter, UndoHistory};

/// Differences at or below this count as equal when `bound = 0` (float rounding of the
/// sampler's interpolation on colours of magnitude ≤ 1, with margin).
pub const LOSSLESS_TOLERANCE: f32 = 1e-6;

/// What [`optimize`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimizeReport {
    /// Faces whose resolution was lowered.
    pub faces_lowered: u32,
    /// Level-0 samples before.
    pub samples_before: u64,
    /// Level-0 samples after.
    pub samples_after: u64,
    /// The largest error of the accepted changes at the test points.
    pub max_error: f32,
    /// Rounds over all faces.
    pub rounds: u32,
    /// The undo step recorded (`None` when nothing changed).
    pub step: Option<StepSummary>,
}

/// The changes [`plan`] found, to be applied with [`apply`] to the store they were planned on.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimizePlan {
    /// Accepted halvings, in the order they were tried (faces may appear more than once).
    pub changes: Vec<(u32, Resolution)>,
    /// The largest error of the accepted changes at the test points.
    pub max_error: f32,
    /// Rounds over all faces.
    pub rounds: u32,
    /// Level-0 samples of the store planned on.
    pub samples_before: u64,
}

/// Lowers face resolutions of `store` while the shown colours stay within `bound` of what
/// they are now (see the module docs), as one undo step in `history`: [`plan`] then [`apply`].
pub fn optimize(store: &mut ColorStore, history: &mut UndoHistory, bound: f32) -> Result<OptimizeReport, BrushError> {
    let plan = plan(store, bound, &|_| {})?;
    apply(store, history, &plan)
}

/// Finds the changes [`optimize`] makes, on a copy of `store` (which it does not touch), so
/// it can run on a worker thread while the editor stays responsive. The reference colours
/// are computed in parallel (rayon); the trials are sequential (each depends on the
/// previous ones). `progress(fraction)` is told how far the first round is.
pub fn plan(store: &ColorStore, bound: f32, progress: &(dyn Fn(f32) + Sync)) -> Result<OptimizePlan, BrushError> {
    if !(bound.is_finite() && bound >= 0.0) {
        return Err(BrushError::InvalidSetting(format!("the error bound must be a number ≥ 0, got {bound}")));
    }
    let tolerance = bound.max(LOSSLESS_TOLERANCE);
    let face_count = store.topology().face_count();
    let (points, reference): (Vec<Vec<[f32; 3]>>, Vec<Vec<Rgba>>) = (0..face_count)
        .into_par_iter()
        .map(|f| {
            let points = test_points(store, f);
            let reference = points.iter().map(|&b| shown(store, f, b)).collect();
            (points, reference)
        })
        .unzip();
    progress(0.2);
    let mut work = store.clone();
    let mut changes: Vec<(u32, Resolution)> = Vec::new();
    let (mut rounds, mut max_error) = (0, 0.0f32);
    loop {
        rounds += 1;
        let mut changed = false;
        for face in 0..face_count {
            if rounds == 1 && face % 4096 == 0 {
                progress(0.2 + 0.8 * face as f32 / face_count.max(1) as f32);
            }
            let Some(r) = work.face_resolution(face) else { continue };
            let Ok(lower) = Resolution::from_log2(r.log2().saturating_sub(1)) else { continue };
            if lower == r {
                continue;
            }
            // What undo keeps of a face: the same snapshot undoes a trial exactly.
            let snapshot = FaceState::capture(&work, face)?;
            work.set_face_resolution(face, lower)?;
            let error = affected_faces(&work, face)
                .into_iter()
                .map(|g| largest_difference(&work, g, &points[g as usize], &reference[g as usize]))
                .fold(0.0f32, f32::max);
            if error <= tolerance {
                changes.push((face, lower));
                max_error = max_error.max(error);
                changed = true;
            } else {
                snapshot.restore(&mut work)?;
            }
        }
        if !changed {
            break;
        }
    }
    progress(1.0);
    Ok(OptimizePlan { changes, max_error, rounds, samples_before: store.sample_count() })
}

/// Applies `plan` to `store` (the store it was planned on, unchanged since) through
/// [`StoreWriter`], the one write path, as one undo step labelled "optimize".
pub fn apply(
    store: &mut ColorStore,
    history: &mut UndoHistory,
    plan: &OptimizePlan,
) -> Result<OptimizeReport, BrushError> {
    let step = if plan.changes.is_empty() {
        None
    } else {
        history.begin_step(store, "optimize")?;
        let result = {
            let mut writer = StoreWriter::new(store, history);
            plan.changes.iter().try_for_each(|&(face, r)| writer.set_face_resolution(face, r).map(|_| ()))
        };
        let step = history.end_step();
        result?;
        step
    };
    let mut lowered: Vec<u32> = plan.changes.iter().map(|&(face, _)| face).collect();
    lowered.sort_unstable();
    lowered.dedup();
    Ok(OptimizeReport {
        faces_lowered: lowered.len() as u32,
        samples_before: plan.samples_before,
        samples_after: store.sample_count(),
        max_error: plan.max_error,
        rounds: plan.rounds,
        step,
    })
}

/// The colour the CPU reference sampler shows (linear, level 0); black where it fails.
fn shown(store: &ColorStore, face: u32, barycentric: [f32; 3]) -> Rgba {
    sample(store, face, barycentric, Filter::Linear, 0).unwrap_or([0.0; 4])
}

/// The largest channel difference between what `store` shows at `points` of `face` and
/// `reference`.
fn largest_difference(store: &ColorStore, face: u32, points: &[[f32; 3]], reference: &[Rgba]) -> f32 {
    points.iter().zip(reference).fold(0.0f32, |worst, (&b, want)| {
        let got = shown(store, face, b);
        (0..4).fold(worst, |w, c| {
            let d = (got[c] - want[c]).abs();
            if d.is_nan() { f32::INFINITY } else { w.max(d) }
        })
    })
}

/// `face` and the faces across its edges.
fn affected_faces(store: &ColorStore, face: u32) -> Vec<u32> {
    let topology = store.topology();
    let mut faces = vec![face];
    if let Some(edges) = topology.face_edges.get(face as usize) {
        for &edge in edges {
            faces.extend(topology.faces_of_edge(edge).iter().map(|&(g, _)| g).filter(|&g| g != face));
        }
    }
    faces.sort_unstable();
    faces.dedup();
    faces
}

/// Barycentrics of the test points of `face` (module docs).
fn test_points(store: &ColorStore, face: u32) -> Vec<[f32; 3]> {
    let Some(r) = store.face_resolution(face) else { return Vec::new() };
    let res = r.get();
    let n = res as f32;
    let at = |u: f32, v: f32| [(n - u - v) / n, u / n, v / n];
    let mut points = Vec::new();
    for j in 0..=res {
        for i in 0..=res - j {
            let (u, v) = (i as f32, j as f32);
            points.push(at(u, v));
            if i + j < res {
                // The lower sub-triangle (i, j), (i+1, j), (i, j+1): centroid and side midpoints.
                points.extend([at(u + 1.0 / 3.0, v + 1.0 / 3.0), at(u + 0.5, v), at(u, v + 0.5), at(u + 0.5, v + 0.5)]);
            }
            if i + j + 2 <= res {
                // The upper sub-triangle (i+1, j), (i, j+1), (i+1, j+1): its centroid.
                points.push(at(u + 2.0 / 3.0, v + 2.0 / 3.0));
            }
        }
    }
    // Edge samples at the edges' own resolution (finer than the face next to a finer face).
    let topology = store.topology();
    for k in 0..3usize {
        let Some(&edge) = topology.face_edges.get(face as usize).and_then(|e| e.get(k)) else { continue };
        let re = store.edge_resolution(edge).map_or(res, Resolution::get);
        if re <= res {
            continue;
        }
        for p in 1..2 * re {
            let t = p as f32 / (2 * re) as f32;
            // Face edge k runs from corner k to corner k + 1.
            let mut b = [0.0f32; 3];
            b[k] = 1.0 - t;
            b[(k + 1) % 3] = t;
            points.push(b);
        }
    }
    points
}
