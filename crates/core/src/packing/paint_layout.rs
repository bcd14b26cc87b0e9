//! The GPU layout used *while painting*: level 0 only, every edge and face interior in its
//! own block with slack, so an edit uploads only what changed (see docs/PAINT_MODE.md).
//!
//! Outside paint mode the GPU holds the compact packed layout with MIP chains
//! ([`crate::packing::packer`]). Repacking that after every dab would upload the whole mesh, and a
//! resolution change would shift every later chain. In paint mode the colour buffer instead
//! holds
//!
//! - vertex `v` at index `v` (one level: `vertex_levels = 1`),
//! - each edge's and each face interior's level-0 samples in a *block* whose capacity is
//!   the sample count rounded up to a power of two (≥ 1 sample of slack to grow in place
//!   for small changes, never less than needed),
//!
//! addressed by the same 16-byte face records the shaders already read (level 0 only, so
//! the shader's level offsets are all zero). After a dab, [`PaintLayout::sync`] returns the
//! dirty blocks as index ranges to re-encode and upload, plus the face records that changed.
//! When an element's sample count outgrows its block (a raised resolution), it moves to a
//! new block — taken from a free list of its size class or from the end of the buffer —
//! and the records of every face that reads it are patched. Uploads are therefore
//! proportional to the samples and records that changed. When the buffer's capacity is
//! exhausted, `sync` says so and the caller re-uploads everything (`grown`); capacity
//! doubles each time, so that is rare.
//!
//! Entering paint mode need not build this layout from scratch: [`PaintLayout::over_packed`]
//! lays it over the compact packing the view already shows (each element's block is level 0
//! of its MIP chain, vertex `v` at `v · vertex_levels`), so the GPU keeps its buffers and the
//! encoded copy is the packing's own bytes. Only elements whose sample count changes move, to
//! blocks past the packing's end; the chains' levels ≥ 1 go stale, which paint mode never reads
//! (it samples level 0 only) and leaving paint mode recomputes for every edited element.

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::Resolution;
use crate::colors::store::{ColorStore, DirtyElements};
use crate::packing::linear::{FaceRecord, MAX_SAMPLES, PackedMesh, pack_word, unpack_word};

/// A block of the colour buffer: `base .. base + capacity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Block {
    /// First sample index.
    pub base: u32,
    /// Samples reserved (a power of two, or 0 for an element without samples).
    pub capacity: u32,
}

/// What [`PaintLayout::sync`] asks the GPU to update.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UploadPlan {
    /// Sample index ranges `(first, count)` to re-encode from the store and upload,
    /// sorted and merged where adjacent.
    pub sample_ranges: Vec<(u32, u32)>,
    /// Faces whose record changed, sorted.
    pub faces: Vec<u32>,
    /// The buffer outgrew its capacity: re-upload everything ([`PaintLayout::packed`]).
    pub grown: bool,
}

impl UploadPlan {
    /// Samples this plan uploads.
    pub fn sample_count(&self) -> u64 {
        self.sample_ranges.iter().map(|&(_, n)| u64::from(n)).sum()
    }
}

/// Block allocation of a store's level-0 samples with slack.
#[derive(Debug, Clone, PartialEq)]
pub struct PaintLayout {
    edge_blocks: Vec<Block>,
    interior_blocks: Vec<Block>,
    /// Free blocks per size class (`log2 capacity`).
    free: Vec<Vec<u32>>,
    /// First unallocated sample.
    end: u64,
    /// Samples the GPU buffer holds.
    capacity: u64,
    records: Vec<FaceRecord>,
    /// Vertex `v`'s sample is at `v · vertex_stride` (1 in a layout of its own, the vertex
    /// levels of the compact packing it was laid over).
    vertex_stride: u32,
    /// The end of the packing this layout was laid over (0 for a layout of its own).
    packed_end: u64,
}

fn block_capacity(samples: u32) -> u32 {
    if samples == 0 { 0 } else { samples.next_power_of_two() }
}

impl PaintLayout {
    /// Lays out every element of `store`, with the buffer's capacity at least `1.5×` the
    /// space used (so early resolution raises allocate without re-uploading).
    pub fn new(store: &ColorStore) -> Self {
        let topology = store.topology();
        let mut layout = PaintLayout {
            edge_blocks: Vec::with_capacity(topology.edge_count() as usize),
            interior_blocks: Vec::with_capacity(topology.face_count() as usize),
            free: vec![Vec::new(); 32],
            end: u64::from(topology.vertex_count),
            capacity: 0,
            records: Vec::new(),
            vertex_stride: 1,
            packed_end: 0,
        };
        for edge in 0..topology.edge_count() {
            let block = layout.allocate(store.edge_samples(edge).len() as u32);
            layout.edge_blocks.push(block);
        }
        for face in 0..topology.face_count() {
            let block = layout.allocate(store.interior_samples(face).len() as u32);
            layout.interior_blocks.push(block);
        }
        layout.capacity = (layout.end + layout.end / 2).clamp(1, MAX_SAMPLES);
        layout.records = (0..topology.face_count()).map(|face| layout.record(store, face)).collect();
        layout
    }

    /// The layout over `packed`, the compact packing of `store` the GPU already holds
    /// ([`crate::packing::packer::PackCache`]): every element's block is level 0 of its chain
    /// there, vertex `v` at `v · vertex_levels`, the face records are the packing's own (a
    /// chain's level 0 starts at its base), and the capacity is the packing's samples, so no
    /// byte moves on entering paint mode. `None` when `packed` is not a packing of `store`'s
    /// topology and resolutions (then lay out anew: [`PaintLayout::new`]).
    pub fn over_packed(store: &ColorStore, packed: &PackedMesh) -> Option<Self> {
        let topology = store.topology();
        let faces = topology.face_count() as usize;
        if packed.face_records.len() != faces
            || packed.indices.len() != faces
            || packed.vertex_levels == 0
            || u64::from(topology.vertex_count) * u64::from(packed.vertex_levels) > packed.sample_count()
        {
            return None;
        }
        let total = packed.sample_count();
        let fits = |base: u32, len: usize| u64::from(base) + len as u64 <= total;
        let mut edge_blocks = vec![Block::default(); topology.edge_count() as usize];
        let mut interior_blocks = vec![Block::default(); faces];
        for (face, record) in packed.face_records.iter().enumerate() {
            let r = store.face_resolution(face as u32)?;
            let (base, log2) = unpack_word(record.interior);
            let len = store.interior_samples(face as u32).len();
            if log2 != r.log2() || !fits(base, len) {
                return None;
            }
            interior_blocks[face] = Block { base: if len == 0 { 0 } else { base }, capacity: len as u32 };
            for (k, &word) in record.edges.iter().enumerate() {
                let edge = topology.face_edges[face][k];
                let (base, log2) = unpack_word(word);
                let len = store.edge_samples(edge).len();
                if log2 != store.edge_resolution(edge)?.log2() || !fits(base, len) {
                    return None;
                }
                edge_blocks[edge as usize] = Block { base: if len == 0 { 0 } else { base }, capacity: len as u32 };
            }
        }
        Some(PaintLayout {
            edge_blocks,
            interior_blocks,
            free: vec![Vec::new(); 32],
            end: total,
            capacity: total,
            records: packed.face_records.clone(),
            vertex_stride: packed.vertex_levels,
            packed_end: total,
        })
    }

    /// Where vertex `v`'s sample is.
    fn vertex_slot(&self, v: u32) -> u32 {
        v.saturating_mul(self.vertex_stride)
    }

    fn allocate(&mut self, samples: u32) -> Block {
        let capacity = block_capacity(samples);
        if capacity == 0 {
            return Block::default();
        }
        let class = capacity.trailing_zeros() as usize;
        if let Some(base) = self.free.get_mut(class).and_then(Vec::pop) {
            return Block { base, capacity };
        }
        let base = self.end.min(u64::from(u32::MAX)) as u32;
        self.end += u64::from(capacity);
        Block { base, capacity }
    }

    /// Frees `block` for reuse by its size class. The blocks of the packing a layout was laid
    /// over ([`PaintLayout::over_packed`]) are never reused: they hold chains, not blocks.
    fn release(&mut self, block: Block) {
        if block.capacity.is_power_of_two()
            && u64::from(block.base) >= self.packed_end
            && let Some(list) = self.free.get_mut(block.capacity.trailing_zeros() as usize)
        {
            list.push(block.base);
        }
    }

    fn record(&self, store: &ColorStore, face: u32) -> FaceRecord {
        let topology = store.topology();
        let r = store.face_resolution(face).unwrap_or(Resolution::ONE);
        let edges = topology.face_edges[face as usize].map(|edge| {
            let r_edge = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
            pack_word(self.edge_blocks[edge as usize].base, r_edge.log2())
        });
        FaceRecord { interior: pack_word(self.interior_blocks[face as usize].base, r.log2()), edges }
    }

    /// Heap bytes of the layout (blocks, free lists, face records).
    pub fn heap_bytes(&self) -> u64 {
        let free: usize = self.free.iter().map(|list| std::mem::size_of_val(list.as_slice())).sum();
        (std::mem::size_of_val(self.edge_blocks.as_slice())
            + std::mem::size_of_val(self.interior_blocks.as_slice())
            + std::mem::size_of_val(self.records.as_slice())
            + free) as u64
    }

    /// Samples the GPU buffer must hold (allocated blocks plus slack).
    pub fn capacity(&self) -> u64 {
        self.capacity
    }

    /// The face records (level 0, paint layout).
    pub fn records(&self) -> &[FaceRecord] {
        &self.records
    }

    /// Block of `edge`.
    pub fn edge_block(&self, edge: u32) -> Option<Block> {
        self.edge_blocks.get(edge as usize).copied()
    }

    /// Block of `face`'s interior.
    pub fn interior_block(&self, face: u32) -> Option<Block> {
        self.interior_blocks.get(face as usize).copied()
    }

    /// Brings the layout up to date with `dirty` (taken from the store after an edit) and
    /// returns what to upload.
    pub fn sync(&mut self, store: &ColorStore, dirty: &DirtyElements) -> UploadPlan {
        let topology = store.topology();
        let mut plan = UploadPlan::default();
        let mut faces_to_patch: Vec<u32> = dirty.resized_faces.clone();
        for &edge in &dirty.resized_edges {
            let needed = store.edge_samples(edge).len() as u32;
            let old = self.edge_blocks[edge as usize];
            if block_capacity(needed) != old.capacity {
                self.release(old);
                self.edge_blocks[edge as usize] = self.allocate(needed);
            }
            faces_to_patch.extend(topology.faces_of_edge(edge).iter().map(|&(face, _)| face));
        }
        for &face in &dirty.resized_faces {
            let needed = store.interior_samples(face).len() as u32;
            let old = self.interior_blocks[face as usize];
            if block_capacity(needed) != old.capacity {
                self.release(old);
                self.interior_blocks[face as usize] = self.allocate(needed);
            }
        }
        faces_to_patch.sort_unstable();
        faces_to_patch.dedup();
        for &face in &faces_to_patch {
            let record = self.record(store, face);
            if self.records[face as usize] != record {
                self.records[face as usize] = record;
                plan.faces.push(face);
            }
        }
        if self.end > self.capacity {
            self.capacity = (self.end * 2).min(MAX_SAMPLES.max(self.end));
            plan.grown = true;
        }
        let mut ranges: Vec<(u32, u32)> = Vec::new();
        ranges.extend(dirty.vertices.iter().map(|&v| (self.vertex_slot(v), 1)));
        for &edge in &dirty.edges {
            let len = store.edge_samples(edge).len() as u32;
            if len > 0 {
                ranges.push((self.edge_blocks[edge as usize].base, len));
            }
        }
        for &face in &dirty.faces {
            let len = store.interior_samples(face).len() as u32;
            if len > 0 {
                ranges.push((self.interior_blocks[face as usize].base, len));
            }
        }
        ranges.sort_unstable();
        for (first, count) in ranges {
            match plan.sample_ranges.last_mut() {
                Some((last_first, last_count)) if *last_first + *last_count == first => *last_count += count,
                _ => plan.sample_ranges.push((first, count)),
            }
        }
        plan
    }

    /// The level-0 colour of every slot in `range` (linear), read from the store; slack
    /// slots are zero.
    pub fn colors(&self, store: &ColorStore, first: u32, count: u32) -> Vec<Rgba> {
        let mut out = vec![[0.0; 4]; count as usize];
        let end = u64::from(first) + u64::from(count);
        let topology = store.topology();
        let mut put = |base: u32, samples: &[Rgba]| {
            for (k, &color) in samples.iter().enumerate() {
                let index = u64::from(base) + k as u64;
                if index >= u64::from(first) && index < end {
                    out[(index - u64::from(first)) as usize] = color;
                }
            }
        };
        for v in 0..topology.vertex_count {
            if let Some(color) = store.vertex_color(v) {
                put(self.vertex_slot(v), &[color]);
            }
        }
        for (edge, block) in self.edge_blocks.iter().enumerate() {
            if block.capacity > 0 && u64::from(block.base) < end && block.base + block.capacity > first {
                put(block.base, store.edge_samples(edge as u32));
            }
        }
        for (face, block) in self.interior_blocks.iter().enumerate() {
            if block.capacity > 0 && u64::from(block.base) < end && block.base + block.capacity > first {
                put(block.base, store.interior_samples(face as u32));
            }
        }
        out
    }

    /// Encodes every sample range of `plan` (as [`PaintLayout::sync`] returned it for
    /// `dirty`) in `format`, concatenated in the plan's order: range `k` starts at byte
    /// `(count₀ + … + count_{k−1}) × bytes_per_sample`. One pass over the dirty elements, each
    /// placed in its range by binary search (O(dirty · log ranges + samples)); slots of a
    /// range that no dirty element covers are zero.
    pub fn encode_plan(
        &self,
        store: &ColorStore,
        dirty: &DirtyElements,
        plan: &UploadPlan,
        format: ColorFormat,
    ) -> Vec<u8> {
        let ranges = &plan.sample_ranges;
        // Sample offset of each range in the output.
        let mut starts = Vec::with_capacity(ranges.len());
        let mut total = 0usize;
        for &(_, count) in ranges {
            starts.push(total);
            total += count as usize;
        }
        let mut colors = vec![[0.0f32; 4]; total];
        let mut put = |base: u32, samples: &[Rgba]| {
            // The range holding `base`: the last one starting at or before it.
            let k = ranges.partition_point(|&(first, _)| first <= base);
            let Some(&(first, count)) = k.checked_sub(1).and_then(|k| ranges.get(k)) else {
                return;
            };
            let within = (base - first) as usize;
            if within >= count as usize {
                return;
            }
            let start = starts[k - 1] + within;
            let room = count as usize - within;
            for (slot, &c) in colors[start..start + room].iter_mut().zip(samples) {
                *slot = c;
            }
        };
        for &v in &dirty.vertices {
            if let Some(color) = store.vertex_color(v) {
                put(self.vertex_slot(v), &[color]);
            }
        }
        for &edge in &dirty.edges {
            put(self.edge_blocks[edge as usize].base, store.edge_samples(edge));
        }
        for &face in &dirty.faces {
            put(self.interior_blocks[face as usize].base, store.interior_samples(face));
        }
        let mut bytes = vec![0u8; colors.len() * format.bytes_per_sample()];
        format.encode_slice(&colors, &mut bytes);
        bytes
    }

    /// The whole paint-layout buffer as a [`PackedMesh`] (level 0, `vertex_levels = 1`,
    /// `capacity` samples) for a full upload, in `format`.
    pub fn packed(&self, store: &ColorStore, positions: &[[f32; 3]], format: ColorFormat) -> PackedMesh {
        // Each element encoded straight into its block (no linear copy of the whole buffer);
        // slack stays zero bytes, which is the encoding of a zero colour in every format.
        let size = format.bytes_per_sample();
        let capacity = self.capacity.min(u64::from(u32::MAX)) as usize;
        let mut bytes = crate::memory::zeroed::<u8>(capacity * size);
        let topology = store.topology();
        let vertices: Vec<Rgba> =
            (0..topology.vertex_count).map(|v| store.vertex_color(v).unwrap_or([0.0; 4])).collect();
        // Every run: the vertices (blocks of `RUN` at their own index), then each edge's and
        // each interior's block, with the samples that go there.
        const RUN: u32 = 4096;
        let stride = self.vertex_stride;
        let vertex_runs: Vec<(Block, Element)> = if stride == 1 {
            (0..topology.vertex_count.div_ceil(RUN))
                .map(|k| {
                    let first = k * RUN;
                    (Block { base: first, capacity: RUN.min(topology.vertex_count - first) }, Element::Vertices(first))
                })
                .collect()
        } else {
            (0..topology.vertex_count).map(|v| (Block { base: v * stride, capacity: 1 }, Element::Vertex(v))).collect()
        };
        let edge_runs = self.edge_blocks.iter().enumerate().map(|(e, &b)| (b, Element::Edge(e as u32)));
        let face_runs = self.interior_blocks.iter().enumerate().map(|(f, &b)| (b, Element::Interior(f as u32)));
        let runs: Vec<(Block, Element)> =
            vertex_runs.into_iter().chain(edge_runs).chain(face_runs).filter(|(b, _)| b.capacity > 0).collect();
        let samples = |element: Element| -> &[Rgba] {
            match element {
                Element::Vertices(first) => {
                    let first = first as usize;
                    vertices.get(first..(first + RUN as usize).min(vertices.len())).unwrap_or(&[])
                }
                Element::Vertex(v) => vertices.get(v as usize..v as usize + 1).unwrap_or(&[]),
                Element::Edge(e) => store.edge_samples(e),
                Element::Interior(f) => store.interior_samples(f),
            }
        };
        encode_runs(&mut bytes, format, &runs, &samples);
        PackedMesh {
            positions: positions.to_vec(),
            indices: store.topology().face_vertices.clone(),
            vertex_levels: self.vertex_stride,
            face_records: self.records.clone(),
            format,
            colors: bytes,
        }
    }
}

/// Whose samples a run of [`PaintLayout::packed`] holds.
#[derive(Debug, Clone, Copy)]
enum Element {
    /// Vertices from this id on (a run of them, at their own index).
    Vertices(u32),
    /// One vertex (at `v · vertex_stride`).
    Vertex(u32),
    Edge(u32),
    Interior(u32),
}

/// Encodes each run's samples at the start of its block of `bytes`. Blocks that come in
/// ascending, disjoint order (a layout as [`PaintLayout::new`] makes it) are cut into
/// disjoint pieces and encoded in parallel; any other order (blocks moved by growth) in
/// one pass. Either way each byte is written by the same encode, so the result is the same.
fn encode_runs<'s>(
    bytes: &mut [u8],
    format: ColorFormat,
    runs: &[(Block, Element)],
    samples: &(impl Fn(Element) -> &'s [Rgba] + Sync),
) {
    use rayon::prelude::*;
    let size = format.bytes_per_sample();
    let put = |bytes: &mut [u8], first: usize, runs: &[(Block, Element)]| {
        for &(block, element) in runs {
            let colors = samples(element);
            let start = (block.base as usize).saturating_sub(first) * size;
            if let Some(out) = bytes.get_mut(start..start + colors.len() * size) {
                format.encode_slice(colors, out);
            }
        }
    };
    let ordered =
        runs.windows(2).all(|w| u64::from(w[0].0.base) + u64::from(w[0].0.capacity) <= u64::from(w[1].0.base));
    if !ordered {
        put(bytes, 0, runs);
        return;
    }
    // Pieces of about `PIECE` runs; each piece's bytes end where the next piece's first block starts.
    const PIECE: usize = 2048;
    let pieces: Vec<&[(Block, Element)]> = runs.chunks(PIECE).collect();
    let mut bounds: Vec<usize> = pieces.iter().map(|p| p[0].0.base as usize * size).collect();
    bounds.push(bytes.len());
    crate::packing::interiors::split_at_bounds(bytes, &bounds)
        .into_par_iter()
        .zip(pieces)
        .for_each(|(out, piece)| put(out, piece[0].0.base as usize, piece));
}

/// Samples of unchanged colour an upload span may bridge between two dirty ranges: one
/// GPU write for both costs less than two (each write has a fixed cost, measured on lavapipe
/// by `bench paint`'s `gpu_upload` row: docs/BENCHMARKS.md, "Other rows") while the bridged
/// bytes are cheap to copy.
pub const MAX_UPLOAD_GAP: u32 = 1024;

/// The paint-mode colour buffer as the GPU holds it, encoded, kept on the CPU beside it: an
/// upload then sends a few long spans, the dirty ranges of a plan merged across gaps of at
/// most [`MAX_UPLOAD_GAP`] samples (the gaps' bytes are this copy's, which the GPU already
/// holds), instead of one write per dirty element. Costs one more copy of the buffer
/// (`capacity × bytes per sample`).
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedBuffer {
    format: ColorFormat,
    bytes: Vec<u8>,
}

impl EncodedBuffer {
    /// The buffer `packed` holds (as [`PaintLayout::packed`] made it, the GPU's copy).
    pub fn from_packed(packed: &PackedMesh) -> Self {
        EncodedBuffer { format: packed.format, bytes: packed.colors.clone() }
    }

    /// [`EncodedBuffer::from_packed`] keeping `packed`'s bytes (no copy).
    pub fn from_packed_owned(packed: PackedMesh) -> Self {
        EncodedBuffer { format: packed.format, bytes: packed.colors }
    }

    /// The buffer `bytes` in `format` (the bytes the GPU holds: the compact packing's, under
    /// a layout [`PaintLayout::over_packed`] it).
    pub fn from_bytes(format: ColorFormat, bytes: Vec<u8>) -> Self {
        EncodedBuffer { format, bytes }
    }

    /// The bytes, given back (e.g. to the packing they were lent from).
    pub fn into_bytes(self) -> Vec<u8> {
        self.bytes
    }

    /// Grows the buffer to `samples` (the new slots zero, the encoding of a zero colour), as
    /// the GPU buffer grows when a plan has `grown`; never shrinks. Returns whether it grew.
    pub fn grow(&mut self, samples: u64) -> bool {
        let len = usize::try_from(samples).unwrap_or(usize::MAX).saturating_mul(self.format.bytes_per_sample());
        if len <= self.bytes.len() {
            return false;
        }
        self.bytes.resize(len, 0);
        true
    }

    /// The encoded samples, `bytes_per_sample` each.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The format the samples are encoded in.
    pub fn format(&self) -> ColorFormat {
        self.format
    }

    /// Encodes the ranges of `plan` (from [`PaintLayout::sync`] for `dirty`) into the buffer
    /// and returns the spans `(first, count)` to upload from [`EncodedBuffer::bytes`]: every
    /// range covered, sorted, disjoint, neighbours merged when at most [`MAX_UPLOAD_GAP`]
    /// samples apart. Ranges past the buffer (a plan that `grown`) are not encoded: rebuild
    /// the buffer from [`PaintLayout::packed`] then.
    pub fn apply(
        &mut self,
        layout: &PaintLayout,
        store: &ColorStore,
        dirty: &DirtyElements,
        plan: &UploadPlan,
    ) -> Vec<(u32, u32)> {
        let size = self.format.bytes_per_sample();
        let encoded = layout.encode_plan(store, dirty, plan, self.format);
        let mut offset = 0usize;
        let mut spans: Vec<(u32, u32)> = Vec::new();
        for &(first, count) in &plan.sample_ranges {
            let len = count as usize * size;
            let start = first as usize * size;
            if let (Some(target), Some(source)) =
                (self.bytes.get_mut(start..start + len), encoded.get(offset..offset + len))
            {
                target.copy_from_slice(source);
                match spans.last_mut() {
                    Some((last_first, last_count))
                        if first.saturating_sub(*last_first + *last_count) <= MAX_UPLOAD_GAP =>
                    {
                        *last_count = first + count - *last_first;
                    }
                    _ => spans.push((first, count)),
                }
            }
            offset += len;
        }
        spans
    }
}
