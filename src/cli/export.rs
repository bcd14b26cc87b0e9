//! `meshpaint export`: a tessellated vertex-colour .glb, or a packed file.

use std::path::PathBuf;

use anyhow::Result;

use meshpaint::colors::format::ColorFormat;

use super::args::{OutputArgs, ResolutionArg, Written, budget, open, parse_format};

/// Arguments of `meshpaint export`.
#[derive(Debug, clap::Args)]
pub(super) struct ExportArgs {
    /// A .glb / .gltf file or a packed file.
    file: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Colour format of a packed output: rgba8 (sRGB, default), rgba16f or rgba32f.
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    #[command(flatten)]
    output: OutputArgs,
}

pub(super) fn run(args: ExportArgs) -> Result<()> {
    let ExportArgs { file: path, resolution, format, output } = args;
    if output.is_glb()? && format.is_some() {
        anyhow::bail!("--format applies to packed output only (.glb colours are always float, linear)");
    }
    // Unlike `pack` and `paint`, a packed input does not keep its format here.
    let packed_format = format.unwrap_or_default();
    let mut budget = budget(Some(packed_format));
    if output.is_glb()? {
        budget.output_check = Some(meshpaint::io::export_gltf::check_tessellation_counts);
    }
    let document = open(&path, resolution, &budget)?;
    match output.write(&document, &path, packed_format)? {
        Written::Glb(summary) => eprintln!(
            "{} → {}: {} faces, {} vertices (one per sample), {} triangles, {} B",
            path.display(),
            output.output.display(),
            document.store.topology().face_count(),
            summary.vertices,
            summary.triangles,
            summary.bytes
        ),
        Written::Packed(packed) => eprintln!(
            "{} → {}: {} faces, {} samples ({})",
            path.display(),
            output.output.display(),
            packed.face_records.len(),
            packed.sample_count(),
            packed_format.name()
        ),
    }
    Ok(())
}
