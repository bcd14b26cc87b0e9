//! Generated UV atlases: a non-overlapping UV layout for any triangle mesh, so that mesh
//! colors can be baked into a texture ([`super::bake_uv`]) when the model's own UVs overlap
//! (mirrored or stacked islands) or are missing (scans: OBJ, PLY, STL).
//!
//! | file | holds |
//! |---|---|
//! | [`atlas`] | [`atlas::generate_uvs`]: charts, flattening and packing by the `uvunwrap` crate, rescaled into a square texture with a gutter of texels between charts |
//! | [`stats`] | what a layout gives each face: texels of UV area, texel density over the surface ([`stats::density`]) |
//! | [`choice`] | which UVs a bake uses: the model's own when they exist and do not overlap, else generated ones, with the reason ([`choice::choose_uvs`]) |

pub mod atlas;
pub mod choice;
pub mod stats;

pub use atlas::{AtlasOptions, GeneratedUvs, UnwrapError, default_atlas_padding, generate_uvs};
pub use choice::{OwnUvCheck, UvChoice, check_own_uvs, choose_uvs};
pub use stats::{DensityStats, density};
