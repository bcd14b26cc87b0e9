//! Mesh Color Textures (Yuksel 2017, `../shared/papers/` 002): mesh colors converted into
//! one 2D atlas whose texels duplicate the shared vertex and edge colours, so the GPU's own
//! bilinear sampler filters them and trilinear filtering is two hardware bilinear lookups.
//!
//! | file | holds |
//! |---|---|
//! | [`layout`] | block resolution per face, pairing, tents (level 0) and squares (levels ≥ 1), the 4-byte face record and the band table the shader reads |
//! | [`mod@build`] | packed mesh colors → atlas texels (reference sampler at every lattice point, `c₃ = c₁ + c₂ − c₀` rings), in parallel bands |
//! | `ring` | which end of a pair's shared edge its tents put the right angle at (RGBA8: the one whose rings clamp less) |
//! | [`strips`] | strips of squares sharing sides at levels ≥ 1, cut into strip rows |
//! | [`sample`] | the CPU evaluation of hardware bilinear / trilinear filtering of the atlas |
//! | [`file`] | the MCT file (`docs/MCT_FORMAT.md`): mesh, records, band table and atlas in one checked, checksummed file |
//!
//! What is exact (tests in `crates/core/tests/core/mct.rs`): at level 0 every texel on a
//! block lattice point is the reference sampler's value there; along every face edge the
//! bilinear reconstruction equals mesh colors' linear filter (legs read one texel row, the
//! hypotenuse's cells are planar thanks to the ring), so both sides of every edge show the
//! same colour — except where a ring texel had to be clamped to the format's range (RGBA8:
//! `[0, 1]`), counted in [`MctStats`]. Inside a face, bilinear is not mesh colors'
//! piecewise-linear filter; the difference is measured, not hidden.

pub mod build;
pub mod file;
pub mod layout;
mod ring;
pub mod sample;
pub mod strips;

pub use build::build;
pub use layout::{BlockFrame, MctBands, MctFaceRecord, MctLayout};

use crate::colors::format::ColorFormat;

/// Why a Mesh Color Texture cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MctError {
    /// A face record does not decode (unknown resolution).
    #[error("face {face}: its record has no valid resolution")]
    BadRecord {
        /// The face.
        face: u32,
    },
    /// One block resolution has more pairs than a face record can index.
    #[error("{pairs} face pairs at block resolution {resolution}: a face record indexes at most 16777216")]
    TooManyFaces {
        /// The block resolution.
        resolution: u32,
        /// Pairs needed.
        pairs: u64,
    },
    /// The atlas would exceed the largest texture side.
    #[error(
        "the Mesh Color Texture needs a {width}×{height}-texel atlas (or wider), more than the largest texture side {max_dimension}; lower the resolution of the finest faces"
    )]
    AtlasTooLarge {
        /// Width chosen.
        width: u32,
        /// Height needed at that width (0 when the width alone is too large).
        height: u64,
        /// Largest texture side allowed.
        max_dimension: u32,
    },
    /// The atlas would exceed the byte budget.
    #[error("the Mesh Color Texture needs {bytes} bytes, over the budget of {max_bytes}")]
    OverBudget {
        /// Bytes needed.
        bytes: u64,
        /// Budget.
        max_bytes: u64,
    },
}

/// Counts from one build.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MctStats {
    /// Texels holding a block lattice point (shared legs counted from both faces).
    pub lattice_texels: u64,
    /// Ring texels written.
    pub ring_texels: u64,
    /// Ring texels whose `c₁ + c₂ − c₀` fell outside the format's range and were clamped.
    pub clamped_ring_texels: u64,
    /// Largest amount (linear colour units) a ring texel was clamped by.
    pub max_ring_clamp: f32,
}

impl MctStats {
    fn merged(self, other: MctStats) -> MctStats {
        MctStats {
            lattice_texels: self.lattice_texels + other.lattice_texels,
            ring_texels: self.ring_texels + other.ring_texels,
            clamped_ring_texels: self.clamped_ring_texels + other.clamped_ring_texels,
            max_ring_clamp: self.max_ring_clamp.max(other.max_ring_clamp),
        }
    }
}

/// A Mesh Color Texture: the layout, the atlas texels (row-major, `width × height`, in
/// `format`) and the build's counts.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshColorTexture {
    /// Records, band table and atlas size.
    pub layout: MctLayout,
    /// Texel encoding (the packed buffers' colour format).
    pub format: ColorFormat,
    /// `width · height · bytes_per_sample` bytes.
    pub texels: Vec<u8>,
    /// Counts from the build.
    pub stats: MctStats,
    /// Per vertex, the samples per world unit mesh colors' level of detail uses
    /// (`packing::lod::VertexLod::density`, from each face's own `R_f`): trilinear filtering
    /// picks its levels from it, and an MCT file does not hold `R_f`.
    pub vertex_density: Vec<f32>,
}

impl MeshColorTexture {
    /// GPU bytes: the atlas, the face records with the strip-row masks, and the entries of the
    /// band table the GPU reads (16 bytes each, [`MctLayout::gpu_band_entries`]).
    pub fn gpu_bytes(&self) -> u64 {
        self.texels.len() as u64 + self.layout.record_bytes() + 16 * self.layout.gpu_band_entries()
    }
}
