//! Htex (Barbier & Dupuy 2022, `../shared/papers/` 004): one square texture per edge — the
//! intrinsic quad of a halfedge and its twin — converted from mesh colors, filtered by the
//! GPU's bilinear sampler with three fetches per pixel (own quad, `Next`, `Prev`) and a
//! border-normalisation channel, continuous across every edge except at corner texels
//! (which [`HtexOptions::equalize_corners`] makes equal).
//!
//! | file | holds |
//! |---|---|
//! | [`halfedge`] | `Next`/`Prev`/`Twin` of a triangle mesh, the quad of each halfedge (boundaries paired with themselves), Algorithm 2, the intrinsic triangle of a face point |
//! | [`layout`] | quad sizes from the adjacent faces' `R`, the blocks shelf-packed into atlas pages with zero borders (why that keeps the paper's seamless filtering: its module doc), the face records and block origins the shader reads |
//! | [`mod@build`] | packed mesh colors → texels (reference sampler at every texel's point; corner equalisation) |
//! | [`sample`] | the CPU evaluation of Algorithm 3 on the pages (bilinear, trilinear) |
//! | [`jumps`] | the largest colour jump across intrinsic and mesh edges |
//!
//! Differences from the paper, on purpose: meshpaint's faces are triangles, so each face is
//! drawn once and the fragment finds its intrinsic triangle from the barycentrics (the
//! paper draws one triangle per halfedge; the filtered colour is the same); quads live in
//! atlas pages of a texture array rather than bindless textures; a face's level of detail
//! is mesh colors' (`packing::lod`), each level a separate block (trilinear = two levels ×
//! three fetches).
//!
//! Exactness (tests in `crates/core/tests/core/htex.rs`): every texel is the reference
//! sampler's value at its point (corner texels at the corner when equalised); the filtered
//! colour is continuous across every intrinsic edge by construction and, with equalised
//! corners, at the corners as well. Inside a quad, bilinear of point samples is not mesh
//! colors' piecewise-linear filter: the difference is measured per R, not hidden.

pub mod build;
pub mod halfedge;
pub mod jumps;
pub mod layout;
pub mod sample;

pub use build::build;
pub use layout::HtexLayout;

use crate::colors::format::ColorFormat;

/// Why an Htex cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum HtexError {
    /// A face record does not decode (unknown resolution).
    #[error("face {face}: its record has no valid resolution")]
    BadRecord {
        /// The face.
        face: u32,
    },
    /// The mesh's topology could not be built.
    #[error("the mesh's topology: {0}")]
    Topology(String),
    /// More quads than a face record can index.
    #[error("{quads} Htex quads: a face record indexes fewer than 134217728")]
    TooManyQuads {
        /// Quads needed.
        quads: u64,
    },
    /// A block or the weight texture is wider than a page may be.
    #[error("an Htex block or weight texture needs {side} texels on a side, more than {max_dimension}")]
    AtlasTooLarge {
        /// Side needed.
        side: u32,
        /// Largest side allowed.
        max_dimension: u32,
    },
    /// The blocks need more pages than allowed.
    #[error("the Htex blocks need more than {max_pages} pages of {page_size}² texels; lower the resolution")]
    TooManyPages {
        /// Page limit.
        max_pages: u32,
        /// Page side.
        page_size: u32,
    },
    /// The pages would exceed the byte budget.
    #[error("the Htex pages need {bytes} bytes, over the budget of {max_bytes}")]
    OverBudget {
        /// Bytes needed.
        bytes: u64,
        /// Budget.
        max_bytes: u64,
    },
}

/// How to build an Htex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtexOptions {
    /// Largest page side (also capped at [`layout::MAX_PAGE`]).
    pub max_dimension: u32,
    /// Largest number of pages (texture array layers; capped at [`layout::MAX_PAGES`]).
    pub max_pages: u32,
    /// Byte budget of the pages, checked before allocating.
    pub max_bytes: u64,
    /// Set every block's corner texels to the colour at the corner (paper §4.4).
    pub equalize_corners: bool,
}

impl Default for HtexOptions {
    fn default() -> Self {
        HtexOptions { max_dimension: 8192, max_pages: 64, max_bytes: 4 << 30, equalize_corners: true }
    }
}

impl HtexOptions {
    /// Pages up to a device's largest texture side and array layers, within `max_bytes`,
    /// corners equalised.
    pub fn within(max_dimension: u32, max_pages: u32, max_bytes: u64) -> Self {
        HtexOptions { max_dimension, max_pages, max_bytes, equalize_corners: true }
    }
}

/// An Htex: the layout, the pages' texels (page-major, row-major, `page_size × page_height` each, in
/// `format`), the R8 weight texture and the per-vertex density trilinear filtering needs.
#[derive(Debug, Clone, PartialEq)]
pub struct HtexTexture {
    /// Pairing, sizes, tables, page geometry.
    pub layout: HtexLayout,
    /// Texel encoding (the packed buffers' colour format).
    pub format: ColorFormat,
    /// `pages · page_size · page_height · bytes_per_sample` bytes.
    pub texels: Vec<u8>,
    /// The border-normalisation texture, R8 (`weight_size`).
    pub weights: Vec<u8>,
    /// Per vertex, mesh colors' samples per world unit (`packing::lod::VertexLod::density`).
    pub vertex_density: Vec<f32>,
    /// Whether corner texels were equalised.
    pub equalized: bool,
}

impl HtexTexture {
    /// GPU bytes: the pages and the tables ([`HtexLayout::table_bytes`]).
    pub fn gpu_bytes(&self) -> u64 {
        self.texels.len() as u64 + self.layout.table_bytes()
    }

    /// Number of quad textures (the paper's E) and faces (F).
    pub fn texture_count(&self) -> (u64, u64) {
        (self.layout.halfedges.quads.len() as u64, self.layout.face_records.len() as u64)
    }
}
