//! The renderer's tests in one binary: GPU pixels against the CPU reference sampler, the
//! WGSL sources the pipelines compile, uploads. They run on lavapipe without a GPU and fail,
//! never skip, without an adapter.

mod common;

mod baseline_materials;
mod gpu_atlas_addressing;
mod gpu_htex;
mod gpu_mct;
mod gpu_paint_upload;
mod gpu_ptex;
mod gpu_vs_cpu;
mod shaders;
