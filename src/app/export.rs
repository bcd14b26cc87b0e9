//! File → Export…: what the export dialog asks for ([`ExportRequest`]), what each choice
//! costs before anything is written ([`estimate`]), and the work of each, run as a job
//! ([`run`]): the colours baked into a texture through the model's UVs or generated ones
//! ([`meshpaint_core::io::export_baked`]), the tessellated vertex-colour glTF at a level or
//! within a vertex budget, with smooth normals ([`meshpaint_core::io::export_fit`]), or the
//! packed file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::convert::unwrap::{UvChoice, choose_uvs};
use meshpaint_core::io::document::{Document, Source, import_source_scene};
use meshpaint_core::io::export_baked::{BakeRequest, OwnMesh, UvSource, bake_export};
use meshpaint_core::io::export_fit::{FitOptions, coarser, level_for, write_fitted_glb};
use meshpaint_core::io::export_gltf::tessellation_counts;
use meshpaint_core::mesh::weld::{WeldedMesh, weld_scene};

use super::document::{Written, write_packed};
use super::jobs::{JobContext, WriteKind};
use super::text::{human_bytes, thousands};

/// What File → Export… writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportWhat {
    /// A textured .glb with the colours baked into a `size × size` texture.
    Baked {
        /// Texture side.
        size: u32,
        /// Which UVs.
        uvs: UvSource,
    },
    /// The tessellated vertex-colour .glb, coarser by `level`, or the finest level within
    /// `max_vertices`.
    Tessellated {
        /// Every face's R divided by `2^level`.
        level: u32,
        /// Instead of `level`: at most this many vertices.
        max_vertices: Option<u64>,
    },
    /// The packed file in `format`.
    Packed {
        /// Colour format.
        format: ColorFormat,
    },
}

/// An export to carry out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExportRequest {
    /// The output file.
    pub path: PathBuf,
    /// What it holds.
    pub what: ExportWhat,
}

impl ExportRequest {
    /// The kind of write job it is.
    pub fn write_kind(&self) -> WriteKind {
        match self.what {
            ExportWhat::Baked { .. } => WriteKind::ExportBaked,
            ExportWhat::Tessellated { .. } => WriteKind::ExportGltf,
            ExportWhat::Packed { .. } => WriteKind::ExportPacked,
        }
    }

    /// The status line's label while it runs.
    pub fn label(&self) -> String {
        let what = match self.what {
            ExportWhat::Baked { .. } => "baked-texture glTF",
            ExportWhat::Tessellated { .. } => "tessellated glTF",
            ExportWhat::Packed { .. } => "packed buffers",
        };
        format!("Exporting {what} to {}", self.path.display())
    }
}

/// What an export will cost, shown before it is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Estimate {
    /// Vertices written (about, for a bake: chart borders split vertices).
    pub vertices: u64,
    /// Triangles written.
    pub triangles: u64,
    /// Bytes of the file (an upper bound for a bake: the PNG at most 4 bytes a texel).
    pub bytes: u64,
    /// The figures in a sentence.
    pub text: String,
}

/// The cost of writing `what` from `document` (a bake's vertex count is estimated as the
/// mesh's vertices plus a fifth for chart borders; the rest is exact or an upper bound).
pub fn estimate(document: &Document, what: ExportWhat) -> Estimate {
    let store = &document.store;
    let faces = u64::from(store.topology().face_count());
    let (vertices, triangles, bytes, text) = match what {
        ExportWhat::Baked { size, .. } => {
            let vertices = document.positions.len() as u64 * 6 / 5;
            let bytes = vertices * 32 + faces * 12 + u64::from(size) * u64::from(size) * 4 + 2048;
            (
                vertices,
                faces,
                bytes,
                format!("about {} vertices, {} triangles, at most", thousands(vertices), thousands(faces)),
            )
        }
        ExportWhat::Tessellated { level, max_vertices } => {
            let counted = match max_vertices {
                Some(max) => level_for(store, max).map(|(level, coarse)| (level, tessellation_counts(&coarse))),
                None if level == 0 => Ok((0, tessellation_counts(store))),
                None => Ok((level, tessellation_counts(&coarser(store, level)))),
            };
            match counted {
                Ok((level, (vertices, triangles))) => {
                    let bytes = vertices * (12 + 12 + 16) + triangles * 12 + 2048;
                    let text = format!(
                        "level {level}: {} vertices, {} triangles ({:.1}× the mesh's), at most",
                        thousands(vertices),
                        thousands(triangles),
                        triangles as f64 / faces.max(1) as f64
                    );
                    (vertices, triangles, bytes, text)
                }
                Err(error) => (0, 0, 0, error.to_string()),
            }
        }
        ExportWhat::Packed { format } => {
            let samples = store.sample_count() * 4 / 3;
            let bytes = samples * format.bytes_per_sample() as u64 + faces * 16 + document.positions.len() as u64 * 12;
            let text = format!(
                "{} vertices, {} triangles, about {} samples with MIP chains in {}, about",
                thousands(document.positions.len() as u64),
                thousands(faces),
                thousands(samples),
                format.name()
            );
            (document.positions.len() as u64, faces, bytes, text)
        }
    };
    let text = if bytes > 0 { format!("{text} {}", human_bytes(bytes)) } else { text };
    Estimate { vertices, triangles, bytes, text }
}

/// The welded mesh of `source` when it is `document`'s mesh (its UVs and normals apply);
/// `None` for a packed file, or a file that changed since it was opened.
pub fn own_mesh(source: &Source, document: &Document, budget: &Budget) -> Result<Option<WeldedMesh>> {
    let Some(scene) = import_source_scene(source, budget)? else {
        return Ok(None);
    };
    let welded = weld_scene(&scene);
    let bits = |p: &[[f32; 3]]| p.iter().map(|v| v.map(f32::to_bits)).collect::<Vec<_>>();
    let same = welded.triangles == document.store.topology().face_vertices
        && bits(&welded.positions_world) == bits(&document.positions);
    Ok(same.then_some(welded))
}

/// Which UVs a `size` bake of `document` (opened from `source`) would use by default.
pub fn check_uvs(source: &Source, document: &Document, size: u32, budget: &Budget) -> Result<UvChoice, String> {
    let own = own_mesh(source, document, budget).map_err(|error| format!("{error:#}"))?;
    Ok(choose_uvs(own.as_ref().map(|w| w.corner_uvs.as_slice()), size))
}

/// Carries out `request` on `document` (opened from `source`) within `budget` (a job's work).
pub fn run(
    request: &ExportRequest,
    document: &Document,
    source: &Source,
    budget: &Budget,
    job: &JobContext,
) -> Result<Written> {
    let path = &request.path;
    match request.what {
        ExportWhat::Packed { format } => write_packed(document, format, path, job),
        ExportWhat::Tessellated { level, max_vertices } => {
            job.progress(0.1, "tessellating");
            let options = FitOptions { level, max_vertices, encoding: None };
            let summary =
                write_fitted_glb(path, &document.positions, &document.store, document.display_format(), options)
                    .with_context(|| format!("exporting {}", path.display()))?;
            let summary_text = format!(
                "level {}, {} vertices, {} triangles, smooth normals, {}",
                summary.level,
                thousands(summary.vertices),
                thousands(summary.triangles),
                human_bytes(summary.bytes)
            );
            Ok(Written { path: path.clone(), bytes: summary.bytes, repack: None, format: None, summary: summary_text })
        }
        ExportWhat::Baked { size, uvs } => bake(document, source, size, uvs, path, budget, job),
    }
}

/// The baked-texture glTF (see [`run`]).
fn bake(
    document: &Document,
    source: &Source,
    size: u32,
    uvs: UvSource,
    path: &Path,
    budget: &Budget,
    job: &JobContext,
) -> Result<Written> {
    job.progress(0.01, "reading the model's UVs");
    let welded = if uvs == UvSource::New { None } else { own_mesh(source, document, budget)? };
    let own = welded.as_ref().map(|w| OwnMesh { corner_uvs: &w.corner_uvs, corner_normals: &w.corner_normals_world });
    let request = BakeRequest { size, uvs, own, png_only: false };
    let baked = bake_export(document, &request, budget, &|stage, fraction| job.progress(fraction, stage))?;
    meshpaint_core::atomic_write::write_atomically(path, &baked.bytes)
        .map_err(|error| anyhow::anyhow!("{}: cannot {}: {}", error.path.display(), error.action, error.source))?;
    let charts = baked.generated.as_ref().map_or(String::new(), |g| format!(", {} charts", g.charts));
    let summary = format!(
        "{size}×{size} texture, {}{charts}; {} vertices, {} triangles, {}",
        baked.choice.reason(),
        thousands(baked.vertices),
        thousands(baked.triangles),
        human_bytes(baked.bytes.len() as u64)
    );
    Ok(Written { path: path.to_owned(), bytes: baked.bytes.len() as u64, repack: None, format: None, summary })
}
