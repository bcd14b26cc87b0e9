//! The open document as the editor holds it: the [`Document`] (its editable
//! [`crate::colors::store::ColorStore`]) side by side with its [`GpuMesh`] and picking BVH, and
//! the work that makes one (open a file, the built-in scene) or writes one (save, export).
//!
//! Everything here runs on a job's worker thread ([`super::jobs`]); the GPU upload too
//! (wgpu devices are shared across threads), so the UI never stalls on a large file.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use crate::camera::BoundingSphere;
use crate::colors::format::ColorFormat;
use crate::colors::layout::Resolution;
use crate::io::document::{Document, SourceKind};
use crate::paint::picking::{BvhPreset, MeshBvh};
use crate::render::{GpuContext, GpuMesh, MeshUploadOptions, OFFSCREEN_FORMAT, Renderer};

use super::editor::thousands;
use super::jobs::JobContext;

/// The built-in scene: the Duck, embedded in the binary so it opens from any directory.
pub const DEFAULT_SCENE_GLB: &[u8] = include_bytes!("../../assets/models/Duck/Duck.glb");
/// The name the built-in scene goes by in titles and messages.
pub const DEFAULT_SCENE_NAME: &str = "Duck (built-in)";

/// The GPU objects the editor shares with its worker threads.
#[derive(Debug)]
pub struct Gpu {
    /// Device and queue.
    pub ctx: Arc<GpuContext>,
    /// Pipelines for the 3D view (offscreen target in [`OFFSCREEN_FORMAT`]).
    pub renderer: Renderer,
}

impl Gpu {
    /// Builds the renderer for `ctx`.
    pub fn new(ctx: Arc<GpuContext>) -> Result<Self> {
        let renderer = Renderer::new(&ctx, OFFSCREEN_FORMAT).context("building the render pipelines")?;
        Ok(Gpu { ctx, renderer })
    }
}

/// A document open in the editor.
#[derive(Debug)]
pub struct OpenDocument {
    /// Positions and the editable colour store (shared with save/export jobs; a later paint
    /// mode edits it through `Arc::make_mut`).
    pub document: Arc<Document>,
    /// The packed colours on the GPU (`None` without a GPU, e.g. in UI tests).
    pub gpu_mesh: Option<GpuMesh>,
    /// Picking BVH over the mesh.
    pub bvh: MeshBvh,
    /// The file it came from (`None` for the built-in scene).
    pub path: Option<PathBuf>,
    /// Where Save writes without asking: the packed file it was opened from or last saved
    /// as (`None` for glTF input until it is saved).
    pub project_path: Option<PathBuf>,
    /// Title for the window and panels.
    pub title: String,
    /// The colour format of the project file (packed input keeps its own; glTF → RGBA8).
    pub format: ColorFormat,
    /// Bounding sphere (framing, depth range).
    pub bounds: BoundingSphere,
    /// Samples at level 0.
    pub samples: u64,
    /// Samples with MIP chains (the packed colour buffer).
    pub samples_with_mips: u64,
    /// Bytes of the packed face records and colours.
    pub packed_bytes: u64,
    /// How long the last repack (store → linear buffers) took.
    pub last_repack: Duration,
}

impl OpenDocument {
    /// Triangles in the mesh.
    pub fn triangles(&self) -> u32 {
        self.document.store.topology().face_count()
    }
}

/// Where a document comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Source {
    /// The built-in Duck.
    BuiltIn,
    /// A glTF or packed file.
    File(PathBuf),
}

impl Source {
    /// Name for messages.
    pub fn name(&self) -> String {
        match self {
            Source::BuiltIn => DEFAULT_SCENE_NAME.to_owned(),
            Source::File(path) => path.display().to_string(),
        }
    }
}

/// Opens `source` (glTF at `resolution`, or packed), packs it, uploads it when `gpu` is
/// given and builds the picking BVH. Refuses meshes without triangles.
pub fn load(source: &Source, resolution: Resolution, gpu: Option<&Gpu>, job: &JobContext) -> Result<OpenDocument> {
    job.progress(0.05, "reading and importing");
    let document = match source {
        Source::BuiltIn => {
            let scene = crate::mesh::import::import_gltf_slice(DEFAULT_SCENE_GLB, None, "Duck.glb")?;
            Document::from_scene(scene, resolution, Path::new(DEFAULT_SCENE_NAME))?
        }
        Source::File(path) => Document::open(path, resolution)?,
    };
    let name = source.name();
    let faces = document.store.topology().face_count();
    anyhow::ensure!(faces > 0, "{name}: the file holds no triangles to paint");
    let format = match document.source {
        SourceKind::Packed(format) => format,
        SourceKind::Gltf => ColorFormat::default(),
    };
    job.progress(0.45, "packing colours with MIP chains");
    let started = Instant::now();
    let packed = document.pack(format).with_context(|| format!("packing {name}"))?;
    let last_repack = started.elapsed();
    let gpu_mesh = match gpu {
        Some(gpu) => {
            job.progress(0.65, "uploading to the GPU");
            let mesh = GpuMesh::upload(&gpu.ctx, &gpu.renderer, &packed, &MeshUploadOptions::default())
                .with_context(|| format!("uploading {name} to the GPU"))?;
            Some(mesh)
        }
        None => None,
    };
    job.progress(0.8, "building the picking BVH");
    let bvh = MeshBvh::build(&document.positions, &document.store.topology().face_vertices, BvhPreset::FastBuild);
    let title = match source {
        Source::BuiltIn => DEFAULT_SCENE_NAME.to_owned(),
        Source::File(path) => path.file_name().map_or_else(|| name.clone(), |n| n.to_string_lossy().into_owned()),
    };
    job.progress(1.0, "done");
    let document_is_packed = matches!(document.source, SourceKind::Packed(_));
    Ok(OpenDocument {
        bounds: BoundingSphere::of_points(&document.positions),
        samples: document.store.sample_count(),
        samples_with_mips: packed.sample_count(),
        packed_bytes: packed.face_record_bytes() + packed.color_bytes(),
        document: Arc::new(document),
        gpu_mesh,
        bvh,
        project_path: match (source, document_is_packed) {
            (Source::File(path), true) => Some(path.clone()),
            _ => None,
        },
        path: match source {
            Source::BuiltIn => None,
            Source::File(path) => Some(path.clone()),
        },
        title,
        format,
        last_repack,
    })
}

/// What a save or export wrote.
#[derive(Debug, Clone)]
pub struct Written {
    /// The file.
    pub path: PathBuf,
    /// Its size in bytes.
    pub bytes: u64,
    /// Repack time when the job packed the store (packed outputs).
    pub repack: Option<Duration>,
    /// Colour format of a packed output.
    pub format: Option<ColorFormat>,
    /// One-line summary for the status line.
    pub summary: String,
}

/// Packs `document` in `format` and writes a packed file (the project format) to `path`.
pub fn write_packed(document: &Document, format: ColorFormat, path: &Path, job: &JobContext) -> Result<Written> {
    job.progress(0.1, "packing colours with MIP chains");
    let started = Instant::now();
    let packed = document.pack(format).with_context(|| format!("packing for {}", path.display()))?;
    let repack = started.elapsed();
    job.progress(0.6, "writing");
    crate::packing::file::write_file(path, &packed)?;
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    job.progress(1.0, "done");
    Ok(Written {
        path: path.to_owned(),
        bytes,
        repack: Some(repack),
        format: Some(format),
        summary: format!("{} samples ({}), {}", thousands(packed.sample_count()), format.name(), human_bytes(bytes)),
    })
}

/// Writes `document` tessellated at each face's resolution as a vertex-colour .glb.
pub fn write_gltf(document: &Document, path: &Path, job: &JobContext) -> Result<Written> {
    job.progress(0.1, "tessellating");
    let summary = crate::io::export_gltf::write_tessellated_glb(path, &document.positions, &document.store)
        .with_context(|| format!("exporting {}", path.display()))?;
    job.progress(1.0, "done");
    Ok(Written {
        path: path.to_owned(),
        bytes: summary.bytes,
        repack: None,
        format: None,
        summary: format!(
            "{} vertices, {} triangles, {}",
            thousands(summary.vertices),
            thousands(summary.triangles),
            human_bytes(summary.bytes)
        ),
    })
}

/// `bytes` as B / KiB / MiB / GiB with one decimal.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 4] = ["B", "KiB", "MiB", "GiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 { format!("{bytes} B") } else { format!("{value:.1} {}", UNITS[unit]) }
}
