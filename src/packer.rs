//! Packing (store → linear buffers with MIP chains) and unpacking (packed → store).
//!
//! Packing is what leaving paint mode and export run. It is deterministic: the same
//! store, positions and format always give the same bytes.
//!
//! # MIP chains
//!
//! Level 0 is the store's samples *after* quantisation to the output format, so the
//! chain is the filter of what is actually stored and an unpacked file packs to the same
//! bytes. Level `l` is computed from level `l − 1` with the thesis' filters, every
//! neighbour weighted ½ against the centre's 1 and the sum normalised by the weights
//! taken:
//!
//! - **vertex** (eq. 2.5): `C'_v = 2/(2 + n) · (C_v + ½ Σ C_e)` over the `n` incident edges
//!   that still hold samples at level `l − 1` (`R_e >> (l−1) >= 2`); `C_e` is the edge's
//!   sample next to the vertex. Past the last level of all its edges a vertex keeps its
//!   colour.
//! - **interior** (eq. 2.6): `C'_ij = ¼ (C_(2i)(2j) + ½ Σ six neighbours)`; the six
//!   neighbours of an interior point of level `l` are interior points of level `l − 1`.
//! - **edge** (eq. 2.6 on the edge): the centre, its two neighbours along the edge (an
//!   endpoint vertex at the ends) and, for every incident face whose resolution equals the
//!   edge's, that face's two interior neighbours. A manifold edge takes 6 neighbours
//!   (weight ¼, exactly eq. 2.6), a **boundary** edge 4 (weight ⅓), a **non-manifold** edge
//!   with `k` such faces `2 + 2k` (weight `1/(2 + k)`). Coarser faces have no samples at
//!   those positions and do not contribute.

use thiserror::Error;

use crate::color::{ColorFormat, Rgba};
use crate::layout::{self, Resolution};
use crate::packed::{FaceRecord, MAX_SAMPLES, PackedMesh, pack_word};
use crate::resample::LATTICE_DIRECTIONS;
use crate::store::{ColorStore, SampleRef};
use crate::topology::{Topology, TopologyError};

/// Errors of packing and unpacking.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PackError {
    /// The colour buffer would exceed the 28-bit sample addressing of face records.
    #[error("{samples} samples exceed the packed limit of {MAX_SAMPLES} (lower some face resolutions)")]
    TooManySamples {
        /// Samples the layout needs.
        samples: u64,
    },
    /// Positions and topology disagree.
    #[error("{positions} positions for a mesh with {vertices} vertices")]
    PositionCount {
        /// Positions given.
        positions: usize,
        /// Vertices in the topology.
        vertices: u32,
    },
    /// The packed mesh's triangles do not form a valid topology.
    #[error("packed mesh: {0}")]
    Topology(#[from] TopologyError),
    /// The packed data is not in the canonical layout this packer writes.
    #[error("packed mesh is not in the canonical layout: {0}")]
    NotCanonical(String),
}

/// Where every element's chain starts in the colour buffer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PackLayout {
    /// Colours per vertex (levels), `1 + log2(max R_f)`.
    pub vertex_levels: u32,
    /// First sample of each edge's chain (0 for edges without samples).
    pub edge_base: Vec<u32>,
    /// First sample of each face's interior chain (0 for faces without interior samples).
    pub interior_base: Vec<u32>,
    /// Total samples.
    pub sample_count: u64,
}

impl PackLayout {
    /// The canonical layout for the store's resolutions.
    pub fn of(store: &ColorStore) -> Result<Self, PackError> {
        let topology = store.topology();
        let max_log2 = store.face_resolutions().iter().map(|r| r.log2()).max().unwrap_or(0);
        let vertex_levels = max_log2 + 1;
        let mut next = u64::from(topology.vertex_count) * u64::from(vertex_levels);
        let mut place = |len: u32| -> u32 {
            if len == 0 {
                return 0;
            }
            let base = next;
            next += u64::from(len);
            // Bases past the limit are caught below, before anyone uses them.
            base.min(u64::from(u32::MAX)) as u32
        };
        let edge_base: Vec<u32> = (0..topology.edge_count())
            .map(|e| place(store.edge_resolution(e).map_or(0, layout::edge_chain_len)))
            .collect();
        let interior_base: Vec<u32> =
            store.face_resolutions().iter().map(|&r| place(layout::interior_chain_len(r))).collect();
        if next > MAX_SAMPLES {
            return Err(PackError::TooManySamples { samples: next });
        }
        Ok(PackLayout { vertex_levels, edge_base, interior_base, sample_count: next })
    }

    /// The 16-byte record of `face`.
    pub fn face_record(&self, store: &ColorStore, face: u32) -> FaceRecord {
        let topology = store.topology();
        let r = store.face_resolution(face).unwrap_or(Resolution::ONE);
        let edges = topology.face_edges[face as usize].map(|edge| {
            let r_edge = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
            pack_word(self.edge_base[edge as usize], r_edge.log2())
        });
        FaceRecord { interior: pack_word(self.interior_base[face as usize], r.log2()), edges }
    }
}

/// Colour buffer in linear `f32` with the addressing of a [`PackLayout`].
struct ChainBuffer<'a> {
    store: &'a ColorStore,
    layout: &'a PackLayout,
    colors: Vec<Rgba>,
}

impl ChainBuffer<'_> {
    fn vertex_index(&self, v: u32, level: u32) -> usize {
        (v * self.layout.vertex_levels + level.min(self.layout.vertex_levels - 1)) as usize
    }

    /// Edge sample at `position` (0..=R_e>>level, endpoints are the vertices) of `edge`.
    fn edge_at(&self, edge: u32, level: u32, position: u32) -> Rgba {
        let r_edge = self.store.edge_resolution(edge).unwrap_or(Resolution::ONE);
        let [lower, higher] = self.store.topology().edge_vertices[edge as usize];
        let r_level = r_edge.get() >> level;
        if position == 0 {
            return self.colors[self.vertex_index(lower, level)];
        }
        if position >= r_level {
            return self.colors[self.vertex_index(higher, level)];
        }
        let offset = layout::edge_level_offset(r_edge, level).unwrap_or(0) + position - 1;
        self.colors[(self.layout.edge_base[edge as usize] + offset) as usize]
    }

    fn interior_index(&self, face: u32, level: u32, i: u32, j: u32) -> usize {
        let r = self.store.face_resolution(face).unwrap_or(Resolution::ONE);
        let r_level = Resolution::from_log2(r.log2() - level).unwrap_or(Resolution::ONE);
        let offset = layout::interior_level_offset(r, level).unwrap_or(0) + layout::interior_offset(r_level, i, j);
        (self.layout.interior_base[face as usize] + offset) as usize
    }
}

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

/// Computes every element's full MIP chain in linear `f32`.
fn build_chains(store: &ColorStore, layout: &PackLayout, format: ColorFormat) -> Vec<Rgba> {
    let topology = store.topology();
    let mut buffer = ChainBuffer { store, layout, colors: vec![[0.0; 4]; layout.sample_count as usize] };
    // Level 0, quantised to the output format.
    for v in 0..topology.vertex_count {
        let color = format.quantize(store.vertex_color(v).unwrap_or([0.0; 4]));
        let index = buffer.vertex_index(v, 0);
        buffer.colors[index] = color;
    }
    for edge in 0..topology.edge_count() {
        let base = layout.edge_base[edge as usize] as usize;
        for (offset, &color) in store.edge_samples(edge).iter().enumerate() {
            buffer.colors[base + offset] = format.quantize(color);
        }
    }
    for face in 0..topology.face_count() {
        let base = layout.interior_base[face as usize] as usize;
        for (offset, &color) in store.interior_samples(face).iter().enumerate() {
            buffer.colors[base + offset] = format.quantize(color);
        }
    }
    let (vertex_edge_offsets, vertex_edge_list) = vertex_edges(topology);
    let mut neighbours: Vec<Rgba> = Vec::with_capacity(16);
    for level in 1..layout.vertex_levels {
        let previous = level - 1;
        // Interiors.
        for face in 0..topology.face_count() {
            let r = store.face_resolution(face).unwrap_or(Resolution::ONE);
            let Ok(r_level) = r.at_level(level) else {
                continue;
            };
            for offset in 0..layout::interior_sample_count(r_level) {
                let Some((i, j)) = layout::interior_sample_at(r_level, offset) else {
                    continue;
                };
                let (ci, cj) = (2 * i, 2 * j);
                let center = buffer.colors[buffer.interior_index(face, previous, ci, cj)];
                neighbours.clear();
                for (di, dj) in LATTICE_DIRECTIONS {
                    let (ni, nj) = ((ci as i32 + di) as u32, (cj as i32 + dj) as u32);
                    neighbours.push(buffer.colors[buffer.interior_index(face, previous, ni, nj)]);
                }
                let index = buffer.interior_index(face, level, i, j);
                buffer.colors[index] = mip_filter(center, &neighbours);
            }
        }
        // Edges.
        for edge in 0..topology.edge_count() {
            let r_edge = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
            let Ok(r_level) = r_edge.at_level(level) else {
                continue;
            };
            let r_previous = r_level.get() * 2;
            let base = layout.edge_base[edge as usize] + layout::edge_level_offset(r_edge, level).unwrap_or(0);
            for k in 1..r_level.get() {
                let position = 2 * k;
                let center = buffer.edge_at(edge, previous, position);
                neighbours.clear();
                neighbours.push(buffer.edge_at(edge, previous, position - 1));
                neighbours.push(buffer.edge_at(edge, previous, position + 1));
                for &(face, face_edge) in topology.faces_of_edge(edge) {
                    if store.face_resolution(face) != Some(r_edge) {
                        continue;
                    }
                    let reversed = topology.is_reversed(face, usize::from(face_edge));
                    let along = if reversed { r_previous - position } else { position };
                    let r_face_previous = Resolution::from_log2(r_edge.log2() - previous).unwrap_or(Resolution::ONE);
                    let (pi, pj) = layout::edge_sample_coords(r_face_previous, face_edge, along);
                    for (di, dj) in LATTICE_DIRECTIONS {
                        let (ni, nj) = (pi as i32 + di, pj as i32 + dj);
                        if ni < 1 || nj < 1 || (ni + nj) as u32 >= r_previous {
                            continue; // not strictly inside the face
                        }
                        let index = buffer.interior_index(face, previous, ni as u32, nj as u32);
                        neighbours.push(buffer.colors[index]);
                    }
                }
                buffer.colors[(base + k - 1) as usize] = mip_filter(center, &neighbours);
            }
        }
        // Vertices.
        for v in 0..topology.vertex_count {
            let center = buffer.colors[buffer.vertex_index(v, previous)];
            neighbours.clear();
            let edges = &vertex_edge_list
                [vertex_edge_offsets[v as usize] as usize..vertex_edge_offsets[v as usize + 1] as usize];
            for &edge in edges {
                let r_edge = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
                let Ok(r_previous) = r_edge.at_level(previous) else {
                    continue;
                };
                if r_previous.get() < 2 {
                    continue;
                }
                let [lower, _] = topology.edge_vertices[edge as usize];
                let position = if v == lower { 1 } else { r_previous.get() - 1 };
                neighbours.push(buffer.edge_at(edge, previous, position));
            }
            let index = buffer.vertex_index(v, level);
            buffer.colors[index] = mip_filter(center, &neighbours);
        }
    }
    buffer.colors
}

/// Packs the store with `positions` (one per vertex) into linear buffers.
pub fn pack(store: &ColorStore, positions: &[[f32; 3]], format: ColorFormat) -> Result<PackedMesh, PackError> {
    let topology = store.topology();
    if positions.len() != topology.vertex_count as usize {
        return Err(PackError::PositionCount { positions: positions.len(), vertices: topology.vertex_count });
    }
    let layout = PackLayout::of(store)?;
    let chains = build_chains(store, &layout, format);
    let mut colors = Vec::with_capacity(chains.len() * format.bytes_per_sample());
    for color in chains {
        format.encode_into(color, &mut colors);
    }
    Ok(PackedMesh {
        positions: positions.to_vec(),
        indices: topology.face_vertices.clone(),
        vertex_levels: layout.vertex_levels,
        face_records: (0..topology.face_count()).map(|f| layout.face_record(store, f)).collect(),
        format,
        colors,
    })
}

/// Unpacks level 0 of a packed mesh into an editable store. The packed data must be in
/// the canonical layout [`pack`] writes (checked record by record).
pub fn unpack(packed: &PackedMesh) -> Result<ColorStore, PackError> {
    let topology = Topology::build(packed.positions.len() as u32, &packed.indices)?;
    if packed.face_records.len() != topology.face_count() as usize {
        return Err(PackError::NotCanonical(format!(
            "{} face records for {} faces",
            packed.face_records.len(),
            topology.face_count()
        )));
    }
    let resolutions = packed
        .face_records
        .iter()
        .enumerate()
        .map(|(face, record)| {
            record.resolution().ok_or_else(|| PackError::NotCanonical(format!("face {face} has an invalid resolution")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4])
        .map_err(|error| PackError::NotCanonical(error.to_string()))?;
    let layout = PackLayout::of(&store)?;
    if layout.vertex_levels != packed.vertex_levels || layout.sample_count != packed.sample_count() {
        return Err(PackError::NotCanonical(format!(
            "expected {} vertex levels and {} samples, found {} and {}",
            layout.vertex_levels,
            layout.sample_count,
            packed.vertex_levels,
            packed.sample_count()
        )));
    }
    for (face, record) in packed.face_records.iter().enumerate() {
        let expected = layout.face_record(&store, face as u32);
        if *record != expected {
            return Err(PackError::NotCanonical(format!(
                "face {face} record {record:?} differs from the canonical {expected:?}"
            )));
        }
    }
    let read = |index: u64| packed.color(index).unwrap_or([0.0; 4]);
    let topology = store.topology().clone();
    for v in 0..topology.vertex_count {
        store.set(SampleRef::Vertex(v), read(u64::from(v) * u64::from(layout.vertex_levels)));
    }
    for edge in 0..topology.edge_count() {
        let count = store.edge_samples(edge).len() as u32;
        for offset in 0..count {
            let color = read(u64::from(layout.edge_base[edge as usize] + offset));
            store.set(SampleRef::Edge { edge, offset }, color);
        }
    }
    for face in 0..topology.face_count() {
        let count = store.interior_samples(face).len() as u32;
        for offset in 0..count {
            let color = read(u64::from(layout.interior_base[face as usize] + offset));
            store.set(SampleRef::Interior { face, offset }, color);
        }
    }
    store.take_dirty();
    Ok(store)
}
