//! `meshpaint bench load`: the seconds from a mesh file to the document on screen and on to
//! the first frame in paint mode, phase by phase, on the editor's own opening path
//! ([`crate::app::document::load`] does the same: pack and upload in parallel with the
//! picking BVH), and the peak memory.
//!
//! Phases: import (read and parse), subdivide (only with `--subdivide N`, not counted in
//! the total: it stands in for a larger file), weld, topology, store (allocate and colour),
//! then pack + upload next to the BVH build (both branches timed; the total counts the
//! wall time of the pair), and one rendered frame: `total_seconds`, the document on screen.
//! Then what Tab does in the editor ([`crate::render::Gpu::upload_paint_layout`], the same
//! call): enter paint mode (paint layout, its upload, the base snapshot of the store) and
//! the first frame of it: `total_to_paint_seconds`, the first frame a brush can touch. The
//! peak memory is read twice: with the document on screen (`peak_resident_on_screen_bytes`)
//! and at the end, in paint mode (`peak_resident_bytes`). The GPU itself is created before the
//! clock starts (the editor has it before any file opens).

use std::path::Path;
use std::time::{Duration, Instant};

use thiserror::Error;

use crate::camera::{DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, default_camera};
use crate::colors::budget::{Budget, BudgetError};
use crate::colors::layout::Resolution;
use crate::io::document::{Document, DocumentError, OpenPhases, import_scene_within};
use crate::io::least_squares::BakeFit;
use crate::packing::packer::{PackCache, PackError};
use crate::packing::paint_layout::PaintLayout;
use crate::paint::picking::{BvhPreset, MeshBvh};
use crate::render::{DrawItem, Gpu, RenderError, RenderSettings};

/// Errors of the load benchmark.
#[derive(Debug, Error)]
pub enum BenchLoadError {
    /// Opening failed.
    #[error(transparent)]
    Document(#[from] DocumentError),
    /// The subdivided mesh is past the budget.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// Packing failed.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// The GPU failed.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// Peak resident memory of this process so far (`VmHWM` of `/proc/self/status`), bytes;
/// `None` where that file does not exist.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Opens `path` at uniform `resolution` (after `subdivide` midpoint subdivisions) as the
/// editor does, timing every phase; renders one `width`×`height` frame. Returns JSON.
pub fn bench_load(
    path: &Path,
    resolution: Resolution,
    subdivide: u32,
    budget: &Budget,
    width: u32,
    height: u32,
) -> Result<serde_json::Value, BenchLoadError> {
    let gpu_started = Instant::now();
    let gpu = Gpu::new_headless()?;
    let gpu_seconds = gpu_started.elapsed().as_secs_f64();
    let budget = (*budget).with_gpu(gpu.budget_limits());
    let started = Instant::now();
    let (scene, kind) = import_scene_within(path, &budget)?;
    let import = started.elapsed();
    let subdivide_started = Instant::now();
    let scene = if subdivide > 0 { crate::io::subdivide::subdivide_scene(&scene, subdivide, &budget)? } else { scene };
    let subdivide_time = subdivide_started.elapsed();
    let mut phases = OpenPhases::default();
    let mut document = Document::from_scene_phased(scene, resolution, BakeFit::default(), path, &budget, &mut phases)?;
    document.source = kind;
    let format = document.display_format();
    let parallel_started = Instant::now();
    let (packed, (bvh, bvh_time)) = rayon::join(
        || -> Result<_, BenchLoadError> {
            let started = Instant::now();
            let cache = PackCache::build(&document.store, &document.positions, format)?;
            let pack = started.elapsed();
            let started = Instant::now();
            let mesh = gpu.upload(cache.packed())?;
            Ok((cache, mesh, pack, started.elapsed()))
        },
        || {
            let started = Instant::now();
            let bvh =
                MeshBvh::build(&document.positions, &document.store.topology().face_vertices, BvhPreset::FastBuild);
            (bvh, started.elapsed())
        },
    );
    let (cache, mesh, pack_time, upload_time) = packed?;
    let parallel = parallel_started.elapsed();
    let frame_started = Instant::now();
    let settings = RenderSettings::new(default_camera(mesh.bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None));
    let image = gpu.render_image(DrawItem::MeshColors(&mesh), &settings, width, height)?;
    let frame = frame_started.elapsed();
    let total = started.elapsed().saturating_sub(subdivide_time);
    let peak_on_screen = peak_resident_bytes();
    // Tab: entering paint mode as the editor does (paint layout, its upload, the base
    // snapshot of the store), then the first frame that shows it.
    let enter_started = Instant::now();
    let layout = PaintLayout::new(&document.store);
    let paint = gpu.upload_paint_layout(&layout, &document.store, &document.positions, format)?;
    let base = document.store.clone();
    let enter_paint = enter_started.elapsed();
    let paint_frame_started = Instant::now();
    let paint_image = gpu.render_image(DrawItem::MeshColors(&paint.mesh), &settings, width, height)?;
    let paint_frame = paint_frame_started.elapsed();
    let total_to_paint = started.elapsed().saturating_sub(subdivide_time);
    // The same frame again: drawing alone (the first one also ran the upload's GPU copies).
    let redraw_started = Instant::now();
    let redraw = gpu.render_image(DrawItem::MeshColors(&paint.mesh), &settings, width, height)?;
    let paint_redraw = redraw_started.elapsed();
    let seconds = |d: Duration| d.as_secs_f64();
    std::hint::black_box((&bvh, &image, &paint_image, &redraw, &base));
    Ok(serde_json::json!({
        "bench": "load",
        "file": path.display().to_string(),
        "subdivide": subdivide,
        "resolution": resolution.get(),
        "triangles": document.store.topology().face_count(),
        "vertices": document.store.topology().vertex_count,
        "store_samples": document.store.sample_count(),
        "packed_samples": cache.packed().sample_count(),
        "threads": rayon::current_num_threads(),
        "gpu_init_seconds": gpu_seconds,
        "phases": {
            "import_seconds": seconds(import),
            "subdivide_seconds": seconds(subdivide_time),
            "weld_seconds": seconds(phases.weld),
            "topology_seconds": seconds(phases.topology),
            "store_seconds": seconds(phases.store),
            "pack_seconds": seconds(pack_time),
            "upload_seconds": seconds(upload_time),
            "bvh_seconds": seconds(bvh_time),
            "pack_upload_bvh_wall_seconds": seconds(parallel),
            "first_frame_seconds": seconds(frame),
            "enter_paint_seconds": seconds(enter_paint),
            "paint_frame_seconds": seconds(paint_frame),
            "paint_redraw_seconds": seconds(paint_redraw),
        },
        "total_seconds": seconds(total),
        "total_note": "import + weld + topology + store + max(pack + upload, BVH) + first frame; subdivision excluded",
        "total_to_paint_seconds": seconds(total_to_paint),
        "total_to_paint_note": "total + entering paint mode (paint layout, upload, base snapshot) + the first frame of the paint layout",
        "peak_resident_bytes": peak_resident_bytes(),
        "peak_resident_on_screen_bytes": peak_on_screen,
    }))
}
