//! `meshpaint bench pack | render | paint`: measurements printed as JSON.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Subcommand;

use meshpaint::colors::format::ColorFormat;

use super::args::{ResolutionArg, ResolutionArg16, budget, open, open_subdivided, parse_format};

#[derive(Debug, Subcommand)]
pub(super) enum BenchCommand {
    /// Repack (store → face records + colour buffer with MIP chains) vs memcpy of the same bytes.
    Pack {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        #[command(flatten)]
        resolution: ResolutionArg16,
        /// Colour formats to measure (default: all three).
        #[arg(long, value_parser = parse_format)]
        format: Vec<ColorFormat>,
        /// Repetitions per measurement (the best and the median are reported).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Midpoint-subdivide the mesh N times first (each ×4 triangles: Bunny144k 576k at 1,
        /// 2.3M at 2).
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
        /// Level-0 samples the stroke of the incremental-repack measurement paints.
        #[arg(long, default_value_t = 100_000)]
        stroke_samples: u64,
    },
    /// Seconds per phase from a mesh file to the first paintable frame (import, weld,
    /// topology, store, pack, upload, BVH, first frame), total and peak memory.
    Load {
        /// A .glb / .gltf / OBJ / PLY / STL file.
        file: PathBuf,
        /// Uniform face resolution R.
        #[arg(short, long, default_value_t = 8)]
        resolution: u64,
        /// Midpoint-subdivide the mesh N times after import (each ×4 triangles; not counted
        /// in the total).
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
        /// Width of the first frame.
        #[arg(long, default_value_t = 1280)]
        width: u32,
        /// Height of the first frame.
        #[arg(long, default_value_t = 720)]
        height: u32,
    },
    /// Frame time of the UV baseline and each mesh-colors filter mode (interleaved), GPU memory.
    Render {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        #[command(flatten)]
        resolution: ResolutionArg,
        /// Image width.
        #[arg(long, default_value_t = 1280)]
        width: u32,
        /// Image height.
        #[arg(long, default_value_t = 720)]
        height: u32,
        /// Frames per mode.
        #[arg(long, default_value_t = 20)]
        frames: usize,
    },
    /// Samples and PSNR (against the UV-textured render) of uniform R = 1…32 next to the
    /// per-face resolutions of --texel-density and --error bounds; one JSON object per line.
    Adaptive {
        /// A textured .glb / .gltf file.
        file: PathBuf,
        /// The largest R the adaptive rules give.
        #[arg(long, default_value_t = 64)]
        max_resolution: u64,
        /// Image size (each view is rendered at 4× and box-filtered).
        #[arg(long, default_value_t = 256)]
        size: u32,
        /// Camera views around the model.
        #[arg(long, default_value_t = 3)]
        views: u32,
    },
    /// Picking and painting: BVH presets, pick latency, dab time and samples/s for brushes
    /// covering ~1k / 10k / 100k samples, upload bytes per dab, repack time.
    Paint {
        /// A .glb / .gltf file or a packed file (default: the Bunny).
        #[arg(default_value = "assets/models/Bunny144k/bunny.glb")]
        file: PathBuf,
        #[command(flatten)]
        resolution: ResolutionArg,
        /// Timed dabs per brush size.
        #[arg(long, default_value_t = 30)]
        dabs: usize,
        /// Print compact JSON (default: indented JSON).
        #[arg(long)]
        json: bool,
    },
}

pub(super) fn run(what: BenchCommand) -> Result<()> {
    match what {
        BenchCommand::Adaptive { file, max_resolution, size, views } => {
            let max = meshpaint::colors::layout::Resolution::new(max_resolution).context("--max-resolution")?;
            let scene = meshpaint::mesh::import::import_gltf(&file)?;
            let rules = meshpaint::bench::adaptive::default_rules(max);
            let rows = meshpaint::bench::adaptive::bench_adaptive(&file, &scene, &rules, Some(max), size, views)?;
            for row in rows {
                let mut value = row.to_json();
                value["bench"] = "adaptive".into();
                value["file"] = file.display().to_string().into();
                println!("{value}");
            }
            Ok(())
        }
        BenchCommand::Pack { file, resolution, format, runs, subdivide, stroke_samples } => {
            let document = open_subdivided(&file, resolution.into(), subdivide, &budget(None))?;
            let formats = if format.is_empty() { ColorFormat::ALL.to_vec() } else { format };
            let mut results = Vec::new();
            for format in formats {
                let result = meshpaint::bench::pack::bench_pack(&document, format, runs)?;
                let mut value = result.to_json();
                let incremental =
                    meshpaint::bench::pack::bench_incremental(&document, format, runs.max(3), stroke_samples)?;
                value["incremental_after_stroke"] = incremental.to_json();
                results.push(value);
            }
            let report = serde_json::json!({
                "bench": "pack",
                "file": file.display().to_string(),
                "subdivide": subdivide,
                "triangles": document.store.topology().face_count(),
                "resolution": resolution.resolution,
                "threads": meshpaint::packing::packer::pack_threads(),
                "results": results,
            });
            println!("{report}");
            Ok(())
        }
        BenchCommand::Load { file, resolution, subdivide, width, height } => {
            let r = meshpaint::colors::layout::Resolution::new(resolution).context("--resolution")?;
            let report = meshpaint::bench::bench_load(&file, r, subdivide, &budget(None), width, height)?;
            println!("{report}");
            Ok(())
        }
        BenchCommand::Paint { file, resolution, dabs, json } => {
            let document = open(&file, resolution, &budget(None))?;
            let options = meshpaint::bench::PaintBenchOptions { dabs, ..Default::default() };
            let mut report = meshpaint::bench::bench_paint(&document, &options)?;
            report["file"] = file.display().to_string().into();
            report["resolution"] = resolution.resolution.into();
            if json {
                println!("{report}");
            } else {
                println!("{}", serde_json::to_string_pretty(&report)?);
            }
            Ok(())
        }
        BenchCommand::Render { file, resolution, width, height, frames } => {
            let document = open(&file, resolution, &budget(None))?;
            let result = meshpaint::bench::bench_render(&file, &document, width, height, frames)?;
            let mut report = result.to_json();
            report["file"] = file.display().to_string().into();
            report["resolution"] = resolution.resolution.into();
            println!("{report}");
            Ok(())
        }
    }
}
