//! The blur brush: each covered sample moves towards the mean of its lattice neighbours
//! (the six neighbours in every face whose lattice contains it, at that face's resolution)
//! by its weight, all means taken before any write (Jacobi).
//!
//! Per face of the dab, the face's whole lattice is gathered once into a local grid
//! (interior rows copied from the face's storage, the boundary read from its edges and
//! vertices), and each covered point sums its neighbours from the grid: no per-neighbour
//! store look-up. Faces up to R = 64 that one sphere reaches unoccluded read those neighbours
//! from their resolution's stencil (`stencil.rs`), with every lattice point's weight computed
//! in one vectorised loop; the others go row by row. The faces are computed in parallel (rayon over chunks of faces, reading
//! the store only). A face's interior is only ever read by the face itself, so its new
//! colours are final; samples on edges and vertices belong to several faces, so each face
//! returns its sums for them, which are accumulated per element (one slot per edge sample
//! and vertex, found through a per-dab element → slot table). Then the interiors and the
//! edges are written in parallel, each in place through its [`ElementSlice`] from
//! [`StoreWriter::split`], and the vertices last.

use glam::DVec3;
use rayon::prelude::*;

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::paint::split::{ElementSlice, Split, UndoLog};
use crate::paint::undo::{Element, StoreWriter};

use super::footprint::Coverage;
use super::kernels::{DabStats, PARALLEL_MIN_SAMPLES, Runs};
use super::scratch::{BlurAcc, Scratch, accumulate_masks, face_elements, position, visit_mask};
use super::settings::BlendMode;
use super::stencil::{Holder, NEIGHBOURS, Stencil, grid_index};

/// Faces per parallel task.
const CHUNK: usize = 32;

/// What one chunk of faces computes: the new interior colours, and the neighbour sums of
/// covered boundary points `(accumulator slot, sum, count, weight)`.
#[derive(Debug, Default)]
struct FaceSums {
    interiors: Runs,
    shared: Vec<(u32, Rgba, u32, f32)>,
}

/// Where the boundary points of one face's lattice are stored: per face edge its edge, the
/// edge's resolution and the shift from the face's (`r_edge = r << shift`), its samples and
/// whether the face walks it reversed; per corner its vertex.
struct Boundary<'a> {
    corners: [u32; 3],
    edges: [(u32, Resolution, u32, &'a [Rgba], bool); 3],
    res: u32,
}

/// A boundary point of a face's lattice: a corner's vertex, or sample `offset` of face edge `k`.
#[derive(Clone, Copy)]
enum BoundaryPoint {
    Vertex(u32),
    Edge { k: usize, offset: u32 },
}

impl<'a> Boundary<'a> {
    /// The boundary of `face` at resolution `r` (`None` when the store disagrees).
    fn of(store: &'a ColorStore, face: u32, r: Resolution, corners: [u32; 3], edges: [u32; 3]) -> Option<Self> {
        let topology = store.topology();
        let mut out = [(0, r, 0, &[][..], false); 3];
        for (k, slot) in out.iter_mut().enumerate() {
            let edge = edges[k];
            let r_edge = store.edge_resolution(edge)?;
            let shift = r_edge.log2().checked_sub(r.log2())?;
            *slot = (edge, r_edge, shift, store.edge_samples(edge), topology.is_reversed(face, k));
        }
        Some(Boundary { corners, edges: out, res: r.get() })
    }

    /// Boundary point `(i, j)` of the lattice ([`layout::classify_sample`]'s conventions:
    /// face edge 0 is `j = 0`, 1 is `i + j = R`, 2 is `i = 0` walked from corner 2; positions
    /// on a finer edge as [`ColorStore::face_sample_ref`] maps them); `None` for interior
    /// points.
    #[inline(always)]
    fn locate(&self, i: u32, j: u32) -> Option<BoundaryPoint> {
        let res = self.res;
        let holder = match (i, j) {
            (0, 0) => Holder { element: 0, position: 0 },
            (i, 0) if i == res => Holder { element: 1, position: 0 },
            (0, j) if j == res => Holder { element: 2, position: 0 },
            (i, 0) => Holder { element: 3, position: i },
            (i, j) if i + j == res => Holder { element: 4, position: j },
            (0, j) => Holder { element: 5, position: res - j },
            _ => return None,
        };
        self.point(holder)
    }

    /// Where the boundary point `holder` names is stored ([`Holder`]'s conventions).
    #[inline(always)]
    fn point(&self, Holder { element, position }: Holder) -> Option<BoundaryPoint> {
        match element {
            0..=2 => self.corners.get(usize::from(element)).map(|&v| BoundaryPoint::Vertex(v)),
            _ => {
                let k = usize::from(element) - 3;
                let &(_, r_edge, shift, _, reversed) = self.edges.get(k)?;
                Some(BoundaryPoint::Edge {
                    k,
                    offset: layout::edge_storage_offset(r_edge, position << shift, reversed),
                })
            }
        }
    }

    /// The colour at boundary point `point`.
    #[inline(always)]
    fn color(&self, store: &ColorStore, point: BoundaryPoint) -> Option<Rgba> {
        match point {
            BoundaryPoint::Vertex(v) => store.vertex_color(v),
            BoundaryPoint::Edge { k, offset } => self.edges.get(k)?.3.get(offset as usize).copied(),
        }
    }

    /// The blur accumulator slot of boundary point `point` (`scratch`'s per-dab tables).
    #[inline(always)]
    fn slot(&self, scratch: &Scratch, point: BoundaryPoint) -> Option<u32> {
        match point {
            BoundaryPoint::Vertex(v) => scratch.vertex_slot.get(v as usize).copied(),
            BoundaryPoint::Edge { k, offset } => {
                scratch.edge_slot.get(self.edges.get(k)?.0 as usize).map(|&s| s + offset)
            }
        }
    }
}

/// The blur dab over `scratch.faces` (masks in `scratch.face_masks`).
pub(super) fn blur_faces<C: Coverage + Sync>(
    coverage: &C,
    positions: &[[f32; 3]],
    writer: &mut StoreWriter,
    scratch: &mut Scratch,
) -> DabStats {
    let mut stats = DabStats { faces: scratch.faces.len() as u32, ..DabStats::default() };
    let stamp = accumulate_masks(writer.store(), scratch);
    assign_slots(writer.store(), scratch, stamp);
    let store = writer.store();
    scratch.stencils.prepare(scratch.faces.iter().filter_map(|&face| store.face_resolution(face)));
    let tables = &*scratch;
    let compute = |faces: &[(u32, u8)]| {
        let mut sums = FaceSums::default();
        let mut buffers = FaceBuffers::default();
        for &face in faces {
            blur_face(coverage, positions, store, tables, face, &mut buffers, &mut sums);
        }
        sums
    };
    let faces: Vec<(u32, u8)> = scratch.faces.iter().copied().zip(scratch.face_masks.iter().copied()).collect();
    let samples: u64 = faces.iter().map(|&(face, _)| store.interior_samples(face).len() as u64).sum();
    stats.parallel = samples >= PARALLEL_MIN_SAMPLES;
    let parts: Vec<FaceSums> =
        if !stats.parallel { vec![compute(&faces)] } else { faces.par_chunks(CHUNK).map(compute).collect() };
    for part in &parts {
        stats.samples_covered += part.interiors.len();
        for &(slot, sum, count, weight) in &part.shared {
            if let Some(acc) = scratch.blur_acc.get_mut(slot as usize) {
                for (total, channel) in acc.sum.iter_mut().zip(sum) {
                    *total += channel;
                }
                acc.count += count;
                acc.weight = acc.weight.max(weight);
            }
        }
    }
    write_blurred(writer, scratch, &faces, &parts, stats.parallel, &mut stats);
    stats
}

/// Edges per parallel task when writing.
const EDGE_CHUNK: usize = 128;

/// Writes the dab: the faces' new interiors (`parts`, one per chunk of [`CHUNK`] faces when
/// `parallel`, else one for all) and the accumulated edge samples in parallel, each element
/// in place through its [`ElementSlice`], then the vertices (every mean was taken before any
/// write).
fn write_blurred(
    writer: &mut StoreWriter,
    scratch: &Scratch,
    faces: &[(u32, u8)],
    parts: &[FaceSums],
    parallel: bool,
    stats: &mut DabStats,
) {
    let mut elements: Vec<Element> = faces.iter().map(|&(face, _)| Element::Interior(face)).collect();
    elements.extend(scratch.blur_edges.iter().map(|&edge| Element::Edge(edge)));
    if let Some(split) = writer.split(&elements) {
        let Split { elements: mut slices, .. } = split;
        let (face_slices, edge_slices) = slices.split_at_mut(faces.len());
        let interiors = |(slices, part): (&mut [ElementSlice], &FaceSums)| {
            let mut log = UndoLog::with_hint(part.interiors.len() as usize);
            part.interiors.apply(slices, &mut log);
            log
        };
        let (acc, edge_slot) = (&scratch.blur_acc, &scratch.edge_slot);
        let edges = |slices: &mut [ElementSlice]| {
            let mut log = UndoLog::with_hint(slices.iter().map(|slice| slice.samples().len()).sum());
            let mut covered = 0u64;
            for slice in slices.iter_mut() {
                let Element::Edge(edge) = slice.element() else {
                    continue;
                };
                let first = edge_slot.get(edge as usize).copied().unwrap_or(0) as usize;
                for k in 0..slice.samples().len() {
                    let Some(acc) = acc.get(first + k) else {
                        break;
                    };
                    if acc.weight <= 0.0 {
                        continue;
                    }
                    covered += 1;
                    if acc.count == 0 {
                        continue;
                    }
                    let old = slice.samples()[k];
                    slice.write(k as u32, towards_mean(old, acc.sum, acc.count, acc.weight), &mut log);
                }
            }
            (log, covered)
        };
        let (interior_logs, edge_parts): (Vec<UndoLog>, Vec<(UndoLog, u64)>) = if parallel {
            rayon::join(
                || face_slices.par_chunks_mut(CHUNK).zip(parts.par_iter()).map(interiors).collect(),
                || edge_slices.par_chunks_mut(EDGE_CHUNK).map(edges).collect(),
            )
        } else {
            let chunk = faces.len().max(1);
            (face_slices.chunks_mut(chunk).zip(parts).map(interiors).collect(), vec![edges(edge_slices)])
        };
        stats.samples_covered += edge_parts.iter().map(|part| part.1).sum::<u64>();
        stats.samples_changed += slices.iter().map(|slice| u64::from(slice.changed())).sum::<u64>();
        let changed: Vec<Element> =
            slices.iter().filter(|slice| slice.changed() > 0).map(ElementSlice::element).collect();
        drop(slices);
        writer.commit(changed, interior_logs.into_iter().chain(edge_parts.into_iter().map(|part| part.0)));
    }
    let mut out = writer.element(Element::Vertices);
    for &v in &scratch.blur_vertices {
        let Some(acc) = scratch.vertex_slot.get(v as usize).and_then(|&slot| scratch.blur_acc.get(slot as usize))
        else {
            continue;
        };
        if acc.weight <= 0.0 {
            continue;
        }
        let Some(old) = out.get(v) else {
            continue;
        };
        stats.samples_covered += 1;
        if acc.count == 0 {
            continue;
        }
        let new = towards_mean(old, acc.sum, acc.count, acc.weight);
        if out.write(v, old, new) {
            stats.samples_changed += 1;
        }
    }
}

/// Gives every edge and vertex of the dab's faces its accumulator slots (an edge one per
/// stored sample), zeroed.
fn assign_slots(store: &ColorStore, scratch: &mut Scratch, stamp: u32) {
    scratch.blur_acc.clear();
    scratch.blur_edges.clear();
    scratch.blur_vertices.clear();
    let topology = store.topology();
    for &face in &scratch.faces {
        let (Some(edges), Some(corners)) =
            (topology.face_edges.get(face as usize), topology.face_vertices.get(face as usize))
        else {
            continue;
        };
        for &edge in edges {
            // The mask stays readable after the visit (`edge_mask`); the stamp moves on.
            if scratch.edge_stamp[edge as usize] == stamp {
                visit_mask(&mut scratch.edge_stamp, &scratch.edge_mask, edge, stamp);
                scratch.edge_slot[edge as usize] = scratch.blur_acc.len() as u32;
                let count = store.edge_samples(edge).len();
                scratch.blur_acc.resize(scratch.blur_acc.len() + count, BlurAcc::default());
                scratch.blur_edges.push(edge);
            }
        }
        for &v in corners {
            if scratch.vertex_stamp[v as usize] == stamp {
                visit_mask(&mut scratch.vertex_stamp, &scratch.vertex_mask, v, stamp);
                scratch.vertex_slot[v as usize] = scratch.blur_acc.len() as u32;
                scratch.blur_acc.push(BlurAcc::default());
                scratch.blur_vertices.push(v);
            }
        }
    }
}

/// One face: gathers its lattice, computes its covered interior samples' new colours and
/// the neighbour sums of its covered boundary points.
fn blur_face<C: Coverage>(
    coverage: &C,
    positions: &[[f32; 3]],
    store: &ColorStore,
    scratch: &Scratch,
    (face, face_mask): (u32, u8),
    buffers: &mut FaceBuffers,
    out: &mut FaceSums,
) {
    let Some((r, corners, edges)) = face_elements(store, face) else {
        return;
    };
    let res = r.get();
    // The mask of a boundary point: its element's (accumulated over the dab's faces).
    let vertex_mask = |k: usize| scratch.vertex_mask[corners[k] as usize];
    let edge_mask = |k: usize| scratch.edge_mask[edges[k] as usize];
    let all = face_mask | vertex_mask(0) | vertex_mask(1) | vertex_mask(2) | edge_mask(0) | edge_mask(1) | edge_mask(2);
    if all == 0 {
        return;
    }
    let Some(boundary) = Boundary::of(store, face, r, corners, edges) else {
        return;
    };
    let [p0, p1, p2] = corners.map(|v| position(positions, v));
    let unoccluded = coverage.unoccluded(&[p0, p1, p2], all);
    if let Some(stencil) = scratch.stencils.get(r).filter(|_| unoccluded) {
        let masks =
            [face_mask, vertex_mask(0), vertex_mask(1), vertex_mask(2), edge_mask(0), edge_mask(1), edge_mask(2)];
        let face = StencilFace { face, corners: [p0, p1, p2], masks, boundary: &boundary };
        if blur_face_stencil(coverage, stencil, store, scratch, &face, buffers, out) {
            return;
        }
    }
    let grid = &mut buffers.grid;
    if !gather_lattice(store, face, &boundary, grid) {
        return;
    }
    let inv = 1.0 / f64::from(res);
    let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
    let whole = coverage.covers(&[p0, p1, p2], all);
    for i in 0..=res {
        let a = p0 + e1 * f64::from(i);
        let range = if whole { Some((0, res - i)) } else { coverage.row_range(a, e2, 0, res - i, all) };
        let Some((j0, j1)) = range else {
            continue;
        };
        let distance = if unoccluded { coverage.row_distance(a, e2) } else { None };
        for j in j0..=j1 {
            let interior_point = i >= 1 && j >= 1 && i + j < res;
            let mask = match (i, j) {
                _ if interior_point => face_mask,
                (0, 0) => vertex_mask(0),
                (i, 0) if i == res => vertex_mask(1),
                (0, j) if j == res => vertex_mask(2),
                (_, 0) => edge_mask(0),
                (i, j) if i + j == res => edge_mask(1),
                _ => edge_mask(2),
            };
            if mask == 0 {
                continue;
            }
            let k = f64::from(j);
            let weight = match distance {
                Some([c0, c1, c2]) => coverage.weight_of_distance_sq(c0 + k * (c1 + k * c2)),
                None if unoccluded => coverage.weight_unoccluded(a + e2 * k, mask),
                None => coverage.weight(a + e2 * k, mask),
            };
            if weight <= 0.0 {
                continue;
            }
            let (sum, count) =
                if interior_point { interior_sum(grid, res, i, j) } else { boundary_sum(grid, res, i, j) };
            if interior_point {
                let new = towards_mean(grid[grid_index(res, i, j)], sum, count, weight);
                let index = (i - 1) * (2 * res - 2 - i) / 2 + (j - 1);
                out.interiors.push(Element::Interior(face), index, new);
                continue;
            }
            let Some(slot) = boundary.locate(i, j).and_then(|point| boundary.slot(scratch, point)) else {
                continue;
            };
            out.shared.push((slot, sum, count, weight));
        }
    }
}

/// A face's working buffers, reused across the faces of a chunk: its lattice
/// ([`grid_index`] order), and its points' squared distances and weights.
#[derive(Default)]
struct FaceBuffers {
    grid: Vec<Rgba>,
    d2: Vec<f64>,
    weights: Vec<f32>,
}

/// What [`blur_face_stencil`] reads of one face: its corners' positions, its masks (the
/// face's, then corners 0–2', then face edges 0–2', [`Holder::element`] + 1) and where its
/// boundary is stored.
struct StencilFace<'a, 'b> {
    face: u32,
    corners: [DVec3; 3],
    masks: [u8; 7],
    boundary: &'a Boundary<'b>,
}

/// [`blur_face`] through the stencil of its resolution, when one sphere reaches the face and
/// none of it is occluded: the squared distance of every lattice point row by row, all their
/// weights in one branch-free, vectorised loop, then the interior points and the boundary
/// points from the stencil's neighbour tables (the same sums, in the same order, as the
/// per-row path). `false`, with nothing done, when the coverage is not one sphere.
fn blur_face_stencil<C: Coverage>(
    coverage: &C,
    stencil: &Stencil,
    store: &ColorStore,
    scratch: &Scratch,
    face: &StencilFace,
    buffers: &mut FaceBuffers,
    out: &mut FaceSums,
) -> bool {
    let res = stencil.res;
    let [p0, p1, p2] = face.corners;
    let inv = 1.0 / f64::from(res);
    let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
    let FaceBuffers { grid, d2, weights } = buffers;
    d2.clear();
    d2.resize(stencil.points, 0.0);
    for i in 0..=res {
        let Some([c0, c1, c2]) = coverage.row_distance(p0 + e1 * f64::from(i), e2) else {
            return false;
        };
        let start = grid_index(res, i, 0);
        for (slot, k) in d2.get_mut(start..start + (res - i + 1) as usize).unwrap_or(&mut []).iter_mut().zip(0u32..) {
            let k = f64::from(k);
            *slot = c0 + k * (c1 + k * c2);
        }
    }
    weights.clear();
    weights.resize(stencil.points, 0.0);
    coverage.weights_of_distance_sq(d2, weights);
    if !gather_stencil(store, face.face, face.boundary, stencil, grid) {
        return true;
    }
    let color = |g: u32| glam::Vec4::from_array(grid.get(g as usize).copied().unwrap_or_default());
    let weight = |g: u32| weights.get(g as usize).copied().unwrap_or(0.0);
    if face.masks[0] != 0 {
        for (index, &(g, [n0, n1, n2, n3, n4, n5])) in (0u32..).zip(&stencil.interior) {
            let w = weight(g);
            if w <= 0.0 {
                continue;
            }
            let sum = glam::Vec4::ZERO + color(n0) + color(n1) + color(n2) + color(n3) + color(n4) + color(n5);
            let new = towards_mean(color(g).to_array(), sum.to_array(), 6, w);
            out.interiors.push(Element::Interior(face.face), index, new);
        }
    }
    for point in &stencil.boundary {
        let mask = face.masks.get(1 + usize::from(point.holder.element)).copied().unwrap_or(0);
        let w = weight(point.grid);
        if mask == 0 || w <= 0.0 {
            continue;
        }
        let mut sum = glam::Vec4::ZERO;
        for &n in point.neighbours.get(..point.count as usize).unwrap_or(&[]) {
            sum += color(n);
        }
        if let Some(slot) = face.boundary.point(point.holder).and_then(|p| face.boundary.slot(scratch, p)) {
            out.shared.push((slot, sum.to_array(), point.count, w));
        }
    }
    true
}

/// [`gather_lattice`] through `stencil`: the interior rows copied, the boundary points read
/// from their holders. `false` when the store does not hold what the face's resolution says.
fn gather_stencil(store: &ColorStore, face: u32, boundary: &Boundary, stencil: &Stencil, grid: &mut Vec<Rgba>) -> bool {
    let res = stencil.res;
    let interior = store.interior_samples(face);
    if interior.len() != stencil.interior.len() {
        return false;
    }
    grid.clear();
    grid.resize(stencil.points, [0.0; 4]);
    for i in 1..res.saturating_sub(1) {
        let (first, len) = (((i - 1) * (2 * res - 2 - i) / 2) as usize, (res - 1 - i) as usize);
        let start = grid_index(res, i, 1);
        if let (Some(to), Some(from)) = (grid.get_mut(start..start + len), interior.get(first..first + len)) {
            to.copy_from_slice(from);
        }
    }
    for point in &stencil.boundary {
        if let Some(slot) = grid.get_mut(point.grid as usize) {
            *slot = boundary.point(point.holder).and_then(|p| boundary.color(store, p)).unwrap_or([0.0; 4]);
        }
    }
    true
}

/// `old` moved towards the mean `sum / count` of its neighbours by `weight` (`count > 0`).
#[inline(always)]
fn towards_mean(old: Rgba, sum: Rgba, count: u32, weight: f32) -> Rgba {
    let inv = 1.0 / count as f32;
    BlendMode::Mix.blend(old, sum.map(|s| s * inv), old, weight)
}

/// The sum of the six neighbours of interior point `(i, j)` (all inside the lattice).
#[inline(always)]
fn interior_sum(grid: &[Rgba], res: u32, i: u32, j: u32) -> (Rgba, u32) {
    let (below, here, above) = (grid_index(res, i - 1, 0), grid_index(res, i, 0), grid_index(res, i + 1, 0));
    let j = j as usize;
    let mut sum = [0.0f32; 4];
    // The order of `NEIGHBOURS` (the same sums, bit for bit).
    for index in [above + j, below + j, here + j + 1, here + j - 1, above + j - 1, below + j + 1] {
        let color = grid[index];
        for (total, channel) in sum.iter_mut().zip(color) {
            *total += channel;
        }
    }
    (sum, 6)
}

/// The sum and count of the neighbours of boundary point `(i, j)` inside the lattice.
fn boundary_sum(grid: &[Rgba], res: u32, i: u32, j: u32) -> (Rgba, u32) {
    let mut sum = [0.0f32; 4];
    let mut count = 0;
    for (di, dj) in NEIGHBOURS {
        let (ni, nj) = (i64::from(i) + di, i64::from(j) + dj);
        if ni < 0 || nj < 0 || ni + nj > i64::from(res) {
            continue;
        }
        let color = grid[grid_index(res, ni as u32, nj as u32)];
        for (total, channel) in sum.iter_mut().zip(color) {
            *total += channel;
        }
        count += 1;
    }
    (sum, count)
}

/// Gathers the whole lattice of `face` (resolution `res`) into `grid` ([`grid_index`]
/// order): interior rows copied, boundary points read from the edges and vertices. `false`
/// when the store does not hold what the face's resolution says.
fn gather_lattice(store: &ColorStore, face: u32, boundary: &Boundary, grid: &mut Vec<Rgba>) -> bool {
    let res = boundary.res;
    grid.clear();
    let interior = store.interior_samples(face);
    for i in 0..=res {
        for j in 0..=res - i {
            let interior_point = i >= 1 && j >= 1 && i + j < res;
            if interior_point && j == 1 {
                let first = ((i - 1) * (2 * res - 2 - i) / 2) as usize;
                let row = interior.get(first..first + (res - 1 - i) as usize).unwrap_or(&[]);
                grid.extend_from_slice(row);
            }
            if !interior_point {
                grid.push(boundary.locate(i, j).and_then(|point| boundary.color(store, point)).unwrap_or([0.0; 4]));
            }
        }
    }
    grid.len() == grid_index(res, res, 0) + 1
}
