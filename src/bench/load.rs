//! `meshpaint bench load`: the seconds from a mesh file to the document on screen and on to
//! the first frame in paint mode, phase by phase, on the editor's own opening path
//! ([`meshpaint_core::io::display::open_for_display`], which the editor opens with: pack and
//! upload in parallel with the picking BVH), and the peak memory.
//!
//! Phases: import (read and parse), subdivide (only with `--subdivide N`, not counted in
//! the total: it stands in for a larger file), weld, topology, store (allocate and colour),
//! then pack + upload next to the BVH build (both branches timed; the total counts the
//! wall time of the pair), and one rendered frame: `total_seconds`, the document on screen.
//! Then what Tab does in the editor ([`meshpaint_render::Gpu::enter_paint`], the same call):
//! enter paint mode (the paint layout laid over the packing the view shows, beside the base
//! snapshot of the store and the vertex → face table; `--eager-paint`: the layout built,
//! encoded and uploaded, the way before) and the first frame of it: `total_to_paint_seconds`,
//! the first frame a brush can touch. `buffers` gives the bytes of every buffer held then. The
//! peak memory is read twice: with the document on screen (`peak_resident_on_screen_bytes`)
//! and at the end, in paint mode (`peak_resident_bytes`). The GPU itself is created before the
//! clock starts (the editor has it before any file opens).

use std::path::Path;
use std::time::{Duration, Instant};

use thiserror::Error;

use meshpaint_core::camera::{DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, default_camera};
use meshpaint_core::colors::budget::{Budget, BudgetError};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::io::display::{Displayed, OpenError, OpenOptions, open_for_display};
use meshpaint_core::io::document::Document;
use meshpaint_core::io::document::{DocumentError, Source};
use meshpaint_core::mesh::topology::VertexFaces;
use meshpaint_core::packing::packer::PackCache;
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

/// Resident memory of this process now (`VmRSS`), bytes; `None` where unknown.
pub fn resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The bytes of every buffer paint mode holds, by owner.
fn buffers(
    document: &Document,
    cache: &PackCache,
    bvh: &meshpaint_core::paint::picking::MeshBvh,
    (mesh, entered): (&meshpaint_render::GpuMesh, &Entered),
) -> serde_json::Value {
    let store = &document.store;
    let (samples, index) = store.heap_bytes();
    let pack = cache.heap_bytes();
    let encoded = entered.start.encoded.bytes().len() as u64;
    let lent = entered.start.mesh.is_none();
    let mut gpu = mesh.gpu_bytes();
    if let Some(paint) = &entered.start.mesh {
        gpu += paint.gpu_bytes();
    }
    let rows = [
        ("mesh", store.topology().heap_bytes() + std::mem::size_of_val(document.positions.as_slice()) as u64),
        ("store_samples", samples),
        ("store_index", index),
        ("packed_colors", if lent { encoded } else { pack.colors }),
        ("packed_records_and_geometry", pack.records_and_geometry),
        ("pack_levels", pack.levels),
        ("pack_tables", pack.tables),
        ("bvh", bvh.heap_bytes()),
        ("gpu_meshes", gpu),
        ("paint_layout", entered.start.layout.heap_bytes()),
        ("paint_encoded", if lent { 0 } else { encoded }),
        ("undo_base", entered.base.unshared_bytes(store)),
        ("vertex_faces", entered.vertex_faces.heap_bytes()),
    ];
    let total: u64 = rows.iter().map(|&(_, bytes)| bytes).sum();
    let mut map: serde_json::Map<String, serde_json::Value> =
        rows.iter().map(|&(name, bytes)| (name.to_owned(), bytes.into())).collect();
    map.insert("total".into(), total.into());
    serde_json::Value::Object(map)
}

/// Opens `path` at uniform `resolution` (after `subdivide` midpoint subdivisions) as the
/// editor does, timing every phase; renders one `width`×`height` frame, enters paint mode as
/// the editor does (`eager_paint`: building and uploading the paint layout instead of laying
/// it over the packing the view shows, the way before) and renders its first frame. Returns JSON.
pub fn bench_load(
    path: &Path,
    resolution: Resolution,
    subdivide: u32,
    budget: &Budget,
    (width, height): (u32, u32),
    eager_paint: bool,
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
    // Tab: entering paint mode as the editor does (paint layout, its upload if any, the base
    // snapshot of the store, the vertex → face table), then the first frame that shows it.
    let mut cache = cache;
    let entered = enter_paint(&gpu, &document, format, (&mut cache, eager_paint))?;
    let enter_paint = entered.seconds.iter().map(|&(_, d)| d).sum::<Duration>();
    // Paint mode draws level 0 only (src/app/state.rs `render_settings`).
    let mut paint_settings = settings;
    paint_settings.filter = meshpaint_render::FilterMode::Linear;
    let paint_mesh = entered.start.mesh.as_ref().unwrap_or(&mesh);
    let paint_frame_started = Instant::now();
    let paint_image = gpu.render_image(DrawItem::MeshColors(paint_mesh), &paint_settings, width, height)?;
    let paint_frame = paint_frame_started.elapsed();
    let total_to_paint = started.elapsed().saturating_sub(timings.subdivide);
    // The same frame again: drawing alone (the first one also ran the upload's GPU copies).
    let redraw_started = Instant::now();
    let redraw = gpu.render_image(DrawItem::MeshColors(paint_mesh), &paint_settings, width, height)?;
    let paint_redraw = redraw_started.elapsed();
    let seconds = |d: Duration| d.as_secs_f64();
    std::hint::black_box((&bvh, &image, &paint_image, &redraw, &entered.base, &entered.vertex_faces));
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
            "enter_paint": entered.parts.iter().map(|&(name, d)| (name.to_owned(), seconds(d).into())).collect::<serde_json::Map<_, _>>(),
            "enter_paint_in_place": entered.start.mesh.is_none(),
            "paint_frame_seconds": seconds(paint_frame),
            "paint_redraw_seconds": seconds(paint_redraw),
        },
        "total_seconds": seconds(total),
        "total_note": "import + weld + topology + store + max(pack + upload, BVH) + first frame; subdivision excluded",
        "total_to_paint_seconds": seconds(total_to_paint),
        "total_to_paint_note": "total + entering paint mode (paint layout over the packing on the GPU, or built and uploaded; base snapshot; vertex → face table) + its first frame",
        "peak_resident_bytes": peak_resident_bytes(),
        "resident_bytes": resident_bytes(),
        "buffers": buffers(&document, &cache, &bvh, (&mesh, &entered)),
        "buffers_note": "heap bytes of each buffer held in paint mode (lavapipe keeps GPU memory in host memory: gpu_* are resident too); packed_colors is the paint buffer's CPU copy when paint mode paints the packing in place; undo_base counts what the base snapshot does not share with the store",
        "peak_resident_on_screen_bytes": peak_on_screen,
    }))
}

/// What entering paint mode made, and the seconds of each of its steps.
struct Entered {
    start: meshpaint_render::PaintStart,
    base: ColorStore,
    vertex_faces: VertexFaces,
    /// The wall time of the steps in order (they add up to `enter_paint_seconds`).
    seconds: Vec<(&'static str, Duration)>,
    /// Each step's own time (side by side in the editor's path).
    parts: Vec<(&'static str, Duration)>,
}

/// Enters paint mode on `document` as the editor's Tab does (src/app/paint.rs
/// `enter_paint_mode`): [`Gpu::enter_paint`] over `cache` (or, `eager`, the paint layout built
/// and uploaded: its layout, encode and upload timed apart), the base snapshot, the
/// vertex → face table.
fn enter_paint(
    gpu: &Gpu,
    document: &Document,
    format: ColorFormat,
    (cache, eager): (&mut PackCache, bool),
) -> Result<Entered, BenchLoadError> {
    let (store, positions) = (&document.store, &document.positions);
    let mut seconds = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |name: &'static str, seconds: &mut Vec<(&'static str, Duration)>| {
        seconds.push((name, clock.elapsed()));
        clock = Instant::now();
    };
    let start = if eager {
        let layout = PaintLayout::new(store);
        lap("paint_layout_seconds", &mut seconds);
        let packed = layout.packed(store, positions, format);
        lap("paint_encode_seconds", &mut seconds);
        let mesh = gpu.upload(&packed)?;
        let bytes = packed.color_bytes() + packed.face_record_bytes();
        let encoded = meshpaint_core::packing::paint_layout::EncodedBuffer::from_packed_owned(packed);
        lap("paint_upload_seconds", &mut seconds);
        meshpaint_render::PaintStart { layout, encoded, mesh: Some(mesh), bytes }
    } else {
        // As the editor: the snapshot and the table beside the layout, each timed on its own;
        // the wall time of the three is `enter_paint_seconds`.
        let ((start, layout_time), (base, base_time, vertex_faces, table_time)) = rayon::join(
            || {
                let started = Instant::now();
                (gpu.enter_paint(store, positions, format, Some(cache)), started.elapsed())
            },
            || {
                let started = Instant::now();
                let base = store.clone();
                let base_time = started.elapsed();
                let started = Instant::now();
                (base, base_time, VertexFaces::of(store.topology()), started.elapsed())
            },
        );
        lap("wall_seconds", &mut seconds);
        let parts = [("paint_layout_seconds", layout_time), ("base_snapshot_seconds", base_time)];
        let parts = parts.into_iter().chain([("vertex_faces_seconds", table_time)]);
        return Ok(Entered { start: start?, base, vertex_faces, seconds, parts: parts.collect() });
    };
    let base = store.clone();
    lap("base_snapshot_seconds", &mut seconds);
    let vertex_faces = VertexFaces::of(store.topology());
    lap("vertex_faces_seconds", &mut seconds);
    Ok(Entered { start, base, vertex_faces, parts: seconds.clone(), seconds })
}
