//! `meshpaint info`: welded topology counts and the sample budget of a file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use meshpaint_core::colors::budget::{Budget, SampleCounts, bytes_text};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::stats::MeshStats;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::{Document, SourceKind};
use meshpaint_core::mesh::orientation::Orientation;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::file as packed_file;

use super::args::{LOG_TARGET, ResolutionArg, is_mct_file, open};

/// Arguments of `meshpaint info`.
#[derive(Debug, clap::Args)]
pub(super) struct InfoArgs {
    /// A .glb / .gltf, .obj, .ply, .stl, packed or MCT file.
    file: PathBuf,
    #[command(flatten)]
    resolution: ResolutionArg,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// Whether `path` starts with the packed-file magic.
fn is_packed_file(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut file = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let read = file.read(&mut head).with_context(|| path.display().to_string())?;
    Ok(packed_file::looks_like_packed(&head[..read]))
}

/// `info FILE.mct`: what the MCT file holds (read through every check of the reader).
fn mct_info(path: &Path, json: bool) -> Result<()> {
    let file = meshpaint_core::mct::file::read_mct(path)?;
    let layout = &file.mct.layout;
    let faces_per_block: Vec<(u32, usize)> = (0u32..)
        .zip(&layout.pairs)
        .filter(|(_, pairs)| !pairs.is_empty())
        .map(|(g, _)| (1 << g, layout.records.iter().filter(|r| r.log2_block() == g).count()))
        .collect();
    let lone = layout.pairs.iter().flatten().filter(|pair| pair[1] == u32::MAX).count();
    if json {
        let value = serde_json::json!({
            "file": path.display().to_string(),
            "kind": "mct",
            "vertices": file.positions.len(),
            "faces": file.indices.len(),
            "format": file.mct.format.name(),
            "atlas_width": layout.width,
            "atlas_height": layout.height,
            "levels": layout.levels,
            "strip_row_masks": layout.masks.len(),
            "lone_faces": lone,
            "gpu_bytes": file.mct.gpu_bytes(),
            "faces_per_block_resolution": faces_per_block.iter().map(|(r, n)| serde_json::json!({"block_resolution": r, "faces": n})).collect::<Vec<_>>(),
        });
        println!("{value}");
        return Ok(());
    }
    println!("{}: Mesh Color Texture file (docs/MCT_FORMAT.md)", path.display());
    println!("  {} vertices, {} faces ({} without a partner)", file.positions.len(), file.indices.len(), lone);
    println!(
        "  atlas {}×{} {} texels, {} levels, {} strip-row masks; {} on the GPU",
        layout.width,
        layout.height,
        file.mct.format.name(),
        layout.levels,
        layout.masks.len(),
        bytes_text(file.mct.gpu_bytes())
    );
    for (resolution, faces) in faces_per_block {
        println!("  block resolution {resolution}: {faces} faces");
    }
    Ok(())
}

pub(super) fn run(args: InfoArgs) -> Result<()> {
    let InfoArgs { file: path, resolution, json } = args;
    if is_mct_file(&path)? {
        return mct_info(&path, json);
    }
    if !is_packed_file(&path)? {
        return gltf_info(&path, resolution, json);
    }
    let budget = Budget::from_environment();
    let document = open(&path, resolution, &budget)?;
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
    extra.extend(Orientation::of(store.topology(), &document.positions).to_json());
    let counts = SampleCounts::of_store(store);
    extra.extend(budget_report("the packed mesh", &budget, &counts, document.display_format()));
    print_stats(&path, &stats, extra, json);
    Ok(())
}

/// `fits_budget`, the limits and the estimate of `counts` against `budget`, and the refusal
/// message when it does not fit (what opening at this R would say).
fn budget_report(
    what: &str,
    budget: &Budget,
    counts: &SampleCounts,
    format: ColorFormat,
) -> serde_json::Map<String, serde_json::Value> {
    let mut map = serde_json::Map::new();
    let check = budget.check(what, counts, format);
    map.insert("fits_budget".into(), check.is_ok().into());
    map.insert("sample_limit".into(), budget.sample_limit().0.into());
    map.insert("memory_budget_bytes".into(), budget.memory_bytes.into());
    map.insert("estimated_bytes".into(), counts.estimated_bytes(format).into());
    if let Err(error) = check {
        map.insert("budget_refusal".into(), error.to_string().into());
    }
    map
}

/// A mesh file (glTF, OBJ, PLY, STL): counts need the welded topology only, not the
/// samples, so this stays cheap at any R (a glTF file's triangles after instancing are
/// checked while it is read).
fn gltf_info(path: &Path, resolution_arg: ResolutionArg, json: bool) -> Result<()> {
    let resolution = resolution_arg.get()?;
    let rule = resolution_arg.rule();
    let budget = Budget::from_environment();
    let (scene, _) = meshpaint_core::io::document::import_scene_within(path, &budget)?;
    for warning in &scene.warnings {
        log::warn!(target: LOG_TARGET, "{}: {warning}", path.display());
    }
    let mesh = meshpaint_core::mesh::weld::weld_scene(&scene);
    let topology = Topology::build(mesh.positions_world.len() as u32, &mesh.triangles)
        .with_context(|| format!("{}: building topology", path.display()))?;
    let mut stats = MeshStats::new(&topology, mesh.degenerate_triangles_dropped, resolution);
    let mut extra = Orientation::of(&topology, &mesh.positions_world).to_json();
    let rule = rule?;
    let (counts, what) = match rule {
        ResolutionRule::Uniform(_) => {
            (SampleCounts::uniform_on(&topology, resolution), format!("R = {resolution} on every face"))
        }
        rule => {
            // Content-driven resolutions, as `pack` chooses them with its default bake: the
            // fit runs; the document's store is allocated only for the error rule (a budget's
            // calibration stores are bounded by `least_squares::MAX_SAMPLES`).
            let face_count = topology.face_count() as usize;
            let resolutions = match rule {
                // The error rule raises the faces still over the bound after the bake
                // (`adaptive::bake_and_verify`), so only the conversion itself gives its count.
                ResolutionRule::ErrorBound { .. } => {
                    let document = Document::from_scene_within(scene.clone(), rule, path, &budget)?;
                    (0..face_count as u32).filter_map(|face| document.store.face_resolution(face)).collect()
                }
                rule => {
                    let fit = meshpaint_core::convert::least_squares::BakeFit::default();
                    let mut phases = meshpaint_core::convert::adaptive::RulePhases::default();
                    let reporter = meshpaint_core::progress::Reporter::silent();
                    let resolutions = meshpaint_core::convert::adaptive::face_resolutions_phased(
                        &mesh,
                        &scene,
                        face_count,
                        rule,
                        fit,
                        &mut phases,
                        reporter.progress(),
                    )?;
                    if let ResolutionRule::Budget { .. } = rule {
                        extra.insert("faces_held_by_budget".into(), phases.faces_held_by_budget.into());
                    }
                    resolutions
                }
            };
            let counts = SampleCounts::of_resolutions(&topology, |f| resolutions[f as usize]);
            stats.samples = counts.samples;
            stats.samples_with_mips = counts.samples_with_mips;
            let (min, max) = resolutions.iter().fold((u32::MAX, 0), |(lo, hi), r| (lo.min(r.get()), hi.max(r.get())));
            extra.insert("rule".into(), rule.describe().into());
            extra.insert("resolution_min".into(), min.into());
            extra.insert("resolution_max".into(), max.into());
            (counts, rule.describe())
        }
    };
    extra.extend(budget_report(&what, &budget, &counts, ColorFormat::default()));
    print_stats(path, &stats, extra, json);
    Ok(())
}

/// Prints `stats` and `extra` as one JSON object or as text lines.
fn print_stats(path: &Path, stats: &MeshStats, extra: serde_json::Map<String, serde_json::Value>, json: bool) {
    if json {
        let mut object = stats.to_json();
        object.extend(extra);
        println!("{}", serde_json::Value::Object(object));
    } else {
        print!("{}:\n{}", path.display(), stats.to_text());
        let number = |key: &str| extra.get(key).and_then(serde_json::Value::as_u64).unwrap_or(0);
        let orientation = Orientation {
            components: number("components"),
            closed_components: number("closed_components"),
            inverted_components: number("inverted_components"),
            closed_signed_volume: extra.get("closed_signed_volume").and_then(serde_json::Value::as_f64).unwrap_or(0.0),
            inconsistent_edges: number("inconsistent_edges"),
        };
        print!("{}", orientation.to_text());
        let fits = extra.get("fits_budget").and_then(serde_json::Value::as_bool).unwrap_or(false);
        let verdict = match extra.get("budget_refusal").and_then(serde_json::Value::as_str) {
            Some(refusal) => format!("exceeded: {refusal}"),
            None if fits => "fits".to_owned(),
            None => "unknown".to_owned(),
        };
        println!(
            "budget:                       {verdict} (estimate {} of {}; at most {} samples with MIP chains)",
            bytes_text(number("estimated_bytes")),
            bytes_text(number("memory_budget_bytes")),
            number("sample_limit")
        );
        const SHOWN: [&str; 10] = [
            "components",
            "closed_components",
            "inverted_components",
            "closed_signed_volume",
            "inconsistent_edges",
            "fits_budget",
            "budget_refusal",
            "sample_limit",
            "memory_budget_bytes",
            "estimated_bytes",
        ];
        for (key, value) in extra.iter().filter(|(key, _)| !SHOWN.contains(&key.as_str())) {
            println!("{key}: {value}");
        }
    }
}
