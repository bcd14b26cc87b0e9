//! The MIP filters of the packer (thesis eq. 2.5 / 2.6) that need no layout: the weighted
//! filter, one face's interior chain, one level of an edge's chain from its neighbours, a
//! vertex's chain from its edges, and the vertex → edge incidence.

use glam::Vec4;

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::mesh::topology::Topology;
use crate::packing::edges::EdgeReader;
use crate::packing::interiors::FaceLevel;

/// `(C + ½ Σ N) / (1 + n/2)`: the thesis' MIP filter with the weights taken.
#[inline]
pub(crate) fn mip_filter(center: Rgba, neighbours: &[Rgba]) -> Rgba {
    let mut sum = MipSum::default();
    for &n in neighbours {
        sum.add(n);
    }
    sum.finish(center)
}

/// [`mip_filter`] one neighbour at a time: the same sums in the same order, so the same
/// bits, for loops that would otherwise collect their neighbours in a list first.
///
/// The sums live in a SIMD register (`glam::Vec4`, lane-wise IEEE adds and multiplies like
/// the scalar code): a neighbour decoded channel by channel into an `[f32; 4]` otherwise
/// went through the stack to be loaded as one vector, a stalled store forward per
/// neighbour.
#[derive(Clone, Copy, Default)]
pub(crate) struct MipSum {
    sum: Vec4,
    count: u32,
}

impl MipSum {
    /// Adds one neighbour.
    #[inline(always)]
    pub(crate) fn add(&mut self, n: Rgba) {
        self.add_vec4(Vec4::from_array(n));
    }

    /// Adds one neighbour already in a register.
    #[inline(always)]
    pub(crate) fn add_vec4(&mut self, n: Vec4) {
        self.sum += n;
        self.count += 1;
    }

    /// The filtered colour of `center` with the neighbours added so far.
    #[inline(always)]
    pub(crate) fn finish(self, center: Rgba) -> Rgba {
        let norm = 1.0 / (1.0 + 0.5 * self.count as f32);
        ((Vec4::from_array(center) + 0.5 * self.sum) * norm).to_array()
    }
}

/// For each vertex, its incident edges (CSR).
pub(crate) fn vertex_edges(topology: &Topology) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; topology.vertex_count as usize + 1];
    for &[a, b] in &topology.edge_vertices {
        offsets[a as usize + 1] += 1;
        offsets[b as usize + 1] += 1;
    }
    for v in 0..topology.vertex_count as usize {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut edges = vec![0u32; offsets[topology.vertex_count as usize] as usize];
    for (edge, &[a, b]) in topology.edge_vertices.iter().enumerate() {
        for v in [a, b] {
            edges[fill[v as usize] as usize] = edge as u32;
            fill[v as usize] += 1;
        }
    }
    (offsets, edges)
}

/// Start of interior row `i` (`i >= 1`) of a face at resolution `r` (thesis eq. 3.2).
pub(crate) fn interior_row_start(r: usize, i: usize) -> usize {
    (i - 1) * (2 * r - 2 - i) / 2
}

/// Computes one face's whole interior chain in place: `chain` starts with level 0.
pub(crate) fn reduce_interior_chain(chain: &mut [Rgba], r: Resolution) {
    for level in 1..=r.log2() {
        let r_src = (r.get() >> (level - 1)) as usize;
        let r_dst = r_src / 2;
        if r_dst < 3 {
            break; // no interior samples at this level or below
        }
        let src_start = layout::interior_level_offset(r, level - 1).unwrap_or(0) as usize;
        let dst_start = layout::interior_level_offset(r, level).unwrap_or(0) as usize;
        let (head, tail) = chain.split_at_mut(dst_start);
        let src = &head[src_start..];
        let mut k = 0;
        for i in 1..r_dst - 1 {
            let a = 2 * i;
            let (row_c, row_m, row_p) =
                (interior_row_start(r_src, a), interior_row_start(r_src, a - 1), interior_row_start(r_src, a + 1));
            for j in 1..r_dst - i {
                let b = 2 * j;
                // Lattice directions (1,0), (−1,0), (0,1), (0,−1), (1,−1), (−1,1).
                let n = [
                    src[row_p + b - 1],
                    src[row_m + b - 1],
                    src[row_c + b],
                    src[row_c + b - 2],
                    src[row_p + b - 2],
                    src[row_m + b],
                ];
                tail[k] = mip_filter(src[row_c + b - 1], &n);
                k += 1;
            }
        }
    }
}

/// The two lattice neighbours strictly inside the face of the point at position `p`
/// along face edge `face_edge`, on a lattice of resolution `rp` (LATTICE_DIRECTIONS order).
pub(crate) fn inside_neighbours(face_edge: u8, p: usize, rp: usize) -> [(usize, usize); 2] {
    match face_edge {
        0 => [(p, 1), (p - 1, 1)],
        1 => [(rp - p - 1, p), (rp - p, p - 1)],
        _ => [(1, rp - p), (1, rp - p - 1)],
    }
}

/// A placeholder face side for the fixed arrays of the packer's edge filters (never read:
/// only the sides counted are passed on).
pub(crate) const NO_SIDE: (FaceLevel<'static>, u8, bool) = (FaceLevel::Upper(&[]), 0, false);

/// Eq. 2.6 on an edge of resolution `r_edge` at `level` (which has samples), in `chain`:
/// each sample from the centre, its two neighbours along the edge, for each face of
/// `equal` (the incident faces of the edge's resolution: their level `level − 1`, face
/// edge, reversed flag) its two lattice neighbours inside the face, then `coarse` (what the
/// coarser faces show, two colours per coarse face for each sample in turn).
pub(crate) fn filter_edge_level(
    chain: &mut [Rgba],
    r_edge: Resolution,
    level: u32,
    equal: &[(FaceLevel, u8, bool)],
    coarse: &[Rgba],
) {
    // The faces' reads dispatched once a level, not once a neighbour: one or two faces (a
    // manifold edge) of one kind, level-0 bytes of one format or `f32` levels above (all
    // faces are at one level of one resolution), get a loop of their own.
    let orientation = |n: usize| equal.get(n).map_or((0, false), |&(_, face_edge, reversed)| (face_edge, reversed));
    let sides = [orientation(0), orientation(1)];
    let bytes = |n: usize, format: ColorFormat| match equal.get(n).map(|side| side.0) {
        Some(FaceLevel::Bytes(bytes, f)) if f == format => Some(bytes),
        None => Some(&[][..]),
        _ => None,
    };
    let upper = |n: usize| match equal.get(n).map(|side| side.0) {
        Some(FaceLevel::Upper(upper)) => Some(upper),
        None => Some(&[][..]),
        _ => None,
    };
    let shape = EdgeLevel { r_edge, level, coarse };
    if equal.len() <= 2 {
        match equal.first().map(|side| side.0) {
            Some(FaceLevel::Bytes(_, format)) => {
                if let (Some(a), Some(b)) = (bytes(0, format), bytes(1, format)) {
                    let faces = [a, b];
                    match format {
                        ColorFormat::Rgba8Srgb => {
                            return shape.filter(chain, &sides[..equal.len()], |n, o| {
                                read(faces[n], o, ColorFormat::Rgba8Srgb)
                            });
                        }
                        ColorFormat::Rgba16F => {
                            return shape
                                .filter(chain, &sides[..equal.len()], |n, o| read(faces[n], o, ColorFormat::Rgba16F));
                        }
                        ColorFormat::Rgba32F => {
                            return shape
                                .filter(chain, &sides[..equal.len()], |n, o| read(faces[n], o, ColorFormat::Rgba32F));
                        }
                    }
                }
            }
            Some(FaceLevel::Upper(_)) => {
                if let (Some(a), Some(b)) = (upper(0), upper(1)) {
                    let faces = [a, b];
                    return shape.filter(chain, &sides[..equal.len()], |n, o| {
                        faces[n].get(o).map_or(Vec4::ZERO, |c| Vec4::from_array(*c))
                    });
                }
            }
            None => return shape.filter(chain, &[], |_, _| Vec4::ZERO),
        }
    }
    let all: Vec<(u8, bool)> = equal.iter().map(|&(_, face_edge, reversed)| (face_edge, reversed)).collect();
    shape.filter(chain, &all, |n, o| equal.get(n).map_or(Vec4::ZERO, |side| side.0.get_vec4(o)))
}

/// Sample `offset` of a face's level-0 bytes in `format` (zero past the end).
#[inline(always)]
fn read(bytes: &[u8], offset: usize, format: ColorFormat) -> Vec4 {
    let size = format.bytes_per_sample();
    bytes.get(offset * size..offset * size + size).map_or(Vec4::ZERO, |b| format.decode_vec4(b))
}

/// One level of an edge chain to filter ([`filter_edge_level`]).
struct EdgeLevel<'a> {
    r_edge: Resolution,
    level: u32,
    coarse: &'a [Rgba],
}

impl EdgeLevel<'_> {
    /// The filter with `face(n, offset)` reading sample `offset` of face `n` of `sides`
    /// (its face edge and reversed flag) at the previous level.
    #[inline(always)]
    fn filter(&self, chain: &mut [Rgba], sides: &[(u8, bool)], face: impl Fn(usize, usize) -> Vec4) {
        let (r_edge, level, coarse) = (self.r_edge, self.level, self.coarse);
        let r_level = r_edge.get() >> level;
        let r_previous = 2 * r_level;
        let previous_start = layout::edge_level_offset(r_edge, level - 1).unwrap_or(0) as usize;
        let level_start = layout::edge_level_offset(r_edge, level).unwrap_or(0) as usize;
        let rp = r_previous as usize;
        let per_k = coarse.len() / (r_level as usize - 1).max(1);
        for k in 1..r_level {
            let position = 2 * k;
            // Positions 2k − 1 … 2k + 1 lie in 1..r_previous: edge samples, never a vertex.
            let at = |p: u32| chain[previous_start + p as usize - 1];
            let center = at(position);
            let mut sum = MipSum::default();
            sum.add(at(position - 1));
            sum.add(at(position + 1));
            for (n, &(face_edge, reversed)) in sides.iter().enumerate() {
                let p = if reversed { r_previous - position } else { position } as usize;
                for (i, j) in inside_neighbours(face_edge, p, rp) {
                    sum.add_vec4(face(n, interior_row_start(rp, i) + j - 1));
                }
            }
            for &n in coarse.get((k as usize - 1) * per_k..k as usize * per_k).unwrap_or(&[]) {
                sum.add(n);
            }
            chain[level_start + k as usize - 1] = sum.finish(center);
        }
    }
}

/// Level `level` of vertex `v` (eq. 2.5) from its incident edges' level `level − 1`.
pub(crate) fn reduce_vertex_level(
    store: &ColorStore,
    incident: &[u32],
    v: u32,
    slot: &mut [Rgba],
    level: usize,
    edges: &EdgeReader,
) {
    let previous = level - 1;
    let mut sum = MipSum::default();
    for &edge in incident {
        let log2 = edge_log2(store, edge);
        if log2 < previous as u32 + 1 {
            continue; // the edge has no samples at the previous level
        }
        let r_previous = 1u32 << (log2 - previous as u32);
        let r_edge = Resolution::from_log2(log2).unwrap_or(Resolution::ONE);
        let level_start = layout::edge_level_offset(r_edge, previous as u32).unwrap_or(0) as usize;
        let position = if v == store.topology().edge_vertices[edge as usize][0] { 1 } else { r_previous - 1 };
        sum.add(edges.get(edge, level_start + position as usize - 1).unwrap_or([0.0; 4]));
    }
    slot[level] = sum.finish(slot[previous]);
}

/// Levels ≥ 1 of vertex `v` (eq. 2.5), every level in one pass over its incident edges:
/// each edge's resolution and which end `v` is are looked up once, not once a level. Each
/// level adds the same neighbours in the same order as [`reduce_vertex_level`], so the same
/// bits.
pub(crate) fn reduce_vertex_chain(store: &ColorStore, incident: &[u32], v: u32, slot: &mut [Rgba], edges: &EdgeReader) {
    const MAX_LEVELS: usize = layout::MAX_LOG2_RESOLUTION as usize + 1;
    debug_assert!(slot.len() <= MAX_LEVELS, "a vertex chain has at most {MAX_LEVELS} levels");
    let levels = slot.len().min(MAX_LEVELS);
    let mut sums = [MipSum::default(); MAX_LEVELS];
    let topology = store.topology();
    for &edge in incident {
        let log2 = edge_log2(store, edge);
        let r_edge = Resolution::from_log2(log2).unwrap_or(Resolution::ONE);
        let first = v == topology.edge_vertices[edge as usize][0];
        let chain = edges.chain(edge);
        // Level `level` reads level `level − 1` of the edge, which has samples while
        // `level ≤ log2`.
        for (level, sum) in sums.iter_mut().enumerate().take(levels.min(log2 as usize + 1)).skip(1) {
            let previous = level as u32 - 1;
            let r_previous = 1u32 << (log2 - previous);
            let level_start = layout::edge_level_offset(r_edge, previous).unwrap_or(0) as usize;
            let position = if first { 1 } else { r_previous - 1 };
            let offset = level_start + position as usize - 1;
            sum.add_vec4(chain.and_then(|chain| chain.get(offset)).unwrap_or(glam::Vec4::ZERO));
        }
    }
    for level in 1..levels {
        slot[level] = sums[level].finish(slot[level - 1]);
    }
}

/// `log2` of `edge`'s resolution (0 for an edge without samples).
pub(crate) fn edge_log2(store: &ColorStore, edge: u32) -> u32 {
    store.edge_resolution(edge).map_or(0, Resolution::log2)
}
