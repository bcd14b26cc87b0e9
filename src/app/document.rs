//! The open document as the editor holds it: the [`Document`] (its editable
//! [`meshpaint_core::colors::store::ColorStore`]) side by side with its [`GpuMesh`] and picking BVH, and
//! the work that makes one (open a file, the built-in scene) or writes one (save, export),
//! and which of its views the 3D view draws ([`OpenDocument::shown_item`]).
//!
//! Loading, building views and writing run on a job's worker thread ([`super::jobs`]); the
//! GPU upload too (wgpu devices are shared across threads), so the UI never stalls on a
//! large file.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use meshpaint_core::camera::BoundingSphere;
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::display::{Displayed, OpenOptions, open_for_display};
use meshpaint_core::io::document::{Document, Source, SourceKind};
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::PackCache;
use meshpaint_core::paint::picking::MeshBvh;
use meshpaint_core::progress::Reporter;
use meshpaint_render::{BaselineMesh, DrawItem, Gpu, GpuHtex, GpuMct, GpuMesh, GpuPtex, MeshGeometry};

use super::jobs::JobContext;
use super::state::{Representation, Shown};
use super::text::{human_bytes, thousands};

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
    /// How the last repack after paint mode went (`None` before the first).
    pub last_repack_how: Option<super::paint_session::Repack>,
    /// The compact packing with its `f32` chains, for an incremental repack when paint mode
    /// ends (`None` until a repack made one, or while paint mode holds it).
    pub pack_cache: Option<PackCache>,
    /// The other views of the document, built the first time they are shown.
    pub alternates: AlternateViews,
    /// Counts changes of the GPU mesh's colours or layout (a repack, paint mode): a Mesh
    /// Color Texture built for an older generation is stale.
    pub mesh_generation: u64,
}

/// The views of a document besides its mesh colors ([`super::state::Shown`]), each built on
/// the GPU by a job the first time it is shown; `Err` says why it cannot be shown.
#[derive(Debug, Default)]
pub struct AlternateViews {
    /// The source file drawn with its UVs and base-colour texture.
    pub source_texture: Option<Result<BaselineMesh, String>>,
    /// The position colour field (the mesh at its own resolutions).
    pub position_colors: Option<Result<GpuMesh, String>>,
    /// The Mesh Color Texture of the packed mesh, with the mesh generation it was built for
    /// ([`OpenDocument::mesh_generation`]).
    pub mct: Option<(u64, Result<BuiltMct, String>)>,
    /// The Htex of the packed mesh, with the mesh generation it was built for.
    pub htex: Option<(u64, Result<BuiltHtex, String>)>,
    /// The packed Ptex of the packed mesh, with the mesh generation it was built for.
    pub ptex: Option<(u64, Result<BuiltPtex, String>)>,
}

/// An Htex on the GPU and what building it cost.
#[derive(Debug)]
pub struct BuiltHtex {
    /// Pages, weight texture and records, drawn with the document's GPU mesh geometry.
    pub htex: GpuHtex,
    /// Store-independent build time (packed mesh → pages), without the upload.
    pub build: Duration,
    /// Quad textures (the paper's E) and faces (F).
    pub textures: (u64, u64),
    /// Pages (width and height, count).
    pub pages: ([u32; 2], u32),
    /// GPU bytes over the packed mesh's face records and colours.
    pub bytes_over_mesh_colors: f64,
}

/// Builds the Htex of `packed` within `budget` and uploads it (a job's work).
pub fn build_htex(
    packed: &PackedMesh,
    geometry: &MeshGeometry,
    budget: &Budget,
    gpu: &Gpu,
    job: &JobContext,
) -> Result<BuiltHtex, String> {
    job.progress(0.1, "pairing halfedges and filling the pages");
    let started = Instant::now();
    let limits = gpu.ctx.limits();
    let options = meshpaint_core::htex::HtexOptions::within(
        limits.max_texture_dimension_2d,
        limits.max_texture_array_layers,
        budget.memory_bytes,
    );
    let texture =
        meshpaint_core::htex::build(packed, &options).map_err(|error| format!("building the Htex: {error}"))?;
    let build = started.elapsed();
    job.progress(0.8, "uploading the pages");
    let htex = gpu.upload_htex(geometry, &texture).map_err(|error| format!("uploading the Htex: {error}"))?;
    let mesh_colors = (packed.face_record_bytes() + packed.color_bytes()).max(1);
    Ok(BuiltHtex {
        build,
        textures: texture.texture_count(),
        pages: ([texture.layout.page_size, texture.layout.page_height], texture.layout.pages),
        bytes_over_mesh_colors: htex.gpu_bytes() as f64 / mesh_colors as f64,
        htex,
    })
}

/// A packed Ptex on the GPU and what building it cost.
#[derive(Debug)]
pub struct BuiltPtex {
    /// The texture, records and tables, drawn with the document's GPU mesh geometry.
    pub ptex: GpuPtex,
    /// Store-independent build time (packed mesh → texture), without the upload.
    pub build: Duration,
    /// Texture, records and tables over the packed mesh's face records and colours.
    pub bytes_over_mesh_colors: f64,
}

/// Builds the packed Ptex of `packed` (as [`build_mct`]) within `budget` and uploads it.
pub fn build_ptex(
    packed: &PackedMesh,
    geometry: &MeshGeometry,
    budget: &Budget,
    gpu: &Gpu,
    job: &JobContext,
) -> Result<BuiltPtex, String> {
    job.progress(0.1, "packing the per-face blocks");
    let started = Instant::now();
    let max_dimension = gpu.ctx.limits().max_texture_dimension_2d;
    let texture = meshpaint_core::ptex::build(packed, max_dimension, budget.memory_bytes)
        .map_err(|error| format!("building the packed Ptex: {error}"))?;
    let build = started.elapsed();
    job.progress(0.8, "uploading the texture");
    let ptex = gpu.upload_ptex(geometry, &texture).map_err(|error| format!("uploading the packed Ptex: {error}"))?;
    let mesh_colors = (packed.face_record_bytes() + packed.color_bytes()).max(1);
    Ok(BuiltPtex { ptex, build, bytes_over_mesh_colors: texture.gpu_bytes() as f64 / mesh_colors as f64 })
}

/// A Mesh Color Texture on the GPU and what building it cost.
#[derive(Debug)]
pub struct BuiltMct {
    /// The atlas, records and band table, drawn with the document's GPU mesh geometry.
    pub mct: GpuMct,
    /// Store-independent build time (packed mesh → atlas), without the upload.
    pub build: Duration,
    /// Atlas, records and band table over the packed mesh's face records and colours.
    pub bytes_over_mesh_colors: f64,
}

/// Builds the Mesh Color Texture of `packed` (the packed mesh of the GPU mesh with the
/// geometry `geometry`) within `budget` and uploads it (a job's work).
pub fn build_mct(
    packed: &PackedMesh,
    geometry: &MeshGeometry,
    budget: &Budget,
    gpu: &Gpu,
    job: &JobContext,
) -> Result<BuiltMct, String> {
    job.progress(0.1, "laying out and filling the atlas");
    let started = Instant::now();
    let max_dimension = gpu.ctx.limits().max_texture_dimension_2d;
    let texture = meshpaint_core::mct::build(packed, max_dimension, budget.memory_bytes)
        .map_err(|error| format!("building the Mesh Color Texture: {error}"))?;
    let build = started.elapsed();
    job.progress(0.8, "uploading the atlas");
    let mct =
        gpu.upload_mct(geometry, &texture).map_err(|error| format!("uploading the Mesh Color Texture: {error}"))?;
    let mesh_colors = (packed.face_record_bytes() + packed.color_bytes()).max(1);
    Ok(BuiltMct { mct, build, bytes_over_mesh_colors: texture.gpu_bytes() as f64 / mesh_colors as f64 })
}

/// One alternate view, built by [`build_alternate`].
#[derive(Debug)]
pub enum AlternateView {
    /// [`AlternateViews::source_texture`].
    SourceTexture(Box<Result<BaselineMesh, String>>),
    /// [`AlternateViews::position_colors`].
    PositionColors(Box<Result<GpuMesh, String>>),
    /// [`AlternateViews::mct`], built for this mesh generation.
    Mct(u64, Box<Result<BuiltMct, String>>),
    /// [`AlternateViews::htex`], built for this mesh generation.
    Htex(u64, Box<Result<BuiltHtex, String>>),
    /// [`AlternateViews::ptex`], built for this mesh generation.
    Ptex(u64, Box<Result<BuiltPtex, String>>),
}

/// Builds the view `shown` of `document`, opened from `source`, on `gpu` (`None` for
/// [`Shown::MeshColors`], which the document always has).
pub fn build_alternate(
    shown: Shown,
    source: &Source,
    document: &Document,
    budget: &Budget,
    gpu: &Gpu,
    job: &JobContext,
) -> Option<AlternateView> {
    let name = source.name();
    match shown {
        Shown::MeshColors => None,
        Shown::SourceTexture => {
            job.progress(0.1, "reading the source file");
            let built = match meshpaint_core::io::document::import_source_scene(source, budget) {
                Ok(Some(scene)) => {
                    job.progress(0.5, "uploading the UV-textured mesh");
                    match gpu.upload_baseline(&scene) {
                        Ok(Some(mesh)) => Ok(mesh),
                        Ok(None) => Err(format!("{name} has no base-colour texture to compare with")),
                        Err(error) => Err(format!("{name}: {error}")),
                    }
                }
                Ok(None) => Err(format!("{name} is a packed file: it keeps no source texture")),
                Err(error) => Err(error.to_string()),
            };
            Some(AlternateView::SourceTexture(Box::new(built)))
        }
        Shown::PositionColors => {
            job.progress(0.1, "colouring by position");
            let store = meshpaint_core::io::document::position_colored(&document.store, &document.positions);
            job.progress(0.4, "packing");
            let built = meshpaint_core::packing::packer::pack(&store, &document.positions, document.display_format())
                .map_err(|error| format!("{name}: {error}"))
                .and_then(|packed| gpu.upload(&packed).map_err(|error| format!("{name}: {error}")));
            Some(AlternateView::PositionColors(Box::new(built)))
        }
    }
}

impl OpenDocument {
    /// Triangles in the mesh.
    pub fn triangles(&self) -> u32 {
        self.document.store.topology().face_count()
    }

    /// Where the document came from: its file, or the built-in scene.
    pub fn source(&self) -> Source {
        self.path.clone().map_or(Source::BuiltIn, Source::File)
    }

    /// Whether the view `shown` still has to be built (never for the mesh colors).
    pub fn is_missing(&self, shown: Shown) -> bool {
        match shown {
            Shown::MeshColors => false,
            Shown::SourceTexture => self.alternates.source_texture.is_none(),
            Shown::PositionColors => self.alternates.position_colors.is_none(),
        }
    }

    /// Why the view `shown` cannot be shown, if building it failed.
    pub fn failure(&self, shown: Shown) -> Option<&str> {
        match shown {
            Shown::MeshColors => None,
            Shown::SourceTexture => self.alternates.source_texture.as_ref().and_then(|b| b.as_ref().err()),
            Shown::PositionColors => self.alternates.position_colors.as_ref().and_then(|b| b.as_ref().err()),
        }
        .map(String::as_str)
    }

    /// Whether the Mesh Color Texture of the current GPU mesh still has to be built.
    pub fn mct_missing(&self) -> bool {
        self.alternates.mct.as_ref().is_none_or(|(generation, _)| *generation != self.mesh_generation)
    }

    /// The Mesh Color Texture of the current GPU mesh, if it is built; `Err` says why it
    /// cannot be.
    pub fn current_mct(&self) -> Option<Result<&BuiltMct, &str>> {
        match &self.alternates.mct {
            Some((generation, built)) if *generation == self.mesh_generation => {
                Some(built.as_ref().map_err(String::as_str))
            }
            _ => None,
        }
    }

    /// Whether the Htex of the current GPU mesh still has to be built.
    pub fn htex_missing(&self) -> bool {
        self.alternates.htex.as_ref().is_none_or(|(generation, _)| *generation != self.mesh_generation)
    }

    /// The Htex of the current GPU mesh, if it is built; `Err` says why it cannot be.
    pub fn current_htex(&self) -> Option<Result<&BuiltHtex, &str>> {
        match &self.alternates.htex {
            Some((generation, built)) if *generation == self.mesh_generation => {
                Some(built.as_ref().map_err(String::as_str))
            }
            _ => None,
        }
    }

    /// Whether the packed Ptex of the current GPU mesh still has to be built.
    pub fn ptex_missing(&self) -> bool {
        self.alternates.ptex.as_ref().is_none_or(|(generation, _)| *generation != self.mesh_generation)
    }

    /// The packed Ptex of the current GPU mesh, if it is built; `Err` says why it cannot be.
    pub fn current_ptex(&self) -> Option<Result<&BuiltPtex, &str>> {
        match &self.alternates.ptex {
            Some((generation, built)) if *generation == self.mesh_generation => {
                Some(built.as_ref().map_err(String::as_str))
            }
            _ => None,
        }
    }

    /// The packed mesh and GPU geometry a Mesh Color Texture is built from (`None` without
    /// a GPU mesh or while paint mode holds the packing).
    pub fn mct_source(&self) -> Option<(PackedMesh, MeshGeometry)> {
        let packed = self.pack_cache.as_ref()?.packed();
        let geometry = self.gpu_mesh.as_ref()?.geometry();
        Some((packed.clone(), geometry))
    }

    /// What the 3D view draws for `shown` in `representation`: that alternate view once it
    /// is built, else the mesh colors (`None` without a GPU).
    pub fn shown_item(&self, shown: Shown, representation: Representation) -> Option<DrawItem<'_>> {
        let alternate = match shown {
            Shown::MeshColors => match representation {
                Representation::MeshColorTexture => {
                    self.current_mct().and_then(Result::ok).map(|b| DrawItem::Mct(&b.mct))
                }
                Representation::PackedPtex => self.current_ptex().and_then(Result::ok).map(|b| DrawItem::Ptex(&b.ptex)),
                Representation::Htex => self.current_htex().and_then(Result::ok).map(|b| DrawItem::Htex(&b.htex)),
                Representation::MeshColors => None,
            },
            Shown::SourceTexture => match &self.alternates.source_texture {
                Some(Ok(mesh)) => Some(DrawItem::Baseline(mesh)),
                _ => None,
            },
            Shown::PositionColors => match &self.alternates.position_colors {
                Some(Ok(mesh)) => Some(DrawItem::MeshColors(mesh)),
                _ => None,
            },
        };
        alternate.or_else(|| self.gpu_mesh.as_ref().map(DrawItem::MeshColors))
    }
}

/// Opens `source` for display through the one open path
/// ([`meshpaint_core::io::display::open_for_display`], within `budget`: a mesh at the face
/// resolutions of `rule`, or packed), uploads it when `gpu` is given and builds the picking BVH.
pub fn load(
    source: &Source,
    rule: ResolutionRule,
    budget: &Budget,
    gpu: Option<&Gpu>,
    job: &JobContext,
) -> Result<OpenDocument> {
    let reporter =
        Reporter::with_cancel_flag(|fraction: f32, stage: &str| job.progress(fraction, stage), job.cancel_flag());
    let upload = |packed: &_| gpu.map(|gpu| gpu.upload(packed)).transpose();
    let displayed = open_for_display(source, &OpenOptions::new(rule, *budget), reporter.progress(), upload)?;
    let Displayed { document, cache, bvh, upload: gpu_mesh, timings } = displayed;
    let packed = cache.packed();
    let document_is_packed = matches!(document.source, SourceKind::Packed(_));
    Ok(OpenDocument {
        bounds: BoundingSphere::of_points(&document.positions),
        samples: document.store.sample_count(),
        samples_with_mips: packed.sample_count(),
        packed_bytes: packed.face_record_bytes() + packed.color_bytes(),
        format: document.display_format(),
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
        title: source.title(),
        last_repack: timings.pack,
        last_repack_how: None,
        pack_cache: Some(cache),
        alternates: AlternateViews::default(),
        mesh_generation: 0,
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
    // The editor's tools paint the store, not yet the layers: when they did, the layers no
    // longer make the store and saving them would lose the paint, so the save is flattened.
    let flattened = !document.layers_in_sync();
    let layers = if flattened { None } else { document.layers_section(format) };
    meshpaint_core::packing::file::write_file_with_layers(path, &packed, layers.as_ref())?;
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    job.progress(1.0, "done");
    Ok(Written {
        path: path.to_owned(),
        bytes,
        repack: Some(repack),
        format: Some(format),
        summary: format!(
            "{} samples ({}), {}{}",
            thousands(packed.sample_count()),
            format.name(),
            human_bytes(bytes),
            if flattened { "; layers flattened (the store was painted outside them)" } else { "" }
        ),
    })
}

/// Writes `document` tessellated at each face's resolution as a vertex-colour .glb.
pub fn write_gltf(document: &Document, path: &Path, job: &JobContext) -> Result<Written> {
    job.progress(0.1, "tessellating");
    let summary = meshpaint_core::io::export_gltf::write_tessellated_glb(path, &document.positions, &document.store)
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
