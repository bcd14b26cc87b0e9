//! The `meshpaint` command line. The GPU-free work lives in the library; this file only
//! parses arguments, calls it, and turns errors into messages and exit codes.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use meshpaint::color::ColorFormat;
use meshpaint::document::{Document, SourceKind};
use meshpaint::layout::Resolution;
use meshpaint::packed_file;
use meshpaint::stats::MeshStats;

/// Paint colour directly on 3D triangle meshes with mesh colors (no UV map).
#[derive(Debug, Parser)]
#[command(name = "meshpaint", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print welded topology counts and the mesh-colors sample budget of a file.
    Info {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        /// Uniform face resolution R (a power of two, 1..=4096) for glTF input.
        #[arg(long, short = 'r', default_value_t = 8)]
        resolution: u64,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Pack a mesh's colours into linear buffers with MIP chains and write a packed file.
    Pack {
        /// A .glb / .gltf file, or a packed file (unpacked and packed again).
        file: PathBuf,
        /// Uniform face resolution R for glTF input (a power of two, 1..=4096).
        #[arg(long, short = 'r', default_value_t = 8)]
        resolution: u64,
        /// Colour format: rgba8 (sRGB, default), rgba16f or rgba32f. Packed input keeps
        /// its own format unless this is given.
        #[arg(long, value_parser = parse_format)]
        format: Option<ColorFormat>,
        /// Output packed file.
        #[arg(long, short = 'o')]
        output: PathBuf,
    },
}

fn parse_format(name: &str) -> Result<ColorFormat, String> {
    ColorFormat::from_name(name).ok_or_else(|| format!("unknown format '{name}' (rgba8, rgba16f, rgba32f)"))
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Info { file, resolution, json } => info(&file, resolution, json),
        Command::Pack { file, resolution, format, output } => pack(&file, resolution, format, &output),
    }
}

fn open(path: &Path, resolution: u64) -> Result<Document> {
    let resolution = Resolution::new(resolution).context("--resolution")?;
    let document = Document::open(path, resolution)?;
    for warning in &document.warnings {
        log::warn!("{}: {warning}", path.display());
    }
    Ok(document)
}

fn info(path: &Path, resolution: u64, json: bool) -> Result<()> {
    let document = open(path, resolution)?;
    let store = &document.store;
    let max_resolution = store.face_resolutions().iter().copied().max().unwrap_or(Resolution::ONE);
    let mut stats = MeshStats::new(store.topology(), document.degenerate_triangles_dropped, max_resolution);
    let mut extra = serde_json::Map::new();
    if let SourceKind::Packed(format) = document.source {
        // A packed file has per-face resolutions: report what it actually holds.
        let packed = document.pack(format)?;
        stats.samples = store.sample_count();
        stats.samples_with_mips = packed.sample_count();
        let min_resolution = store.face_resolutions().iter().copied().min().unwrap_or(Resolution::ONE);
        extra.insert("resolution_min".into(), min_resolution.get().into());
        extra.insert("format".into(), format.name().into());
        extra.insert("face_record_bytes".into(), packed.face_record_bytes().into());
        extra.insert("color_bytes".into(), packed.color_bytes().into());
    }
    if json {
        let mut object = stats.to_json();
        object.extend(extra);
        println!("{}", serde_json::Value::Object(object));
    } else {
        print!("{}:\n{}", path.display(), stats.to_text());
        for (key, value) in extra {
            println!("{key}: {value}");
        }
    }
    Ok(())
}

fn pack(path: &Path, resolution: u64, format: Option<ColorFormat>, output: &Path) -> Result<()> {
    let document = open(path, resolution)?;
    let format = match (format, document.source) {
        (Some(format), _) => format,
        (None, SourceKind::Packed(format)) => format,
        (None, SourceKind::Gltf) => ColorFormat::default(),
    };
    let packed = document.pack(format).with_context(|| format!("packing {}", path.display()))?;
    packed_file::write_file(output, &packed)?;
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
    Ok(())
}
