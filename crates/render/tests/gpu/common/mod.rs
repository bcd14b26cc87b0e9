//! What this test binary's modules share: meshpaint-testkit (paths, temporary files, small
//! meshes, the deterministic random sources) and the headless GPU.
#![allow(unused_imports, dead_code)] // each module uses a different subset

#[path = "../../common/gpu.rs"]
pub mod gpu;

pub use meshpaint_testkit::*;
