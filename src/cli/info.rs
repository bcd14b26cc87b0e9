//! `meshpaint info`: welded topology counts and the sample budget of a file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use meshpaint::colors::layout::Resolution;
use meshpaint::colors::stats::MeshStats;
use meshpaint::io::document::SourceKind;
use meshpaint::packing::file as packed_file;

use super::args::{LOG_TARGET, ResolutionArg, open};

/// Arguments of `meshpaint info`.
#[derive(Debug, clap::Args)]
pub(super) struct InfoArgs {
    /// A .glb / .gltf, .obj, .ply, .stl or packed file.
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

pub(super) fn run(args: InfoArgs) -> Result<()> {
    let InfoArgs { file: path, resolution, json } = args;
    if !is_packed_file(&path)? {
        return gltf_info(&path, resolution, json);
    }
    let document = open(&path, resolution)?;
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
    print_stats(&path, &stats, extra, json);
    Ok(())
}

/// A mesh file (glTF, OBJ, PLY, STL): counts need the welded topology only, not the samples, so this stays
/// cheap at any R.
fn gltf_info(path: &Path, resolution: ResolutionArg, json: bool) -> Result<()> {
    let resolution = resolution.get()?;
    let (scene, _) = meshpaint::io::document::import_scene(path)?;
    for warning in &scene.warnings {
        log::warn!(target: LOG_TARGET, "{}: {warning}", path.display());
    }
    let mesh = meshpaint::mesh::weld::weld_scene(&scene);
    let topology = meshpaint::mesh::topology::Topology::build(mesh.positions_world.len() as u32, &mesh.triangles)
        .with_context(|| format!("{}: building topology", path.display()))?;
    let stats = MeshStats::new(&topology, mesh.degenerate_triangles_dropped, resolution);
    print_stats(path, &stats, serde_json::Map::new(), json);
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
        for (key, value) in extra {
            println!("{key}: {value}");
        }
    }
}
