//! `meshpaint optimize`: lower each face's R while what the mesh shows stays within E.

use std::path::PathBuf;

use anyhow::{Context, Result};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::paint::UndoHistory;
use meshpaint_core::paint::optimize::optimize;

use super::args::{OutputArgs, ResolutionArg, Written, budget, open, packed_format, parse_format};

/// Arguments of `meshpaint optimize`.
#[derive(Debug, clap::Args)]
pub(super) struct OptimizeArgs {
    /// A .glb / .gltf file or a packed file.
    file: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// The error bound E: the largest change of any shown colour channel (linear light,
    /// 0..1) at the test points; 0 is lossless.
    #[arg(long, short = 'e', default_value_t = 0.0)]
    error: f32,
    /// Colour format of a packed output (default: a packed input's own, else rgba8).
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    output: OutputArgs,
}

pub(super) fn run(args: OptimizeArgs) -> Result<()> {
    let OptimizeArgs { file: path, resolution, error, format, json, output } = args;
    let mut document = open(&path, resolution, &budget(format))?;
    let started = std::time::Instant::now();
    let report = optimize(&mut document.store, &mut UndoHistory::new(0), error)
        .with_context(|| format!("optimizing {}", path.display()))?;
    let seconds = started.elapsed().as_secs_f64();
    let format = packed_format(format, document.source);
    let written = output.write(&document, &path, format)?;
    let bytes = match &written {
        Written::Glb(summary) => summary.bytes,
        Written::Packed(packed) => packed.face_record_bytes() + packed.color_bytes(),
    };
    if json {
        let value = serde_json::json!({
            "file": path.display().to_string(),
            "error_bound": error,
            "faces": document.store.topology().face_count(),
            "faces_lowered": report.faces_lowered,
            "samples_before": report.samples_before,
            "samples_after": report.samples_after,
            "max_error": report.max_error,
            "rounds": report.rounds,
            "seconds": seconds,
            "output": output.output.display().to_string(),
            "output_bytes": bytes,
        });
        println!("{value}");
    } else {
        println!(
            "{} → {}: {} of {} faces lowered, samples {} → {} ({:.1} %), largest change {:.3e} (bound {error}), {:.2} s",
            path.display(),
            output.output.display(),
            report.faces_lowered,
            document.store.topology().face_count(),
            report.samples_before,
            report.samples_after,
            100.0 * report.samples_after as f64 / report.samples_before.max(1) as f64,
            report.max_error,
            seconds
        );
    }
    Ok(())
}
