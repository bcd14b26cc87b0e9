//! The straightforward packer, kept as the reference: every chain built in one `f32` buffer,
//! level 0 quantised then the whole buffer encoded, one thread. `crates/core/tests/core/packer.rs` checks that
//! [`crate::packing::packer::pack`] and the incremental repack give exactly its bytes.

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::mesh::topology::Topology;
use crate::packing::linear::{FaceRecord, PackedMesh};
use crate::packing::packer::{PackError, PackLayout};
use crate::packing::sampler::{self, Filter, MeshColorSource};

/// `(C + ½ Σ N) / (1 + n/2)`: the thesis' MIP filter with the weights taken.
fn mip_filter(center: Rgba, neighbours: &[Rgba]) -> Rgba {
    let mut sum = [0.0f32; 4];
    for n in neighbours {
        for c in 0..4 {
            sum[c] += n[c];
        }
    }
    let norm = 1.0 / (1.0 + 0.5 * neighbours.len() as f32);
    std::array::from_fn(|c| (center[c] + 0.5 * sum[c]) * norm)
}

/// For each vertex, its incident edges (CSR).
fn vertex_edges(topology: &Topology) -> (Vec<u32>, Vec<u32>) {
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
fn interior_row_start(r: usize, i: usize) -> usize {
    (i - 1) * (2 * r - 2 - i) / 2
}

/// Computes one face's whole interior chain in place: `chain` starts with level 0.
fn reduce_interior_chain(chain: &mut [Rgba], r: Resolution) {
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

/// Runs `work` over `items` split into at most `threads` contiguous chunks.
fn in_parallel<T: Send>(items: &mut [T], _threads: usize, work: impl Fn(&mut [T]) + Sync) {
    work(items);
}

fn pack_threads() -> usize {
    1
}

/// Computes every element's full MIP chain in linear `f32`.
fn build_chains(store: &ColorStore, layout: &PackLayout, format: ColorFormat) -> Vec<Rgba> {
    let topology = store.topology();
    let threads = pack_threads();
    let mut colors = vec![[0.0f32; 4]; layout.sample_count as usize];
    // Level 0, quantised to the output format (so the chain filters what is stored).
    let levels = layout.vertex_levels as usize;
    let vertex_section = topology.vertex_count as usize * levels;
    for v in 0..topology.vertex_count as usize {
        colors[v * levels] = format.quantize(store.vertex_color(v as u32).unwrap_or([0.0; 4]));
    }
    for edge in 0..topology.edge_count() {
        let base = layout.edge_base[edge as usize] as usize;
        let samples = store.edge_samples(edge);
        for (slot, &color) in colors[base..base + samples.len()].iter_mut().zip(samples) {
            *slot = format.quantize(color);
        }
    }
    // Interiors: each face's chain is contiguous and independent; faces are laid out in
    // order, so the interior section splits into per-face slices processed in parallel.
    {
        let interior_start = layout.interior_base.iter().copied().find(|&b| b != 0).unwrap_or(0) as usize;
        let interior_start = interior_start.max(vertex_section);
        let (_, interiors) = colors.split_at_mut(interior_start.min(layout.sample_count as usize));
        let mut faces: Vec<(u32, &mut [Rgba])> = Vec::with_capacity(topology.face_count() as usize);
        let mut rest = interiors;
        for face in 0..topology.face_count() {
            let r = store.face_resolution(face).unwrap_or(Resolution::ONE);
            let len = layout::interior_chain_len(r) as usize;
            let (chain, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            faces.push((face, chain));
        }
        in_parallel(&mut faces, threads, |part| {
            for (face, chain) in part.iter_mut() {
                let r = store.face_resolution(*face).unwrap_or(Resolution::ONE);
                let level0 = store.interior_samples(*face);
                for (slot, &color) in chain.iter_mut().zip(level0) {
                    *slot = format.quantize(color);
                }
                reduce_interior_chain(chain, r);
            }
        });
    }
    reduce_edges_and_vertices(store, layout, &mut colors, threads);
    colors
}

/// Per-edge data the edge and vertex passes read in their inner loops.
struct EdgeInfo {
    log2: u32,
    base: usize,
    vertices: [u32; 2],
    /// Incident faces at the edge's resolution: (interior chain base, face edge, reversed).
    full_faces: Vec<(usize, u8, bool)>,
    /// Incident faces coarser than the edge: (face, face edge, reversed).
    coarse_faces: Vec<(u32, u8, bool)>,
}

/// The colour buffer while the edge and vertex chains are being built, read through the
/// sampler's addressing (every level below the one being built is final).
struct ChainsView<'a> {
    store: &'a ColorStore,
    records: &'a [FaceRecord],
    vertex_levels: u32,
    vertex_colors: &'a [Rgba],
    edge_colors: &'a [Rgba],
    interior_colors: &'a [Rgba],
    vertex_section: usize,
    interior_start: usize,
}

impl ChainsView<'_> {
    fn at(&self, index: u64) -> Option<Rgba> {
        let index = usize::try_from(index).ok()?;
        if index < self.vertex_section {
            self.vertex_colors.get(index).copied()
        } else if index < self.interior_start {
            self.edge_colors.get(index - self.vertex_section).copied()
        } else {
            self.interior_colors.get(index - self.interior_start).copied()
        }
    }
}

impl MeshColorSource for ChainsView<'_> {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        self.store.face_resolution(face)
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        let record = self.records.get(face as usize)?;
        let corners = self.store.topology().face_vertices.get(face as usize)?;
        self.at(sampler::record_sample_index(record, corners, self.vertex_levels, level, i, j)?)
    }

    fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution> {
        Some(self.records.get(face as usize)?.edge(usize::from(k))?.1)
    }

    fn edge_color(&self, face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
        let record = self.records.get(face as usize)?;
        let corners = self.store.topology().face_vertices.get(face as usize)?;
        self.at(sampler::record_edge_index(record, corners, k, level, p)?)
    }
}

/// The two lattice neighbours strictly inside the face of the point at position `p`
/// along face edge `face_edge`, on a lattice of resolution `rp` (LATTICE_DIRECTIONS order).
fn inside_neighbours(face_edge: u8, p: usize, rp: usize) -> [(usize, usize); 2] {
    match face_edge {
        0 => [(p, 1), (p - 1, 1)],
        1 => [(rp - p - 1, p), (rp - p, p - 1)],
        _ => [(1, rp - p), (1, rp - p - 1)],
    }
}

/// Edge MIP levels (eq. 2.6 on edges) and vertex MIP levels (eq. 2.5), level by level.
/// The buffer splits into vertex / edge / interior sections: a pass writes one section
/// in parallel chunks while reading the others.
/// Long: one level loop over three borrowed sections (coarse-face neighbours, edges,
/// vertices in parallel chunks); splitting it would re-split the buffer per helper.
fn reduce_edges_and_vertices(store: &ColorStore, layout: &PackLayout, colors: &mut [Rgba], threads: usize) {
    let topology = store.topology();
    let levels = layout.vertex_levels as usize;
    let vertex_section = topology.vertex_count as usize * levels;
    let edges: Vec<EdgeInfo> = (0..topology.edge_count())
        .map(|edge| {
            let r_edge = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
            let full_faces = topology
                .faces_of_edge(edge)
                .iter()
                .filter(|&&(face, _)| store.face_resolution(face) == Some(r_edge))
                .map(|&(face, k)| {
                    (layout.interior_base[face as usize] as usize, k, topology.is_reversed(face, usize::from(k)))
                })
                .collect();
            let coarse_faces = topology
                .faces_of_edge(edge)
                .iter()
                .filter(|&&(face, _)| store.face_resolution(face) != Some(r_edge))
                .map(|&(face, k)| (face, k, topology.is_reversed(face, usize::from(k))))
                .collect();
            EdgeInfo {
                log2: r_edge.log2(),
                base: layout.edge_base[edge as usize] as usize,
                vertices: topology.edge_vertices[edge as usize],
                full_faces,
                coarse_faces,
            }
        })
        .collect();
    let edge_section_end = edges
        .iter()
        .map(|e| e.base + layout::edge_chain_len(Resolution::from_log2(e.log2).unwrap_or(Resolution::ONE)) as usize)
        .max()
        .unwrap_or(vertex_section)
        .max(vertex_section);
    let (vertex_colors, rest) = colors.split_at_mut(vertex_section);
    let (edge_colors, interior_colors) = rest.split_at_mut(edge_section_end - vertex_section);
    let interior_colors: &[Rgba] = interior_colors;
    let interior_start = edge_section_end;
    let (vertex_edge_offsets, vertex_edge_list) = vertex_edges(topology);
    let records: Vec<FaceRecord> = (0..topology.face_count()).map(|f| layout.face_record(store, f)).collect();
    for level in 1..levels {
        let previous = level - 1;
        let coarse_neighbours = {
            let view = ChainsView {
                store,
                records: &records,
                vertex_levels: layout.vertex_levels,
                vertex_colors: &*vertex_colors,
                edge_colors: &*edge_colors,
                interior_colors,
                vertex_section,
                interior_start,
            };
            coarse_neighbours(&view, &edges, level as u32)
        };
        // Edges: each edge's chain is its own slice.
        {
            let vertex_colors: &[Rgba] = vertex_colors;
            let mut chains: Vec<(&EdgeInfo, &[Rgba], &mut [Rgba])> = Vec::with_capacity(edges.len());
            let mut rest: &mut [Rgba] = edge_colors;
            let mut cursor = vertex_section;
            for (n, info) in edges.iter().enumerate() {
                let len = layout::edge_chain_len(Resolution::from_log2(info.log2).unwrap_or(Resolution::ONE)) as usize;
                if len == 0 {
                    continue;
                }
                let (_, tail) = std::mem::take(&mut rest).split_at_mut(info.base - cursor);
                let (chain, tail) = tail.split_at_mut(len);
                rest = tail;
                cursor = info.base + len;
                chains.push((info, &coarse_neighbours[n], chain));
            }
            in_parallel(&mut chains, threads, |part| {
                let mut neighbours: Vec<Rgba> = Vec::with_capacity(16);
                for (info, coarse, chain) in part.iter_mut() {
                    reduce_edge_level(
                        info,
                        coarse,
                        chain,
                        level as u32,
                        vertex_colors,
                        levels,
                        interior_colors,
                        interior_start,
                        &mut neighbours,
                    );
                }
            });
        }
        // Vertices: each vertex's levels are a slice of `levels` colours.
        {
            let edge_colors: &[Rgba] = edge_colors;
            let mut slots: Vec<(u32, &mut [Rgba])> =
                vertex_colors.chunks_mut(levels).enumerate().map(|(v, s)| (v as u32, s)).collect();
            in_parallel(&mut slots, threads, |part| {
                let mut neighbours: Vec<Rgba> = Vec::with_capacity(16);
                for (v, slot) in part.iter_mut() {
                    neighbours.clear();
                    let range =
                        vertex_edge_offsets[*v as usize] as usize..vertex_edge_offsets[*v as usize + 1] as usize;
                    for &edge in &vertex_edge_list[range] {
                        let info = &edges[edge as usize];
                        if info.log2 < previous as u32 + 1 {
                            continue; // the edge has no samples at the previous level
                        }
                        let r_previous = 1u32 << (info.log2 - previous as u32);
                        let r_edge = Resolution::from_log2(info.log2).unwrap_or(Resolution::ONE);
                        let level_start =
                            info.base + layout::edge_level_offset(r_edge, previous as u32).unwrap_or(0) as usize;
                        let position = if *v == info.vertices[0] { 1 } else { r_previous - 1 };
                        neighbours.push(edge_colors[level_start - vertex_section + position as usize - 1]);
                    }
                    slot[level] = mip_filter(slot[previous], &neighbours);
                }
            });
        }
    }
}

/// What coarser faces show next to each edge sample of level `level − 1` (the seam rule):
/// per edge, for `k` in `1..r_level`, two colours per coarse face.
fn coarse_neighbours(view: &ChainsView, edges: &[EdgeInfo], level: u32) -> Vec<Vec<Rgba>> {
    edges
        .iter()
        .map(|info| {
            let mut out = Vec::new();
            if info.coarse_faces.is_empty() || info.log2 < level + 1 {
                return out;
            }
            let r_level = 1usize << (info.log2 - level);
            let rp = 2 * r_level;
            for k in 1..r_level {
                for &(face, face_edge, reversed) in &info.coarse_faces {
                    let p = if reversed { rp - 2 * k } else { 2 * k };
                    for (i, j) in inside_neighbours(face_edge, p, rp) {
                        let w = [(rp - i - j) as f32, i as f32, j as f32].map(|w| w / rp as f32);
                        let color = sampler::sample(view, face, w, Filter::Linear, level - 1);
                        out.push(color.unwrap_or([0.0; 4]));
                    }
                }
            }
            out
        })
        .collect()
}

/// Level `level` of one edge chain from level `level − 1`.
#[allow(clippy::too_many_arguments)]
fn reduce_edge_level(
    info: &EdgeInfo,
    coarse: &[Rgba],
    chain: &mut [Rgba],
    level: u32,
    vertex_colors: &[Rgba],
    levels: usize,
    interior_colors: &[Rgba],
    interior_start: usize,
    neighbours: &mut Vec<Rgba>,
) {
    if info.log2 < level + 1 {
        return; // resolution 1 at this level: no edge samples
    }
    let r_edge = Resolution::from_log2(info.log2).unwrap_or(Resolution::ONE);
    let r_level = 1u32 << (info.log2 - level);
    let r_previous = 2 * r_level;
    let previous_start = layout::edge_level_offset(r_edge, level - 1).unwrap_or(0) as usize;
    let level_start = layout::edge_level_offset(r_edge, level).unwrap_or(0) as usize;
    let [lower, higher] = info.vertices;
    let lower_color = vertex_colors[lower as usize * levels + level as usize - 1];
    let higher_color = vertex_colors[higher as usize * levels + level as usize - 1];
    let face_level_offset = layout::interior_level_offset(r_edge, level - 1).unwrap_or(0) as usize;
    let rp = r_previous as usize;
    for k in 1..r_level {
        let position = 2 * k;
        let at = |p: u32| -> Rgba {
            if p == 0 {
                lower_color
            } else if p >= r_previous {
                higher_color
            } else {
                chain[previous_start + p as usize - 1]
            }
        };
        let center = at(position);
        neighbours.clear();
        neighbours.push(at(position - 1));
        neighbours.push(at(position + 1));
        for &(face_base, face_edge, reversed) in &info.full_faces {
            let p = if reversed { r_previous - position } else { position } as usize;
            // The two lattice neighbours strictly inside the face, in LATTICE_DIRECTIONS order.
            let inside = match face_edge {
                0 => [(p, 1), (p - 1, 1)],
                1 => [(rp - p - 1, p), (rp - p, p - 1)],
                _ => [(1, rp - p), (1, rp - p - 1)],
            };
            let start = face_base - interior_start + face_level_offset;
            for (i, j) in inside {
                neighbours.push(interior_colors[start + interior_row_start(rp, i) + j - 1]);
            }
        }
        // Coarser faces: what they show at those two points (computed beforehand).
        let per_k = 2 * info.coarse_faces.len();
        neighbours.extend_from_slice(coarse.get((k as usize - 1) * per_k..k as usize * per_k).unwrap_or(&[]));
        chain[level_start + k as usize - 1] = mip_filter(center, neighbours);
    }
}

/// The packer as it was before the rayon / encode-once rewrite, serial: the reference the
/// new packer and the incremental repack are tested against byte for byte.
pub fn pack_reference(
    store: &ColorStore,
    positions: &[[f32; 3]],
    format: ColorFormat,
) -> Result<PackedMesh, PackError> {
    let topology = store.topology();
    if positions.len() != topology.vertex_count as usize {
        return Err(PackError::PositionCount { positions: positions.len(), vertices: topology.vertex_count });
    }
    let layout = PackLayout::of(store)?;
    let chains = build_chains(store, &layout, format);
    let size = format.bytes_per_sample();
    let mut colors = vec![0u8; chains.len() * size];
    format.encode_slice(&chains, &mut colors);
    Ok(PackedMesh {
        positions: positions.to_vec(),
        indices: topology.face_vertices.clone(),
        vertex_levels: layout.vertex_levels,
        face_records: (0..topology.face_count()).map(|f| layout.face_record(store, f)).collect(),
        format,
        colors,
    })
}
