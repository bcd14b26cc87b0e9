//! The colour brush's kernels: every stored sample of a dab's faces blended once (interior
//! rows per face, each shared edge and vertex once).
//!
//! A dab lists its elements (each face interior, and each shared edge and vertex once),
//! [splits](StoreWriter::split) the writer into one [`ElementSlice`] per edge and interior,
//! and blends them in parallel (rayon over chunks of the list), each written in place: no
//! element's new colour depends on another element's. Each task records the undo step's old
//! colours into its own [`UndoLog`]; the vertices are written last, on the calling thread.
//! [`Runs`] carry the blur's new interior colours from its compute pass to its write.

use glam::DVec3;

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::packing::sampler::{self, Filter};
use rayon::prelude::*;

use crate::mesh::topology::Topology;
use crate::paint::split::{ElementSlice, Split, UndoLog};
use crate::paint::undo::{Element, StoreWriter};

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
    /// Whether the dab's kernels ran on the thread pool (8192 samples or more to compute).
    pub parallel: bool,
}

impl DabStats {
    pub(super) fn add(&mut self, other: DabStats) {
        self.faces += other.faces;
        self.samples_covered += other.samples_covered;
        self.samples_changed += other.samples_changed;
        self.faces_resized += other.faces_resized;
        self.parallel |= other.parallel;
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

/// One lattice row of an element: the points `a + b·k` for `k` in `ks`, stored at index
/// `first + k − 1`.
#[derive(Debug, Clone, Copy)]
struct Row {
    a: DVec3,
    b: DVec3,
    ks: (u32, u32),
    first: u32,
}

/// New colours of part of a dab: runs `(element, first index, length)` of consecutive
/// samples, their colours concatenated in `colors`.
#[derive(Debug, Default)]
pub(super) struct Runs {
    runs: Vec<(Element, u32, u32)>,
    colors: Vec<Rgba>,
}

impl Runs {
    /// Appends the new colour of sample `index` of `element`.
    #[inline(always)]
    pub(super) fn push(&mut self, element: Element, index: u32, color: Rgba) {
        match self.runs.last_mut() {
            Some((last, first, len)) if *last == element && *first + *len == index => *len += 1,
            _ => self.runs.push((element, index, 1)),
        }
        self.colors.push(color);
    }

    /// Samples listed.
    pub(super) fn len(&self) -> u64 {
        self.colors.len() as u64
    }

    /// Writes the new colours into `slices` (the elements of the runs, in the runs' order,
    /// possibly with others between), recording old colours into `log`.
    pub(super) fn apply(&self, slices: &mut [ElementSlice], log: &mut UndoLog) {
        let mut offset = 0usize;
        let mut cursor = 0usize;
        for &(element, first, len) in &self.runs {
            let colors = self.colors.get(offset..offset + len as usize).unwrap_or(&[]);
            offset += len as usize;
            while slices.get(cursor).is_some_and(|slice| slice.element() != element) {
                cursor += 1;
            }
            let Some(slice) = slices.get_mut(cursor) else {
                return;
            };
            for (index, &color) in (first..).zip(colors) {
                slice.write(index, color, log);
            }
        }
    }
}

/// A paint dab's kernel: where it reaches, what it writes, and the mesh's positions.
struct Kernel<'a, C> {
    coverage: &'a C,
    op: &'a PaintOp<'a>,
    positions: &'a [[f32; 3]],
}

/// Where one element's new colours go: its writer, the task's undo log, and the count of
/// covered samples.
struct Out<'s, 'a> {
    slice: &'s mut ElementSlice<'a>,
    log: &'s mut UndoLog,
    covered: &'s mut u64,
}

impl<C: Coverage> Kernel<'_, C> {
    /// Blends the samples of `row` with a positive weight (`base_other(k, old)` is the base
    /// colour of point `k` when the base holds the element at another resolution, for Erase
    /// to base).
    #[inline(always)]
    fn row(
        &self,
        out: &mut Out,
        (row, mask, unoccluded): (Row, u8, bool),
        base_same: Option<&[Rgba]>,
        base_other: impl Fn(u32, Rgba) -> Rgba,
    ) {
        let coverage = self.coverage;
        match (unoccluded, coverage.row_distance(row.a, row.b)) {
            (true, Some([c0, c1, c2])) if mask != 0 => {
                let weight = |k: f64| coverage.weight_of_distance_sq(c0 + k * (c1 + k * c2));
                self.row_with(out, row, base_same, base_other, weight);
            }
            (true, _) => {
                let weight = |k: f64| coverage.weight_unoccluded(row.a + row.b * k, mask);
                self.row_with(out, row, base_same, base_other, weight);
            }
            (false, _) => {
                self.row_with(out, row, base_same, base_other, |k: f64| coverage.weight(row.a + row.b * k, mask));
            }
        }
    }

    /// Whether the element's samples can take [`Kernel::blend_stream`]: one sphere reaching
    /// it, no occlusion to test, and a blend that needs no base colour.
    #[inline(always)]
    fn streams(&self, mask: u8, unoccluded: bool) -> bool {
        mask != 0 && unoccluded && self.op.blend != BlendMode::EraseToBase
    }

    /// Blends the element's samples `0, 1, …`, which `rows` lists in storage order as rows of
    /// `count` points `k = 1..=count` at squared distance `c[0] + k·(c[1] + k·c[2])` from the
    /// one sphere's centre: their weights [`BATCH`] at a time
    /// ([`Coverage::weights_of_distance_sq`], one vectorised loop), then the blend of those
    /// with a positive weight, the blend mode chosen once per element.
    #[inline(always)]
    fn blend_stream(&self, out: &mut Out, rows: impl Iterator<Item = ([f64; 3], u32)>) {
        let color = self.op.color;
        match self.op.blend {
            BlendMode::Mix => self.stream_with(out, rows, |old, w| BlendMode::Mix.blend(old, color, old, w)),
            BlendMode::Add => self.stream_with(out, rows, |old, w| BlendMode::Add.blend(old, color, old, w)),
            BlendMode::Multiply => {
                self.stream_with(out, rows, |old, w| BlendMode::Multiply.blend(old, color, old, w));
            }
            BlendMode::EraseToBase => {}
        }
    }

    /// [`Kernel::blend_stream`] with the blend `blend(old, weight)`.
    #[inline(always)]
    fn stream_with(
        &self,
        out: &mut Out,
        rows: impl Iterator<Item = ([f64; 3], u32)>,
        blend: impl Fn(Rgba, f32) -> Rgba,
    ) {
        let (mut d2, mut weights) = ([0.0f64; BATCH], [0.0f32; BATCH]);
        // The storage index of `d2[0]`, and the distances buffered.
        let (mut start, mut n) = (0u32, 0usize);
        let mut flush = |d2: &[f64], start: u32| {
            if let Some(weights) = weights.get_mut(..d2.len()) {
                self.coverage.weights_of_distance_sq(d2, weights);
                *out.covered += out.slice.blend_run(start, weights, out.log, &blend);
            }
        };
        for ([c0, c1, c2], count) in rows {
            let mut k = 1u32;
            while k <= count {
                let take = ((count - k + 1) as usize).min(BATCH - n);
                if let Some(slots) = d2.get_mut(n..n + take) {
                    for (slot, k) in slots.iter_mut().zip(k..) {
                        let k = f64::from(k);
                        *slot = c0 + k * (c1 + k * c2);
                    }
                }
                (n, k) = (n + take, k + take as u32);
                if n == BATCH {
                    flush(&d2, start);
                    (start, n) = (start + BATCH as u32, 0);
                }
            }
        }
        flush(d2.get(..n).unwrap_or(&[]), start);
    }

    /// [`Kernel::row`] with `weight(k)`, the weight of point `k`.
    #[inline(always)]
    fn row_with(
        &self,
        out: &mut Out,
        row: Row,
        base_same: Option<&[Rgba]>,
        base_other: impl Fn(u32, Rgba) -> Rgba,
        weight: impl Fn(f64) -> f32,
    ) {
        let (k0, k1) = row.ks;
        if k0 > k1 || row.first + k0 == 0 {
            return;
        }
        let op = self.op;
        for k in k0..=k1 {
            let index = row.first + k - 1;
            let Some(&old) = out.slice.samples().get(index as usize) else {
                break;
            };
            let w = weight(f64::from(k));
            if w <= 0.0 {
                continue;
            }
            let base = match (op.blend, base_same) {
                (BlendMode::EraseToBase, Some(base)) => base.get(index as usize).copied().unwrap_or(old),
                (BlendMode::EraseToBase, None) => base_other(k, old),
                _ => old,
            };
            *out.covered += 1;
            out.slice.write(index, op.blend.blend(old, op.color, base, w), out.log);
        }
    }

    /// Blends the interior samples of `face` (resolution `r`, mask `mask`).
    fn interior(&self, topology: &Topology, (face, r, mask): (u32, Resolution, u8), out: &mut Out) {
        let op = self.op;
        let Some(corners) = topology.face_vertices.get(face as usize) else {
            return;
        };
        let res = r.get();
        if res < 3 {
            return;
        }
        let [p0, p1, p2] = corners.map(|v| position(self.positions, v));
        let inv = 1.0 / f64::from(res);
        let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
        let unoccluded = self.coverage.unoccluded(&[p0, p1, p2], mask);
        if self.streams(mask, unoccluded) && self.coverage.row_distance(p0, e2).is_some() {
            // Every interior point in storage order: row `i`, then `k` along it.
            let rows = (1..res - 1).map(|i| {
                let c = self.coverage.row_distance(p0 + e1 * f64::from(i), e2).unwrap_or([f64::NAN; 3]);
                (c, res - 1 - i)
            });
            self.blend_stream(out, rows);
            return;
        }
        let base_same = op.base.and_then(|b| (b.face_resolution(face) == Some(r)).then(|| b.interior_samples(face)));
        let whole = self.coverage.covers(&[p0, p1, p2], mask);
        for i in 1..res - 1 {
            let a = p0 + e1 * f64::from(i);
            let range =
                if whole { Some((1, res - 1 - i)) } else { self.coverage.row_range(a, e2, 1, res - 1 - i, mask) };
            let Some(ks) = range else {
                continue;
            };
            let row = Row { a, b: e2, ks, first: (i - 1) * (2 * res - 2 - i) / 2 };
            let base_other = |j: u32, old: Rgba| op.base_on_face(face, r, i, j, old);
            self.row(out, (row, mask, unoccluded), base_same, base_other);
        }
    }

    /// Blends the samples of `edge` (at the edge's resolution `r`).
    fn edge(&self, topology: &Topology, (edge, r, mask): (u32, Resolution, u8), out: &mut Out) {
        let Some(&[lo, hi]) = topology.edge_vertices.get(edge as usize) else {
            return;
        };
        let res = r.get();
        if res < 2 {
            return;
        }
        let (a, end) = (position(self.positions, lo), position(self.positions, hi));
        let b = (end - a) / f64::from(res);
        let range = if self.coverage.covers(&[a, end], mask) {
            Some((1, res - 1))
        } else {
            self.coverage.row_range(a, b, 1, res - 1, mask)
        };
        let Some(ks) = range else {
            return;
        };
        let unoccluded = self.coverage.unoccluded(&[a, end], mask);
        if self.streams(mask, unoccluded)
            && let Some(c) = self.coverage.row_distance(a, b)
        {
            self.blend_stream(out, std::iter::once((c, res - 1)));
            return;
        }
        let op = self.op;
        let base_same =
            op.base.and_then(|base| (base.edge_resolution(edge) == Some(r)).then(|| base.edge_samples(edge)));
        let base_other = |k: u32, old: Rgba| base_on_edge(op, topology, edge, r, k, old);
        let row = Row { a, b, ks, first: 0 };
        self.row(out, (row, mask, unoccluded), base_same, base_other);
    }

    /// The new colour of vertex `v` (mask `mask`) from its colour `old`, `None` outside.
    fn vertex(&self, v: u32, mask: u8, old: Rgba) -> Option<Rgba> {
        let w = self.coverage.weight(position(self.positions, v), mask);
        if w <= 0.0 {
            return None;
        }
        let op = self.op;
        let base = match op.blend {
            BlendMode::EraseToBase => op.base.and_then(|base| base.vertex_color(v)).unwrap_or(old),
            _ => old,
        };
        Some(op.blend.blend(old, op.color, base, w))
    }
}

/// The base colour at position `k` (from the lower vertex) of `edge` at resolution `r`, sampled
/// on the edge's first face when the base holds the edge at another resolution.
fn base_on_edge(op: &PaintOp, topology: &Topology, edge: u32, r: Resolution, k: u32, fallback: Rgba) -> Rgba {
    let Some(base) = op.base else {
        return fallback;
    };
    let Some(&(face, face_edge)) = topology.faces_of_edge(edge).first() else {
        return fallback;
    };
    let t = k as f32 / r.get() as f32;
    let reversed = topology.is_reversed(face, usize::from(face_edge));
    let mut bary = [0.0f32; 3];
    let (start, end) = (usize::from(face_edge), (usize::from(face_edge) + 1) % 3);
    // Not reversed: the face edge starts at the lower vertex.
    let along = if reversed { 1.0 - t } else { t };
    bary[start] = 1.0 - along;
    bary[end] = along;
    sampler::sample(base, face, bary, Filter::Linear, 0).unwrap_or(fallback)
}

/// One entry of a dab's work list: an element and the mask of the spheres that reach it.
#[derive(Debug, Clone, Copy)]
enum Item {
    Interior(u32),
    Edge(u32),
    Vertex(u32),
}

/// Samples whose weights [`Kernel::blend_stream`] computes at a time.
const BATCH: usize = 64;

/// Samples below which a dab computes on the calling thread (handing work to rayon costs
/// more than it saves).
pub(super) const PARALLEL_MIN_SAMPLES: u64 = 8192;
/// Work-list entries per parallel task.
const CHUNK: usize = 64;

/// The dab's work list: each face interior with a mask, and each shared edge and vertex
/// once (the serial order of the faces), with the samples they hold.
fn work_list(store: &ColorStore, scratch: &mut Scratch) -> (Vec<(Item, u8)>, u64) {
    let stamp = accumulate_masks(store, scratch);
    let topology = store.topology();
    let mut work = Vec::with_capacity(scratch.faces.len() * 3);
    let mut samples = 0u64;
    for (&face, &mask) in scratch.faces.iter().zip(&scratch.face_masks) {
        if mask != 0 {
            work.push((Item::Interior(face), mask));
            samples += store.interior_samples(face).len() as u64;
        }
        let Some((&edges, &corners)) =
            topology.face_edges.get(face as usize).zip(topology.face_vertices.get(face as usize))
        else {
            continue;
        };
        for edge in edges {
            let mask = visit_mask(&mut scratch.edge_stamp, &scratch.edge_mask, edge, stamp);
            if mask != 0 {
                work.push((Item::Edge(edge), mask));
                samples += store.edge_samples(edge).len() as u64;
            }
        }
        for v in corners {
            let mask = visit_mask(&mut scratch.vertex_stamp, &scratch.vertex_mask, v, stamp);
            if mask != 0 {
                work.push((Item::Vertex(v), mask));
                samples += 1;
            }
        }
    }
    (work, samples)
}

/// Paints every sample of the faces in `scratch.faces` (masks in `scratch.face_masks`), each
/// shared vertex and edge once: the edges and face interiors in parallel, each written in
/// place through its [`ElementSlice`] (no element's new colour depends on another's), then
/// the vertices.
pub(super) fn paint_faces<C: Coverage + Sync>(
    coverage: &C,
    op: &PaintOp,
    positions: &[[f32; 3]],
    writer: &mut StoreWriter,
    scratch: &mut Scratch,
) -> DabStats {
    let kernel = Kernel { coverage, op, positions };
    let (work, samples) = work_list(writer.store(), scratch);
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    // Edges and interiors with their resolution and mask; vertices apart.
    let store = writer.store();
    let (mut elements, mut jobs, mut vertices) = (Vec::with_capacity(work.len()), Vec::new(), Vec::new());
    for &(item, mask) in &work {
        let (element, r) = match item {
            Item::Interior(face) => (Element::Interior(face), store.face_resolution(face)),
            Item::Edge(edge) => (Element::Edge(edge), store.edge_resolution(edge)),
            Item::Vertex(v) => {
                vertices.push((v, mask));
                continue;
            }
        };
        if let Some(r) = r {
            elements.push(element);
            jobs.push((element, r, mask));
        }
    }
    if let Some(split) = writer.split(&elements) {
        let Split { topology, elements: mut slices } = split;
        let compute = |(slices, jobs): (&mut [ElementSlice], &[(Element, Resolution, u8)])| {
            let samples = slices.iter().map(|slice| slice.samples().len()).sum();
            let (mut log, mut covered) = (UndoLog::with_hint(samples), 0u64);
            for (slice, &(element, r, mask)) in slices.iter_mut().zip(jobs) {
                let mut out = Out { slice, log: &mut log, covered: &mut covered };
                match element {
                    Element::Interior(face) => kernel.interior(topology, (face, r, mask), &mut out),
                    Element::Edge(edge) => kernel.edge(topology, (edge, r, mask), &mut out),
                    Element::Vertices => {}
                }
            }
            (log, covered)
        };
        stats.parallel = samples >= PARALLEL_MIN_SAMPLES;
        let parts: Vec<(UndoLog, u64)> = if !stats.parallel {
            vec![compute((&mut slices, &jobs))]
        } else {
            slices.par_chunks_mut(CHUNK).zip(jobs.par_chunks(CHUNK)).map(compute).collect()
        };
        let changed: Vec<Element> = slices.iter().filter(|s| s.changed() > 0).map(ElementSlice::element).collect();
        stats.samples_changed += slices.iter().map(|s| u64::from(s.changed())).sum::<u64>();
        stats.samples_covered += parts.iter().map(|part| part.1).sum::<u64>();
        drop(slices);
        writer.commit(changed, parts.into_iter().map(|part| part.0));
    }
    let mut out = writer.element(Element::Vertices);
    for (v, mask) in vertices {
        let Some(new) = out.get(v).and_then(|old| kernel.vertex(v, mask, old)) else {
            continue;
        };
        stats.samples_covered += 1;
        stats.samples_changed += out.update_run(v, 1, |_, _| Some(new));
    }
    stats
}
