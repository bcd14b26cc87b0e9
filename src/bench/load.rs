//! `meshpaint bench load`: the seconds from a mesh file to the document on screen and on to
//! the first frame in paint mode, phase by phase, on the editor's own opening path
//! ([`meshpaint_core::io::display::open_for_display`], which the editor opens with: pack and
//! upload in parallel with the picking BVH), and the peak memory.
//!
//! Phases: import (read and parse), subdivide (only with `--subdivide N`, not counted in
//! the total: it stands in for a larger file), weld, topology, store (allocate and colour),
//! then pack + upload next to the BVH build (both branches timed; the total counts the
//! wall time of the pair), and one rendered frame: `total_seconds`, the document on screen.
//! Then what Tab does in the editor ([`meshpaint_render::Gpu::upload_paint_layout`], the same
//! call): enter paint mode (paint layout, its upload, the base snapshot of the store) and
//! the first frame of it: `total_to_paint_seconds`, the first frame a brush can touch. The
//! peak memory is read twice: with the document on screen (`peak_resident_on_screen_bytes`)
//! and at the end, in paint mode (`peak_resident_bytes`). The GPU itself is created before the
//! clock starts (the editor has it before any file opens).

use std::path::Path;
use std::time::{Duration, Instant};

use thiserror::Error;

use meshpaint_core::camera::{DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, default_camera};
use meshpaint_core::colors::budget::{Budget, BudgetError};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::display::{Displayed, OpenError, OpenOptions, open_for_display};
use meshpaint_core::io::document::{DocumentError, Source};
use meshpaint_core::packing::packer::PackError;
use meshpaint_core::packing::paint_layout::PaintLayout;
use meshpaint_core::progress::Reporter;
use meshpaint_render::{DrawItem, Gpu, RenderError, RenderSettings};

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

impl From<OpenError<RenderError>> for BenchLoadError {
    fn from(error: OpenError<RenderError>) -> Self {
        match error {
            OpenError::Document(error) => error.into(),
            OpenError::Upload { source, .. } => source.into(),
        }
    }
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
    let options = OpenOptions { rule: resolution.into(), subdivide, budget };
    let source = Source::File(path.to_owned());
    let displayed = open_for_display(&source, &options, Reporter::silent().progress(), |packed| gpu.upload(packed))?;
    let Displayed { document, cache, bvh, upload: mesh, timings } = displayed;
    let format = document.display_format();
    let frame_started = Instant::now();
    let settings = RenderSettings::new(default_camera(mesh.bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None));
    let image = gpu.render_image(DrawItem::MeshColors(&mesh), &settings, width, height)?;
    let frame = frame_started.elapsed();
    let total = started.elapsed().saturating_sub(timings.subdivide);
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
    let total_to_paint = started.elapsed().saturating_sub(timings.subdivide);
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
            "import_seconds": seconds(timings.import),
            "subdivide_seconds": seconds(timings.subdivide),
            "weld_seconds": seconds(timings.phases.weld),
            "topology_seconds": seconds(timings.phases.topology),
            "store_seconds": seconds(timings.phases.store),
            "pack_seconds": seconds(timings.pack),
            "upload_seconds": seconds(timings.upload),
            "bvh_seconds": seconds(timings.bvh),
            "pack_upload_bvh_wall_seconds": seconds(timings.pack_upload_bvh),
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
