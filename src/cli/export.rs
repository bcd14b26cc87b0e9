//! `meshpaint export`: a tessellated vertex-colour .glb, a packed file, (`--texture`) the
//! colours baked into the model's own UVs or a generated UV atlas, as a textured .glb or a
//! plain PNG, or
//! (`--representation mct`) a Mesh Color Texture file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use meshpaint_core::colors::budget::ATLAS_MAX_WIDTH;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::io::document::{Document, SourceKind, import_scene};
use meshpaint_core::io::export_baked::{BakeRequest, BakedExport, OwnMesh, UvSource, bake_export};
use meshpaint_core::io::export_fit::{FitOptions, write_fitted_glb};
use meshpaint_core::io::export_gltf::ColorEncoding;
use meshpaint_core::mct;
use meshpaint_core::mct::file::write_mct;
use meshpaint_core::mesh::weld::weld_scene;

use super::args::{LOG_TARGET, OutputArgs, Representation, ResolutionArg, Written, budget, open, parse_format};

/// Arguments of `meshpaint export`.
#[derive(Debug, clap::Args)]
pub(super) struct ExportArgs {
    /// A .glb / .gltf, .obj, .ply, .stl or packed file.
    file: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Colour format of a packed output: rgba8 (sRGB, default), rgba16f or rgba32f.
    #[arg(long, value_parser = parse_format)]
    format: Option<ColorFormat>,
    /// Bake the colours into a SIZE × SIZE texture through the model's UVs or generated ones
    /// (--uvs): -o OUT.glb writes the mesh with those UVs and this texture, -o OUT.png the
    /// texture alone.
    #[arg(long, value_name = "SIZE")]
    texture: Option<u32>,
    /// With --texture: `new` generates a non-overlapping UV atlas; a file: bake into that
    /// model's UVs (its welded mesh must be FILE's; for packed input, the model it came
    /// from). Default: FILE's own UVs when every face has some and none overlap, else new.
    #[arg(long, value_name = "new|SOURCE", requires = "texture")]
    uvs: Option<String>,
    /// .glb: tessellate every face at R >> LEVEL (at least 1); the error is reported.
    #[arg(long, value_name = "LEVEL", conflicts_with_all = ["max_vertices", "texture"])]
    level: Option<u32>,
    /// .glb: the finest level whose tessellation has at most N vertices.
    #[arg(long, value_name = "N", conflicts_with = "texture")]
    max_vertices: Option<u64>,
    /// .glb COLOR_0: auto (normalized u8 or u16 when no colour changes, else float; the
    /// default with --level / --max-vertices), float, u16 or u8.
    #[arg(long, value_enum, conflicts_with = "texture")]
    colors: Option<ColorsArg>,
    /// What a non-.glb OUT holds: mesh-colors (a packed file), mct (a Mesh Color Texture
    /// file: mesh, face records, band table and one atlas in --format; docs/MCT_FORMAT.md) or
    /// ptex (a packed Ptex file: mesh, face records, nRes/nRow tables and one texture;
    /// docs/PTEX_FORMAT.md); htex has no file yet (render it).
    #[arg(
        long,
        value_enum,
        default_value_t = Representation::MeshColors,
        conflicts_with_all = ["texture", "level", "max_vertices", "colors"]
    )]
    representation: Representation,
    #[command(flatten)]
    output: OutputArgs,
}

/// `--colors` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum ColorsArg {
    Auto,
    Float,
    U16,
    U8,
}

pub(super) fn run(args: ExportArgs) -> Result<()> {
    if args.representation == Representation::Mct {
        return export_mct(&args);
    }
    if args.representation == Representation::Htex {
        anyhow::bail!(
            "--representation htex has no file format yet: render it with `meshpaint render --representation htex`"
        );
    }
    if args.representation == Representation::Ptex {
        return export_ptex(&args);
    }
    if let Some(size) = args.texture {
        return export_texture(&args, size);
    }
    if args.level.is_some() || args.max_vertices.is_some() || args.colors.is_some() {
        return export_fitted(&args);
    }
    let ExportArgs { file: path, resolution, format, output, .. } = args;
    if output.is_glb()? && format.is_some() {
        anyhow::bail!("--format applies to packed output only (.glb colours are always float, linear)");
    }
    // Unlike `pack` and `paint`, a packed input does not keep its format here.
    let packed_format = format.unwrap_or_default();
    let mut budget = budget(Some(packed_format));
    if output.is_glb()? {
        budget.output_check = Some(meshpaint_core::io::export_gltf::check_tessellation_counts);
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

/// `--representation mct`: the document packed in `--format` (rgba8 by default), its Mesh
/// Color Texture built in an atlas of at most 16384 texels a side (the GPU atlas width of the
/// budget module) within the memory budget, written as an MCT file.
fn export_mct(args: &ExportArgs) -> Result<()> {
    let (path, out) = (&args.file, &args.output.output);
    let extension = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if matches!(extension.as_deref(), Some("glb" | "gltf")) {
        anyhow::bail!(
            "{}: --representation mct writes an MCT file, not glTF; name the output e.g. OUT.mct",
            out.display()
        );
    }
    let format = args.format.unwrap_or_default();
    let budget = budget(Some(format));
    let document = open(path, args.resolution, &budget)?;
    let packed = document.pack(format).with_context(|| format!("packing {}", path.display()))?;
    let texture = mct::build(&packed, ATLAS_MAX_WIDTH as u32, budget.memory_bytes)
        .with_context(|| format!("building the Mesh Color Texture of {}", path.display()))?;
    write_mct(out, &packed.positions, &packed.indices, &texture)?;
    eprintln!(
        "{} → {}: {} faces, {}×{} atlas in {}, {} levels, {} GPU bytes ({} ring texels clamped)",
        path.display(),
        out.display(),
        texture.layout.records.len(),
        texture.layout.width,
        texture.layout.height,
        format.name(),
        texture.layout.levels,
        texture.gpu_bytes(),
        texture.stats.clamped_ring_texels
    );
    Ok(())
}

/// `--representation ptex`: the packed Ptex file (docs/PTEX_FORMAT.md), built as for
/// `--representation mct`.
fn export_ptex(args: &ExportArgs) -> Result<()> {
    let (path, out) = (&args.file, &args.output.output);
    let extension = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if matches!(extension.as_deref(), Some("glb" | "gltf")) {
        anyhow::bail!("{}: --representation ptex writes a packed Ptex file; name it e.g. OUT.ptx", out.display());
    }
    let format = args.format.unwrap_or_default();
    let budget = budget(Some(format));
    let document = open(path, args.resolution, &budget)?;
    let packed = document.pack(format).with_context(|| format!("packing {}", path.display()))?;
    let texture = meshpaint_core::ptex::build(&packed, ATLAS_MAX_WIDTH as u32, budget.memory_bytes)
        .with_context(|| format!("building the packed Ptex of {}", path.display()))?;
    meshpaint_core::ptex::file::write_ptex(out, &packed.positions, &packed.indices, &texture)?;
    eprintln!(
        "{} → {}: {} faces, {} blocks, {}×{} texture in {}, {} levels, {} GPU bytes",
        path.display(),
        out.display(),
        texture.layout.records.len(),
        texture.layout.blocks.len(),
        texture.layout.width,
        texture.layout.height,
        format.name(),
        texture.layout.levels,
        texture.gpu_bytes()
    );
    Ok(())
}

/// `--texture SIZE`: bake into the model's own UVs or generated ones (`--uvs`), write a
/// textured .glb or a PNG.
fn export_texture(args: &ExportArgs, size: u32) -> Result<()> {
    let (path, out) = (&args.file, &args.output.output);
    let extension = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let png_only = match extension.as_deref() {
        Some("png") => true,
        Some("glb") => false,
        _ => anyhow::bail!("{}: with --texture the output is a .glb or a .png", out.display()),
    };
    anyhow::ensure!(args.format.is_none(), "--format applies to packed output only");
    let budget = budget(None);
    let document = open(path, args.resolution, &budget)?;
    // Where the model's own UVs come from: --uvs FILE, else FILE itself (a packed file has none).
    let (uvs, uv_file) = match (args.uvs.as_deref(), document.source) {
        (Some("new"), _) => (UvSource::New, None),
        (Some(source), _) => (UvSource::Own, Some(Path::new(source))),
        (None, SourceKind::Packed(_)) => (UvSource::Auto, None),
        (None, _) => (UvSource::Auto, Some(path.as_path())),
    };
    let welded = match uv_file {
        Some(uv_file) => {
            let (scene, _) = import_scene(uv_file)?;
            let welded = weld_scene(&scene);
            check_same_mesh(&document, &welded.positions_world, &welded.triangles, path, uv_file)?;
            Some(welded)
        }
        None => None,
    };
    let own = welded.as_ref().map(|w| OwnMesh { corner_uvs: &w.corner_uvs, corner_normals: &w.corner_normals_world });
    let request = BakeRequest { size, uvs, own, png_only };
    let baked =
        bake_export(&document, &request, &budget, &|_, _| {}).with_context(|| format!("baking {}", path.display()))?;
    report_bake(&baked, uv_file.unwrap_or(path), document.store.topology().face_count());
    meshpaint_core::atomic_write::write_atomically(out, &baked.bytes)
        .map_err(|error| anyhow::anyhow!("{}: cannot {}: {}", error.path.display(), error.action, error.source))?;
    let coverage = baked.covered_texels as f64 / (f64::from(size) * f64::from(size)) * 100.0;
    eprintln!(
        "{} → {}: {size}×{size} texture, UVs: {}; {coverage:.1}% of the texels in UV islands, texel density \
         p5/median/p95 {:.1}/{:.1}/{:.1} per unit (spread {:.2}), {} of {} faces without UVs, {} vertices, {} B",
        path.display(),
        out.display(),
        baked.choice.reason(),
        baked.density.p5,
        baked.density.median,
        baked.density.p95,
        baked.density.spread(),
        baked.faces_without_uvs,
        document.store.topology().face_count(),
        baked.vertices,
        baked.bytes.len()
    );
    Ok(())
}

/// Warns about faces without UVs and paint lost to overlapping UVs; states the generated
/// layout.
fn report_bake(baked: &BakedExport, uv_file: &Path, faces: u32) {
    if let Some(generated) = &baked.generated {
        eprintln!(
            "generated atlas: {} charts, {:.1}% of the texture covered, gutter {} texels, {} faces without area, {:.2} s",
            generated.charts,
            generated.utilization * 100.0,
            generated.padding,
            generated.faces_without_area.len(),
            generated.elapsed.as_secs_f64()
        );
    }
    if baked.faces_without_uvs > 0 {
        log::warn!(
            target: LOG_TARGET,
            "{}: {} of {faces} faces have no UVs (no area in texture space) and are not in the texture",
            uv_file.display(),
            baked.faces_without_uvs,
        );
    }
    if baked.conflicting_texels > 0 {
        log::warn!(
            target: LOG_TARGET,
            "{}: overlapping or mirrored UV islands: {} texels have clearly different colours (> 32 steps) in \
             two faces; the texture keeps one face's colour, the others' are lost (--uvs new avoids it)",
            uv_file.display(),
            baked.conflicting_texels
        );
    }
}

/// `--level`, `--max-vertices`, `--colors`: the tessellated .glb fitted to the content.
fn export_fitted(args: &ExportArgs) -> Result<()> {
    let (path, out) = (&args.file, &args.output.output);
    anyhow::ensure!(args.output.is_glb()?, "--level, --max-vertices and --colors apply to .glb output");
    anyhow::ensure!(args.format.is_none(), "--format applies to packed output only");
    let document = open(path, args.resolution, &budget(None))?;
    let encoding = match args.colors.unwrap_or(ColorsArg::Auto) {
        ColorsArg::Auto => None,
        ColorsArg::Float => Some(ColorEncoding::Float),
        ColorsArg::U16 => Some(ColorEncoding::Unorm16),
        ColorsArg::U8 => Some(ColorEncoding::Unorm8),
    };
    let options = FitOptions { level: args.level.unwrap_or(0), max_vertices: args.max_vertices, encoding };
    let summary = write_fitted_glb(out, &document.positions, &document.store, document.display_format(), options)
        .with_context(|| format!("exporting {}", path.display()))?;
    let (colors, as_float) = summary.color_bytes;
    eprintln!(
        "{} → {}: level {}, {} vertices, {} triangles, COLOR_0 {:?} ({colors} B instead of {as_float} B as float), \
         error against the full-resolution colours: max {} / RMS {:.2} 8-bit steps, {} B",
        path.display(),
        out.display(),
        summary.level,
        summary.vertices,
        summary.triangles,
        summary.encoding,
        summary.error_steps.0,
        summary.error_steps.1,
        summary.bytes
    );
    Ok(())
}

/// Refuses UVs from a mesh other than the document's (another file, or another version of it).
fn check_same_mesh(
    document: &Document,
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    path: &Path,
    uv_file: &Path,
) -> Result<()> {
    let bits = |p: &[[f32; 3]]| p.iter().map(|v| v.map(f32::to_bits)).collect::<Vec<_>>();
    let same = document.store.topology().face_vertices == triangles && bits(&document.positions) == bits(positions);
    anyhow::ensure!(
        same,
        "{}: its mesh ({} vertices, {} faces) is not the mesh of {} ({} vertices, {} faces), so its UVs do not apply",
        uv_file.display(),
        positions.len(),
        triangles.len(),
        path.display(),
        document.positions.len(),
        document.store.topology().face_count()
    );
    Ok(())
}
