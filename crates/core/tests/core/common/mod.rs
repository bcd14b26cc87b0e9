//! What this test binary's modules share: meshpaint-testkit (paths, temporary files, small
//! meshes, the deterministic random sources).
#![allow(unused_imports, dead_code)] // each module uses a different subset

pub use meshpaint_testkit::*;
