//! The `meshpaint` command line. The GPU-free work lives in the library; this file only
//! parses arguments, calls it, and turns errors into messages and exit codes.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use meshpaint::colors::format::ColorFormat;
use meshpaint::colors::layout::Resolution;
use meshpaint::colors::stats::MeshStats;
use meshpaint::io::document::{Document, SourceKind};
use meshpaint::packing::file as packed_file;

/// Paint colour directly on 3D triangle meshes with mesh colors (no UV map).
///
/// With no subcommand, opens the editor: on FILE, or on the built-in Duck.
#[derive(Debug, Parser)]
#[command(name = "meshpaint", version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// A .glb / .gltf or packed file to open in the editor (default: the built-in Duck).
    file: Option<PathBuf>,
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
    /// Measure speed (and error where it applies); prints JSON.
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
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
    /// Render a mesh offscreen on the GPU (lavapipe without one) and write a PNG.
    Render(RenderArgs),
    /// Export a mesh's colours: OUT ending in .glb gets the mesh tessellated at each face's
    /// resolution with one COLOR_0 vertex per sample; any other name gets a packed file.
    Export {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        /// Uniform face resolution R for glTF input (a power of two, 1..=4096).
        #[arg(long, short = 'r', default_value_t = 8)]
        resolution: u64,
        /// Colour format of a packed output: rgba8 (sRGB, default), rgba16f or rgba32f.
        #[arg(long, value_parser = parse_format)]
        format: Option<ColorFormat>,
        /// Output file: .glb (tessellated, vertex colours) or a packed file (e.g. .mpk).
        #[arg(long, short = 'o')]
        output: PathBuf,
    },
    /// Replay a brush stroke headlessly and write the painted mesh.
    ///
    /// Uses the editor's camera, picking and brush code. OUT ending in .glb gets a
    /// tessellated vertex-colour glTF, any other name a packed file.
    Paint(PaintArgs),
    /// Test helper: writes a recovery file (and now and then a saved file) in a loop,
    /// printing each generation after its write returns, until killed.
    #[command(hide = true, name = "autosave-soak")]
    AutosaveSoak(SoakArgs),
}

#[derive(Debug, Subcommand)]
enum BenchCommand {
    /// Repack (store → face records + colour buffer with MIP chains) vs memcpy of the same bytes.
    Pack {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        /// Uniform face resolution R for glTF input.
        #[arg(long, short = 'r', default_value_t = 16)]
        resolution: u64,
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
        /// Uniform face resolution R for glTF input.
        #[arg(long, short = 'r', default_value_t = 8)]
        resolution: u64,
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
    /// Picking and painting: BVH presets, pick latency, dab time and samples/s for brushes
    /// covering ~1k / 10k / 100k samples, upload bytes per dab, repack time.
    Paint {
        /// A .glb / .gltf file or a packed file (default: the Bunny).
        #[arg(default_value = "assets/models/Bunny144k/bunny.glb")]
        file: PathBuf,
        /// Uniform face resolution R for glTF input.
        #[arg(long, short = 'r', default_value_t = 8)]
        resolution: u64,
        /// Timed dabs per brush size.
        #[arg(long, default_value_t = 30)]
        dabs: usize,
        /// Print compact JSON (default: indented JSON).
        #[arg(long)]
        json: bool,
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
            eprintln!("error: {}", error_message(&error));
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    let Some(command) = cli.command else {
        return meshpaint::app::run(meshpaint::app::AppOptions { file: cli.file });
    };
    match command {
        Command::Info { file, resolution, json } => info(&file, resolution, json),
        Command::Pack { file, resolution, format, output } => pack(&file, resolution, format, &output),
        Command::Bench { what } => bench(what),
        Command::Render(args) => render(args),
        Command::Export { file, resolution, format, output } => export(&file, resolution, format, &output),
        Command::Paint(args) => paint(args),
        Command::AutosaveSoak(args) => autosave_soak(args),
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

/// The error and its causes on one line, skipping causes its message already quotes
/// (our error types name the file and include the cause's text).
fn error_message(error: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if !message.contains(&text) {
            if !message.is_empty() {
                message.push_str(": ");
            }
            message.push_str(&text);
        }
    }
    message
}

/// Whether `path` starts with the packed-file magic.
fn is_packed_file(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut file = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let read = file.read(&mut head).with_context(|| path.display().to_string())?;
    Ok(packed_file::looks_like_packed(&head[..read]))
}

fn info(path: &Path, resolution: u64, json: bool) -> Result<()> {
    if !is_packed_file(path)? {
        // Counts need the welded topology only, not the samples: stay cheap at any R.
        let resolution = Resolution::new(resolution).context("--resolution")?;
        let scene = meshpaint::mesh::import::import_gltf(path)?;
        for warning in &scene.warnings {
            log::warn!("{}: {warning}", path.display());
        }
        let mesh = meshpaint::mesh::weld::weld_scene(&scene);
        let topology = meshpaint::mesh::topology::Topology::build(mesh.positions_world.len() as u32, &mesh.triangles)
            .with_context(|| format!("{}: building topology", path.display()))?;
        let stats = MeshStats::new(&topology, mesh.degenerate_triangles_dropped, resolution);
        if json {
            println!("{}", serde_json::Value::Object(stats.to_json()));
        } else {
            print!("{}:\n{}", path.display(), stats.to_text());
        }
        return Ok(());
    }
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

fn bench(what: BenchCommand) -> Result<()> {
    match what {
        BenchCommand::Pack { file, resolution, format, runs } => {
            let document = open(&file, resolution)?;
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
                "resolution": resolution,
                "threads": 1,
                "results": results,
            });
            println!("{report}");
            Ok(())
        }
        BenchCommand::Paint { file, resolution, dabs, json } => {
            let document = open(&file, resolution)?;
            let options = meshpaint::bench::PaintBenchOptions { dabs, ..Default::default() };
            let mut report = meshpaint::bench::bench_paint(&document, &options)?;
            report["file"] = file.display().to_string().into();
            report["resolution"] = resolution.into();
            if json {
                println!("{report}");
            } else {
                println!("{}", serde_json::to_string_pretty(&report)?);
            }
            Ok(())
        }
        BenchCommand::Render { file, resolution, width, height, frames } => {
            let document = open(&file, resolution)?;
            let result = meshpaint::bench::bench_render(&file, &document, width, height, frames)?;
            let mut report = result.to_json();
            report["file"] = file.display().to_string().into();
            report["resolution"] = resolution.into();
            println!("{report}");
            Ok(())
        }
    }
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

/// Arguments of `meshpaint render`.
#[derive(Debug, clap::Args)]
struct RenderArgs {
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
    /// Uniform face resolution R for glTF input (a power of two, 1..=4096).
    #[arg(long, short = 'r', default_value_t = 8)]
    resolution: u64,
    /// Shading: unlit (the exact colour) or lit (Lambert + ambient).
    #[arg(long, value_enum, default_value_t = RenderShading::Lit)]
    shading: RenderShading,
    /// Camera yaw around +Y in degrees (0 looks along −Z).
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    yaw: f64,
    /// Camera pitch above the horizon in degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pitch: f64,
    /// Eye distance from the scene centre (default: frame the bounding sphere).
    #[arg(long)]
    distance: Option<f64>,
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

fn render(args: RenderArgs) -> Result<()> {
    use meshpaint::camera::default_camera;
    use meshpaint::io::document::{Source, open_for_display};
    use meshpaint::render::{DrawItem, FilterMode, Gpu, Overlays, RenderSettings, Shading};
    let filter = match (args.filter, args.level) {
        (RenderFilter::Nearest, None) => FilterMode::Nearest,
        (RenderFilter::Nearest, Some(level)) => FilterMode::NearestMipLevel(level),
        (RenderFilter::Linear, None) => FilterMode::Linear,
        (RenderFilter::Linear | RenderFilter::Mip, Some(level)) => FilterMode::MipLevel(level),
        (RenderFilter::Mip, None) => anyhow::bail!("--filter mip needs --level N"),
        (RenderFilter::Trilinear, None) => FilterMode::Trilinear,
        (RenderFilter::Trilinear, Some(_)) => anyhow::bail!("--level does not apply to --filter trilinear"),
    };
    if let Some(distance) = args.distance {
        anyhow::ensure!(distance.is_finite() && distance > 0.0, "--distance must be a positive number");
    }
    let settings = |bounds| {
        let mut settings = RenderSettings::new(default_camera(bounds, args.yaw, args.pitch, args.distance));
        settings.filter = filter;
        settings.shading = match args.shading {
            RenderShading::Unlit => Shading::Unlit,
            RenderShading::Lit => Shading::Lit,
        };
        settings.overlays = Overlays { wireframe: args.wireframe, heatmap: args.heatmap };
        settings
    };
    let started = std::time::Instant::now();
    let gpu = Gpu::new_headless()?;
    let (image, triangles, samples) = if args.baseline_uv {
        let scene = meshpaint::mesh::import::import_gltf(&args.file)?;
        let mesh = gpu.upload_baseline(&scene)?.with_context(|| {
            format!(
                "{}: --baseline-uv needs a glTF file with a base-colour texture, and no material has one",
                args.file.display()
            )
        })?;
        let image = gpu.render_image(DrawItem::Baseline(&mesh), &settings(mesh.bounds), args.width, args.height)?;
        (image, mesh.vertex_count / 3, 0)
    } else {
        let resolution = Resolution::new(args.resolution).context("--resolution")?;
        let displayed = open_for_display(&Source::File(args.file.clone()), resolution, &mut |_, _| {})?;
        for warning in &displayed.document.warnings {
            log::warn!("{}: {warning}", args.file.display());
        }
        let mesh = gpu.upload(&displayed.packed)?;
        let image = gpu.render_image(DrawItem::MeshColors(&mesh), &settings(mesh.bounds), args.width, args.height)?;
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

/// `meshpaint export`: a tessellated vertex-colour .glb, or a packed file.
fn export(path: &Path, resolution: u64, format: Option<ColorFormat>, output: &Path) -> Result<()> {
    let extension = output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if extension.as_deref() == Some("gltf") {
        anyhow::bail!("{}: glTF output is written as binary glTF only; name the output .glb", output.display());
    }
    if extension.as_deref() == Some("glb") && format.is_some() {
        anyhow::bail!("--format applies to packed output only (.glb colours are always float, linear)");
    }
    let document = open(path, resolution)?;
    if extension.as_deref() == Some("glb") {
        let summary = meshpaint::io::export_gltf::write_tessellated_glb(output, &document.positions, &document.store)
            .with_context(|| format!("exporting {}", path.display()))?;
        eprintln!(
            "{} → {}: {} faces, {} vertices (one per sample), {} triangles, {} B",
            path.display(),
            output.display(),
            document.store.topology().face_count(),
            summary.vertices,
            summary.triangles,
            summary.bytes
        );
        return Ok(());
    }
    let format = format.unwrap_or_default();
    let packed = document.pack(format).with_context(|| format!("packing {}", path.display()))?;
    packed_file::write_file(output, &packed)?;
    eprintln!(
        "{} → {}: {} faces, {} samples ({})",
        path.display(),
        output.display(),
        packed.face_records.len(),
        packed.sample_count(),
        format.name()
    );
    Ok(())
}

/// Arguments of `meshpaint paint`.
#[derive(Debug, clap::Args)]
struct PaintArgs {
    /// A .glb / .gltf file or a packed file.
    file: PathBuf,
    /// Cursor positions in pixels of the WIDTH × HEIGHT view: "x0,y0 x1,y1 …".
    #[arg(long, allow_hyphen_values = true)]
    stroke: String,
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
    falloff: meshpaint::paint::brush::Falloff,
    /// Distance between dabs, percent of the radius.
    #[arg(long, default_value_t = 10.0)]
    spacing: f64,
    /// Blend mode: mix, add, multiply or erase (back to the colours before the stroke).
    #[arg(long, default_value = "mix", value_parser = parse_blend)]
    blend: meshpaint::paint::brush::BlendMode,
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
    /// Camera yaw around +Y in degrees (as `meshpaint render`).
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    yaw: f64,
    /// Camera pitch above the horizon in degrees.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pitch: f64,
    /// Eye distance from the scene centre (default: frame the bounding sphere).
    #[arg(long)]
    distance: Option<f64>,
    /// View width in pixels.
    #[arg(long, default_value_t = 1024)]
    width: u32,
    /// View height in pixels.
    #[arg(long, default_value_t = 768)]
    height: u32,
    /// Uniform face resolution R for glTF input (a power of two, 1..=4096).
    #[arg(long, short = 'r', default_value_t = 8)]
    resolution: u64,
    /// Colour format of a packed output (default: the input's, rgba8 for glTF).
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    /// Output: .glb (tessellated, vertex colours) or a packed file.
    #[arg(long, short = 'o')]
    output: PathBuf,
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

fn parse_falloff(name: &str) -> Result<meshpaint::paint::brush::Falloff, String> {
    meshpaint::paint::brush::Falloff::from_name(name)
        .ok_or_else(|| format!("unknown falloff '{name}' (smooth, linear, constant, sharp)"))
}

fn parse_blend(name: &str) -> Result<meshpaint::paint::brush::BlendMode, String> {
    meshpaint::paint::brush::BlendMode::from_name(name)
        .ok_or_else(|| format!("unknown blend mode '{name}' (mix, add, multiply, erase)"))
}

/// `meshpaint paint`: one stroke replayed through the editor's brush code.
fn paint(args: PaintArgs) -> Result<()> {
    use meshpaint::paint::brush::{BrushRadius, BrushSettings, PaintView, Painter, ResolutionOp, Tool};
    let extension = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if extension.as_deref() == Some("gltf") {
        anyhow::bail!("{}: glTF output is written as binary glTF only; name the output .glb", args.output.display());
    }
    let stroke = meshpaint::paint::brush::parse_stroke(&args.stroke).map_err(|e| anyhow::anyhow!("--stroke: {e}"))?;
    let color = meshpaint::paint::brush::parse_hex_color(&args.color)
        .with_context(|| format!("--color '{}' is not #rrggbb", args.color))?;
    if let Some(distance) = args.distance {
        anyhow::ensure!(distance.is_finite() && distance > 0.0, "--distance must be a positive number");
    }
    anyhow::ensure!(args.width > 0 && args.height > 0, "--width and --height must be positive");
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
    };
    settings.validate()?;

    let started = std::time::Instant::now();
    let mut document = open(&args.file, args.resolution)?;
    let bounds = meshpaint::camera::BoundingSphere::of_points(&document.positions);
    let camera = meshpaint::camera::default_camera(bounds, args.yaw, args.pitch, args.distance);
    let bvh = meshpaint::paint::picking::MeshBvh::build(
        &document.positions,
        &document.store.topology().face_vertices,
        meshpaint::paint::picking::BvhPreset::default(),
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
    let mut history = meshpaint::paint::undo::UndoHistory::default();
    let (update, _) =
        meshpaint::paint::brush::replay_stroke(&mut painter, &view, &mut document.store, &mut history, &stroke)?;

    if extension.as_deref() == Some("glb") {
        anyhow::ensure!(args.format.is_none(), "--format applies to packed output only");
        meshpaint::io::export_gltf::write_tessellated_glb(&args.output, &document.positions, &document.store)
            .with_context(|| format!("exporting {}", args.file.display()))?;
    } else {
        let format = match (args.format, document.source) {
            (Some(format), _) => format,
            (None, SourceKind::Packed(format)) => format,
            (None, SourceKind::Gltf) => ColorFormat::default(),
        };
        let packed = document.pack(format).with_context(|| format!("packing {}", args.file.display()))?;
        packed_file::write_file(&args.output, &packed)?;
    }
    eprintln!(
        "{} → {}: {} cursor positions, {} dabs, {} samples covered, {} changed, {} faces resized ({:.2} s)",
        args.file.display(),
        args.output.display(),
        stroke.len(),
        update.dabs.len(),
        update.stats.samples_covered,
        update.stats.samples_changed,
        update.stats.faces_resized,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Arguments of the hidden `meshpaint autosave-soak` (used by tests/autosave.rs).
#[derive(Debug, clap::Args)]
struct SoakArgs {
    /// The document (glTF or packed).
    file: PathBuf,
    /// The recovery file to write in a loop.
    #[arg(long)]
    recovery: PathBuf,
    /// A file saved normally every few generations.
    #[arg(long)]
    saved: PathBuf,
    /// Uniform face resolution R for glTF input.
    #[arg(long, short = 'r', default_value_t = 8)]
    resolution: u64,
    /// The first generation written.
    #[arg(long, default_value_t = 1)]
    start_generation: u64,
    /// Stop after this many generations (0: until killed).
    #[arg(long, default_value_t = 0)]
    iterations: u64,
}

/// Writes generation `g` (vertex 0's red channel is `g`, and a band of samples changes) to the
/// recovery file, and every third generation to the saved file too, printing
/// `recovery G` / `saved G` after each write returns.
fn autosave_soak(args: SoakArgs) -> Result<()> {
    use std::io::Write;
    let mut document = open(&args.file, args.resolution)?;
    let mut stdout = std::io::stdout();
    let vertices = document.store.topology().vertex_count;
    anyhow::ensure!(vertices > 0, "{}: no vertices", args.file.display());
    let mut generation = args.start_generation;
    let last = args.start_generation.saturating_add(args.iterations.saturating_sub(1));
    loop {
        let marker = generation as f32;
        document.store.set(meshpaint::colors::store::SampleRef::Vertex(0), [marker, 0.0, 0.0, 1.0]);
        for face in (0..document.store.topology().face_count()).step_by(7) {
            let len = document.store.interior_samples(face).len() as u32;
            for offset in 0..len {
                let shade = ((generation + u64::from(offset)) % 17) as f32 / 16.0;
                document.store.set(
                    meshpaint::colors::store::SampleRef::Interior { face, offset },
                    [shade, 0.5, 1.0 - shade, 1.0],
                );
            }
        }
        meshpaint::io::autosave::write_recovery(&args.recovery, &document)?;
        writeln!(stdout, "recovery {generation}")?;
        stdout.flush()?;
        if generation.is_multiple_of(3) {
            let packed = document.pack(meshpaint::io::autosave::RECOVERY_FORMAT)?;
            packed_file::write_file(&args.saved, &packed)?;
            writeln!(stdout, "saved {generation}")?;
            stdout.flush()?;
        }
        if args.iterations != 0 && generation >= last {
            return Ok(());
        }
        generation += 1;
    }
}
