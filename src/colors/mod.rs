//! The mesh-colors core: layout math, colour formats, the editable store, exact
//! resampling between resolutions and the sample budget of a mesh (`meshpaint info`).

pub mod format;
pub mod layout;
pub mod resample;
pub mod stats;
pub mod store;

pub use format::{ColorFormat, Rgba};
pub use layout::Resolution;
pub use store::ColorStore;
