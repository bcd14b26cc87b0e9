//! `meshpaint bench pack | render | paint | adaptive | extremes`: measurements printed as JSON.

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
        /// Print compact JSON (default: indented JSON).
        #[arg(long)]
        json: bool,
    },
    /// The numerical extremes (R = 4096 in perspective, offsets 1e5 / 1e6, scale 1e-4,
    /// slivers, valence 200, RGBA16F's largest value, HDR Add, NaN / ∞ colours, grazing
    /// brushes, the shader's index precision): per case the error measured against an
    /// independent truth and the tolerance its test enforces. Fails when a case is over.
    Extremes {
        /// One JSON object per line (default: a table).
        #[arg(long)]
        json: bool,
    },
}

pub(super) fn run(what: BenchCommand) -> Result<()> {
    match what {
        BenchCommand::Extremes { json } => extremes(json),
        BenchCommand::Adaptive { file, max_resolution, size, views } => {
            let max = meshpaint::colors::layout::Resolution::new(max_resolution).context("--max-resolution")?;
            let scene = meshpaint::mesh::import::import_gltf(&file)?;
            let rules = meshpaint::bench::adaptive::default_rules(max);
            let rows = meshpaint::bench::adaptive::bench_adaptive(&file, &scene, &rules, Some(max), size, views)?;
            for row in &rows {
                let mut value = row.to_json();
                value["bench"] = "adaptive".into();
                value["file"] = file.display().to_string().into();
                println!("{value}");
            }
            let texels = meshpaint::bench::adaptive::uv_island_texels(&scene);
            let mut summary = meshpaint::bench::adaptive::summary(&rows, texels);
            summary["bench"] = "adaptive-summary".into();
            summary["file"] = file.display().to_string().into();
            println!("{summary}");
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

/// `bench extremes`: every case, as JSON lines or a table; an error when a case fails.
fn extremes(json: bool) -> Result<()> {
    let gpu = meshpaint::render::Gpu::new_headless()?;
    let cases = meshpaint::bench::extremes::extreme_cases(&gpu)?;
    for case in &cases {
        if json {
            println!("{}", case.to_json());
        } else {
            println!(
                "{:<32} {:>12.4e} ≤ {:<10.3e} {}  {} [{}]",
                case.case,
                case.measured,
                case.tolerance,
                if case.passes() { "ok  " } else { "FAIL" },
                case.unit,
                case.outcome
            );
        }
    }
    let failed: Vec<&str> = cases.iter().filter(|c| !c.passes()).map(|c| c.case.as_str()).collect();
    if !failed.is_empty() {
        anyhow::bail!("{} of {} extreme cases fail their tolerance: {}", failed.len(), cases.len(), failed.join(", "));
    }
    Ok(())
}
