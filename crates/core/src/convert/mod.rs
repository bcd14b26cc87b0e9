//! Conversion: one signal into another, no files. A source texture into mesh colors
//! ([`bake`]: the point bake; [`least_squares`]: the fit of the reconstruction), each face at
//! the resolution its content needs ([`adaptive`]); mesh colors back into the model's own UV
//! texture ([`bake_uv`]), or into a generated UV atlas when those overlap or are missing
//! ([`unwrap`]); a scene's triangles split 1→4 ([`subdivide`], budget first).

pub mod adaptive;
pub mod bake;
pub mod bake_uv;
pub mod least_squares;
pub mod subdivide;
pub mod unwrap;
