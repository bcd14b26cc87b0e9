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
//! - **edge** (eq. 2.6 on the edge): the centre, its two neighbours along the edge (at
//!   `2k ± 1` on the finer level: edge samples, never an endpoint vertex, so edges next to
//!   faces of their own resolution only need their faces' interiors and compute every level
//!   in one pass) and, for every incident face, that face's two lattice
//!   neighbours inside it at the edge's level-`(l − 1)` spacing. A face whose resolution
//!   equals the edge's has interior samples there; a **coarser** face has none, and
//!   contributes what it shows there at level `l − 1` — its linear filter with the seam
//!   rule ([`crate::packing::sampler`]), so the chain filters the same reconstruction the
//!   sampler draws. A manifold edge thus always takes 6 neighbours (weight ¼, exactly
//!   eq. 2.6), a **boundary** edge 4 (weight ⅓), a **non-manifold** edge with `k` faces
//!   `2 + 2k` (weight `1/(2 + k)`). Equal-resolution faces come first, coarser ones after
//!   (so meshes of one resolution give the same bytes as before coarser faces counted).

use rayon::prelude::*;

mod update;

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::packing::chains_view::ChainsView;
use crate::packing::edges::{EdgePrefix, EdgeReader};
use crate::packing::interiors::{InteriorPrefix, InteriorReader, split_at_bounds};
use crate::packing::linear::{FaceRecord, PackedMesh};
use crate::packing::mip::{
    NO_SIDE, edge_log2, filter_edge_level, inside_neighbours, reduce_interior_chain, reduce_vertex_chain,
    reduce_vertex_level, vertex_edges,
};
use crate::packing::sampler::{self, Filter};

pub use crate::packing::canonical::{PackError, PackLayout};

/// Worker threads the packer runs on (rayon's global pool).
pub fn pack_threads() -> usize {
    rayon::current_num_threads()
}

/// Elements per parallel task.
const BLOCK: usize = 1024;

/// How many elements ahead a pass prefetches what it will read: the one-pass edge chains
/// their faces' interiors, the vertex pass its vertices' edges.
const PREFETCH_AHEAD: u32 = 24;

/// The colour buffer's three sections.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Sections {
    /// Colours per vertex.
    levels: usize,
    /// End of the vertex section (`V · levels`).
    vertex_end: usize,
    /// End of the edge section (start of the interiors).
    edge_end: usize,
    /// Total samples.
    total: usize,
}

impl Sections {
    /// The sections of `layout`; the edge section is as long as `edges` says.
    fn of(store: &ColorStore, layout: &PackLayout, edges: &EdgePrefix) -> Self {
        let levels = layout.vertex_levels as usize;
        let vertex_end = store.topology().vertex_count as usize * levels;
        let edge_samples = edges.chain.last().copied().unwrap_or(0) as usize;
        Sections { levels, vertex_end, edge_end: vertex_end + edge_samples, total: layout.sample_count as usize }
    }
}

/// What the edge and vertex passes read: store, layout, records, sections.
struct Context<'a> {
    store: &'a ColorStore,
    layout: &'a PackLayout,
    records: &'a [FaceRecord],
    sections: Sections,
    format: ColorFormat,
    prefix: &'a InteriorPrefix,
    edges: &'a EdgePrefix,
    /// The chains a relayout has in place already (`None`: compute every chain).
    kept: Option<&'a Kept>,
}

/// The chains a relayout ([`PackCache::relayout`]) has already moved to their places in the
/// new layout, because nothing they read changed: a face's interior when its samples and
/// resolution did not change; an edge's chain when neither did its own nor any of its
/// faces' (an edge with a coarser face is flagged too, but its levels ≥ 1 are always
/// recomputed: what that face shows reads its vertices); a vertex's chain when its colour
/// did not change and all its edges are kept (next to a coarse edge only its level 0 stays:
/// the coarse loop recomputes the rest).
struct Kept {
    faces: Vec<bool>,
    edges: Vec<bool>,
    /// Vertices whose chain is in place (its colour and every incident edge kept).
    vertices: Vec<bool>,
}

impl Kept {
    fn vertex(&self, v: u32) -> bool {
        self.vertices.get(v as usize).copied().unwrap_or(false)
    }

    fn face(&self, face: u32) -> bool {
        self.faces.get(face as usize).copied().unwrap_or(false)
    }

    fn edge(&self, edge: u32) -> bool {
        self.edges.get(edge as usize).copied().unwrap_or(false)
    }
}

impl Context<'_> {
    /// The interior section as written so far (`bytes`: its colour bytes).
    fn interiors<'b>(&'b self, bytes: &'b [u8], upper: &'b [Rgba]) -> InteriorReader<'b> {
        InteriorReader { store: self.store, prefix: self.prefix, bytes, upper, format: self.format }
    }

    fn edge_log2(&self, edge: u32) -> u32 {
        edge_log2(self.store, edge)
    }

    /// Whether `edge` has an incident face coarser than itself.
    fn has_coarse_faces(&self, edge: u32) -> bool {
        let r_edge = self.store.edge_resolution(edge);
        self.store.topology().faces_of_edge(edge).iter().any(|&(face, _)| self.store.face_resolution(face) != r_edge)
    }

    /// Writes level 0 of every vertex in `ids` (block `vertex` chains) and its encoding.
    fn vertex_level0(&self, v: u32, chain: &mut [Rgba], bytes: &mut [u8]) {
        let size = self.format.bytes_per_sample();
        let color = self.store.vertex_color(v).unwrap_or([0.0; 4]);
        chain[0] = self.format.encode_quantized(color, &mut bytes[..size]);
    }

    /// The edge section as written so far (`bytes`: its colour bytes, `upper`: the edges'
    /// levels ≥ 1).
    fn edge_reader<'b>(&'b self, bytes: &'b [u8], upper: &'b [Rgba]) -> EdgeReader<'b> {
        EdgeReader { prefix: self.edges, bytes, upper, format: self.format }
    }

    /// Builds `edge`'s chain in `scratch`: level 0 from the store, encoded into `bytes` (the
    /// chain's bytes) and, unless it has coarser faces, every level above, encoded and
    /// copied to `upper` (the edge's levels ≥ 1).
    fn edge_chain(
        &self,
        edge: u32,
        coarse: bool,
        scratch: &mut Vec<Rgba>,
        out: (&mut [u8], &mut [Rgba]),
        interiors: &InteriorReader,
    ) {
        let (bytes, upper) = out;
        scratch.clear();
        scratch.resize(bytes.len() / self.format.bytes_per_sample(), [0.0; 4]);
        self.format.encode_quantized_slice(self.store.edge_samples(edge), bytes, scratch);
        if coarse {
            return;
        }
        reduce_edge_chain(self, edge, scratch, interiors);
        let n0 = scratch.len() - upper.len();
        self.format.encode_slice(&scratch[n0..], &mut bytes[n0 * self.format.bytes_per_sample()..]);
        upper.copy_from_slice(&scratch[n0..]);
    }

    /// Builds every edge's chain ([`Context::edge_chain`]): `bytes` is the edge section,
    /// `upper` every edge's levels ≥ 1 (blocks of edges in parallel). Each edge prefetches
    /// the interiors of the faces [`PREFETCH_AHEAD`] edges on, so their loads overlap work.
    fn all_edge_chains(&self, bytes: &mut [u8], upper: &mut [Rgba], coarse: &[bool], interiors: &InteriorReader) {
        let topology = self.store.topology();
        let size = self.format.bytes_per_sample();
        for_each_chain((bytes, upper), size, (&self.edges.chain, &self.edges.upper), |e, scratch, bytes, upper| {
            if !coarse[e] && self.kept.is_some_and(|kept| kept.edge(e as u32)) {
                return;
            }
            for &(face, _) in topology.faces_of_edge((e as u32).saturating_add(PREFETCH_AHEAD)) {
                interiors.prefetch(face);
            }
            self.edge_chain(e as u32, coarse[e], scratch, (bytes, upper), interiors);
        });
    }

    /// Builds `face`'s whole interior chain in `scratch` and writes its encoding to `bytes`
    /// (level 0 encoded once) and its levels ≥ 1 to `upper`.
    fn interior_chain(&self, face: u32, scratch: &mut Vec<Rgba>, upper: &mut [Rgba], bytes: &mut [u8]) {
        if self.kept.is_some_and(|kept| kept.face(face)) {
            return;
        }
        let size = self.format.bytes_per_sample();
        let level0 = self.store.interior_samples(face);
        let r = self.store.face_resolution(face).unwrap_or(Resolution::ONE);
        scratch.clear();
        scratch.resize(layout::interior_chain_len(r) as usize, [0.0; 4]);
        self.format.encode_quantized_slice(level0, bytes, scratch);
        reduce_interior_chain(scratch, r);
        let n0 = level0.len().min(scratch.len());
        self.format.encode_slice(&scratch[n0..], &mut bytes[n0 * size..]);
        for (slot, &color) in upper.iter_mut().zip(&scratch[n0..]) {
            *slot = color;
        }
    }

    /// Builds every face's interior chain: `bytes` is the interior section, `upper` every
    /// face's levels ≥ 1 (blocks of faces in parallel, one scratch chain per block).
    fn all_interior_chains(&self, bytes: &mut [u8], upper: &mut [Rgba]) {
        let size = self.format.bytes_per_sample();
        for_each_chain((bytes, upper), size, (&self.prefix.chain, &self.prefix.upper), |f, scratch, bytes, upper| {
            self.interior_chain(f as u32, scratch, upper, bytes);
        });
    }
}

/// Runs `work(id, scratch, bytes, upper)` for every element that has samples, in parallel
/// blocks of [`BLOCK`] ids: `bytes` and `upper` are one section of the colour bytes and its
/// `f32` levels ≥ 1, laid out by the prefix sums `prefix` (chain, upper; `count + 1` long),
/// and each element gets its own pieces of both (and one scratch chain per block).
fn for_each_chain(
    (bytes, upper): (&mut [u8], &mut [Rgba]),
    size: usize,
    (chain, up): (&[u32], &[u32]),
    work: impl Fn(usize, &mut Vec<Rgba>, &mut [u8], &mut [Rgba]) + Sync,
) {
    let count = chain.len().saturating_sub(1);
    let block_first: Vec<usize> = (0..=count.div_ceil(BLOCK)).map(|b| (b * BLOCK).min(count)).collect();
    let byte_bounds: Vec<usize> = block_first.iter().map(|&e| chain[e] as usize * size).collect();
    let upper_bounds: Vec<usize> = block_first.iter().map(|&e| up[e] as usize).collect();
    split_at_bounds(bytes, &byte_bounds)
        .into_par_iter()
        .zip(split_at_bounds(upper, &upper_bounds))
        .enumerate()
        .for_each(|(b, (bytes, upper))| {
            let mut scratch = Vec::new();
            let (first, end) = (block_first[b], block_first[b + 1]);
            for e in first..end {
                let (c, c_end) = ((chain[e] - chain[first]) as usize, (chain[e + 1] - chain[first]) as usize);
                let (u, u_end) = ((up[e] - up[first]) as usize, (up[e + 1] - up[first]) as usize);
                if c_end > c {
                    work(e, &mut scratch, &mut bytes[c * size..c_end * size], &mut upper[u..u_end]);
                }
            }
        });
}

/// What the coarser faces of `edge` show next to its level-`(level − 1)` samples (the seam
/// rule): for `k` in `1..r_level`, two colours per coarse face.
fn coarse_neighbours(ctx: &Context, view: &ChainsView, edge: u32, level: u32) -> Vec<Rgba> {
    let mut out = Vec::new();
    let log2 = ctx.edge_log2(edge);
    if log2 < level + 1 {
        return out;
    }
    let r_edge = ctx.store.edge_resolution(edge);
    let topology = ctx.store.topology();
    let r_level = 1usize << (log2 - level);
    let rp = 2 * r_level;
    for k in 1..r_level {
        for &(face, face_edge) in topology.faces_of_edge(edge) {
            if ctx.store.face_resolution(face) == r_edge {
                continue;
            }
            let reversed = topology.is_reversed(face, usize::from(face_edge));
            let p = if reversed { rp - 2 * k } else { 2 * k };
            for (i, j) in inside_neighbours(face_edge, p, rp) {
                let w = [(rp - i - j) as f32, i as f32, j as f32].map(|w| w / rp as f32);
                let color = sampler::sample(view, face, w, Filter::Linear, level - 1);
                out.push(color.unwrap_or([0.0; 4]));
            }
        }
    }
    out
}

/// Level `level` of `edge`'s chain from level `level − 1` (eq. 2.6 on the edge).
fn reduce_edge_level(
    ctx: &Context,
    edge: u32,
    coarse: &[Rgba],
    chain: &mut [Rgba],
    level: u32,
    interiors: &InteriorReader,
) {
    let log2 = ctx.edge_log2(edge);
    if log2 < level + 1 {
        return; // resolution 1 at this level: no edge samples
    }
    let store = ctx.store;
    let topology = store.topology();
    let r_edge = Resolution::from_log2(log2).unwrap_or(Resolution::ONE);
    let face_level_offset = layout::interior_level_offset(r_edge, level - 1).unwrap_or(0) as usize;
    // The equal-resolution faces' level − 1, in `faces` order (a manifold edge has ≤ 2:
    // no allocation).
    let equal = topology.faces_of_edge(edge).iter().filter(|&&(face, _)| store.face_resolution(face) == Some(r_edge));
    let side = |&(face, face_edge): &(u32, u8)| {
        (interiors.level(face, face_level_offset), face_edge, topology.is_reversed(face, usize::from(face_edge)))
    };
    let mut two = [NO_SIDE; 2];
    let mut more = Vec::new();
    let mut n = 0;
    for face in equal {
        if n < 2 {
            two[n] = side(face);
        } else {
            if more.is_empty() {
                more.extend_from_slice(&two);
            }
            more.push(side(face));
        }
        n += 1;
    }
    filter_edge_level(chain, r_edge, level, if n <= 2 { &two[..n] } else { &more }, coarse);
}

/// Levels ≥ 1 of `edge`'s chain when none of its faces is coarser than the edge: every
/// level in one go, the edge's resolution and its faces' orientations looked up once
/// instead of once a level (each level adds the same neighbours in the same order as
/// [`reduce_edge_level`], so the same bits); an edge with more than two faces goes level by
/// level through it.
fn reduce_edge_chain(ctx: &Context, edge: u32, chain: &mut [Rgba], interiors: &InteriorReader) {
    let log2 = ctx.edge_log2(edge);
    let topology = ctx.store.topology();
    let faces = topology.faces_of_edge(edge);
    if faces.len() > 2 {
        for level in 1..log2 {
            reduce_edge_level(ctx, edge, &[], chain, level, interiors);
        }
        return;
    }
    let r_edge = Resolution::from_log2(log2).unwrap_or(Resolution::ONE);
    let sides: [Option<(u32, u8, bool)>; 2] = std::array::from_fn(|n| {
        faces.get(n).map(|&(face, face_edge)| (face, face_edge, topology.is_reversed(face, usize::from(face_edge))))
    });
    let n = faces.len();
    let mut levels = [NO_SIDE; 2];
    for level in 1..log2 {
        let face_level_offset = layout::interior_level_offset(r_edge, level - 1).unwrap_or(0) as usize;
        for (slot, &(face, e, reversed)) in levels.iter_mut().zip(sides.iter().flatten()) {
            *slot = (interiors.level(face, face_level_offset), e, reversed);
        }
        filter_edge_level(chain, r_edge, level, &levels[..n], &[]);
    }
}

/// Sorted edge ids → what their coarse faces show at `level − 1`, for the ids of `edges`
/// that have coarse faces.
fn coarse_table(ctx: &Context, view: &ChainsView, edges: &[u32], level: u32) -> (Vec<u32>, Vec<Vec<Rgba>>) {
    let ids: Vec<u32> = edges.par_iter().copied().filter(|&e| ctx.has_coarse_faces(e)).collect();
    let values = ids.par_iter().map(|&e| coarse_neighbours(ctx, view, e, level)).collect();
    (ids, values)
}

fn coarse_of(table: &(Vec<u32>, Vec<Vec<Rgba>>), edge: u32) -> &[Rgba] {
    match table.0.binary_search(&edge) {
        Ok(n) => &table.1[n],
        Err(_) => &[],
    }
}

/// The full pack into `chains` (the vertex and edge sections), `upper` (the interiors'
/// levels ≥ 1) and `bytes` (`layout.sample_count` samples).
/// Long: three sections split and re-split per pass (level 0, interiors, each level of
/// edges and vertices, encoding), each pass a few lines of rayon.
fn build_all(
    ctx: &Context,
    chains: &mut [Rgba],
    upper: &mut [Rgba],
    bytes: &mut [u8],
    vertex_edge: &(Vec<u32>, Vec<u32>),
) {
    let store = ctx.store;
    let topology = store.topology();
    let layout = ctx.layout;
    let s = ctx.sections;
    let size = ctx.format.bytes_per_sample();
    let (vertex_colors, edge_upper) = chains.split_at_mut(s.vertex_end);
    let (vertex_bytes, rest_bytes) = bytes.split_at_mut(s.vertex_end * size);
    let (edge_bytes, interior_bytes) = rest_bytes.split_at_mut((s.edge_end - s.vertex_end) * size);
    let levels = s.levels;
    // Every interior chain first: an interior reads nothing else.
    ctx.all_interior_chains(interior_bytes, upper);
    let interiors = ctx.interiors(interior_bytes, upper);
    // An edge without coarser faces reads only its own previous level and its faces'
    // interiors (never a vertex: its neighbours along the edge sit at 2k ± 1, inside
    // 1..r), so all its levels are computed, and encoded, in one pass while its faces are
    // in cache. Edges with coarser faces read what those faces show at the previous level,
    // which reads vertices: they, and the vertices next to them, go level by level after.
    let coarse_flag: Vec<bool> = (0..topology.edge_count()).into_par_iter().map(|e| ctx.has_coarse_faces(e)).collect();
    let coarse_edges: Vec<u32> = (0..topology.edge_count()).filter(|&e| coarse_flag[e as usize]).collect();
    let mut simple = vec![true; topology.vertex_count as usize];
    for &e in &coarse_edges {
        for v in topology.edge_vertices[e as usize] {
            simple[v as usize] = false;
        }
    }
    ctx.all_edge_chains(edge_bytes, edge_upper, &coarse_flag, &interiors);
    let (offsets, list) = vertex_edge;
    let incident = |v: usize| &list[offsets[v] as usize..offsets[v + 1] as usize];
    {
        let edges = ctx.edge_reader(edge_bytes, edge_upper);
        vertex_colors
            .par_chunks_mut(levels)
            .zip(vertex_bytes.par_chunks_mut(levels * size))
            .enumerate()
            .with_min_len(BLOCK)
            .for_each(|(v, (slot, out))| {
                if ctx.kept.is_some_and(|kept| kept.vertex(v as u32)) {
                    return;
                }
                ctx.vertex_level0(v as u32, slot, out);
                if simple[v] && levels > 1 {
                    // The edges of the vertex PREFETCH_AHEAD on, so their loads overlap work
                    // (it made the Bunny's RGBA16F rebuild at R = 16 faster: `bench pack`).
                    if v + (PREFETCH_AHEAD as usize) < offsets.len() - 1 {
                        for &edge in incident(v + PREFETCH_AHEAD as usize) {
                            edges.prefetch(edge);
                        }
                    }
                    reduce_vertex_chain(ctx.store, incident(v), v as u32, slot, &edges);
                    ctx.format.encode_slice(&slot[1..], &mut out[size..]);
                }
            });
    }
    if coarse_edges.is_empty() {
        return;
    }
    for level in 1..levels {
        // Each edge with coarser faces in a scratch chain (few edges: collected, then copied).
        let done: Vec<(u32, Vec<Rgba>)> = {
            let edges = ctx.edge_reader(edge_bytes, edge_upper);
            let view = ChainsView {
                store,
                records: ctx.records,
                vertex_levels: layout.vertex_levels,
                vertex_colors: &*vertex_colors,
                edges,
                interiors,
                vertex_section: s.vertex_end,
                interior_start: s.edge_end,
            };
            let coarse = coarse_table(ctx, &view, &coarse_edges, level as u32);
            coarse_edges
                .par_iter()
                .map(|&e| {
                    let mut chain = Vec::new();
                    edges.chain_into(e, &mut chain);
                    reduce_edge_level(ctx, e, coarse_of(&coarse, e), &mut chain, level as u32, &interiors);
                    (e, chain)
                })
                .collect()
        };
        for (e, chain) in done {
            let (c, u) = ctx.edges.ranges(e);
            let n0 = c.len() - u.len();
            edge_upper[u].copy_from_slice(&chain[n0..]);
        }
        let edges = ctx.edge_reader(edge_bytes, edge_upper);
        vertex_colors.par_chunks_mut(levels).enumerate().with_min_len(BLOCK).for_each(|(v, slot)| {
            if !simple[v] {
                reduce_vertex_level(ctx.store, incident(v), v as u32, slot, level, &edges);
            }
        });
    }
    // Levels 1.. of the edges and vertices done level by level, encoded once final.
    for &e in &coarse_edges {
        let (c, u) = ctx.edges.ranges(e);
        let n0 = c.len() - u.len();
        ctx.format.encode_slice(&edge_upper[u], &mut edge_bytes[(c.start + n0) * size..c.end * size]);
    }
    if levels > 1 {
        vertex_colors.par_chunks(levels).zip(vertex_bytes.par_chunks_mut(levels * size)).enumerate().for_each(
            |(v, (chain, out))| {
                if !simple[v] {
                    ctx.format.encode_slice(&chain[1..], &mut out[size..]);
                }
            },
        );
    }
}

/// A packed mesh with what an incremental repack needs: its layout, the vertex chains and
/// the edges' and interiors' levels ≥ 1 in `f32` (level 0 is read back from the bytes,
/// [`crate::packing::edges`], [`crate::packing::interiors`]) and the vertex → edge
/// incidence. Built by a full pack; [`PackCache::update`] then recomputes only the chains
/// an edit reaches.
#[derive(Debug, Clone, PartialEq)]
pub struct PackCache {
    layout: PackLayout,
    sections: Sections,
    /// The vertex chains, then every edge's levels ≥ 1 ([`EdgePrefix::upper`]).
    chains: Vec<Rgba>,
    prefix: InteriorPrefix,
    edges: EdgePrefix,
    upper: Vec<Rgba>,
    vertex_edge: (Vec<u32>, Vec<u32>),
    packed: PackedMesh,
}

/// Heap bytes of a [`PackCache`] by buffer ([`PackCache::heap_bytes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PackBytes {
    /// The encoded colour buffer (what the GPU holds).
    pub colors: u64,
    /// Face records and the packed copies of positions and indices.
    pub records_and_geometry: u64,
    /// The `f32` MIP levels kept for incremental repacks (vertex chains, levels ≥ 1).
    pub levels: u64,
    /// Layout and prefix tables, the vertex → edge incidence.
    pub tables: u64,
}

/// What a full pack lays out before it writes: the canonical layout, the edge and interior
/// prefixes, the vertex → edge incidence and, for a relayout, the chains already in place.
struct Plan {
    layout: PackLayout,
    edges: EdgePrefix,
    prefix: InteriorPrefix,
    vertex_edge: (Vec<u32>, Vec<u32>),
    kept: Option<Kept>,
}

impl Plan {
    /// The plan of a pack of `store` from scratch.
    fn of(store: &ColorStore) -> Result<Self, PackError> {
        // Four passes over the mesh that read only the store, side by side.
        let ((layout, edges), (prefix, vertex_edge)) = rayon::join(
            || rayon::join(|| PackLayout::of(store), || EdgePrefix::of(store)),
            || rayon::join(|| InteriorPrefix::of(store), || vertex_edges(store.topology())),
        );
        Ok(Plan { layout: layout?, edges, prefix, vertex_edge, kept: None })
    }
}

/// The buffers of an earlier pack, reused by [`PackCache::rebuild`] (empty for a first pack).
#[derive(Default)]
struct Buffers {
    chains: Vec<Rgba>,
    upper: Vec<Rgba>,
    colors: Vec<u8>,
    records: Vec<FaceRecord>,
    positions: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
}

/// `buffer` cut or grown to `len` elements. Kept elements keep their old values (the
/// caller overwrites every element); when the capacity does not suffice the old memory is
/// released first, so the peak holds one buffer, not two.
/// Fresh memory is zeroed with huge pages advised ([`crate::memory`]).
fn reuse<T: Copy + bytemuck::Zeroable>(mut buffer: Vec<T>, len: usize) -> Vec<T> {
    if buffer.capacity() < len {
        drop(buffer);
        return crate::memory::zeroed(len);
    }
    buffer.truncate(len);
    buffer.resize(len, T::zeroed());
    buffer
}

/// Samples an incremental repack rewrote, as sorted, merged `(first, count)` ranges.
pub type SampleRanges = Vec<(u64, u64)>;

impl PackCache {
    /// Packs `store` (a full pack) and keeps what an incremental repack needs.
    pub fn build(store: &ColorStore, positions: &[[f32; 3]], format: ColorFormat) -> Result<Self, PackError> {
        Self::build_into(store, positions, format, Buffers::default(), None)
    }

    /// A full pack of `store` into this cache's buffers (what leaving paint mode runs when
    /// a resolution changed): memory already written is written again instead of fresh
    /// memory being mapped, which on this kind of machine costs more than the writes
    /// ([`crate::memory`]). Gives exactly the bytes of [`PackCache::build`]: every
    /// sample of every buffer is rewritten.
    pub fn rebuild(self, store: &ColorStore, positions: &[[f32; 3]], format: ColorFormat) -> Result<Self, PackError> {
        let PackCache { chains, upper, packed, .. } = self;
        let PackedMesh { positions: old_positions, indices, face_records, colors, .. } = packed;
        Self::build_into(
            store,
            positions,
            format,
            Buffers { chains, upper, colors, records: face_records, positions: old_positions, indices },
            None,
        )
    }

    /// The full pack, into `buffers` (reused where their capacity suffices).
    fn build_into(
        store: &ColorStore,
        positions: &[[f32; 3]],
        format: ColorFormat,
        buffers: Buffers,
        plan: Option<Plan>,
    ) -> Result<Self, PackError> {
        let topology = store.topology();
        if positions.len() != topology.vertex_count as usize {
            return Err(PackError::PositionCount { positions: positions.len(), vertices: topology.vertex_count });
        }
        let Plan { layout, edges, prefix, vertex_edge, kept } = match plan {
            Some(plan) => plan,
            None => Plan::of(store)?,
        };
        let kept = kept.as_ref();
        let sections = Sections::of(store, &layout, &edges);
        let Buffers { chains, upper, colors, mut records, positions: mut position_copy, mut indices } = buffers;
        records.clear();
        records.par_extend(
            (0..topology.face_count()).into_par_iter().with_min_len(BLOCK).map(|f| layout.face_record(store, f)),
        );
        let size = format.bytes_per_sample();
        // Every sample of these three is written by `build_all`, or was moved into place by a
        // relayout (`kept`): stale contents never show.
        let mut chains = reuse(chains, sections.vertex_end + edges.upper_len());
        let mut upper = reuse(upper, prefix.upper_len());
        let mut colors = reuse(colors, sections.total * size);
        {
            let ctx = Context {
                store,
                layout: &layout,
                records: &records,
                sections,
                format,
                prefix: &prefix,
                edges: &edges,
                kept,
            };
            build_all(&ctx, &mut chains, &mut upper, &mut colors, &vertex_edge);
        }
        position_copy.clear();
        position_copy.extend_from_slice(positions);
        indices.clear();
        indices.extend_from_slice(&topology.face_vertices);
        let packed = PackedMesh {
            positions: position_copy,
            indices,
            vertex_levels: layout.vertex_levels,
            face_records: records,
            format,
            colors,
        };
        Ok(PackCache { layout, sections, chains, prefix, edges, upper, vertex_edge, packed })
    }

    /// The packed mesh.
    pub fn packed(&self) -> &PackedMesh {
        &self.packed
    }

    /// Lends the packed colour bytes out: paint mode edits level 0 in them in place
    /// ([`crate::packing::paint_layout::PaintLayout::over_packed`]). Until they come back
    /// ([`PackCache::return_colors`]) the cache has no colours: [`PackCache::update`] refuses
    /// and a relayout packs in full.
    pub fn lend_colors(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.packed.colors)
    }

    /// Takes back the bytes [`PackCache::lend_colors`] lent, cut to this packing's length
    /// (paint mode may have grown them). Their chains must differ from this packing's only in
    /// level 0 of elements the next update or relayout is told are dirty, which it rewrites
    /// with the chains that read them.
    pub fn return_colors(&mut self, mut bytes: Vec<u8>) {
        bytes.truncate(self.sections.total * self.packed.format.bytes_per_sample());
        self.packed.colors = bytes;
    }

    /// Heap bytes of the packing and what an incremental repack keeps beside it.
    pub fn heap_bytes(&self) -> PackBytes {
        fn bytes<T>(v: &[T]) -> u64 {
            std::mem::size_of_val(v) as u64
        }
        let p = &self.packed;
        PackBytes {
            colors: bytes(&p.colors),
            records_and_geometry: bytes(&p.face_records) + bytes(&p.positions) + bytes(&p.indices),
            levels: bytes(&self.chains) + bytes(&self.upper),
            tables: bytes(&self.layout.edge_base)
                + bytes(&self.layout.interior_base)
                + bytes(&self.prefix.chain)
                + bytes(&self.prefix.upper)
                + bytes(&self.edges.chain)
                + bytes(&self.edges.upper)
                + bytes(&self.vertex_edge.0)
                + bytes(&self.vertex_edge.1),
        }
    }

    /// Whether the colour bytes are all here (not lent, or given back whole).
    fn has_colors(&self) -> bool {
        self.packed.colors.len() == self.sections.total * self.packed.format.bytes_per_sample()
    }

    /// The packed mesh, dropping the rest.
    pub fn into_packed(self) -> PackedMesh {
        self.packed
    }
}

/// Packs the store with `positions` (one per vertex) into linear buffers.
pub fn pack(store: &ColorStore, positions: &[[f32; 3]], format: ColorFormat) -> Result<PackedMesh, PackError> {
    Ok(PackCache::build(store, positions, format)?.into_packed())
}
