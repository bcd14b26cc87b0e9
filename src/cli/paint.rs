//! `meshpaint paint`: one stroke replayed through the editor's brush code.

use std::path::PathBuf;

use anyhow::{Context, Result};

use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::paint::brush::{
    BlendMode, BrushRadius, BrushSettings, Falloff, PaintView, Painter, PressureResponse, ResolutionOp, Tool,
};

use super::args::{CameraArgs, OutputArgs, ResolutionArg, budget, open, packed_format, parse_format};

/// Arguments of `meshpaint paint`.
#[derive(Debug, clap::Args)]
pub(super) struct PaintArgs {
    /// A .glb / .gltf, .obj, .ply, .stl or packed file.
    file: PathBuf,
    /// Cursor positions in pixels of the WIDTH × HEIGHT view, each with an optional pen
    /// pressure in 0..=1 (1 when left out): "x0,y0 x1,y1,p1 …".
    #[arg(long, allow_hyphen_values = true)]
    stroke: String,
    /// What the stroke's pen pressure scales: radius, strength, both or none.
    #[arg(long, default_value = "radius", value_parser = parse_pressure)]
    pressure: PressureResponse,
    /// Brush colour, sRGB hex (#rrggbb).
    #[arg(long, default_value = "#ff0000")]
    color: String,
    /// Brush radius in pixels (converted to world units at each dab's depth).
    #[arg(long, default_value_t = 30.0)]
    radius_px: f64,
    /// Brush radius in world units (overrides --radius-px).
    #[arg(long)]
    radius_world: Option<f64>,
    /// Weight at the brush centre, 0..=1.
    #[arg(long, default_value_t = 1.0)]
    strength: f32,
    /// Falloff: smooth, linear, constant or sharp.
    #[arg(long, default_value = "smooth", value_parser = parse_falloff)]
    falloff: Falloff,
    /// Distance between dabs, percent of the radius.
    #[arg(long, default_value_t = 10.0)]
    spacing: f64,
    /// Blend mode: mix, add, multiply or erase (back to the colours before the stroke).
    #[arg(long, default_value = "mix", value_parser = parse_blend)]
    blend: BlendMode,
    /// Tool: paint, blur, raise / lower (face resolution), or set (to --target-resolution).
    #[arg(long, value_enum, default_value_t = PaintTool::Paint)]
    tool: PaintTool,
    /// The resolution `--tool set` gives faces under the brush.
    #[arg(long)]
    target_resolution: Option<u64>,
    /// Paint hidden samples too (no occlusion test).
    #[arg(long)]
    no_occlusion: bool,
    /// Paint samples on back faces too.
    #[arg(long)]
    no_backface_culling: bool,
    /// Also paint mirrored across x = centre of the mesh bounds.
    #[arg(long)]
    mirror_x: bool,
    /// Resolution follows the brush: raise faces under each dab to the R that resolves it
    /// (spacing ≤ radius / 4), up to this R.
    #[arg(long, value_name = "MAX_R")]
    follow_resolution: Option<u64>,
    #[command(flatten)]
    camera: CameraArgs,
    /// View width in pixels.
    #[arg(long, default_value_t = 1024)]
    width: u32,
    /// View height in pixels.
    #[arg(long, default_value_t = 768)]
    height: u32,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Colour format of a packed output (default: the input's, rgba8 for glTF).
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    #[command(flatten)]
    output: OutputArgs,
}

/// `--tool` values of `meshpaint paint`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum PaintTool {
    Paint,
    Blur,
    Raise,
    Lower,
    Set,
}

fn parse_falloff(name: &str) -> Result<Falloff, String> {
    Falloff::from_name(name).ok_or_else(|| format!("unknown falloff '{name}' (smooth, linear, constant, sharp)"))
}

fn parse_pressure(name: &str) -> Result<PressureResponse, String> {
    PressureResponse::from_name(name)
        .ok_or_else(|| format!("unknown pressure response '{name}' (radius, strength, both, none)"))
}

fn parse_blend(name: &str) -> Result<BlendMode, String> {
    BlendMode::from_name(name).ok_or_else(|| format!("unknown blend mode '{name}' (mix, add, multiply, erase)"))
}

/// The brush settings the arguments describe, in `color`, validated.
fn brush_settings(args: &PaintArgs, color: Rgba) -> Result<BrushSettings> {
    let tool = match (args.tool, args.target_resolution) {
        (PaintTool::Paint, None) => Tool::Paint,
        (PaintTool::Blur, None) => Tool::Blur,
        (PaintTool::Raise, None) => Tool::Resolution(ResolutionOp::Raise),
        (PaintTool::Lower, None) => Tool::Resolution(ResolutionOp::Lower),
        (PaintTool::Set, Some(r)) => {
            Tool::Resolution(ResolutionOp::Set(Resolution::new(r).context("--target-resolution")?))
        }
        (PaintTool::Set, None) => anyhow::bail!("--tool set needs --target-resolution N"),
        (_, Some(_)) => anyhow::bail!("--target-resolution applies to --tool set only"),
    };
    let radius = match args.radius_world {
        Some(radius_world) => BrushRadius::World { radius_world },
        None => BrushRadius::Pixels { radius_px: args.radius_px },
    };
    let settings = BrushSettings {
        tool,
        color,
        blend: args.blend,
        radius,
        strength: args.strength,
        falloff: args.falloff,
        spacing_percent: args.spacing,
        occlusion: !args.no_occlusion,
        backface_culling: !args.no_backface_culling,
        mirror_x: args.mirror_x,
        follow_resolution: args
            .follow_resolution
            .map(|max| Resolution::new(max).context("--follow-resolution"))
            .transpose()?,
        pressure: args.pressure,
    };
    settings.validate()?;
    Ok(settings)
}

pub(super) fn run(args: PaintArgs) -> Result<()> {
    let glb = args.output.is_glb()?;
    let stroke =
        meshpaint_core::paint::brush::parse_stroke(&args.stroke).map_err(|e| anyhow::anyhow!("--stroke: {e}"))?;
    let color = meshpaint_core::paint::brush::parse_hex_color(&args.color)
        .with_context(|| format!("--color '{}' is not #rrggbb or #rgb", args.color))?;
    args.camera.check()?;
    anyhow::ensure!(args.width > 0 && args.height > 0, "--width and --height must be positive");
    let settings = brush_settings(&args, color)?;

    let started = std::time::Instant::now();
    let mut budget = budget(args.format);
    if glb {
        budget.output_check = Some(meshpaint_core::io::export_gltf::check_tessellation_counts);
    }
    let mut document = open(&args.file, args.resolution, &budget)?;
    let format = packed_format(args.format, document.source);
    let bounds = meshpaint_core::camera::BoundingSphere::of_points(&document.positions);
    let camera = args.camera.camera(bounds);
    let bvh = meshpaint_core::paint::picking::MeshBvh::build(
        &document.positions,
        &document.store.topology().face_vertices,
        meshpaint_core::paint::picking::BvhPreset::default(),
    );
    let base = document.store.clone();
    let view = PaintView {
        positions: &document.positions,
        bvh: &bvh,
        camera: &camera,
        viewport_px: [args.width, args.height],
        base: Some(&base),
    };
    let mut painter = Painter::new(&document.positions);
    painter.set_settings(settings);
    painter.set_budget(Some((budget, format)));
    let mut history = meshpaint_core::paint::undo::UndoHistory::default();
    let (update, _) =
        meshpaint_core::paint::brush::replay_stroke(&mut painter, &view, &mut document.store, &mut history, &stroke)?;

    if glb {
        anyhow::ensure!(args.format.is_none(), "--format applies to packed output only");
    }
    args.output.write(&document, &args.file, format)?;
    eprintln!(
        "{} → {}: {} cursor positions, {} dabs, {} samples covered, {} changed, {} faces resized ({:.2} s)",
        args.file.display(),
        args.output.output.display(),
        stroke.len(),
        update.dabs.len(),
        update.stats.samples_covered,
        update.stats.samples_changed,
        update.stats.faces_resized,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
