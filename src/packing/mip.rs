//! The MIP filters of the packer (thesis eq. 2.5 / 2.6) that need no layout: the weighted
//! filter, one face's interior chain, and the vertex → edge incidence.

use glam::Vec4;

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution};
use crate::mesh::topology::Topology;

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
