//! `meshpaint bench pack | render | paint | adaptive | trade | extremes | unwrap`: measurements printed as JSON.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Subcommand;

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::convert::least_squares::BakeFit;

use super::args::{ResolutionArg, ResolutionArg16, budget, open, open_subdivided, parse_format};

/// `--bake`: how a conversion turns the texture into samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(super) enum BakeArg {
    /// The least-squares fit of the reconstruction to the texture (the default).
    LeastSquares,
    /// Each sample reads the texture prefiltered to its spacing.
    Point,
}

impl From<BakeArg> for BakeFit {
    fn from(arg: BakeArg) -> Self {
        match arg {
            BakeArg::LeastSquares => BakeFit::LeastSquares,
            BakeArg::Point => BakeFit::Point,
        }
    }
}

#[derive(Debug, Subcommand)]
pub(super) enum BenchCommand {
    /// Repack (store → face records + colour buffer with MIP chains) vs memcpy of the same bytes.
    Pack {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        #[command(flatten)]
        resolution: ResolutionArg16,
        /// Colour formats to measure (default: all three).
        #[arg(long, value_parser = parse_format)]
        format: Vec<ColorFormat>,
        /// Repetitions per measurement (the best and the median are reported).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Midpoint-subdivide the mesh N times first (each ×4 triangles: Bunny144k 576k at 1,
        /// 2.3M at 2).
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
        /// Level-0 samples the stroke of the incremental-repack measurement paints.
        #[arg(long, default_value_t = 100_000)]
        stroke_samples: u64,
    },
    /// Seconds per phase from a mesh file to the document on screen (import, weld, topology,
    /// store, pack, upload, BVH, first frame) and on to the first frame in paint mode (enter
    /// paint mode, its first frame), both totals and peak memory.
    Load {
        /// A .glb / .gltf / OBJ / PLY / STL file.
        file: PathBuf,
        /// Uniform face resolution R.
        #[arg(short, long, default_value_t = 8)]
        resolution: u64,
        /// Midpoint-subdivide the mesh N times after import (each ×4 triangles; not counted
        /// in the total).
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
        /// Width of the first frame.
        #[arg(long, default_value_t = 1280)]
        width: u32,
        /// Height of the first frame.
        #[arg(long, default_value_t = 720)]
        height: u32,
        /// Enter paint mode the way before: build and upload the paint layout (timed step by
        /// step) instead of painting the packing the view shows in place.
        #[arg(long)]
        eager_paint: bool,
    },
    /// Dab-to-screen latency as the editor paints: open, enter paint mode, strokes of one
    /// pointer move per frame; per move the dab and the 3D view's frame finished on the GPU
    /// (median, p90), with partial redraws and drawing every frame whole.
    Latency {
        /// A .glb / .gltf / OBJ / PLY / STL file.
        file: PathBuf,
        /// Uniform face resolution R.
        #[arg(short, long, default_value_t = 8)]
        resolution: u64,
        /// Width of the 3D view.
        #[arg(long, default_value_t = 1280)]
        width: u32,
        /// Height of the 3D view.
        #[arg(long, default_value_t = 720)]
        height: u32,
        /// Pointer moves per stroke.
        #[arg(long, default_value_t = 30)]
        moves: usize,
        /// Brush radius in pixels (default: the editor's brush).
        #[arg(long)]
        radius_px: Option<f64>,
    },
    /// Frame time of the UV baseline and each mesh-colors filter mode (interleaved), GPU memory.
    Render {
        /// A .glb / .gltf file or a packed file.
        file: PathBuf,
        #[command(flatten)]
        resolution: ResolutionArg,
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
    /// Samples and PSNR (against the UV-textured render) of uniform R = 1…32 next to the
    /// per-face resolutions of --texel-density and --error bounds; one JSON object per line.
    Adaptive {
        /// A textured .glb / .gltf file.
        file: PathBuf,
        /// The largest R the adaptive rules give (default: the layout's largest, as `pack`).
        #[arg(long, default_value_t = u64::from(meshpaint_core::colors::layout::MAX_RESOLUTION))]
        max_resolution: u64,
        /// Image size (each view is rendered at --supersample × and box-filtered).
        #[arg(long, default_value_t = 256)]
        size: u32,
        /// Camera views around the model.
        #[arg(long, default_value_t = 3)]
        views: u32,
        /// Supersampling per axis of both renders (the reference converges with it; see
        /// docs/ADAPTIVE.md).
        #[arg(long, default_value_t = meshpaint::bench::adaptive::ADAPTIVE_SUPERSAMPLE)]
        supersample: u32,
        /// The bakes to compare (each rule is converted with each): the least-squares fit
        /// (the conversion's default) and the point bake it starts from.
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = [BakeArg::LeastSquares, BakeArg::Point])]
        bake: Vec<BakeArg>,
        /// Measure only these rules (comma-separated `uniform:R`, `texel-density`, `error:E`,
        /// `samples:N`; no budget rows are added) instead of uniform R = 1…32 with a budget
        /// row beside each R ≥ 4, texel density and error bounds 0.05…0.0025.
        #[arg(long, value_delimiter = ',')]
        rules: Vec<String>,
        #[command(flatten)]
        close_up: CloseUpArgs,
    },
    /// What every choice costs and buys: representation (mesh colors, Mesh Color Texture,
    /// packed Ptex, Htex) × filter × resolution (uniform R 1…32 and --error bounds) × colour
    /// format, per view at several distances — PSNR, max error, FLIP against a
    /// 4×4-supersampled reference, samples, GPU bytes, pack and build time, frame-time ratio
    /// to the UV baseline (interleaved), dab throughput; plus seam jumps of every
    /// representation and BVH presets. One JSON object
    /// per line; with --out, error-vs-cost plots (PNG).
    Trade(TradeArgs),
    /// Picking and painting: BVH presets, pick latency, dab time and samples/s for brushes
    /// covering ~1k / 10k / 100k samples, upload bytes per dab, repack time.
    Paint {
        /// A .glb / .gltf file or a packed file (default: the Bunny).
        #[arg(default_value = "assets/models/Bunny144k/bunny.glb")]
        file: PathBuf,
        #[command(flatten)]
        resolution: ResolutionArg,
        /// Timed dabs per brush size.
        #[arg(long, default_value_t = 30)]
        dabs: usize,
        /// Split every triangle into four this many times before measuring (Bunny144k:
        /// 1 → 576 184 triangles, 2 → 2 304 736), the way to reach a million triangles.
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
        /// Target footprints, samples per dab (default 1000, 10000, 100000).
        #[arg(long, value_delimiter = ',')]
        dab_samples: Vec<u64>,
        /// Print compact JSON (default: indented JSON).
        #[arg(long)]
        json: bool,
        /// Measure only these dab rows (e.g. `blur`, `paint`, `occlusion_frame_paced`) and
        /// nothing else: for a profiler (`perf record -g -- meshpaint bench paint … --rows blur`).
        #[arg(long, value_delimiter = ',')]
        rows: Vec<String>,
    },
    /// A hard stroke's edge on a close-up against the ideal stroke (the dabs' spheres on the
    /// surface, supersampled): edge-band PSNR and mean error, samples and stroke time, as
    /// painted today, anti-aliased, with resolution following the brush, and both; one JSON
    /// object per variant.
    BrushEdge {
        /// A .glb / .gltf / OBJ / PLY / STL file.
        file: PathBuf,
        /// The document's uniform R.
        #[arg(short, long, default_value_t = 8)]
        resolution: u64,
        /// Image side, pixels.
        #[arg(long, default_value_t = 320)]
        size: u32,
        /// Subsamples per pixel per axis (renders and truth).
        #[arg(long, default_value_t = 8)]
        supersample: u32,
        /// The close-up: the framing distance divided by this.
        #[arg(long, default_value_t = 4.0)]
        zoom: f64,
        /// Brush radius, pixels.
        #[arg(long, default_value_t = 20.0)]
        radius_px: f64,
        /// Write the images (truth and each variant) into DIR.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// A generated UV atlas (`export --texture SIZE --uvs new`): seconds, charts, share of the
    /// texture used, texels inside two faces' UVs, texel density over the surface; one JSON
    /// object.
    Unwrap {
        /// A .glb / .gltf / OBJ / PLY / STL file.
        file: PathBuf,
        /// Texture side.
        #[arg(long, default_value_t = 4096)]
        size: u32,
        /// Midpoint-subdivide the mesh N times first (Bunny144k: 1 → 576k triangles, 2 → 2.3M).
        #[arg(long, default_value_t = 0)]
        subdivide: u32,
    },
    /// The numerical extremes (R = 4096 in perspective, offsets 1e5 / 1e6, scale 1e-4,
    /// slivers, valence 200, RGBA16F's largest value, HDR Add, NaN / ∞ colours, grazing
    /// brushes, the shader's index precision): per case the error measured against an
    /// independent truth and the tolerance its test enforces. Fails when a case is over.
    Extremes {
        /// One JSON object per line (default: a table).
        #[arg(long)]
        json: bool,
    },
}

/// `bench trade`'s arguments.
#[derive(Debug, clap::Args)]
pub(super) struct TradeArgs {
    /// A .glb / .gltf file (textured: the UV render is the reference) or a packed file.
    pub(super) file: PathBuf,
    /// View directions around the model (each at near, mid, far and tiny distances).
    #[arg(long, default_value_t = 1)]
    pub(super) views: u32,
    /// Write the plots trade_<name>_bytes.png and trade_<name>_frame.png into DIR.
    #[arg(long, value_name = "DIR")]
    pub(super) out: Option<PathBuf>,
    /// The largest R the --error bounds give a face.
    #[arg(long, default_value_t = 64)]
    pub(super) max_resolution: u64,
    /// Image side in pixels (the reference is rendered at 4× and box-filtered).
    #[arg(long, default_value_t = 256)]
    pub(super) size: u32,
    /// Largest uniform R measured (powers of two from 1).
    #[arg(long, default_value_t = 32)]
    pub(super) max_uniform: u64,
    /// Interleaved timing rounds per view.
    #[arg(long, default_value_t = 5)]
    pub(super) frames: usize,
    /// The --error bounds measured (comma-separated; textured glTF only).
    #[arg(long, value_delimiter = ',', default_values_t = [0.05f32, 0.02, 0.01, 0.005])]
    pub(super) errors: Vec<f32>,
    /// Leave out the numerical extremes (`bench extremes`), which the report includes
    /// after the configurations (`"bench": "extremes"` rows).
    #[arg(long)]
    pub(super) no_extremes: bool,
    /// Colour formats measured (comma-separated; default: rgba8, rgba16f, rgba32f).
    #[arg(long, value_parser = parse_format, value_delimiter = ',')]
    pub(super) formats: Vec<ColorFormat>,
    /// The representations measured (comma-separated: mesh-colors, mct, ptex, htex; default
    /// all four; mesh colors are always measured).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub(super) representation: Vec<super::args::Representation>,
    /// Leave out the Mesh Color Texture rows (removes mct from --representation).
    #[arg(long)]
    pub(super) no_mct: bool,
    /// Leave out the packed Ptex rows (removes ptex from --representation).
    #[arg(long)]
    pub(super) no_ptex: bool,
}

impl TradeArgs {
    /// Whether `--representation` lists `r` (or is empty: every representation).
    fn wants(&self, r: super::args::Representation) -> bool {
        self.representation.is_empty() || self.representation.contains(&r)
    }

    /// The study these flags ask for.
    fn options(&self) -> Result<meshpaint::bench::trade::TradeOptions> {
        use meshpaint_core::colors::layout::Resolution;
        anyhow::ensure!(self.size >= 8, "--size must be at least 8");
        anyhow::ensure!(self.errors.iter().all(|e| e.is_finite() && *e >= 0.0), "--errors must be numbers ≥ 0");
        let max_uniform = Resolution::new(self.max_uniform).context("--max-uniform")?;
        Ok(meshpaint::bench::trade::TradeOptions {
            views: self.views,
            size: self.size,
            max_resolution: Resolution::new(self.max_resolution).context("--max-resolution")?,
            uniform: (0..=max_uniform.log2()).filter_map(|l| Resolution::from_log2(l).ok()).collect(),
            formats: if self.formats.is_empty() { ColorFormat::ALL.to_vec() } else { self.formats.clone() },
            mct: !self.no_mct && self.wants(super::args::Representation::Mct),
            ptex: !self.no_ptex && self.wants(super::args::Representation::Ptex),
            htex: self.wants(super::args::Representation::Htex),
            frames: self.frames,
            error_bounds: self.errors.clone(),
            ..Default::default()
        })
    }
}

/// Runs one benchmark command.
pub(super) fn run(what: BenchCommand) -> Result<()> {
    match what {
        BenchCommand::Extremes { json } => extremes(json),
        BenchCommand::Unwrap { file, size, subdivide } => unwrap(&file, size, subdivide),
        BenchCommand::BrushEdge { file, resolution, size, supersample, zoom, radius_px, out } => {
            let resolution = meshpaint_core::colors::layout::Resolution::new(resolution).context("--resolution")?;
            anyhow::ensure!(size >= 16 && zoom.is_finite() && zoom > 0.0, "--size ≥ 16 and --zoom > 0");
            let options = meshpaint::bench::brush_edge::BrushEdgeOptions {
                resolution,
                size,
                supersample,
                zoom,
                radius_px,
                out,
                ..Default::default()
            };
            meshpaint::bench::brush_edge::bench_brush_edge(&file, &options, &mut |row| println!("{row}"))?;
            Ok(())
        }
        BenchCommand::Trade(args) => trade(&args),
        BenchCommand::Adaptive { file, max_resolution, size, views, supersample, bake, rules, close_up } => {
            let options = meshpaint::bench::adaptive::AdaptiveOptions {
                budget_max: None,
                size,
                views,
                supersample,
                fits: bake.iter().map(|&b| b.into()).collect(),
                close_up: close_up.get()?,
            };
            adaptive(file, max_resolution, options, rules)
        }
        BenchCommand::Pack { file, resolution, format, runs, subdivide, stroke_samples } => {
            pack(file, resolution, format, runs, subdivide, stroke_samples)
        }
        BenchCommand::Load { file, resolution, subdivide, width, height, eager_paint } => {
            load(file, resolution, subdivide, (width, height), eager_paint)
        }
        BenchCommand::Latency { file, resolution, width, height, moves, radius_px } => {
            let resolution = meshpaint_core::colors::layout::Resolution::new(resolution).context("--resolution")?;
            let options =
                meshpaint::bench::latency::LatencyOptions { resolution, size: [width, height], moves, radius_px };
            println!("{}", meshpaint::bench::latency::bench_latency(&file, &options)?);
            Ok(())
        }
        BenchCommand::Paint { file, resolution, dabs, subdivide, dab_samples, json, rows } => {
            paint(file, resolution, dabs, subdivide, dab_samples, json, rows)
        }
        BenchCommand::Render { file, resolution, width, height, frames } => {
            render(file, resolution, width, height, frames)
        }
    }
}

/// `bench unwrap`: a generated UV atlas's cost and quality.
fn unwrap(file: &std::path::Path, size: u32, subdivide: u32) -> Result<()> {
    use meshpaint_core::convert::unwrap::{AtlasOptions, density, generate_uvs};
    let budget = budget(None);
    let (scene, _) = meshpaint_core::io::document::import_scene_within(file, &budget)?;
    let scene = meshpaint_core::convert::subdivide::subdivide_scene(&scene, subdivide, &budget)?;
    let welded = meshpaint_core::mesh::weld::weld_scene(&scene);
    let (positions, triangles) = (&welded.positions_world, &welded.triangles);
    let generated = generate_uvs(positions, triangles, AtlasOptions::new(size), &|_, _| {})
        .with_context(|| format!("unwrapping {}", file.display()))?;
    let stats = density(positions, triangles, &generated.corner_uvs, size);
    let coverage = meshpaint_core::convert::bake_uv::uv_coverage(&generated.corner_uvs, size);
    let row = serde_json::json!({
        "file": file.display().to_string(),
        "triangles": triangles.len(),
        "size": size,
        "padding": generated.padding,
        "charts": generated.charts,
        "seconds": generated.elapsed.as_secs_f64(),
        "utilization": generated.utilization,
        "faces_without_area": generated.faces_without_area.len(),
        "overlapping_texels": coverage.overlapping_texels,
        "density_p5": stats.p5,
        "density_median": stats.median,
        "density_p95": stats.p95,
        "density_spread": stats.spread(),
    });
    println!("{row}");
    Ok(())
}

/// `bench trade`: every choice's cost and error side by side, the extremes, the plots.
fn trade(args: &TradeArgs) -> Result<()> {
    let options = args.options()?;
    let file = &args.file;
    // One line per row as soon as its view is measured.
    let rows = meshpaint::bench::trade::bench_trade_streaming(file, &options, &mut |row| println!("{row}"))?;
    if !args.no_extremes {
        let gpu = meshpaint_render::Gpu::new_headless()?;
        for mut row in meshpaint::bench::extremes::extremes_rows(&gpu)? {
            row["bench"] = "extremes".into();
            println!("{row}");
        }
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let stem = file.file_stem().map_or("mesh".to_owned(), |s| s.to_string_lossy().to_lowercase());
        for written in meshpaint::bench::trade::write_plots(&rows, dir, &stem)? {
            eprintln!("wrote {}", written.display());
        }
    }
    Ok(())
}

/// `bench adaptive`: each resolution rule's samples, time and error against a supersampled reference.
fn adaptive(
    file: PathBuf,
    max_resolution: u64,
    mut options: meshpaint::bench::adaptive::AdaptiveOptions,
    rules: Vec<String>,
) -> Result<()> {
    let max = meshpaint_core::colors::layout::Resolution::new(max_resolution).context("--max-resolution")?;
    let chosen = rules
        .iter()
        .map(|rule| meshpaint::bench::adaptive::parse_rule(rule, max).map_err(|err| anyhow::anyhow!("--rules {err}")))
        .collect::<Result<Vec<_>>>()?;
    let scene = meshpaint_core::mesh::import::import_gltf(&file)?;
    options.budget_max = chosen.is_empty().then_some(max);
    let fits = options.fits.clone();
    // One line per row as soon as it is measured: a large asset takes minutes per row.
    let mut print_row = |row: &meshpaint::bench::adaptive::AdaptiveRow| {
        let mut value = row.to_json();
        value["bench"] = "adaptive".into();
        value["file"] = file.display().to_string().into();
        println!("{value}");
    };
    let rules = if chosen.is_empty() { meshpaint::bench::adaptive::default_rules(max) } else { chosen };
    let rows = meshpaint::bench::adaptive::bench_adaptive(&file, &scene, &rules, &options, &mut print_row)?;
    let texels = meshpaint::bench::adaptive::uv_island_texels(&scene);
    for fit in fits {
        let mut summary = meshpaint::bench::adaptive::summary(&rows, fit, texels);
        summary["uv_face_texels"] = meshpaint::bench::adaptive::uv_face_texels(&scene).into();
        summary["bench"] = "adaptive-summary".into();
        summary["file"] = file.display().to_string().into();
        println!("{summary}");
    }
    Ok(())
}

// `--look-at X,Y,Z --distance D [--yaw --pitch]` of `bench adaptive`: one close-up view.
#[derive(Debug, Clone, clap::Args)]
pub(super) struct CloseUpArgs {
    /// Measure one close-up view looking at this point (world X,Y,Z; e.g. a region's `center`
    /// printed by `meshpaint synth`) instead of --views cameras around the model.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true, requires = "distance")]
    look_at: Option<Vec<f64>>,
    /// Eye distance from --look-at.
    #[arg(long)]
    distance: Option<f64>,
    /// Yaw of the close-up, degrees (0: the eye on +Z looking along −Z).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    yaw: f64,
    /// Pitch of the close-up, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pitch: f64,
}

impl CloseUpArgs {
    fn get(&self) -> Result<Option<meshpaint::bench::adaptive::CloseUp>> {
        let Some(target) = &self.look_at else { return Ok(None) };
        let distance = self.distance.unwrap_or(0.0);
        anyhow::ensure!(distance.is_finite() && distance > 0.0, "--distance must be a positive number");
        anyhow::ensure!(
            target.len() == 3 && target.iter().all(|v| v.is_finite()),
            "--look-at takes three finite numbers X,Y,Z"
        );
        Ok(Some(meshpaint::bench::adaptive::CloseUp {
            target: [target[0], target[1], target[2]],
            distance,
            yaw_degrees: self.yaw,
            pitch_degrees: self.pitch,
        }))
    }
}

/// `bench pack`: the full repack, the incremental repack after a stroke and the relayout after a resolution stroke, per format.
fn pack(
    file: PathBuf,
    resolution: ResolutionArg16,
    format: Vec<ColorFormat>,
    runs: usize,
    subdivide: u32,
    stroke_samples: u64,
) -> Result<()> {
    let document = open_subdivided(&file, resolution.into(), subdivide, &budget(None))?;
    let formats = if format.is_empty() { ColorFormat::ALL.to_vec() } else { format };
    let mut results = Vec::new();
    for format in formats {
        let result = meshpaint::bench::pack::bench_pack(&document, format, runs)?;
        let mut value = result.to_json();
        let incremental = meshpaint::bench::pack::bench_incremental(&document, format, runs.max(3), stroke_samples)?;
        value["incremental_after_stroke"] = incremental.to_json();
        let relayout = meshpaint::bench::pack::bench_relayout(&document, format, runs.max(3), stroke_samples)?;
        value["relayout_after_resolution_stroke"] = relayout.to_json();
        results.push(value);
    }
    let report = serde_json::json!({
        "bench": "pack",
        "file": file.display().to_string(),
        "subdivide": subdivide,
        "triangles": document.store.topology().face_count(),
        "resolution": resolution.resolution,
        "threads": meshpaint_core::packing::packer::pack_threads(),
        "caller_in_pool": meshpaint_core::threads::caller_in_pool(),
        "results": results,
    });
    println!("{report}");
    Ok(())
}

/// `bench load`: from a file to the document on screen and on to paint mode, phase by phase.
fn load(file: PathBuf, resolution: u64, subdivide: u32, size: (u32, u32), eager_paint: bool) -> Result<()> {
    let r = meshpaint_core::colors::layout::Resolution::new(resolution).context("--resolution")?;
    let report = meshpaint::bench::bench_load(&file, r, subdivide, &budget(None), size, eager_paint)?;
    println!("{report}");
    Ok(())
}

/// `bench paint`: the brush rows (samples per second) on the document.
fn paint(
    file: PathBuf,
    resolution: ResolutionArg,
    dabs: usize,
    subdivide: u32,
    dab_samples: Vec<u64>,
    json: bool,
    rows: Vec<String>,
) -> Result<()> {
    let document = open_subdivided(&file, resolution, subdivide, &budget(None))?;
    let known = |row: &String| {
        meshpaint::bench::paint::ROWS.iter().any(|&(name, ..)| {
            *row == name
                || (meshpaint::bench::paint::FRAME_PACED_ROWS.contains(&name) && *row == format!("{name}_frame_paced"))
        })
    };
    if let Some(row) = rows.iter().find(|row| !known(row)) {
        anyhow::bail!("--rows: no row named {row:?}");
    }
    let mut options = meshpaint::bench::PaintBenchOptions { dabs, rows, ..Default::default() };
    if !dab_samples.is_empty() {
        options.target_samples = dab_samples;
    }
    let mut report = meshpaint::bench::bench_paint(&document, &options)?;
    report["file"] = file.display().to_string().into();
    report["resolution"] = resolution.resolution.into();
    report["subdivide"] = subdivide.into();
    if json {
        println!("{report}");
    } else {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}

/// `bench render`: frame times of the view.
fn render(file: PathBuf, resolution: ResolutionArg, width: u32, height: u32, frames: usize) -> Result<()> {
    let document = open(&file, resolution, &budget(None))?;
    let result = meshpaint::bench::bench_render(&file, &document, width, height, frames)?;
    let mut report = result.to_json();
    report["file"] = file.display().to_string().into();
    report["resolution"] = resolution.resolution.into();
    println!("{report}");
    Ok(())
}

/// `bench extremes`: every case, as JSON lines or a table; an error when a case fails.
fn extremes(json: bool) -> Result<()> {
    let gpu = meshpaint_render::Gpu::new_headless()?;
    let cases = meshpaint::bench::extremes::extreme_cases(&gpu)?;
    for case in &cases {
        if json {
            println!("{}", case.to_json());
        } else {
            println!(
                "{:<32} {:>12.4e} ≤ {:<10.3e} {}  {} [{}]",
                case.case,
                case.measured,
                case.tolerance,
                if case.passes() { "ok  " } else { "FAIL" },
                case.unit,
                case.outcome
            );
        }
    }
    let failed: Vec<&str> = cases.iter().filter(|c| !c.passes()).map(|c| c.case.as_str()).collect();
    if !failed.is_empty() {
        anyhow::bail!("{} of {} extreme cases fail their tolerance: {}", failed.len(), cases.len(), failed.join(", "));
    }
    Ok(())
}
