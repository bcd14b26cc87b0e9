//! Helpers shared by the integration tests: deterministic random sources, small meshes,
//! paths, temporary files and the headless GPU. Each test file includes this with
//! `mod common;` and uses a different subset, hence the `dead_code` allowance.
#![allow(dead_code, unused_imports)] // each test file uses a different subset, re-exports included

pub mod gpu;
pub mod meshes;
pub mod rng;
pub mod temp;

use std::path::{Path, PathBuf};

pub use meshes::{Mesh, OCTAHEDRON_TRIANGLES, icosphere, join, octahedron, octahedron_mesh};
pub use rng::{Rng, SplitMix64};
pub use temp::{TempDir, TempFile, output_dir, update_screenshot};

/// A path relative to the crate root.
pub fn crate_path(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// A model under `assets/models/`.
pub fn model(relative: &str) -> PathBuf {
    crate_path("assets/models").join(relative)
}
