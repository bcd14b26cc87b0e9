//! The mesh-colors core: layout math, colour formats, the editable store, exact
//! resampling between resolutions, the sample budget of a mesh (`meshpaint info`) and the
//! limits every operation that creates samples checks first ([`budget`]).

pub mod budget;
pub mod format;
pub mod layout;
pub mod psnr;
pub mod resample;
mod slab;
mod srgb8;
pub mod stats;
pub mod store;

pub use format::{ColorFormat, Rgba};
pub use layout::Resolution;
pub use store::ColorStore;
