//! `meshpaint render`: a headless GPU render written as a PNG.

use std::path::PathBuf;

use anyhow::{Context, Result};

use meshpaint::render::{FilterMode, Overlays, RenderRequest, Shading};

use super::args::{CameraArgs, ResolutionArg};

/// Arguments of `meshpaint render`.
#[derive(Debug, clap::Args)]
pub(super) struct RenderArgs {
    /// A .glb / .gltf file or a packed file.
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
    /// Filter: nearest, linear, mip (linear at --level) or trilinear (automatic level).
    #[arg(long, value_enum, default_value_t = RenderFilter::Trilinear)]
    filter: RenderFilter,
    /// MIP level for --filter mip (also selects a level for nearest or linear).
    #[arg(long)]
    level: Option<u32>,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Shading: unlit (the exact colour) or lit (Lambert + ambient).
    #[arg(long, value_enum, default_value_t = RenderShading::Lit)]
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
}

/// `--filter` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum RenderFilter {
    Nearest,
    Linear,
    Mip,
    Trilinear,
}

/// `--shading` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum RenderShading {
    Unlit,
    Lit,
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
    })
}

pub(super) fn run(args: RenderArgs) -> Result<()> {
    let filter = filter_mode(args.filter, args.level)?;
    args.camera.check()?;
    let request = RenderRequest {
        path: args.file.clone(),
        resolution: args.resolution.get()?,
        width: args.width,
        height: args.height,
        filter,
        shading: match args.shading {
            RenderShading::Unlit => Shading::Unlit,
            RenderShading::Lit => Shading::Lit,
        },
        overlays: Overlays { wireframe: args.wireframe, heatmap: args.heatmap },
        yaw_degrees: args.camera.yaw,
        pitch_degrees: args.camera.pitch,
        distance: args.camera.distance,
        baseline_uv: args.baseline_uv,
    };
    let started = std::time::Instant::now();
    let rendered = meshpaint::render::render_file(&request)?;
    rendered.image.save(&args.output).with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "{} → {}: {}×{}, {} triangles, {} samples, {} ({:.2} s)",
        args.file.display(),
        args.output.display(),
        args.width,
        args.height,
        rendered.triangles,
        rendered.samples,
        rendered.adapter,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
