//! Where every block of the packed Ptex lies: blocks sorted by their resolution, one *slice*
//! of rows per resolution `2^k`, every block's level `ℓ` in the slice of its resolution
//! `2^(m − ℓ)`, placed by the paper's two tables.
//!
//! Blocks are sorted by `m = log2 R_b` **ascending** (the paper's Listing 1 needs that order:
//! a face has a level of resolution `2^k` exactly when `nRes[k] <= faceID`). Then
//!
//! - `nRes[k]` = the first block of resolution `2^k` or more (the number of blocks with
//!   `m < k`); slice `k` holds blocks `nRes[k]..N`, each at resolution `2^k`, in that order;
//! - a slice packs its blocks row-major from the texture's left edge, `⌊W / s⌋` to a row,
//!   each `s = 2^k + 2` texels square (the one-texel border on every side), so block `b`'s
//!   index in slice `k` is `i = b − nRes[k]` and its top-left texel (border included) is
//!   `(s · (i mod ⌊W/s⌋), nRow[k] + s · ⌊i / ⌊W/s⌋⌋)`;
//! - `nRow[k]` = the slice's first texture row; slices are stacked from the finest down.
//!
//! Listing 1 of the paper has two slips, fixed here and tested: the block's place in its
//! slice, `iUV = (i mod perRow, i / perRow)`, is in blocks and must be scaled by `s` before
//! the border offset is added, and the face coordinate is scaled by the interior resolution
//! `2^k` (the listing multiplies by `size · size`).

use crate::colors::layout::MAX_LOG2_RESOLUTION;
use crate::mct::layout::{block_resolutions, pair_faces};
use crate::mct::strips::EdgeFaces;
use crate::packing::linear::PackedMesh;
use crate::ptex::PtexError;

/// Number of slices (resolutions `2^0 ..= 2^12`).
pub const SLICES: usize = MAX_LOG2_RESOLUTION as usize + 1;

/// Largest number of blocks a face record indexes (28 bits).
pub const MAX_BLOCKS: u32 = 1 << 28;

/// One face's place in a `u32` (keep in sync with `ptex_record_*` in
/// crates/render/shaders/ptex.wgsl):
///
/// | bits | field |
/// |---|---|
/// | 0–1 | corner of the face's third vertex (the one off the block's diagonal) |
/// | 2 | `p` is the corner after it (1) or before it (0); `q` is the remaining one |
/// | 3 | the face is its block's second (upper-right half) |
/// | 4–31 | block index (blocks sorted by resolution) |
#[repr(transparent)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PtexFaceRecord(pub u32);

const _: () = assert!(std::mem::size_of::<PtexFaceRecord>() == 4);

impl PtexFaceRecord {
    /// Packs the fields; `corner_t < 3`, `block < MAX_BLOCKS`.
    pub fn new(corner_t: u32, p_next: bool, second: bool, block: u32) -> Self {
        PtexFaceRecord((corner_t & 3) | (u32::from(p_next) << 2) | (u32::from(second) << 3) | (block << 4))
    }
    /// The corner of the third vertex.
    pub fn corner_t(self) -> usize {
        ((self.0 & 3) as usize).min(2)
    }
    /// The corner of `p` (square corner `(1, 0)`).
    pub fn corner_p(self) -> usize {
        (self.corner_t() + if self.0 & 4 != 0 { 1 } else { 2 }) % 3
    }
    /// The corner of `q` (square corner `(0, 1)`).
    pub fn corner_q(self) -> usize {
        3 - self.corner_t() - self.corner_p()
    }
    /// Whether the face is its block's second.
    pub fn second(self) -> bool {
        self.0 & 8 != 0
    }
    /// The block index.
    pub fn block(self) -> u32 {
        self.0 >> 4
    }
    /// The point `(u, v)` of the unit square of barycentric `w` (face corner order): the
    /// first face's third vertex at `(0, 0)`, the second's at `(1, 1)`, `p` at `(1, 0)`,
    /// `q` at `(0, 1)`.
    pub fn square_point(self, w: [f32; 3]) -> [f32; 2] {
        let (t, p, q) = (w[self.corner_t()], w[self.corner_p()], w[self.corner_q()]);
        if self.second() { [p + t, q + t] } else { [p, q] }
    }
}

/// The paper's tables, per slice `k` (resolution `2^k`): `nRes`, `nRow` and the blocks per
/// row `⌊W / (2^k + 2)⌋` (at least 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PtexTables {
    /// First block with `m >= k` (blocks with `m < k`).
    pub n_res: [u32; SLICES],
    /// First texture row of slice `k`.
    pub n_row: [u32; SLICES],
    /// Blocks per row in slice `k`.
    pub per_row: [u32; SLICES],
}

impl PtexTables {
    /// Listing 1's clamp: the finest slice at most `wanted` that holds `block` (`None` for a
    /// block past the last: `nRes[0] = 0`, so every real block is in slice 0).
    pub fn slice(&self, block: u32, wanted: u32) -> Option<u32> {
        let mut k = wanted.min(SLICES as u32 - 1) as i64;
        while k >= 0 && self.n_res[k as usize] > block {
            k -= 1;
        }
        (k >= 0).then_some(k as u32)
    }
    /// `log2` of the block's level-0 resolution (its finest slice).
    pub fn log2_of(&self, block: u32) -> u32 {
        self.slice(block, SLICES as u32 - 1).unwrap_or(0)
    }
    /// The top-left texel (border included) of `block` in slice `k` (`k <= log2_of(block)`).
    pub fn origin(&self, block: u32, k: u32) -> [i64; 2] {
        let k = k.min(SLICES as u32 - 1) as usize;
        let s = (1i64 << k) + 2;
        let i = i64::from(block.saturating_sub(self.n_res[k]));
        let per_row = i64::from(self.per_row[k].max(1));
        [s * (i % per_row), i64::from(self.n_row[k]) + s * (i / per_row)]
    }
}

/// One block: a pair of faces sharing the diagonal `p → q`, or a lone face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PtexBlock {
    /// Vertex ids at the square's corners `(0, 0)`, `(1, 0)`, `(1, 1)`, `(0, 1)`:
    /// `t₁, p, t₂, q`.
    pub corners: [u32; 4],
    /// Face of the lower-left half and of the upper-right half: for a lone face, the face
    /// across its diagonal (drawn from its own block; `t₂` its third vertex) or, on a
    /// boundary, the face itself mirrored (`t₂ = t₁`).
    pub faces: [u32; 2],
    /// Whether `faces[1]` is drawn from this block.
    pub paired: bool,
    /// `log2` of the level-0 resolution.
    pub log2: u32,
}

/// The packed layout of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct PtexLayout {
    /// One record per face.
    pub records: Vec<PtexFaceRecord>,
    /// Blocks, sorted by `log2` ascending.
    pub blocks: Vec<PtexBlock>,
    /// `nRes`, `nRow` and blocks per row.
    pub tables: PtexTables,
    /// Texture width in texels.
    pub width: u32,
    /// Texture height in texels.
    pub height: u32,
    /// Levels trilinear filtering clamps to: the packed mesh's vertex levels (a block past
    /// its own last level reads its 1×1 slice).
    pub levels: u32,
}

/// A face's block at one level: the texel of its interior `(0, 0)` and its resolution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PtexFrame {
    /// Texel of the block's interior `(0, 0)` (its top-left texel plus the border).
    pub origin: [i64; 2],
    /// Interior resolution `2^k`.
    pub n: u32,
    /// The face's record.
    pub record: PtexFaceRecord,
}

impl PtexFrame {
    /// The texel-space point (texel centres at integers) of barycentric `w`.
    pub fn point(&self, w: [f32; 3]) -> [f32; 2] {
        let uv = self.record.square_point(w);
        let n = self.n as f32;
        std::array::from_fn(|c| self.origin[c] as f32 + uv[c] * n - 0.5)
    }
}

impl PtexLayout {
    /// Lays out `packed`'s faces in a texture at most `max_dimension` texels on a side.
    pub fn new(packed: &PackedMesh, max_dimension: u32) -> Result<PtexLayout, PtexError> {
        let log2_blocks = block_resolutions(packed).map_err(|e| match e {
            crate::mct::MctError::BadRecord { face } => PtexError::BadRecord { face },
            _ => PtexError::BadRecord { face: 0 },
        })?;
        let (groups, edges) = pair_faces(packed, &log2_blocks);
        let total: u64 = groups.iter().map(|g| g.len() as u64).sum();
        if total >= u64::from(MAX_BLOCKS) {
            return Err(PtexError::TooManyBlocks { blocks: total });
        }
        let mut blocks = Vec::with_capacity(total as usize);
        let mut records = vec![PtexFaceRecord::default(); packed.indices.len()];
        for (g, list) in groups.iter().enumerate() {
            for &pair in list {
                let block = orient(packed, &edges, pair, g as u32);
                let index = blocks.len() as u32;
                for (side, &face) in block.faces.iter().enumerate().take(if block.paired { 2 } else { 1 }) {
                    records[face as usize] = record_of(packed, &block, face, side == 1, index);
                }
                blocks.push(block);
            }
        }
        let mut counts = [0u64; SLICES];
        for b in &blocks {
            for count in counts.iter_mut().take(b.log2 as usize + 1) {
                *count += 1;
            }
        }
        let width = choose_width(&counts, max_dimension)?;
        let (tables, height) = place(&counts, width);
        if height > u64::from(max_dimension) {
            return Err(PtexError::AtlasTooLarge { width, height, max_dimension });
        }
        let levels = packed.vertex_levels.clamp(1, SLICES as u32);
        Ok(PtexLayout { records, blocks, tables, width, height: height.max(1) as u32, levels })
    }

    /// `face`'s block at `level` (slice `m − min(level, m)`), or `None` for no such face.
    pub fn frame(&self, face: u32, level: u32) -> Option<PtexFrame> {
        let record = *self.records.get(face as usize)?;
        let block = record.block();
        let m = self.tables.log2_of(block);
        let k = m - level.min(m);
        let [x, y] = self.tables.origin(block, k);
        Some(PtexFrame { origin: [x + 1, y + 1], n: 1 << k, record })
    }

    /// Texels in the texture.
    pub fn texel_count(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }
}

/// Blocks with `m >= k` per slice, placed at width `width`: the tables and the height.
fn place(counts: &[u64; SLICES], width: u32) -> (PtexTables, u64) {
    let mut tables = PtexTables::default();
    let total = counts[0];
    let mut y = 0u64;
    for k in (0..SLICES).rev() {
        let s = (1u64 << k) + 2;
        let per_row = (u64::from(width) / s).max(1);
        tables.n_res[k] = (total - counts[k]) as u32;
        tables.per_row[k] = per_row.min(u64::from(u32::MAX)) as u32;
        tables.n_row[k] = y.min(u64::from(u32::MAX)) as u32;
        y += counts[k].div_ceil(per_row) * s;
    }
    (tables, y)
}

/// The width of least area (ties: the squarer) that holds the finest block and keeps both
/// sides within `max_dimension`.
fn choose_width(counts: &[u64; SLICES], max_dimension: u32) -> Result<u32, PtexError> {
    let finest = (0..SLICES).rev().find(|&k| counts[k] > 0).unwrap_or(0);
    let widest = (1u64 << finest) + 2;
    if widest > u64::from(max_dimension) {
        return Err(PtexError::AtlasTooLarge { width: widest as u32, height: 0, max_dimension });
    }
    let mut best: Option<(u64, u64, u32)> = None;
    for width in widest..=u64::from(max_dimension) {
        let (_, height) = place(counts, width as u32);
        if height <= u64::from(max_dimension) {
            let key = (width * height.max(1), width.abs_diff(height));
            if best.is_none_or(|(area, skew, _)| key < (area, skew)) {
                best = Some((key.0, key.1, width as u32));
            }
        }
        if height < width / 2 {
            break;
        }
    }
    match best {
        Some((_, _, width)) => Ok(width),
        None => {
            let (_, height) = place(counts, max_dimension);
            Err(PtexError::AtlasTooLarge { width: max_dimension, height, max_dimension })
        }
    }
}

/// The block of `[f, g]` (`g = u32::MAX`: `f` alone) at `log2`: for a pair, `p → q` the
/// shared edge in `f`'s winding; for a lone face, its diagonal a boundary edge if it has
/// one, else its first edge.
fn orient(packed: &PackedMesh, edges: &EdgeFaces, [f, g]: [u32; 2], log2: u32) -> PtexBlock {
    let c = packed.indices[f as usize];
    let across = |a: u32, b: u32| -> Option<u32> {
        edges.faces(a, b).and_then(|pair| pair.into_iter().find(|&h| h != f && h != u32::MAX))
    };
    if g != u32::MAX {
        let d = packed.indices[g as usize];
        let k = (0..3).find(|&k| !d.contains(&c[k])).unwrap_or(0);
        let (t1, p, q) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
        let t2 = d.into_iter().find(|&v| v != p && v != q).unwrap_or(t1);
        return PtexBlock { corners: [t1, p, t2, q], faces: [f, g], paired: true, log2 };
    }
    let k = (0..3).find(|&k| across(c[k], c[(k + 1) % 3]).is_none()).unwrap_or(0);
    let (p, q, t1) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
    let (h, t2) = match across(p, q) {
        Some(h) => {
            let d = packed.indices[h as usize];
            (h, d.into_iter().find(|&v| v != p && v != q).unwrap_or(t1))
        }
        None => (f, t1),
    };
    PtexBlock { corners: [t1, p, t2, q], faces: [f, h], paired: false, log2 }
}

/// The record of `face`, the first or second face of `block`.
fn record_of(packed: &PackedMesh, block: &PtexBlock, face: u32, second: bool, index: u32) -> PtexFaceRecord {
    let c = packed.indices[face as usize];
    let [t1, p, t2, _] = block.corners;
    let t = if second { t2 } else { t1 };
    let find = |v: u32| c.iter().position(|&x| x == v).unwrap_or(0);
    let (ct, cp) = (find(t), find(p));
    PtexFaceRecord::new(ct as u32, cp == (ct + 1) % 3, second, index)
}

/// The corners of `face` (third, p, q) in `block`'s half `second` (vertex ids → corners).
pub(crate) fn half_corners(packed: &PackedMesh, block: &PtexBlock, second: bool) -> [usize; 3] {
    let face = block.faces[usize::from(second)];
    let c = packed.indices[face as usize];
    let [t1, p, t2, q] = block.corners;
    let t = if second { t2 } else { t1 };
    let find = |v: u32, fallback: usize| c.iter().position(|&x| x == v).unwrap_or(fallback);
    [find(t, 0), find(p, 1), find(q, 2)]
}
