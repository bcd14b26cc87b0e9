//! From the store to linear buffers and back: the packed layout (face records and the
//! colour buffer with MIP chains), the packer, the CPU reference sampler over the MIP
//! chains, the paint-mode block layout and the packed file format.
//!
//! | file | holds |
//! |---|---|
//! | [`linear`] | the linear GPU layout: 16-byte face records, colour buffer with MIP chains |
//! | [`canonical`] | the canonical layout: where each element's chain starts, each face's record |
//! | [`packer`] | store → linear (MIP chains, eq. 2.5/2.6): the full pack; `packer/update.rs` the repacks from an earlier pack (only the chains an edit reaches; a new layout after resolution changes, chains no edit reached moved in place) |
//! | [`paint_layout`] | paint mode: level 0 in blocks with slack; dirty ranges and patched records |
//! | [`lod`] | the level of detail of trilinear filtering, continuous over the mesh (per-vertex density and normal) |
//! | [`reference`] | the straightforward serial packer the fast and incremental ones are tested against byte for byte |
//! | [`unpack`] | linear → store (level 0 of the canonical layout); a store's chains in `f32` for reference sampling |
//! | [`sampler`] | the CPU reference sampler (nearest, linear, MIP level) on the store and on packed buffers: the truth the GPU is tested against |
//! | [`file`] | the packed file format (docs/FORMAT.md): writer and hostile-input-proof reader |

pub mod canonical;
pub(crate) mod chains_view;
pub(crate) mod edges;
pub mod file;
pub(crate) mod interiors;
pub mod linear;
pub mod lod;
pub(crate) mod mip;
pub mod packer;
pub mod paint_layout;
pub mod reference;
pub mod sampler;
pub mod unpack;

pub use linear::{FaceRecord, PackedMesh};
pub use packer::{PackCache, PackError, pack};
pub use paint_layout::PaintLayout;
