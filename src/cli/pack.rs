//! `meshpaint pack`: store → linear buffers with MIP chains → packed file.

use std::path::PathBuf;

use anyhow::{Context, Result};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::packing::file as packed_file;

use super::args::{ResolutionArg, budget, open, packed_format, parse_format};

/// Arguments of `meshpaint pack`.
#[derive(Debug, clap::Args)]
pub(super) struct PackArgs {
    /// A .glb / .gltf, .obj, .ply or .stl file, or a packed file (unpacked and packed again).
    file: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Colour format: rgba8 (sRGB, default), rgba16f or rgba32f. Packed input keeps
    /// its own format unless this is given.
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    /// Output packed file.
    #[arg(long, short = 'o')]
    output: PathBuf,
}

pub(super) fn run(args: PackArgs) -> Result<()> {
    let PackArgs { file: path, resolution, format, output } = args;
    let document = open(&path, resolution, &budget(format))?;
    let format = packed_format(format, document.source);
    let packed = document.pack(format).with_context(|| format!("packing {}", path.display()))?;
    packed_file::write_file(&output, &packed)?;
    eprintln!(
        "{} → {}: {} faces, {} samples, {} B face records, {} B colours ({})",
        path.display(),
        output.display(),
        packed.face_records.len(),
        packed.sample_count(),
        packed.face_record_bytes(),
        packed.color_bytes(),
        format.name()
    );
    if let Some(conversion) = &document.conversion {
        eprintln!("{}: {}", path.display(), conversion.summary());
    }
    Ok(())
}
