//! The argument groups several commands share (flattened into each with
//! `#[command(flatten)]`), and the helpers every command uses to open its input.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::{Document, SourceKind};
use meshpaint_core::io::export_gltf::ExportSummary;
use meshpaint_core::packing::file as packed_file;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::progress::Reporter;

/// The help of `-r/--resolution` (one text for both groups below).
const RESOLUTION_HELP: &str = "Uniform face resolution R for glTF input (a power of two, 1..=4096)";

// `-r/--resolution` with R = 8 by default. Plain comments, not doc comments, on the
// groups: a flattened struct's doc would become the command's about text.
#[derive(Debug, Clone, Copy, clap::Args)]
pub(super) struct ResolutionArg {
    #[arg(long, short = 'r', default_value_t = 8, help = RESOLUTION_HELP)]
    pub(super) resolution: u64,
    #[command(flatten)]
    pub(super) adaptive: AdaptiveArgs,
}

// `--error E`, `--texel-density` and `--max-resolution R`: per-face resolution chosen by
// the content of a textured glTF (crates/core/src/convert/adaptive.rs) instead of a uniform `-r`.
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub(super) struct AdaptiveArgs {
    /// Per-face R for textured glTF: the lowest R whose reconstruction stays within E of the
    /// texture (RMS over the face of sRGB-encoded differences, 0..1); replaces -r.
    #[arg(long, conflicts_with_all = ["resolution", "texel_density"])]
    pub(super) error: Option<f32>,
    /// Per-face R for textured glTF: about one sample per texel each face covers (its UV
    /// area), the total near the texels in use; replaces -r.
    #[arg(long, conflicts_with = "resolution")]
    pub(super) texel_density: bool,
    /// Per-face R for textured glTF within a budget of N level-0 samples: the resolutions
    /// with the least texture error (area-weighted) that fit; replaces -r.
    #[arg(long, value_name = "N", conflicts_with_all = ["resolution", "texel_density", "error"])]
    pub(super) samples: Option<u64>,
    /// The largest R that --error, --texel-density and --samples give a face. By default
    /// the layout's largest: a face is held by its texels (two samples a texel at most) and
    /// by the rule, not by a fixed cap.
    #[arg(long, default_value_t = u64::from(meshpaint_core::colors::layout::MAX_RESOLUTION))]
    pub(super) max_resolution: u64,
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
        ResolutionArg { resolution: arg.resolution, adaptive: AdaptiveArgs::default() }
    }
}

impl ResolutionArg {
    /// The checked uniform resolution.
    pub(super) fn get(self) -> Result<Resolution> {
        Resolution::new(self.resolution).context("--resolution")
    }

    /// The checked rule: `--error`, `--texel-density` or uniform `-r`.
    pub(super) fn rule(self) -> Result<ResolutionRule> {
        let AdaptiveArgs { error, texel_density, samples, max_resolution } = self.adaptive;
        let max = || Resolution::new(max_resolution).context("--max-resolution");
        if let Some(samples) = samples {
            return Ok(ResolutionRule::Budget { samples, max: max()? });
        }
        Ok(match (error, texel_density) {
            (Some(bound), _) => {
                anyhow::ensure!(bound.is_finite() && bound >= 0.0, "--error must be a number ≥ 0, got {bound}");
                ResolutionRule::ErrorBound { bound, max: max()? }
            }
            (None, true) => ResolutionRule::TexelDensity { max: max()? },
            (None, false) => ResolutionRule::Uniform(self.get()?),
        })
    }
}

// `--yaw`, `--pitch`, `--distance` and `--up` of the orbit camera (`render`, `paint`).
#[derive(Debug, Clone, Copy, clap::Args)]
pub(super) struct CameraArgs {
    /// Camera yaw around the up axis in degrees (0 looks along −Z; with `--up z`, along +Y).
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub(super) yaw: f64,
    /// Camera pitch above the horizon in degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub(super) pitch: f64,
    /// Eye distance from the scene centre (default: frame the bounding sphere).
    #[arg(long)]
    pub(super) distance: Option<f64>,
    /// The axis that is up on screen: y, or z for Z-up files (scans, CAD); only the view
    /// turns, never the geometry.
    #[arg(long, default_value = "y", value_parser = parse_up)]
    pub(super) up: meshpaint_core::camera::UpAxis,
}

fn parse_up(name: &str) -> Result<meshpaint_core::camera::UpAxis, String> {
    meshpaint_core::camera::UpAxis::from_name(name).ok_or_else(|| format!("unknown up axis '{name}' (y, z)"))
}

impl CameraArgs {
    /// The camera these arguments give for a scene of `bounds`.
    pub(super) fn camera(&self, bounds: meshpaint_core::camera::BoundingSphere) -> meshpaint_core::camera::OrbitCamera {
        let camera = meshpaint_core::camera::default_camera(bounds, self.yaw, self.pitch, self.distance);
        meshpaint_core::camera::OrbitCamera { up: self.up, ..camera }
    }

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

/// `--representation` values: how a mesh's colours are laid out for the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub(super) enum Representation {
    /// Mesh colors: face records and a colour buffer with MIP chains (the packed file,
    /// docs/FORMAT.md).
    #[default]
    MeshColors,
    /// A Mesh Color Texture: one 2D atlas whose texels duplicate the shared vertex and edge
    /// colours, filtered by the GPU's own sampler (the MCT file, docs/MCT_FORMAT.md).
    Mct,
    /// Packed Ptex: per-pair square blocks with every MIP level, sorted by resolution into one
    /// texture with one-texel borders from the neighbours (crates/core/src/ptex; docs/PTEX.md).
    Ptex,
    /// Htex: one square texture per edge (a halfedge and its twin) in atlas pages, three
    /// hardware bilinear fetches per pixel (docs/HTEX.md).
    Htex,
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
            let summary = meshpaint_core::io::export_gltf::write_tessellated_glb(
                &self.output,
                &document.positions,
                &document.store,
            )
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
/// Whether `path` starts with the MCT-file magic (`meshpaint export --representation mct`).
pub(super) fn is_mct_file(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut file = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let read = file.read(&mut head).with_context(|| path.display().to_string())?;
    Ok(meshpaint_core::mct::file::looks_like_mct(&head[..read]))
}

/// Whether `path` starts with the packed Ptex file's magic (docs/PTEX_FORMAT.md).
pub(super) fn is_ptex_file(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut file = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let read = file.read(&mut head).with_context(|| path.display().to_string())?;
    Ok(meshpaint_core::ptex::file::looks_like_ptex(&head[..read]))
}

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

/// The budget of a command whose output is packed in `format` (the input's own when `None`).
pub(super) fn budget(format: Option<ColorFormat>) -> Budget {
    Budget { format, ..Budget::from_environment() }
}

/// Opens a glTF or packed file at `resolution` within `budget`, logging the importer's
/// warnings.
/// A long conversion shows a progress bar on stderr when it is a terminal.
pub(super) fn open(path: &Path, resolution: ResolutionArg, budget: &Budget) -> Result<Document> {
    let bar = super::progress_bar::ProgressBar::new();
    let name = path.file_name().unwrap_or(path.as_os_str()).to_string_lossy();
    let reporter = Reporter::new(|fraction, stage: &str| bar.set(fraction, &format!("{name}: {stage}")));
    let document = open_with(path, resolution, budget, reporter.progress());
    bar.finish();
    document
}

/// [`open`], reporting the conversion to `progress` (no bar of its own).
pub(super) fn open_with(
    path: &Path,
    resolution: ResolutionArg,
    budget: &Budget,
    progress: meshpaint_core::progress::Progress<'_>,
) -> Result<Document> {
    let document = Document::open_reporting(path, resolution.rule()?, budget, progress)?;
    for warning in &document.warnings {
        log::warn!(target: LOG_TARGET, "{}: {warning}", path.display());
    }
    Ok(document)
}

/// [`open`], after midpoint-subdividing a mesh file's scene `subdivide` times (how the
/// benchmarks reach a million triangles); `subdivide = 0` is [`open`].
pub(super) fn open_subdivided(
    path: &Path,
    resolution: ResolutionArg,
    subdivide: u32,
    budget: &Budget,
) -> Result<Document> {
    if subdivide == 0 {
        return open(path, resolution, budget);
    }
    let (scene, kind) = meshpaint_core::io::document::import_scene_within(path, budget)?;
    let scene = meshpaint_core::convert::subdivide::subdivide_scene(&scene, subdivide, budget)?;
    let mut document = Document::from_scene_within(scene, resolution.rule()?, path, budget)?;
    document.source = kind;
    for warning in &document.warnings {
        log::warn!(target: LOG_TARGET, "{}: {warning}", path.display());
    }
    Ok(document)
}
