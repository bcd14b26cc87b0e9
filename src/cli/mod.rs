//! The `meshpaint` command line: the clap types and the dispatch to one file per command.
//! The GPU-free work lives in the library; these files parse arguments, call it, and
//! turn results into output (`main.rs` turns errors into messages and exit codes).

mod args;
mod bench;
mod convert;
mod export;
mod info;
mod optimize;
mod pack;
mod paint;
mod progress_bar;
mod render;
mod soak;
mod synth;

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};

/// Paint colour directly on 3D triangle meshes with mesh colors (no UV map).
///
/// With no subcommand, opens the editor: on FILE, or on the built-in Duck.
#[derive(Debug, Parser)]
#[command(name = "meshpaint", version, about, args_conflicts_with_subcommands = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// A .glb / .gltf, .obj, .ply, .stl or packed file to open in the editor (default: the built-in Duck).
    file: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print welded topology counts and the mesh-colors sample budget of a file.
    Info(info::InfoArgs),
    /// Measure speed (and error where it applies); prints JSON.
    Bench {
        #[command(subcommand)]
        what: bench::BenchCommand,
    },
    /// Pack a mesh's colours into linear buffers with MIP chains and write a packed file.
    Pack(pack::PackArgs),
    /// Pack a library: files, directories and list files in, one packed file per asset out
    /// (resumable, shardable with --shard I/N); one JSON line per asset on stdout.
    Convert(convert::ConvertArgs),
    /// Lower each face's resolution while every shown colour stays within an error bound
    /// (0 = lossless) and write the result (.glb tessellated, any other name packed).
    Optimize(optimize::OptimizeArgs),
    /// Render a mesh offscreen on the GPU (lavapipe without one) and write a PNG.
    Render(render::RenderArgs),
    /// Export a mesh's colours: OUT ending in .glb gets the mesh tessellated at each face's
    /// resolution with one COLOR_0 vertex per sample; any other name gets a packed file.
    Export(export::ExportArgs),
    /// Replay a brush stroke headlessly and write the painted mesh.
    ///
    /// Uses the editor's camera, picking and brush code. OUT ending in .glb gets a
    /// tessellated vertex-colour glTF, any other name a packed file.
    Paint(paint::PaintArgs),
    /// Write a production-like test asset (truck, materials, islands) as a .glb; prints JSON.
    Synth(synth::SynthArgs),
    /// Test helper: writes a recovery file (and now and then a saved file) in a loop,
    /// printing each generation after its write returns, until killed.
    #[command(hide = true, name = "autosave-soak")]
    AutosaveSoak(soak::SoakArgs),
}

/// Runs the command (with none, the editor).
pub fn run(cli: Cli) -> Result<()> {
    let Some(command) = cli.command else {
        return meshpaint::app::run(meshpaint::app::AppOptions { file: cli.file });
    };
    match command {
        Command::Info(args) => info::run(args),
        Command::Pack(args) => pack::run(args),
        Command::Bench { what } => bench::run(what),
        Command::Convert(args) => convert::run(args),
        Command::Optimize(args) => optimize::run(args),
        Command::Render(args) => render::run(args),
        Command::Export(args) => export::run(args),
        Command::Paint(args) => paint::run(args),
        Command::Synth(args) => synth::run(args),
        Command::AutosaveSoak(args) => soak::run(args),
    }
}
