//! The argument groups several commands share (flattened into each with
//! `#[command(flatten)]`), and the helpers every command uses to open its input.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use meshpaint::colors::format::ColorFormat;
use meshpaint::colors::layout::Resolution;
use meshpaint::io::document::{Document, SourceKind};
use meshpaint::io::export_gltf::ExportSummary;
use meshpaint::packing::file as packed_file;
use meshpaint::packing::linear::PackedMesh;

/// The help of `-r/--resolution` (one text for both groups below).
const RESOLUTION_HELP: &str = "Uniform face resolution R for glTF input (a power of two, 1..=4096)";

// `-r/--resolution` with R = 8 by default. Plain comments, not doc comments, on the
// groups: a flattened struct's doc would become the command's about text.
#[derive(Debug, Clone, Copy, clap::Args)]
pub(super) struct ResolutionArg {
    #[arg(long, short = 'r', default_value_t = 8, help = RESOLUTION_HELP)]
    pub(super) resolution: u64,
}

// `-r/--resolution` with R = 16 by default (`bench pack`). Not a const generic: clap keeps
// the default's text in one static shared by every instantiation.
#[derive(Debug, Clone, Copy, clap::Args)]
pub(super) struct ResolutionArg16 {
    #[arg(long, short = 'r', default_value_t = 16, help = RESOLUTION_HELP)]
    pub(super) resolution: u64,
}

impl From<ResolutionArg16> for ResolutionArg {
    fn from(arg: ResolutionArg16) -> Self {
        ResolutionArg { resolution: arg.resolution }
    }
}

impl ResolutionArg {
    /// The checked resolution.
    pub(super) fn get(self) -> Result<Resolution> {
        Resolution::new(self.resolution).context("--resolution")
    }
}

// `--yaw`, `--pitch` and `--distance` of the orbit camera (`render`, `paint`).
#[derive(Debug, Clone, Copy, clap::Args)]
pub(super) struct CameraArgs {
    /// Camera yaw around +Y in degrees (0 looks along −Z).
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub(super) yaw: f64,
    /// Camera pitch above the horizon in degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub(super) pitch: f64,
    /// Eye distance from the scene centre (default: frame the bounding sphere).
    #[arg(long)]
    pub(super) distance: Option<f64>,
}

impl CameraArgs {
    /// Refuses a `--distance` that is not a positive number.
    pub(super) fn check(&self) -> Result<()> {
        if let Some(distance) = self.distance {
            anyhow::ensure!(distance.is_finite() && distance > 0.0, "--distance must be a positive number");
        }
        Ok(())
    }
}

// `-o/--output` of a command that writes a painted mesh (`export`, `paint`): a name ending
// in .glb gets a tessellated vertex-colour glTF, any other name a packed file.
#[derive(Debug, Clone, clap::Args)]
pub(super) struct OutputArgs {
    /// Output: .glb (tessellated, vertex colours) or a packed file (e.g. .mpk).
    #[arg(long, short = 'o')]
    pub(super) output: PathBuf,
}

/// What [`OutputArgs::write`] wrote.
pub(super) enum Written {
    /// A tessellated binary glTF.
    Glb(ExportSummary),
    /// A packed file.
    Packed(PackedMesh),
}

impl OutputArgs {
    /// Whether the output is a .glb; refuses .gltf (only binary glTF is written).
    pub(super) fn is_glb(&self) -> Result<bool> {
        let extension = self.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if extension.as_deref() == Some("gltf") {
            anyhow::bail!(
                "{}: glTF output is written as binary glTF only; name the output .glb",
                self.output.display()
            );
        }
        Ok(extension.as_deref() == Some("glb"))
    }

    /// Writes `document` (read from `input`): tessellated to a .glb, or packed in
    /// `packed_format` to any other name.
    pub(super) fn write(&self, document: &Document, input: &Path, packed_format: ColorFormat) -> Result<Written> {
        if self.is_glb()? {
            let summary =
                meshpaint::io::export_gltf::write_tessellated_glb(&self.output, &document.positions, &document.store)
                    .with_context(|| format!("exporting {}", input.display()))?;
            return Ok(Written::Glb(summary));
        }
        let packed = document.pack(packed_format).with_context(|| format!("packing {}", input.display()))?;
        packed_file::write_file(&self.output, &packed)?;
        Ok(Written::Packed(packed))
    }
}

/// The log target of the command line's warnings: the binary's root, as when they were
/// logged from `main.rs` (keeps the `[WARN  meshpaint]` prefix and `RUST_LOG` filters).
pub(super) const LOG_TARGET: &str = "meshpaint";

/// `--format` values.
pub(super) fn parse_format(name: &str) -> Result<ColorFormat, String> {
    ColorFormat::from_name(name).ok_or_else(|| format!("unknown format '{name}' (rgba8, rgba16f, rgba32f)"))
}

/// The packed output format: `--format` if given, else a packed input's own, else rgba8.
pub(super) fn packed_format(format: Option<ColorFormat>, source: SourceKind) -> ColorFormat {
    match (format, source) {
        (Some(format), _) => format,
        (None, SourceKind::Packed(format)) => format,
        (None, SourceKind::Gltf | SourceKind::Mesh(_)) => ColorFormat::default(),
    }
}

/// Opens a glTF or packed file at `resolution`, logging the importer's warnings.
pub(super) fn open(path: &Path, resolution: ResolutionArg) -> Result<Document> {
    let resolution = resolution.get()?;
    let document = Document::open(path, resolution)?;
    for warning in &document.warnings {
        log::warn!(target: LOG_TARGET, "{}: {warning}", path.display());
    }
    Ok(document)
}
