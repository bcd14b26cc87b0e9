//! Repacks that start from an earlier pack: [`PackCache::update`] recomputes only the chains
//! an edit reaches when no resolution changed; [`PackCache::relayout`] lays out anew after
//! resolution changes and copies every chain the edits did not reach.

use rayon::prelude::*;

use super::{
    BLOCK, Buffers, Context, Kept, PackCache, Plan, SampleRanges, Sections, coarse_of, coarse_table, reduce_edge_level,
};
use crate::colors::layout::{self, Resolution};
use crate::colors::store::{ColorStore, DirtyElements};
use crate::packing::PackError;
use crate::packing::chains_view::ChainsView;
use crate::packing::edges::EdgePrefix;
use crate::packing::interiors::InteriorPrefix;
use crate::packing::interiors::dirty_pieces;
use crate::packing::linear::PackedMesh;
use crate::packing::mip::reduce_vertex_level;

impl PackCache {
    /// A full pack of `store` after edits that may have changed resolutions (`dirty`:
    /// everything changed in `store` since this cache was built or last updated, as for
    /// [`PackCache::update`]), in this cache's format and buffers: a new layout, into which
    /// each face interior, edge and vertex chain that reads nothing an edit changed is
    /// moved, in place, instead of recomputed (a vertex chain re-levelled when the largest
    /// resolution changed). Computed: the chains of edited or resized faces, edges and
    /// vertices, every edge of such a face, every vertex of such an edge, the levels ≥ 1 of
    /// every edge with a coarser face (what that face shows reads its vertices) and of the
    /// vertices next to one. Gives exactly the bytes of [`PackCache::build`]; each buffer's
    /// capacity grows to the larger of the two layouts, no more.
    pub fn relayout(
        self,
        store: &ColorStore,
        positions: &[[f32; 3]],
        dirty: &DirtyElements,
    ) -> Result<Self, PackError> {
        let topology = store.topology();
        let format = self.packed.format;
        let (faces, edges) = (topology.face_count() as usize, topology.edge_count() as usize);
        if faces != self.packed.face_records.len()
            || !self.has_colors()
            || edges != self.layout.edge_base.len()
            || topology.vertex_count as usize != self.packed.positions.len()
        {
            return self.rebuild(store, positions, format);
        }
        // Refused layouts (too many samples) before anything moves.
        let (layout, (new_edges, new_prefix)) = rayon::join(
            || super::PackLayout::of(store),
            || rayon::join(|| EdgePrefix::of(store), || InteriorPrefix::of(store)),
        );
        let layout = layout?;
        let new = Sections::of(store, &layout, &new_edges);
        let mut kept = Kept { faces: vec![true; faces], edges: Vec::new(), vertices: Vec::new() };
        for &f in dirty.faces.iter().chain(&dirty.resized_faces) {
            if let Some(face) = kept.faces.get_mut(f as usize) {
                *face = false;
            }
        }
        kept.edges = (0..edges as u32)
            .into_par_iter()
            .map(|e| topology.faces_of_edge(e).iter().all(|&(f, _)| kept.face(f)))
            .collect();
        for &e in dirty.edges.iter().chain(&dirty.resized_edges) {
            if let Some(edge) = kept.edges.get_mut(e as usize) {
                *edge = false;
            }
        }
        let (bytes, edge_upper, face_upper) =
            kept_moves(&mut kept, (&self.sections, &self.edges, &self.prefix), (&new, &new_edges, &new_prefix));
        let bytes = bytes.scaled(format.bytes_per_sample());
        let size = format.bytes_per_sample();
        if !(bytes.fit(self.packed.colors.len(), new.total * size)
            && edge_upper.fit(self.chains.len(), new.vertex_end + new_edges.upper_len())
            && face_upper.fit(self.upper.len(), new_prefix.upper_len()))
        {
            return self.rebuild(store, positions, format); // never: both layouts are the store's
        }
        // A vertex chain is in place when its colour and every incident edge are: with more
        // levels than before its new levels repeat its last (no edge of it has samples
        // there), with fewer it is cut.
        let (offsets, incident) = &self.vertex_edge;
        let mut vertices = vec![true; topology.vertex_count as usize];
        for &v in &dirty.vertices {
            if let Some(vertex) = vertices.get_mut(v as usize) {
                *vertex = false;
            }
        }
        // From a single level a vertex's colour is the store's, unfiltered (a −0.0 stays
        // −0.0, where the filter of its next level gives +0.0): then every vertex is computed.
        if self.layout.vertex_levels == 1 && layout.vertex_levels > 1 {
            vertices.fill(false);
        }
        kept.vertices = (0..topology.vertex_count as usize)
            .into_par_iter()
            .map(|v| {
                vertices[v] && incident[offsets[v] as usize..offsets[v + 1] as usize].iter().all(|&e| kept.edge(e))
            })
            .collect();
        let levels = (self.layout.vertex_levels as usize, layout.vertex_levels as usize);
        let shape = (topology.vertex_count as usize, levels);
        let PackCache { chains, upper, packed, vertex_edge, .. } = self;
        let PackedMesh { positions: old_positions, indices, face_records, colors, .. } = packed;
        // Three buffers, each moved on one thread (a buffer's moves go in order), side by side.
        let (colors, (chains, upper)) = rayon::join(
            || relaid(colors, bytes, new.total * size, shape, size),
            || {
                rayon::join(
                    || relaid(chains, edge_upper, new.vertex_end + new_edges.upper_len(), shape, 1),
                    || face_upper.apply(upper, new_prefix.upper_len()),
                )
            },
        );
        let buffers = Buffers { colors, chains, upper, records: face_records, positions: old_positions, indices };
        let plan = Plan { layout, edges: new_edges, prefix: new_prefix, vertex_edge, kept: Some(kept) };
        Self::build_into(store, positions, format, buffers, Some(plan))
    }

    /// Brings the packed mesh up to date with the edits in `dirty` (everything changed in
    /// `store` since this cache was built or last updated): level 0 of the dirty elements,
    /// the interior chains of dirty faces and, level by level, the edge and vertex chains
    /// whose inputs changed. Gives exactly the bytes of a full pack of `store`. Returns the
    /// rewritten sample ranges, or `None` when the layout no longer fits (a resolution
    /// changed, or the store is not the one packed): then build a new cache.
    /// Long: one level loop over the growing sets of edges and vertices it recomputes and
    /// the buffer sections it borrows; split, the sets would travel through every helper.
    pub fn update(&mut self, store: &ColorStore, dirty: &DirtyElements) -> Option<SampleRanges> {
        let topology = store.topology();
        if !dirty.resized_faces.is_empty()
            || !dirty.resized_edges.is_empty()
            || !self.has_colors()
            || topology.face_count() as usize != self.packed.face_records.len()
            || topology.vertex_count as usize != self.packed.positions.len()
            || topology.edge_count() as usize != self.layout.edge_base.len()
        {
            return None;
        }
        let format = self.packed.format;
        let size = format.bytes_per_sample();
        let s = self.sections;
        let levels = s.levels;
        let layout = &self.layout;
        let prefix = &self.prefix;
        let ctx = Context {
            store,
            layout,
            records: &self.packed.face_records,
            sections: s,
            format,
            prefix,
            edges: &self.edges,
            kept: None,
        };
        let chains = &mut self.chains;
        let upper = &mut self.upper;
        let bytes = &mut self.packed.colors;
        let interior_len =
            |f: u32| layout::interior_chain_len(store.face_resolution(f).unwrap_or(Resolution::ONE)) as usize;
        // Level 0 and whole interior chains.
        for &v in &dirty.vertices {
            let at = v as usize * levels;
            ctx.vertex_level0(v, &mut chains[at..at + levels], &mut bytes[at * size..(at + levels) * size]);
        }
        let mut scratch = Vec::new();
        for &e in &dirty.edges {
            let (c, u) = self.edges.ranges(e);
            scratch.resize(c.len() - u.len(), [0.0; 4]);
            let out = &mut bytes[(s.vertex_end + c.start) * size..(s.vertex_end + c.end) * size];
            format.encode_quantized_slice(store.edge_samples(e), out, &mut scratch);
        }
        {
            let (_, interior_bytes) = bytes.split_at_mut(s.edge_end * size);
            let mut work = dirty_pieces(prefix, &dirty.faces, size, interior_bytes, upper);
            work.par_iter_mut()
                .for_each_init(Vec::new, |scratch, (f, out, up)| ctx.interior_chain(*f, scratch, up, out));
        }
        // Which edges and vertices each level recomputes: an edge at level l reads its own
        // level l − 1, its endpoints', its faces' (interiors, and what coarse faces show,
        // which may read any element of such a face); a vertex reads its edges'. So a face
        // is touched when any of its elements changed at a finer level, and every edge of a
        // touched face is recomputed from there on (cumulative sets, a safe superset).
        let mut edge_flag = vec![false; topology.edge_count() as usize];
        let mut vertex_flag = vec![false; topology.vertex_count as usize];
        let mut face_flag = vec![false; topology.face_count() as usize];
        let mut edges: Vec<u32> = Vec::new();
        let mut vertices: Vec<u32> = Vec::new();
        for &e in &dirty.edges {
            if !std::mem::replace(&mut edge_flag[e as usize], true) {
                edges.push(e);
            }
        }
        for &v in &dirty.vertices {
            if !std::mem::replace(&mut vertex_flag[v as usize], true) {
                vertices.push(v);
            }
        }
        let (offsets, incident) = &self.vertex_edge;
        let mut touched: Vec<u32> = Vec::new();
        for level in 1..levels {
            // Faces whose elements changed at a finer level (E and V as of level − 1).
            touched.clear();
            let mut touch = |face: u32, touched: &mut Vec<u32>| {
                if !std::mem::replace(&mut face_flag[face as usize], true) {
                    touched.push(face);
                }
            };
            for &f in &dirty.faces {
                touch(f, &mut touched);
            }
            for &v in &vertices {
                for &e in &incident[offsets[v as usize] as usize..offsets[v as usize + 1] as usize] {
                    for &(f, _) in topology.faces_of_edge(e) {
                        touch(f, &mut touched);
                    }
                }
            }
            for &e in &edges {
                for &(f, _) in topology.faces_of_edge(e) {
                    touch(f, &mut touched);
                }
            }
            for &f in &touched {
                face_flag[f as usize] = false;
            }
            // Vertices read their edges; edges read everything of their faces.
            let previous_edges = edges.len();
            for &e in &edges[..previous_edges] {
                for v in topology.edge_vertices[e as usize] {
                    if !std::mem::replace(&mut vertex_flag[v as usize], true) {
                        vertices.push(v);
                    }
                }
            }
            for &f in &touched {
                for e in topology.face_edges[f as usize] {
                    if !std::mem::replace(&mut edge_flag[e as usize], true) {
                        edges.push(e);
                    }
                }
            }
            edges.sort_unstable();
            vertices.sort_unstable();
            let (vertex_colors, edge_upper) = chains.split_at_mut(s.vertex_end);
            let interiors = ctx.interiors(&bytes[s.edge_end * size..], upper);
            let edge_bytes = &bytes[s.vertex_end * size..s.edge_end * size];
            let coarse = {
                let view = ChainsView {
                    store,
                    records: ctx.records,
                    vertex_levels: layout.vertex_levels,
                    vertex_colors: &*vertex_colors,
                    edges: ctx.edge_reader(edge_bytes, edge_upper),
                    interiors,
                    vertex_section: s.vertex_end,
                    interior_start: s.edge_end,
                };
                coarse_table(&ctx, &view, &edges, level as u32)
            };
            for &e in &edges {
                let (c, u) = self.edges.ranges(e);
                if c.is_empty() {
                    continue;
                }
                ctx.edge_reader(edge_bytes, edge_upper).chain_into(e, &mut scratch);
                reduce_edge_level(&ctx, e, coarse_of(&coarse, e), &mut scratch, level as u32, &interiors);
                let n0 = c.len() - u.len();
                edge_upper[u].copy_from_slice(&scratch[n0..]);
            }
            let reader = ctx.edge_reader(edge_bytes, edge_upper);
            for &v in &vertices {
                let at = v as usize * levels;
                let list = &incident[offsets[v as usize] as usize..offsets[v as usize + 1] as usize];
                reduce_vertex_level(store, list, v, &mut vertex_colors[at..at + levels], level, &reader);
            }
        }
        // Encode what changed; report it as ranges.
        let mut ranges: Vec<(u64, u64)> = Vec::new();
        for &v in &vertices {
            let at = v as usize * levels;
            format.encode_slice(&chains[at + 1..at + levels], &mut bytes[(at + 1) * size..(at + levels) * size]);
            ranges.push((at as u64, levels as u64));
        }
        for &e in &edges {
            let (c, u) = self.edges.ranges(e);
            if !c.is_empty() {
                let (first, n0) = (s.vertex_end + c.start, c.len() - u.len());
                let upper_levels = &chains[s.vertex_end + u.start..s.vertex_end + u.end];
                format.encode_slice(upper_levels, &mut bytes[(first + n0) * size..(s.vertex_end + c.end) * size]);
                ranges.push((first as u64, c.len() as u64));
            }
        }
        for &f in &dirty.faces {
            let (at, len) = (layout.interior_base[f as usize] as usize, interior_len(f));
            if len > 0 {
                ranges.push((at as u64, len as u64));
            }
        }
        ranges.sort_unstable();
        let mut merged: SampleRanges = Vec::with_capacity(ranges.len());
        for (first, count) in ranges {
            match merged.last_mut() {
                Some((last_first, last_count)) if *last_first + *last_count >= first => {
                    *last_count = (*last_count).max(first + count - *last_first);
                }
                _ => merged.push((first, count)),
            }
        }
        Some(merged)
    }
}

/// Where each kept chain is and goes, from the `old` layout (sections, edge and interior
/// prefixes) to the `new`: its samples in the colour bytes, its levels ≥ 1 in `chains`
/// (edges) and in `upper` (faces). A chain whose lengths differ is not kept (never: kept
/// means same resolution). Blocks of elements in parallel, joined in order.
fn kept_moves(
    kept: &mut Kept,
    (old, old_edges, old_prefix): (&Sections, &EdgePrefix, &InteriorPrefix),
    (new, new_edges, new_prefix): (&Sections, &EdgePrefix, &InteriorPrefix),
) -> (Moves, Moves, Moves) {
    let edge_blocks: Vec<(Moves, Moves)> = kept
        .edges
        .par_chunks_mut(BLOCK)
        .enumerate()
        .map(|(block, flags)| {
            let (mut bytes, mut upper) = (Moves::default(), Moves::default());
            for (k, flag) in flags.iter_mut().enumerate() {
                let e = (block * BLOCK + k) as u32;
                let ((c, u), (c_new, u_new)) = (old_edges.ranges(e), new_edges.ranges(e));
                if *flag && c.len() == c_new.len() && u.len() == u_new.len() {
                    bytes.push(old.vertex_end + c.start, new.vertex_end + c_new.start, c.len());
                    upper.push(old.vertex_end + u.start, new.vertex_end + u_new.start, u.len());
                } else {
                    *flag = false;
                }
            }
            (bytes, upper)
        })
        .collect();
    let face_blocks: Vec<(Moves, Moves)> = kept
        .faces
        .par_chunks_mut(BLOCK)
        .enumerate()
        .map(|(block, flags)| {
            let (mut bytes, mut upper) = (Moves::default(), Moves::default());
            for (k, flag) in flags.iter_mut().enumerate() {
                let f = block * BLOCK + k;
                let span = |prefix: &[u32]| (prefix[f] as usize, (prefix[f + 1] - prefix[f]) as usize);
                let ((c, n), (c_new, n_new)) = (span(&old_prefix.chain), span(&new_prefix.chain));
                let ((u, m), (u_new, m_new)) = (span(&old_prefix.upper), span(&new_prefix.upper));
                if *flag && n == n_new && m == m_new {
                    bytes.push(old.edge_end + c, new.edge_end + c_new, n);
                    upper.push(u, u_new, m);
                } else {
                    *flag = false;
                }
            }
            (bytes, upper)
        })
        .collect();
    let (mut bytes, mut edge_upper, mut face_upper) = (Moves::default(), Moves::default(), Moves::default());
    for (block_bytes, block_upper) in edge_blocks {
        bytes.append(block_bytes);
        edge_upper.append(block_upper);
    }
    for (block_bytes, block_upper) in face_blocks {
        bytes.append(block_bytes);
        face_upper.append(block_upper);
    }
    (bytes, edge_upper, face_upper)
}

/// `buffer` (a vertex section first, `unit` elements a level) with `moves` applied and the
/// vertex section re-laid from `from` to `to` levels a vertex (`shape`: vertices, (from,
/// to)), cut or grown to `len`. The vertex section only shrinks into itself and only grows
/// into room the moves cleared, so it is re-laid before the moves when it shrinks, after
/// them when it grows.
fn relaid<T: Copy + bytemuck::Zeroable>(
    mut buffer: Vec<T>,
    moves: Moves,
    len: usize,
    (vertices, (from, to)): (usize, (usize, usize)),
    unit: usize,
) -> Vec<T> {
    if to < from {
        relevel(&mut buffer, vertices, (from, to), unit);
    }
    let mut buffer = moves.apply(buffer, len);
    if to > from {
        relevel(&mut buffer, vertices, (from, to), unit);
    }
    buffer
}

/// Re-lays `vertices` chains of `from` levels (each level `unit` elements, from the start of
/// `buffer`) as chains of `to` levels: level `l` of a new chain is level `min(l, from − 1)`
/// of the old. In place: growing goes last vertex first and shrinking first vertex first,
/// so no element is overwritten before it is read.
fn relevel<T: Copy>(buffer: &mut [T], vertices: usize, (from, to): (usize, usize), unit: usize) {
    if from == 0 || buffer.len() < vertices * from.max(to) * unit {
        return; // never: the caller's sections hold both shapes
    }
    let copy = |buffer: &mut [T], v: usize, level: usize| {
        let source = (v * from + level.min(from - 1)) * unit;
        buffer.copy_within(source..source + unit, (v * to + level) * unit);
    };
    if to > from {
        for v in (0..vertices).rev() {
            for level in (0..to).rev() {
                copy(buffer, v, level);
            }
        }
    } else {
        for v in 0..vertices {
            for level in 0..to {
                copy(buffer, v, level);
            }
        }
    }
}

/// Runs of elements that move within one buffer from one layout to the next: `(from, to,
/// count)`, increasing in both `from` and `to` (both layouts keep the elements' order),
/// neighbouring moves merged into one.
#[derive(Default)]
struct Moves(Vec<(usize, usize, usize)>);

impl Moves {
    fn push(&mut self, from: usize, to: usize, count: usize) {
        if count == 0 {
            return;
        }
        match self.0.last_mut() {
            Some((last_from, last_to, last_count))
                if *last_from + *last_count == from && *last_to + *last_count == to =>
            {
                *last_count += count;
            }
            _ => self.0.push((from, to, count)),
        }
    }

    /// `other`'s moves after these (merged where they meet).
    fn append(&mut self, other: Moves) {
        for (from, to, count) in other.0 {
            self.push(from, to, count);
        }
    }

    /// The same moves in units `size` times smaller (samples to bytes).
    fn scaled(self, size: usize) -> Self {
        Moves(self.0.into_iter().map(|(from, to, count)| (from * size, to * size, count * size)).collect())
    }

    /// Whether every run lies within a buffer of `old_len` elements before and `len` after.
    fn fit(&self, old_len: usize, len: usize) -> bool {
        self.0.iter().all(|&(from, to, count)| from + count <= old_len && to + count <= len)
    }

    /// `buffer` with every run moved ([`Moves::fit`] its length and `len`), then cut or
    /// grown to `len`; what no run covers is left as it was (the caller rewrites it). Runs
    /// moving towards the start go first to last, runs moving towards the end last to first:
    /// since both layouts keep the order, no run then overwrites one not yet moved (a run's
    /// own overlap is `copy_within`'s).
    fn apply<T: Copy + bytemuck::Zeroable>(self, mut buffer: Vec<T>, len: usize) -> Vec<T> {
        if buffer.len() < len {
            // Exactly as large as the new layout: `resize` alone may double the capacity.
            buffer.reserve_exact(len - buffer.len());
            buffer.resize(len, T::zeroed());
        }
        for &(from, to, count) in self.0.iter().filter(|m| m.1 < m.0) {
            buffer.copy_within(from..from + count, to);
        }
        for &(from, to, count) in self.0.iter().rev().filter(|m| m.1 > m.0) {
            buffer.copy_within(from..from + count, to);
        }
        buffer.truncate(len);
        buffer
    }
}

#[cfg(test)]
mod tests {
    use super::Moves;

    /// Every run moved out of place into a copy: the truth in-place moves must equal.
    fn moved_aside(buffer: &[u32], moves: &[(usize, usize, usize)], len: usize) -> Vec<u32> {
        let mut out = buffer.to_vec();
        out.resize(len.max(buffer.len()), 0);
        for &(from, to, count) in moves {
            out[to..to + count].copy_from_slice(&buffer[from..from + count]);
        }
        out.truncate(len);
        out
    }

    #[test]
    fn in_place_moves_equal_moves_out_of_place() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n.max(1)) as usize
        };
        for round in 0..400 {
            // Elements of random lengths, each kept (moved) or not, laid out again with
            // other lengths for the ones not kept: both layouts keep the order.
            let elements = 1 + next(40);
            let (mut from, mut to, mut runs) = (0usize, 0usize, Vec::new());
            for _ in 0..elements {
                let len = next(if round % 4 == 0 { 2000 } else { 30 });
                if next(3) > 0 {
                    runs.push((from, to, len));
                    from += len;
                    to += len;
                } else {
                    from += len;
                    to += next(60);
                }
            }
            let buffer: Vec<u32> = (0..from as u32).collect();
            let truth_runs: Vec<_> = runs.iter().copied().filter(|r| r.2 > 0).collect();
            let truth = moved_aside(&buffer, &truth_runs, to);
            let mut moves = Moves::default();
            for &(f, t, n) in &runs {
                moves.push(f, t, n);
            }
            let got = moves.apply(buffer.clone(), to);
            for &(_, t, n) in &truth_runs {
                assert_eq!(got[t..t + n], truth[t..t + n], "round {round}");
            }
        }
    }
}
