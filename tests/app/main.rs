//! The application's tests in one binary: the `meshpaint` command line end to end, the
//! benchmarks, GPU renders through the binary, and the workspace's layout rules.

mod common;

mod adaptive;
mod architecture;
mod autosave;
mod bake_uv;
mod bench_cli;
mod brush;
mod brush_edge;
mod budget;
mod cli;
mod convert;
mod durability;
mod examples;
mod export_fit;
mod export_gltf;
mod export_uvs;
mod extremes;
mod formats;
mod gpu_render;
mod logo_closeup;
mod mct_file;
mod production_assets;
mod ptex_cli;
mod rule_flags;
mod trade;
mod validator;
mod winding;
