//! `meshpaint bench pack | render | paint`: measurements printed as JSON.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Subcommand;

use meshpaint::colors::format::ColorFormat;

use super::args::{ResolutionArg, ResolutionArg16, budget, open, parse_format};

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
        /// Split every triangle into four this many times before measuring (Bunny144k:
        /// 1 → 576 184 triangles, 2 → 2 304 736), the way to reach a million triangles.
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
        /// Target footprints, samples per dab (default 1000, 10000, 100000).
        #[arg(long, value_delimiter = ',')]
        dab_samples: Vec<u64>,
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
        BenchCommand::Pack { file, resolution, format, runs } => {
            let document = open(&file, resolution.into(), &budget(None))?;
            let formats = if format.is_empty() { ColorFormat::ALL.to_vec() } else { format };
            let mut results = Vec::new();
            for format in formats {
                let result = meshpaint::bench::pack::bench_pack(&document, format, runs)?;
                results.push(result.to_json());
            }
            let report = serde_json::json!({
                "bench": "pack",
                "file": file.display().to_string(),
                "triangles": document.store.topology().face_count(),
                "resolution": resolution.resolution,
                "threads": 1,
                "results": results,
            });
            println!("{report}");
            Ok(())
        }
        BenchCommand::Paint { file, resolution, dabs, subdivide, dab_samples, json } => {
            let document = if subdivide == 0 {
                open(&file, resolution, &budget(None))?
            } else {
                let budget = budget(None);
                let (scene, _) = meshpaint::io::document::import_scene_within(&file, &budget)?;
                let scene = meshpaint::mesh::subdivide::subdivide_scene(&scene, subdivide, &budget)?;
                meshpaint::io::document::Document::from_scene_within(scene, resolution.rule()?, &file, &budget)?
            };
            let mut options = meshpaint::bench::PaintBenchOptions { dabs, ..Default::default() };
            if !dab_samples.is_empty() {
                options.target_samples = dab_samples;
            }
            let mut report = meshpaint::bench::bench_paint(&document, &options)?;
            report["file"] = file.display().to_string().into();
            report["resolution"] = resolution.resolution.into();
            report["subdivide"] = subdivide.into();
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
