//! # meshpaint — the application: the editor, the command line and the benchmarks
//!
//! Paint colour directly on triangle meshes with *mesh colors* (Yuksel et al. 2010):
//! samples on every vertex, edge and face of each triangle at a per-face power-of-two
//! resolution `R`, shared along edges so that painting has no seams and needs no UV map.
//!
//! ## Architecture
//!
//! The workspace has three crates; data flows one way, from the core through the renderer
//! to the application:
//!
//! | crate | holds | depends on |
//! |---|---|---|
//! | `meshpaint-core` (`crates/core`) | everything that is not drawing: meshes, the mesh-colors layout and store, packing and the packed file, picking, brush and undo, conversion, files (its `lib.rs` has the table of its folders) | no GPU or UI crate |
//! | `meshpaint-render` (`crates/render`) | the GPU: wgpu context, packed buffers on the GPU, the WGSL sampling pipelines (`crates/render/shaders/`), the UV baseline, readback | core, wgpu |
//! | `meshpaint` (this crate) | [`app`]: the desktop editor (winit, egui, wgpu): window, panels, input, background jobs; [`bench`](mod@bench): the measurements behind `meshpaint bench` (time, size and error, as JSON; [`bench::trade`] every choice's cost and error side by side, [`bench::plot`] its PNG plots; [`bench::extremes`] the numerical extremes); the binary's command line (`src/cli/`) | core, render, egui, winit, plotters, nv-flip |
//!
//! `app` and `bench` do not import each other: what both need (the PSNR of two images)
//! lives in the core. The binary (`src/main.rs`) and the editor are the only places where
//! everything meets.
//!
//! ## Data flow
//!
//! ```text
//! load:   file ─ import ─▶ Scene ─ weld ─▶ WeldedMesh ─ topology ─▶ Topology      (core)
//! edit:   store (maps: vertex / edge / face → samples)                            (core)
//! show:   pack (MIP chains) ─▶ linear buffers ─▶ GPU (render) / export (core)
//! paint:  cursor → ray → BVH → brush → StoreWriter → store → dirty ranges → GPU upload
//! ```

pub mod app;
pub mod bench;
