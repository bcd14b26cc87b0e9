//! Quad sizes, atlas pages and the tables the shader reads.
//!
//! Quad `q` of edge `e` is `n × n` texels with `n = max(R_f)` over the faces of its
//! halfedges (at least 2, so that each corner has a texel of its own), and `n_l = max(1,
//! n >> l)` at MIP level `l`. Texel `(i, j)` of a level sits at quad point
//! `((i + ½) / n_l, (j + ½) / n_l)`. Every level of every quad is one *block* of
//! `(n_l + 2)²` texels: the level's texels framed by a one-texel border of zeros. Blocks
//! are shelf-packed, largest first, into square pages of a 2D texture array.
//!
//! # How seamless filtering survives the atlas
//!
//! The paper keeps one texture per quad sampled `CLAMP_TO_BORDER` with a zero border, and
//! divides the sum of three fetches by the same sum of a border-normalisation channel
//! (1 inside, 0 in the border). In an atlas the neighbours' texels would leak into the
//! bilinear footprint; the block's zero border replaces the sampler's border colour: the
//! shader clamps each fetch's texel coordinate to `[−½, n_l + ½]` per axis (the centres of
//! the border texels), so a footprint reads at most the border — exactly what
//! `CLAMP_TO_BORDER` returns for a footprint that leaves the texture, and 0 for a point
//! farther outside. The normalisation channel is a second, small texture holding one
//! block per resolution (1 inside, 0 border: "one per texture resolution", paper §4.4),
//! fetched at the same in-block point, so its weights are the hardware's own.
//!
//! # Tables
//!
//! - face records, 3 `u32` per face (face edge `k`): `quad | lower << 27 | log2 n << 28`
//!   ([`HtexLayout::face_records`]; quad ids below 2²⁷);
//! - block origins, `levels` `u32` per quad, level `l` at `q · levels + l` (every quad has
//!   every level of the mesh: 1-texel blocks past its own last, as mesh colors' vertex
//!   chains go on): `x | y << 13 | page << 26` of the block's top-left
//!   border texel ([`HtexLayout::origins`]; pages ≤ 8192 texels, ≤ 64 pages);
//! - the weight texture: the block of resolution `2^s` at x `Σ_{t<s} (2^t + 2)`, y 0.

use crate::htex::HtexError;
use crate::htex::halfedge::{Halfedges, NONE};
use crate::mesh::topology::Topology;
use crate::packing::linear::PackedMesh;
use crate::packing::sampler::MeshColorSource;

/// Largest page side (origins hold 13 bits per axis).
pub const MAX_PAGE: u32 = 8192;
/// Largest page count (origins hold 6 bits).
pub const MAX_PAGES: u32 = 64;
/// Largest quad count (face records hold 27 bits).
pub const MAX_QUADS: u64 = 1 << 27;
/// Smallest quad side.
pub const MIN_SIZE_LOG2: u32 = 1;

/// Where every block lives, and the tables the GPU reads.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HtexLayout {
    /// The halfedge pairing.
    pub halfedges: Halfedges,
    /// `log2 n` of each quad (level 0).
    pub quad_log2: Vec<u8>,
    /// Per face, per face edge: `quad | lower << 27 | log2 n << 28`.
    pub face_records: Vec<[u32; 3]>,
    /// Levels stored per quad: `1 + max log2 n` (1-texel blocks past a quad's own last).
    pub levels: u32,
    /// Block origins, `levels` per quad: `x | y << 13 | page << 26`.
    pub origins: Vec<u32>,
    /// Page width in texels.
    pub page_size: u32,
    /// Page height in texels (a lone page is cut to its last row of blocks).
    pub page_height: u32,
    /// Number of pages.
    pub pages: u32,
    /// Weight texture size (width, height).
    pub weight_size: [u32; 2],
}

/// A block's place: page and top-left border texel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockOrigin {
    /// Page.
    pub page: u32,
    /// Top-left border texel.
    pub x: u32,
    /// Top-left border texel.
    pub y: u32,
}

impl BlockOrigin {
    /// Decodes an origin word.
    pub fn from_word(word: u32) -> BlockOrigin {
        BlockOrigin { x: word & 0x1fff, y: (word >> 13) & 0x1fff, page: word >> 26 }
    }
    /// Encodes it.
    pub fn word(self) -> u32 {
        self.x | (self.y << 13) | (self.page << 26)
    }
}

/// Face record word of face edge `k`: `(quad, lower, log2 n)`.
pub fn decode_record(word: u32) -> (u32, bool, u32) {
    (word & ((1 << 27) - 1), word & (1 << 27) != 0, word >> 28)
}

/// x of the weight block of resolution `2^s`.
pub fn weight_block_x(s: u32) -> u32 {
    (0..s).map(|t| (1u32 << t) + 2).sum()
}

impl HtexLayout {
    /// Pairs the halfedges of `packed`, sizes the quads from the faces' `R` and packs every
    /// level's block into pages at most `max_dimension` texels (and [`MAX_PAGE`]) on a side.
    pub fn new(packed: &PackedMesh, max_dimension: u32, max_pages: u32) -> Result<HtexLayout, HtexError> {
        let topology = Topology::build(packed.positions.len() as u32, &packed.indices)
            .map_err(|e| HtexError::Topology(e.to_string()))?;
        let halfedges = Halfedges::of(&topology);
        if halfedges.quads.len() as u64 >= MAX_QUADS {
            return Err(HtexError::TooManyQuads { quads: halfedges.quads.len() as u64 });
        }
        let face_log2 = |h: u32| -> Result<u32, HtexError> {
            let face = h / 3;
            Ok(packed.face_resolution(face).ok_or(HtexError::BadRecord { face })?.log2())
        };
        let mut quad_log2 = Vec::with_capacity(halfedges.quads.len());
        for &[a, b] in &halfedges.quads {
            let mut log2 = face_log2(a)?;
            if b != NONE {
                log2 = log2.max(face_log2(b)?);
            }
            quad_log2.push(log2.max(MIN_SIZE_LOG2) as u8);
        }
        let max_log2 = quad_log2.iter().copied().max().unwrap_or(MIN_SIZE_LOG2 as u8) as u32;
        let levels = max_log2 + 1;
        let face_records = (0..packed.indices.len() as u32)
            .map(|f| {
                std::array::from_fn(|k| {
                    let h = 3 * f + k as u32;
                    let q = halfedges.quad[h as usize];
                    q | (u32::from(halfedges.is_lower(h)) << 27) | (u32::from(quad_log2[q as usize]) << 28)
                })
            })
            .collect();
        let weight_size = [weight_block_x(max_log2 + 1), (1 << max_log2) + 2];
        let limit = max_dimension.min(MAX_PAGE);
        if weight_size[0] > limit {
            return Err(HtexError::AtlasTooLarge { side: weight_size[0], max_dimension: limit });
        }
        let (origins, [page_size, page_height], pages) = pack(&quad_log2, levels, limit, max_pages.min(MAX_PAGES))?;
        Ok(HtexLayout {
            halfedges,
            quad_log2,
            face_records,
            levels,
            origins,
            page_size,
            page_height,
            pages,
            weight_size,
        })
    }

    /// Side of quad `q` at `level` (`max(1, n >> level)`).
    pub fn size(&self, q: u32, level: u32) -> u32 {
        let log2 = u32::from(self.quad_log2[q as usize]);
        1 << log2.saturating_sub(level)
    }

    /// Origin of quad `q`'s block at `level` (clamped to the mesh's last level).
    pub fn origin(&self, q: u32, level: u32) -> BlockOrigin {
        let l = level.min(self.levels - 1);
        BlockOrigin::from_word(self.origins[(q * self.levels + l) as usize])
    }

    /// Texels in all pages.
    pub fn texel_count(&self) -> u64 {
        u64::from(self.page_size) * u64::from(self.page_height) * u64::from(self.pages)
    }

    /// Texels inside blocks (not borders, not free space): what the colours need.
    pub fn inside_texels(&self) -> u64 {
        self.quad_log2
            .iter()
            .map(|&log2| (0..self.levels).map(|l| 1u64 << (2 * u32::from(log2).saturating_sub(l))).sum::<u64>())
            .sum()
    }

    /// Bytes of the tables the GPU reads (face records, origins, weight texture in R8).
    pub fn table_bytes(&self) -> u64 {
        12 * self.face_records.len() as u64
            + 4 * self.origins.len() as u64
            + u64::from(self.weight_size[0]) * u64::from(self.weight_size[1])
    }
}

/// Shelf-packs every quad's blocks, largest first; returns the origin words, page width
/// and height, and page count.
fn pack(quad_log2: &[u8], levels: u32, limit: u32, max_pages: u32) -> Result<(Vec<u32>, [u32; 2], u32), HtexError> {
    let area: u64 = quad_log2
        .iter()
        .map(|&log2| (0..levels).map(|l| ((1u64 << u32::from(log2).saturating_sub(l)) + 2).pow(2)).sum::<u64>())
        .sum();
    let largest = (1u32 << quad_log2.iter().copied().max().unwrap_or(1)) + 2;
    // A square that would hold all blocks with ~10 % shelf slack, in whole 64-texel steps.
    let wanted = ((area as f64 * 1.1).sqrt().ceil() as u32).max(largest).next_multiple_of(64);
    let page_size = wanted.min(limit);
    if largest > page_size {
        return Err(HtexError::AtlasTooLarge { side: largest, max_dimension: limit });
    }
    // Blocks by side, largest first, then by level and quad (deterministic).
    let mut blocks: Vec<(u8, u32, u32)> = Vec::with_capacity(quad_log2.len() * levels as usize);
    for l in 0..levels {
        for (q, &log2) in quad_log2.iter().enumerate() {
            blocks.push((log2.saturating_sub(l as u8), l, q as u32));
        }
    }
    blocks.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut origins = vec![0u32; quad_log2.len() * levels as usize];
    let (mut page, mut x, mut y, mut row) = (0u32, 0u32, 0u32, 0u32);
    for (side_log2, l, q) in blocks {
        let side = (1u32 << side_log2) + 2;
        if x + side > page_size {
            (x, y, row) = (0, y + row, 0);
        }
        if y + side > page_size {
            (page, x, y, row) = (page + 1, 0, 0, 0);
            if page >= max_pages {
                return Err(HtexError::TooManyPages { max_pages, page_size });
            }
        }
        origins[(q * levels + l) as usize] = BlockOrigin { page, x, y }.word();
        x += side;
        row = row.max(side);
    }
    // A lone page ends at its last row of blocks.
    let height = if page == 0 { y + row } else { page_size };
    Ok((origins, [page_size, height.max(1)], page + 1))
}
