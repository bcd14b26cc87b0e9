//! The colour brush's kernels: every stored sample of a dab's faces blended once (interior
//! rows per face, each shared edge and vertex once), written through the [`StoreWriter`].
//!
//! The interior rows and the edge walk share `Kernel::row`, which updates one run of an
//! element's samples in place ([`ElementWriter::update_run`]: one look-up per run, an undo
//! bit test per write; the hot path allocates nothing and hashes nothing).

use glam::DVec3;

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::packing::sampler::{self, Filter};
use crate::paint::undo::{Element, ElementWriter, StoreWriter};

use super::footprint::Coverage;
use super::scratch::{Scratch, accumulate_masks, position, visit_mask};
use super::settings::BlendMode;

/// Counts of one dab.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DabStats {
    /// Faces the BVH query returned (both spheres with mirror).
    pub faces: u32,
    /// Samples inside the footprint with a positive weight (each updated once).
    pub samples_covered: u64,
    /// Samples whose colour changed.
    pub samples_changed: u64,
    /// Faces whose resolution changed.
    pub faces_resized: u32,
}

impl DabStats {
    pub(super) fn add(&mut self, other: DabStats) {
        self.faces += other.faces;
        self.samples_covered += other.samples_covered;
        self.samples_changed += other.samples_changed;
        self.faces_resized += other.faces_resized;
    }
}

/// What a paint dab writes.
#[derive(Debug, Clone, Copy)]
pub(super) struct PaintOp<'a> {
    pub(super) blend: BlendMode,
    pub(super) color: Rgba,
    /// Required for Erase to base.
    pub(super) base: Option<&'a ColorStore>,
}

impl PaintOp<'_> {
    /// The base colour at lattice point `(i, j)` of `face` at resolution `r`, sampled
    /// linearly when the base holds the face at another resolution.
    fn base_on_face(&self, face: u32, r: Resolution, i: u32, j: u32, fallback: Rgba) -> Rgba {
        let Some(base) = self.base else {
            return fallback;
        };
        let bary = layout::sample_barycentric(r, i, j).map(|w| w as f32);
        sampler::sample(base, face, bary, Filter::Linear, 0).unwrap_or(fallback)
    }
}

/// Counts of one element's update.
#[derive(Debug, Clone, Copy, Default)]
struct ElementCounts {
    covered: u64,
    changed: u64,
}

/// One lattice row of an element: the points `a + b·k` for `k` in `ks`, stored at index
/// `first + k − 1`.
#[derive(Debug, Clone, Copy)]
struct Row {
    a: DVec3,
    b: DVec3,
    ks: (u32, u32),
    first: u32,
}

/// A paint dab's kernel: where it reaches, what it writes, and the mesh's positions.
struct Kernel<'a, C> {
    coverage: &'a C,
    op: &'a PaintOp<'a>,
    positions: &'a [[f32; 3]],
}

impl<C: Coverage> Kernel<'_, C> {
    /// Blends the samples of `row` with a positive weight, in place (one run of the
    /// element); `base_other(store, k, old)` is the base colour of point `k` when the base
    /// holds the element at another resolution (Erase to base).
    #[inline(always)]
    fn row(
        &self,
        out: &mut ElementWriter,
        (row, mask, unoccluded): (Row, u8, bool),
        base_same: Option<&[Rgba]>,
        base_other: impl Fn(&ColorStore, u32, Rgba) -> Rgba,
        counts: &mut ElementCounts,
    ) {
        if unoccluded {
            self.row_with(out, (row, mask), base_same, base_other, counts, |p, mask| {
                self.coverage.weight_unoccluded(p, mask)
            });
        } else {
            self.row_with(out, (row, mask), base_same, base_other, counts, |p, mask| self.coverage.weight(p, mask));
        }
    }

    /// [`Kernel::row`] with the weight function `weight`.
    #[inline(always)]
    fn row_with(
        &self,
        out: &mut ElementWriter,
        (row, mask): (Row, u8),
        base_same: Option<&[Rgba]>,
        base_other: impl Fn(&ColorStore, u32, Rgba) -> Rgba,
        counts: &mut ElementCounts,
        weight: impl Fn(DVec3, u8) -> f32,
    ) {
        let (k0, k1) = row.ks;
        if k0 > k1 || row.first + k0 == 0 {
            return;
        }
        let op = self.op;
        // Erase to a base at another resolution reads the store: its colours come first.
        let others: Vec<Rgba> = if op.blend == BlendMode::EraseToBase && base_same.is_none() {
            (k0..=k1)
                .map(|k| {
                    let old = out.get(row.first + k - 1).unwrap_or_default();
                    base_other(out.store(), k, old)
                })
                .collect()
        } else {
            Vec::new()
        };
        let first = row.first + k0 - 1;
        let mut covered = 0;
        let changed = out.update_run(first, k1 - k0 + 1, |index, old| {
            let k = index - first + k0;
            let w = weight(row.a + row.b * f64::from(k), mask);
            if w <= 0.0 {
                return None;
            }
            covered += 1;
            let base = match (op.blend, base_same) {
                (BlendMode::EraseToBase, Some(base)) => base.get(index as usize).copied().unwrap_or(old),
                (BlendMode::EraseToBase, None) => others.get((k - k0) as usize).copied().unwrap_or(old),
                _ => old,
            };
            Some(op.blend.blend(old, op.color, base, w))
        });
        counts.covered += covered;
        counts.changed += changed;
    }

    /// Paints the interior samples of `face` (mask `mask`).
    fn interior(&self, writer: &mut StoreWriter, face: u32, mask: u8) -> ElementCounts {
        let (op, mut counts) = (self.op, ElementCounts::default());
        let store = writer.store();
        let (Some(r), Some(corners)) = (store.face_resolution(face), store.topology().face_vertices.get(face as usize))
        else {
            return counts;
        };
        let res = r.get();
        if res < 3 {
            return counts;
        }
        let [p0, p1, p2] = corners.map(|v| position(self.positions, v));
        let inv = 1.0 / f64::from(res);
        let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
        let base_same = op.base.and_then(|b| (b.face_resolution(face) == Some(r)).then(|| b.interior_samples(face)));
        let whole = self.coverage.covers(&[p0, p1, p2], mask);
        let unoccluded = self.coverage.unoccluded(&[p0, p1, p2], mask);
        let mut out = writer.element(Element::Interior(face));
        for i in 1..res - 1 {
            let a = p0 + e1 * f64::from(i);
            let range =
                if whole { Some((1, res - 1 - i)) } else { self.coverage.row_range(a, e2, 1, res - 1 - i, mask) };
            let Some(ks) = range else {
                continue;
            };
            let row = Row { a, b: e2, ks, first: (i - 1) * (2 * res - 2 - i) / 2 };
            let base_other = |_: &ColorStore, j: u32, old: Rgba| op.base_on_face(face, r, i, j, old);
            self.row(&mut out, (row, mask, unoccluded), base_same, base_other, &mut counts);
        }
        counts
    }

    /// Paints the samples of `edge` (at the edge's resolution).
    fn edge(&self, writer: &mut StoreWriter, edge: u32, mask: u8) -> ElementCounts {
        let store = writer.store();
        let (Some(r), Some(&[lo, hi])) =
            (store.edge_resolution(edge), store.topology().edge_vertices.get(edge as usize))
        else {
            return ElementCounts::default();
        };
        let res = r.get();
        if res < 2 {
            return ElementCounts::default();
        }
        let (a, end) = (position(self.positions, lo), position(self.positions, hi));
        let b = (end - a) / f64::from(res);
        let range = if self.coverage.covers(&[a, end], mask) {
            Some((1, res - 1))
        } else {
            self.coverage.row_range(a, b, 1, res - 1, mask)
        };
        let Some(ks) = range else {
            return ElementCounts::default();
        };
        let op = self.op;
        let base_same =
            op.base.and_then(|base| (base.edge_resolution(edge) == Some(r)).then(|| base.edge_samples(edge)));
        let base_other = |store: &ColorStore, k: u32, old: Rgba| base_on_edge(op, store, edge, r, k, old);
        let mut counts = ElementCounts::default();
        let row = Row { a, b, ks, first: 0 };
        let unoccluded = self.coverage.unoccluded(&[a, end], mask);
        self.row(&mut writer.element(Element::Edge(edge)), (row, mask, unoccluded), base_same, base_other, &mut counts);
        counts
    }

    /// Paints vertex `v` (mask `mask`).
    fn vertex(&self, writer: &mut StoreWriter, v: u32, mask: u8) -> ElementCounts {
        let mut counts = ElementCounts::default();
        let w = self.coverage.weight(position(self.positions, v), mask);
        if w > 0.0 {
            let op = self.op;
            let mut out = writer.element(Element::Vertices);
            counts.covered = u64::from(out.get(v).is_some());
            counts.changed = out.update_run(v, 1, |_, old| {
                let base = match op.blend {
                    BlendMode::EraseToBase => op.base.and_then(|base| base.vertex_color(v)).unwrap_or(old),
                    _ => old,
                };
                Some(op.blend.blend(old, op.color, base, w))
            });
        }
        counts
    }
}

/// The base colour at position `k` (from the lower vertex) of `edge` at resolution `r`, sampled
/// on the edge's first face when the base holds the edge at another resolution.
fn base_on_edge(op: &PaintOp, store: &ColorStore, edge: u32, r: Resolution, k: u32, fallback: Rgba) -> Rgba {
    let Some(base) = op.base else {
        return fallback;
    };
    let Some(&(face, face_edge)) = store.topology().faces_of_edge(edge).first() else {
        return fallback;
    };
    let t = k as f32 / r.get() as f32;
    let reversed = store.topology().is_reversed(face, usize::from(face_edge));
    let mut bary = [0.0f32; 3];
    let (start, end) = (usize::from(face_edge), (usize::from(face_edge) + 1) % 3);
    // Not reversed: the face edge starts at the lower vertex.
    let along = if reversed { 1.0 - t } else { t };
    bary[start] = 1.0 - along;
    bary[end] = along;
    sampler::sample(base, face, bary, Filter::Linear, 0).unwrap_or(fallback)
}

/// Paints every sample of the faces in `scratch.faces` (masks in `scratch.face_masks`), each
/// shared vertex and edge once.
pub(super) fn paint_faces<C: Coverage>(
    coverage: &C,
    op: &PaintOp,
    positions: &[[f32; 3]],
    writer: &mut StoreWriter,
    scratch: &mut Scratch,
) -> DabStats {
    let kernel = Kernel { coverage, op, positions };
    let stamp = accumulate_masks(writer.store(), scratch);
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    let mut add = |counts: ElementCounts| {
        stats.samples_covered += counts.covered;
        stats.samples_changed += counts.changed;
    };
    let faces = std::mem::take(&mut scratch.faces);
    for (&face, &mask) in faces.iter().zip(&scratch.face_masks) {
        if mask != 0 {
            add(kernel.interior(writer, face, mask));
        }
        let topology = writer.store().topology();
        let Some((&edges, &corners)) =
            topology.face_edges.get(face as usize).zip(topology.face_vertices.get(face as usize))
        else {
            continue;
        };
        for edge in edges {
            let mask = visit_mask(&mut scratch.edge_stamp, &scratch.edge_mask, edge, stamp);
            if mask != 0 {
                add(kernel.edge(writer, edge, mask));
            }
        }
        for v in corners {
            let mask = visit_mask(&mut scratch.vertex_stamp, &scratch.vertex_mask, v, stamp);
            if mask != 0 {
                add(kernel.vertex(writer, v, mask));
            }
        }
    }
    scratch.faces = faces;
    stats
}
