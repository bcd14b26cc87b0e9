//! The blur brush: each covered sample moves towards the mean of its lattice neighbours
//! (the six neighbours in every face whose lattice contains it, at that face's resolution)
//! by its weight, all means taken before any write (Jacobi).

use crate::colors::store::ColorStore;
use crate::paint::undo::StoreWriter;

use super::footprint::Coverage;
use super::kernels::DabStats;
use super::scratch::{BlurTerm, Scratch, accumulate_masks, face_elements, position};
use super::settings::BlendMode;

/// The blur dab over `scratch.faces` (masks in `scratch.face_masks`).
pub(super) fn blur_faces<C: Coverage>(
    coverage: &C,
    positions: &[[f32; 3]],
    writer: &mut StoreWriter,
    scratch: &mut Scratch,
) -> DabStats {
    let mut terms = std::mem::take(&mut scratch.blur);
    terms.clear();
    collect_terms(coverage, positions, writer.store(), scratch, &mut terms);
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    write_terms(writer, &mut terms, &mut stats);
    scratch.blur = terms;
    stats
}

/// Pushes one [`BlurTerm`] per covered sample and face (a shared sample gets one per face
/// whose lattice contains it).
fn collect_terms<C: Coverage>(
    coverage: &C,
    positions: &[[f32; 3]],
    store: &ColorStore,
    scratch: &mut Scratch,
    terms: &mut Vec<BlurTerm>,
) {
    let stamp = accumulate_masks(store, scratch);
    const NEIGHBOURS: [(i64, i64); 6] = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)];
    for (&face, &face_mask) in scratch.faces.iter().zip(&scratch.face_masks) {
        let Some((r, corners, edges)) = face_elements(store, face) else {
            continue;
        };
        let res = r.get();
        let [p0, p1, p2] = corners.map(|v| position(positions, v));
        let inv = 1.0 / f64::from(res);
        let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
        // The mask of a lattice point: its element's (accumulated for shared elements).
        let vertex_mask = |k: usize| {
            let v = corners[k] as usize;
            if scratch.vertex_stamp[v] == stamp { scratch.vertex_mask[v] } else { 0 }
        };
        let edge_mask = |k: usize| {
            let e = edges[k] as usize;
            if scratch.edge_stamp[e] == stamp { scratch.edge_mask[e] } else { 0 }
        };
        let all =
            face_mask | vertex_mask(0) | vertex_mask(1) | vertex_mask(2) | edge_mask(0) | edge_mask(1) | edge_mask(2);
        if all == 0 {
            continue;
        }
        for i in 0..=res {
            let a = p0 + e1 * f64::from(i);
            let Some((j0, j1)) = coverage.row_range(a, e2, 0, res - i, all) else {
                continue;
            };
            for j in j0..=j1 {
                let mask = match (i, j) {
                    (0, 0) => vertex_mask(0),
                    (i, 0) if i == res => vertex_mask(1),
                    (0, j) if j == res => vertex_mask(2),
                    (_, 0) => edge_mask(0),
                    (i, j) if i + j == res => edge_mask(1),
                    (0, _) => edge_mask(2),
                    _ => face_mask,
                };
                if mask == 0 {
                    continue;
                }
                let weight = coverage.weight(a + e2 * f64::from(j), mask);
                if weight <= 0.0 {
                    continue;
                }
                let Some(sample) = store.face_sample_ref(face, i, j) else {
                    continue;
                };
                let mut sum = [0.0f32; 4];
                let mut count = 0;
                for (di, dj) in NEIGHBOURS {
                    let (ni, nj) = (i64::from(i) + di, i64::from(j) + dj);
                    if ni < 0 || nj < 0 || ni + nj > i64::from(res) {
                        continue;
                    }
                    if let Some(color) = store.face_sample(face, ni as u32, nj as u32) {
                        for c in 0..4 {
                            sum[c] += color[c];
                        }
                        count += 1;
                    }
                }
                terms.push(BlurTerm { sample, sum, count, weight });
            }
        }
    }
}

/// Merges the terms of the faces sharing a sample, then writes each sample once (every mean
/// was taken before any write).
fn write_terms(writer: &mut StoreWriter, terms: &mut [BlurTerm], stats: &mut DabStats) {
    terms.sort_unstable_by_key(|term| term.sample);
    let mut k = 0;
    while k < terms.len() {
        let mut merged = terms[k];
        let mut next = k + 1;
        while next < terms.len() && terms[next].sample == merged.sample {
            let term = terms[next];
            for c in 0..4 {
                merged.sum[c] += term.sum[c];
            }
            merged.count += term.count;
            merged.weight = merged.weight.max(term.weight);
            next += 1;
        }
        k = next;
        let Some(old) = writer.store().get(merged.sample) else {
            continue;
        };
        stats.samples_covered += 1;
        if merged.count == 0 {
            continue;
        }
        let mean = merged.sum.map(|s| s / merged.count as f32);
        let new = BlendMode::Mix.blend(old, mean, old, merged.weight);
        if writer.set(merged.sample, new) {
            stats.samples_changed += 1;
        }
    }
}
