//! `meshpaint render`: a headless GPU render written as a PNG.

use std::path::PathBuf;

use anyhow::{Context, Result};

use meshpaint_core::colors::budget::Budget;
use meshpaint_core::io::display::{OpenOptions, open_for_display};
use meshpaint_core::io::document::Source;
use meshpaint_core::mct::file::read_mct;
use meshpaint_core::packing::lod::VertexLod;
use meshpaint_core::progress::Reporter;
use meshpaint_render::{DrawItem, FilterMode, Gpu, MeshGeometry, Overlays, RenderSettings, Shading};

use super::args::{CameraArgs, LOG_TARGET, Representation, ResolutionArg, is_mct_file, is_ptex_file};

/// Arguments of `meshpaint render`.
#[derive(Debug, clap::Args)]
pub(super) struct RenderArgs {
    /// A .glb / .gltf, .obj, .ply, .stl, packed or MCT file (an MCT file, from `export
    /// --representation mct`, is drawn as Mesh Color Textures).
    file: PathBuf,
    /// Output PNG.
    #[arg(long, short = 'o')]
    output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 1024)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 768)]
    height: u32,
    /// Filter: nearest, linear, mip (linear at --level), trilinear (automatic level) or
    /// anisotropic (Mesh Color Textures, where the GPU offers it; otherwise trilinear).
    #[arg(long, value_enum, default_value_t = RenderFilter::Trilinear)]
    filter: RenderFilter,
    /// MIP level for --filter mip (also selects a level for nearest or linear).
    #[arg(long)]
    level: Option<u32>,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Shading: unlit (the exact colour) or lit (Lambert + ambient).
    #[arg(long, value_enum, default_value_t = RenderShading::Smooth)]
    shading: RenderShading,
    #[command(flatten)]
    camera: CameraArgs,
    /// Overlay triangle edges.
    #[arg(long)]
    wireframe: bool,
    /// Show per-face resolution as a heat map instead of the colours.
    #[arg(long)]
    heatmap: bool,
    /// Draw the glTF UVs and base-colour texture (the baseline) instead of mesh colors.
    #[arg(long)]
    baseline_uv: bool,
    /// Show a colour field of the position instead of the document's colours (a view of the
    /// shape and its samples; the document is unchanged).
    #[arg(long, conflicts_with = "baseline_uv")]
    position_colors: bool,
    /// mesh-colors (software filter in the shader), mct (Mesh Color Textures: the same
    /// colours in a 2D atlas filtered by the GPU's sampler; docs/MCT.md), ptex (packed Ptex:
    /// per-pair square blocks with borders, hardware bilinear; docs/PTEX.md) or htex (one
    /// texture per edge, three hardware fetches; docs/HTEX.md). Nearest filters draw bilinear
    /// with mct, ptex and htex; anisotropic draws trilinear with ptex and htex.
    #[arg(long, value_enum, default_value_t = Representation::MeshColors, conflicts_with = "baseline_uv")]
    representation: Representation,
}

/// `--filter` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum RenderFilter {
    Nearest,
    Linear,
    Mip,
    Trilinear,
    /// Mesh Color Textures: the GPU's anisotropic sampler where the adapter has one (mesh
    /// colors: trilinear).
    Anisotropic,
}

/// `--shading` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum RenderShading {
    /// The colours as they are.
    Unlit,
    /// Lit with vertex normals; edges sharper than 45° stay sharp.
    #[value(alias = "lit")]
    Smooth,
    /// Lit with face normals (faceted).
    Flat,
}

/// The filter mode `--filter` and `--level` select.
fn filter_mode(filter: RenderFilter, level: Option<u32>) -> Result<FilterMode> {
    Ok(match (filter, level) {
        (RenderFilter::Nearest, None) => FilterMode::Nearest,
        (RenderFilter::Nearest, Some(level)) => FilterMode::NearestMipLevel(level),
        (RenderFilter::Linear, None) => FilterMode::Linear,
        (RenderFilter::Linear | RenderFilter::Mip, Some(level)) => FilterMode::MipLevel(level),
        (RenderFilter::Mip, None) => anyhow::bail!("--filter mip needs --level N"),
        (RenderFilter::Trilinear, None) => FilterMode::Trilinear,
        (RenderFilter::Trilinear, Some(_)) => anyhow::bail!("--level does not apply to --filter trilinear"),
        (RenderFilter::Anisotropic, None) => FilterMode::Anisotropic,
        (RenderFilter::Anisotropic, Some(_)) => anyhow::bail!("--level does not apply to --filter anisotropic"),
    })
}

/// `--representation htex`: the Htex of `packed` (the packed mesh of `mesh`) within
/// `max_bytes`, drawn with `settings`.
fn htex_image(
    gpu: &Gpu,
    packed: &meshpaint_core::packing::linear::PackedMesh,
    mesh: &meshpaint_render::GpuMesh,
    max_bytes: u64,
    settings: &RenderSettings,
    args: &RenderArgs,
) -> Result<image::RgbaImage> {
    let limits = gpu.ctx.limits();
    let options = meshpaint_core::htex::HtexOptions::within(
        limits.max_texture_dimension_2d,
        limits.max_texture_array_layers,
        max_bytes,
    );
    let texture = meshpaint_core::htex::build(packed, &options)
        .with_context(|| format!("{}: building the Htex", args.file.display()))?;
    let htex = gpu.upload_htex(&mesh.geometry(), &texture)?;
    Ok(gpu.render_image(DrawItem::Htex(&htex), settings, args.width, args.height)?)
}

/// `--representation ptex`: the packed Ptex of `packed` (the packed mesh of `mesh`) within
/// `max_bytes`, drawn with `settings`.
fn ptex_image(
    gpu: &Gpu,
    packed: &meshpaint_core::packing::linear::PackedMesh,
    mesh: &meshpaint_render::GpuMesh,
    max_bytes: u64,
    settings: &RenderSettings,
    args: &RenderArgs,
) -> Result<image::RgbaImage> {
    let max_dimension = gpu.ctx.limits().max_texture_dimension_2d;
    let texture = meshpaint_core::ptex::build(packed, max_dimension, max_bytes)
        .with_context(|| format!("{}: building the packed Ptex", args.file.display()))?;
    let ptex = gpu.upload_ptex(&mesh.geometry(), &texture)?;
    Ok(gpu.render_image(DrawItem::Ptex(&ptex), settings, args.width, args.height)?)
}

/// A packed Ptex file (docs/PTEX_FORMAT.md) drawn as the texture it holds: the image and
/// its face count.
fn render_ptex_file(
    args: &RenderArgs,
    gpu: &Gpu,
    settings: &dyn Fn(meshpaint_core::camera::BoundingSphere) -> RenderSettings,
) -> Result<(image::RgbaImage, u32, u64)> {
    anyhow::ensure!(
        !args.baseline_uv && !args.position_colors,
        "{}: a packed Ptex file holds its texture only (no --baseline-uv, no --position-colors)",
        args.file.display()
    );
    let file = meshpaint_core::ptex::file::read_ptex(&args.file)?;
    let lod = VertexLod::with_density(&file.positions, &file.indices, file.ptex.vertex_density.clone());
    let (geometry, bounds) = MeshGeometry::upload(&gpu.ctx, &file.positions, &file.indices, &lod)
        .with_context(|| format!("{}: uploading its mesh", args.file.display()))?;
    let ptex = gpu.upload_ptex(&geometry, &file.ptex).with_context(|| format!("{}", args.file.display()))?;
    let image = gpu.render_image(DrawItem::Ptex(&ptex), &settings(bounds), args.width, args.height)?;
    Ok((image, geometry.face_count, 0))
}

pub(super) fn run(args: RenderArgs) -> Result<()> {
    let filter = filter_mode(args.filter, args.level)?;
    args.camera.check()?;
    let camera = args.camera;
    let settings = |bounds| {
        let mut settings = RenderSettings::new(camera.camera(bounds));
        settings.filter = filter;
        settings.shading = match args.shading {
            RenderShading::Unlit => Shading::Unlit,
            RenderShading::Smooth => Shading::Smooth,
            RenderShading::Flat => Shading::Lit,
        };
        settings.overlays = Overlays { wireframe: args.wireframe, heatmap: args.heatmap };
        settings
    };
    let started = std::time::Instant::now();
    let gpu = Gpu::new_headless()?;
    let budget = Budget::from_environment().with_gpu(gpu.budget_limits());
    let (image, triangles, samples) = if is_mct_file(&args.file)? {
        anyhow::ensure!(
            !args.baseline_uv && !args.position_colors,
            "{}: an MCT file holds its Mesh Color Texture only (no --baseline-uv, no --position-colors)",
            args.file.display()
        );
        let file = read_mct(&args.file)?;
        let lod = VertexLod::with_density(&file.positions, &file.indices, file.mct.vertex_density.clone());
        let (geometry, bounds) = MeshGeometry::upload(&gpu.ctx, &file.positions, &file.indices, &lod)
            .with_context(|| format!("{}: uploading its mesh", args.file.display()))?;
        let mct = gpu.upload_mct(&geometry, &file.mct).with_context(|| format!("{}", args.file.display()))?;
        let image = gpu.render_image(DrawItem::Mct(&mct), &settings(bounds), args.width, args.height)?;
        (image, geometry.face_count, 0)
    } else if is_ptex_file(&args.file)? {
        render_ptex_file(&args, &gpu, &settings)?
    } else if args.baseline_uv {
        let (scene, _) = meshpaint_core::io::document::import_scene_within(&args.file, &budget)?;
        let mesh = gpu.upload_baseline(&scene)?.with_context(|| {
            format!(
                "{}: --baseline-uv needs a glTF file with a base-colour texture, and no material has one",
                args.file.display()
            )
        })?;
        let image = gpu.render_image(DrawItem::Baseline(&mesh), &settings(mesh.bounds), args.width, args.height)?;
        (image, mesh.vertex_count / 3, 0)
    } else {
        let source = Source::File(args.file.clone());
        let options = OpenOptions::new(args.resolution.rule()?, budget);
        let upload = |packed: &_| if args.position_colors { Ok(None) } else { gpu.upload(packed).map(Some) };
        let displayed = open_for_display(&source, &options, Reporter::silent().progress(), upload)?;
        for warning in &displayed.document.warnings {
            log::warn!(target: LOG_TARGET, "{}: {warning}", args.file.display());
        }
        let document = &displayed.document;
        let shown = if args.position_colors {
            let store = meshpaint_core::io::document::position_colored(&document.store, &document.positions);
            Some(meshpaint_core::io::document::Document { store, ..document.clone() })
        } else {
            None
        };
        let shown = shown.as_ref().unwrap_or(document);
        let mesh = match displayed.upload {
            Some(mesh) => mesh,
            None => gpu.upload(&shown.pack(document.display_format())?)?,
        };
        let image = match args.representation {
            Representation::MeshColors => {
                gpu.render_image(DrawItem::MeshColors(&mesh), &settings(mesh.bounds), args.width, args.height)?
            }
            Representation::Mct => {
                let packed = shown.pack(document.display_format())?;
                let max_dimension = gpu.ctx.limits().max_texture_dimension_2d;
                let texture = meshpaint_core::mct::build(&packed, max_dimension, budget.memory_bytes)
                    .with_context(|| format!("{}: building the Mesh Color Texture", args.file.display()))?;
                let mct = gpu.upload_mct(&mesh.geometry(), &texture)?;
                gpu.render_image(DrawItem::Mct(&mct), &settings(mesh.bounds), args.width, args.height)?
            }
            Representation::Htex => {
                let packed = shown.pack(document.display_format())?;
                htex_image(&gpu, &packed, &mesh, budget.memory_bytes, &settings(mesh.bounds), &args)?
            }
            Representation::Ptex => {
                let packed = shown.pack(document.display_format())?;
                ptex_image(&gpu, &packed, &mesh, budget.memory_bytes, &settings(mesh.bounds), &args)?
            }
        };
        (image, mesh.face_count, mesh.atlas.samples)
    };
    image.save(&args.output).with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "{} → {}: {}×{}, {} triangles, {} samples, {} ({:.2} s)",
        args.file.display(),
        args.output.display(),
        args.width,
        args.height,
        triangles,
        samples,
        gpu.describe(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
