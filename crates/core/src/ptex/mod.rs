//! Packed Ptex (Kim, Hillesland, Hensley 2011, `../shared/papers/` 001): per-face square
//! textures with their whole MIP chains packed into one 2D texture, each block with a
//! one-texel border copied from its neighbours so that the GPU's bilinear sampler filters
//! across face edges, placed by two small tables (`nRes`, `nRow`).
//!
//! **Triangles in squares: a pair layout.** Ptex stores a triangle in a square with its own
//! convention (the texels of the upper-right half rotated into the triangle), which hardware
//! bilinear filtering cannot read. Here two faces sharing an edge `p → q` fill one square
//! (block) along its anti-diagonal, as Mesh Color Textures' squares do: the first face's third
//! vertex at `(0, 0)`, `p` at `(1, 0)`, `q` at `(0, 1)`, the second face's third vertex at
//! `(1, 1)` — the pair is one bilinear patch with no texel wasted, the shared edge is interior
//! to the block (continuous by construction), and every other mesh edge is a *side* of a
//! block, so that a neighbour's texel row along it is a row or column of its block: the border
//! is that row, copied. Pairs are the MCT matching (faces of the same block resolution
//! `R_b = max(R_f, R_e)`, `mct::layout`). A face left without a partner takes a square alone;
//! its upper half holds the face across its diagonal (unfolded, so bilinear across the
//! diagonal sees that face's colours) or, on a boundary, the face itself mirrored.
//!
//! A block's side is `n = R_b` texels at level 0 (a power of two, as many texels per pair as
//! the pair has mesh-color samples, to first order), `n >> ℓ` at level `ℓ` down to 1×1; every
//! texel is the reference sampler's linear filter of level `ℓ` at the texel's centre.
//!
//! | file | holds |
//! |---|---|
//! | [`layout`] | blocks (pairs), the face record, sorting by resolution, the `nRes` / `nRow` tables and the atlas width |
//! | [`mod@build`] | texels from the packed mesh (reference sampler) and the borders copied from the neighbours |
//! | [`sample`] | the CPU evaluation of hardware bilinear and of the paper's trilinear (two levels, per-pixel level of detail) |
//! | [`file`] | the packed Ptex file (`docs/PTEX_FORMAT.md`): mesh, records, tables and texture in one checked, checksummed file |
//!
//! What is exact (tests in `crates/core/tests/core/ptex.rs`): every interior texel is the
//! reference at its centre; a border texel across an edge between blocks of the same
//! resolution is the neighbour's texel, so bilinear filtering on both sides of such an edge
//! reads the same two texel rows and agrees on the edge. Where resolutions differ the border
//! is the neighbour's row resampled linearly, and inside a face bilinear is not mesh colors'
//! piecewise-linear filter: both measured, not hidden.

pub mod build;
pub mod file;
pub mod layout;
pub mod sample;

pub use build::build;
pub use layout::{PtexBlock, PtexFaceRecord, PtexFrame, PtexLayout, PtexTables, SLICES};

/// Why a packed Ptex cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PtexError {
    /// A face record does not decode (unknown resolution).
    #[error("face {face}: its record has no valid resolution")]
    BadRecord {
        /// The face.
        face: u32,
    },
    /// More blocks than a face record can index.
    #[error("{blocks} Ptex blocks: a face record indexes at most 268435456")]
    TooManyBlocks {
        /// Blocks needed.
        blocks: u64,
    },
    /// The packed texture would exceed the largest texture side.
    #[error(
        "the packed Ptex needs a {width}×{height}-texel texture (or wider), more than the largest texture side {max_dimension}; lower the resolution of the finest faces"
    )]
    AtlasTooLarge {
        /// Width chosen.
        width: u32,
        /// Height needed at that width (0 when the width alone is too large).
        height: u64,
        /// Largest texture side allowed.
        max_dimension: u32,
    },
    /// The packed texture would exceed the byte budget.
    #[error("the packed Ptex needs {bytes} bytes, over the budget of {max_bytes}")]
    OverBudget {
        /// Bytes needed.
        bytes: u64,
        /// Budget.
        max_bytes: u64,
    },
}

/// Counts from one build (texels over all levels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PtexStats {
    /// Interior texels (the blocks' own `n × n`).
    pub interior_texels: u64,
    /// Border texels copied from a neighbour block of the same resolution at that level.
    pub copied_border_texels: u64,
    /// Border texels resampled from a neighbour block of another resolution.
    pub resampled_border_texels: u64,
    /// Border texels across a lone face's diagonal from the neighbour's side: the
    /// reference sampler at the point unfolded into the neighbour.
    pub unfolded_border_texels: u64,
    /// Border texels on a mesh boundary (or non-manifold edge): the block's own row (clamp).
    pub clamped_border_texels: u64,
    /// Border corner texels (the mean of the two border texels beside them).
    pub corner_texels: u64,
}

impl PtexStats {
    fn merged(self, o: PtexStats) -> PtexStats {
        PtexStats {
            interior_texels: self.interior_texels + o.interior_texels,
            copied_border_texels: self.copied_border_texels + o.copied_border_texels,
            resampled_border_texels: self.resampled_border_texels + o.resampled_border_texels,
            unfolded_border_texels: self.unfolded_border_texels + o.unfolded_border_texels,
            clamped_border_texels: self.clamped_border_texels + o.clamped_border_texels,
            corner_texels: self.corner_texels + o.corner_texels,
        }
    }

    /// All border texels (sides and corners).
    pub fn border_texels(&self) -> u64 {
        self.copied_border_texels
            + self.resampled_border_texels
            + self.unfolded_border_texels
            + self.clamped_border_texels
            + self.corner_texels
    }
}

/// A packed Ptex: the layout, the texels (row-major, `width × height`, in `format`) and the
/// build's counts.
#[derive(Debug, Clone, PartialEq)]
pub struct PackedPtex {
    /// Blocks, records, tables and texture size.
    pub layout: PtexLayout,
    /// Texel encoding (the packed buffers' colour format).
    pub format: crate::colors::format::ColorFormat,
    /// `width · height · bytes_per_sample` bytes.
    pub texels: Vec<u8>,
    /// Counts from the build.
    pub stats: PtexStats,
    /// Per vertex, mesh colors' level-of-detail density (`packing::lod::VertexLod::density`):
    /// trilinear filtering picks its levels as mesh colors do.
    pub vertex_density: Vec<f32>,
}

impl PackedPtex {
    /// GPU bytes: the texture, one `u32` record per face and the tables (16 bytes a slice).
    pub fn gpu_bytes(&self) -> u64 {
        self.texels.len() as u64 + 4 * self.layout.records.len() as u64 + 16 * SLICES as u64
    }

    /// Texels of the texture holding no block or border (the packing's waste).
    pub fn unused_texels(&self) -> u64 {
        self.layout.texel_count().saturating_sub(self.stats.interior_texels + self.stats.border_texels())
    }
}
