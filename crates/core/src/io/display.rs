//! The one way a document is opened for display — by the editor, `meshpaint render`,
//! `meshpaint bench load` and the examples: import (optionally subdivided), colour, refuse a
//! mesh without triangles, then pack the colours with their MIP chains and hand them to
//! the caller's upload while the picking BVH is built beside them. Every phase is timed.
//!
//! The core knows no GPU: the upload is the caller's closure (the editor and the benchmark
//! upload to wgpu; the command line keeps the packed buffers).

use std::path::Path;
use std::time::{Duration, Instant};

use thiserror::Error;

use crate::colors::budget::Budget;
use crate::convert::adaptive::ResolutionRule;
use crate::convert::least_squares::BakeFit;
use crate::convert::subdivide::subdivide_scene;
use crate::mesh::import::import_gltf_slice_within;
use crate::packing::file as packed_file;
use crate::packing::linear::PackedMesh;
use crate::packing::packer::{PackCache, PackError};
use crate::paint::picking::{BvhPreset, MeshBvh};
use crate::progress::Progress;

use super::document::{
    BUILT_IN_GLB, BUILT_IN_NAME, Document, DocumentError, OpenPhases, Source, import_limits, import_scene_within,
    read_head,
};

/// How to open a document for display.
#[derive(Debug, Clone, Copy)]
pub struct OpenOptions {
    /// The face resolutions of a mesh (a packed file keeps its own).
    pub rule: ResolutionRule,
    /// 1→4 midpoint subdivisions of a mesh before it is coloured (0: none). The benchmarks
    /// stand a larger file in with them; a packed file is refused with it.
    pub subdivide: u32,
    /// The limits every count is checked against before anything is allocated.
    pub budget: Budget,
}

impl OpenOptions {
    /// `rule` within `budget`, not subdivided.
    pub fn new(rule: impl Into<ResolutionRule>, budget: Budget) -> Self {
        OpenOptions { rule: rule.into(), subdivide: 0, budget }
    }
}

/// How long each phase of [`open_for_display`] took.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OpenTimings {
    /// Reading and parsing the file (a packed file: reading and unpacking it).
    pub import: Duration,
    /// The midpoint subdivisions ([`OpenOptions::subdivide`]).
    pub subdivide: Duration,
    /// Weld, topology and store of a mesh.
    pub phases: OpenPhases,
    /// Packing the colours with their MIP chains.
    pub pack: Duration,
    /// The caller's upload of the packed buffers.
    pub upload: Duration,
    /// Building the picking BVH (beside pack and upload).
    pub bvh: Duration,
    /// The wall time of pack + upload beside the BVH.
    pub pack_upload_bvh: Duration,
    /// Everything but the subdivisions: the document on the caller's side.
    pub total: Duration,
}

/// A document opened for display: the document, its packed buffers (in
/// [`Document::display_format`], kept by the cache that repacks edits), the picking BVH,
/// what the caller's upload returned, and the timings.
#[derive(Debug)]
pub struct Displayed<U> {
    /// The document.
    pub document: Document,
    /// Its packed buffers.
    pub cache: PackCache,
    /// The picking BVH of its triangles.
    pub bvh: MeshBvh,
    /// What the upload returned.
    pub upload: U,
    /// How long each phase took.
    pub timings: OpenTimings,
}

impl<U> Displayed<U> {
    /// The packed buffers.
    pub fn packed(&self) -> &PackedMesh {
        self.cache.packed()
    }
}

/// Why [`open_for_display`] failed.
#[derive(Debug, Error)]
pub enum OpenError<E> {
    /// Opening the document failed.
    #[error(transparent)]
    Document(#[from] DocumentError),
    /// The caller's upload failed.
    #[error("uploading {name}: {source}")]
    Upload {
        /// The source's name.
        name: String,
        /// The upload's error.
        source: E,
    },
}

/// Opens `source` for display: a mesh at the face resolutions of `options.rule` (after
/// `options.subdivide` subdivisions) or a packed file, within `options.budget`; refuses a
/// mesh without triangles; packs it in its display format and calls `upload` on the packed
/// buffers while the BVH is built beside them. `progress` is told each stage and the
/// conversion's faces done (from either thread); once cancelled, the conversion stops with
/// [`DocumentError::Cancelled`]. Importer notes are in `document.warnings`.
pub fn open_for_display<U: Send, E: Send>(
    source: &Source,
    options: &OpenOptions,
    progress: Progress<'_>,
    upload: impl FnOnce(&PackedMesh) -> Result<U, E> + Send,
) -> Result<Displayed<U>, OpenError<E>> {
    let started = Instant::now();
    let mut timings = OpenTimings::default();
    progress.report(0.0, "reading and importing");
    let document = open_document(source, options, &mut timings, progress.part(0.05, 0.85))?;
    let name = source.name();
    if document.store.topology().face_count() == 0 {
        return Err(DocumentError::NoTriangles { path: name.into() }.into());
    }
    progress.report(0.85, "packing colours with MIP chains, building the picking BVH");
    let parallel = Instant::now();
    let (packed, (bvh, bvh_time)) = rayon::join(
        || -> Result<_, OpenError<E>> {
            let started = Instant::now();
            let pack_error = |source: PackError| DocumentError::Pack { path: name.clone().into(), source };
            let cache = PackCache::build(&document.store, &document.positions, document.display_format())
                .map_err(pack_error)?;
            let pack = started.elapsed();
            progress.report(0.95, "uploading");
            let started = Instant::now();
            let uploaded = upload(cache.packed()).map_err(|source| OpenError::Upload { name: name.clone(), source })?;
            Ok((cache, uploaded, pack, started.elapsed()))
        },
        || {
            let started = Instant::now();
            let bvh =
                MeshBvh::build(&document.positions, &document.store.topology().face_vertices, BvhPreset::FastBuild);
            (bvh, started.elapsed())
        },
    );
    let (cache, upload, pack, upload_time) = packed?;
    timings.pack_upload_bvh = parallel.elapsed();
    (timings.pack, timings.upload, timings.bvh) = (pack, upload_time, bvh_time);
    timings.total = started.elapsed().saturating_sub(timings.subdivide);
    progress.report(1.0, "done");
    Ok(Displayed { document, cache, bvh, upload, timings })
}

/// The document of `source`, timing its phases into `timings`.
fn open_document(
    source: &Source,
    options: &OpenOptions,
    timings: &mut OpenTimings,
    progress: Progress<'_>,
) -> Result<Document, DocumentError> {
    let OpenOptions { rule, subdivide, ref budget } = *options;
    let started = Instant::now();
    let (scene, kind, name) = match source {
        Source::BuiltIn => {
            let scene = import_gltf_slice_within(BUILT_IN_GLB, None, "Duck.glb", &import_limits(budget))?;
            (scene, super::SourceKind::Gltf, Path::new(BUILT_IN_NAME).to_owned())
        }
        Source::File(path) => {
            if subdivide == 0 && packed_file::looks_like_packed(&read_head(path)?) {
                let document = Document::open_within(path, rule, budget)?;
                timings.import = started.elapsed();
                return Ok(document);
            }
            let (scene, kind) = import_scene_within(path, budget)?;
            (scene, kind, path.clone())
        }
    };
    timings.import = started.elapsed();
    let scene = if subdivide > 0 {
        let started = Instant::now();
        let scene = subdivide_scene(&scene, subdivide, budget)
            .map_err(|source| DocumentError::Budget { path: name.clone(), source })?;
        timings.subdivide = started.elapsed();
        scene
    } else {
        scene
    };
    let mut document =
        Document::from_scene_phased(scene, rule, BakeFit::default(), &name, budget, &mut timings.phases, progress)?;
    document.source = kind;
    Ok(document)
}
