//! `meshpaint bench paint`: BVH presets, pick latency, dab throughput per brush size and
//! tool, the bytes each dab uploads and the repack time, on the editor's own code paths; `headline` is the editor's defaults
//! (occlusion and backface culling on) on the largest brush.
//!
//! Upload bytes come from [`PaintLayout::sync`] and [`PaintLayout::encode_plan`], exactly
//! what the editor's paint mode sends to the GPU after a dab (samples and patched face
//! records), not from a formula of our own.

use std::time::Instant;

use glam::DVec3;

use crate::bench::pack::Timing;
use meshpaint_core::camera::{BoundingSphere, DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, OrbitCamera, default_camera};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::linear::FaceRecord;
use meshpaint_core::packing::paint_layout::PaintLayout;
use meshpaint_core::paint::brush::{
    BlendMode, BrushError, BrushSettings, Falloff, PaintView, Painter, Tool, samples_within,
};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;
use meshpaint_render::Gpu;

/// Options of [`bench_paint`].
#[derive(Debug, Clone, PartialEq)]
pub struct PaintBenchOptions {
    /// Viewport size, pixels.
    pub viewport_px: [u32; 2],
    /// Target footprints, samples per dab.
    pub target_samples: Vec<u64>,
    /// Timed dabs per brush size (best and median reported).
    pub dabs: usize,
    /// Picks timed per preset.
    pub picks: usize,
    /// Repack repetitions.
    pub pack_runs: usize,
    /// Only these rows of [`ROWS`] (a frame-paced one as `<row>_frame_paced`), and nothing
    /// else (no BVH presets, session-first dab, GPU upload or repack): what a profiler should
    /// see of one kind of dab. Empty: everything.
    pub rows: Vec<String>,
}

impl Default for PaintBenchOptions {
    fn default() -> Self {
        PaintBenchOptions {
            viewport_px: [1280, 720],
            target_samples: vec![1_000, 10_000, 100_000],
            dabs: 30,
            picks: 2000,
            pack_runs: 3,
            rows: Vec::new(),
        }
    }
}

/// The rows measured per brush size: (name, tool, backface culling, occlusion, one undo
/// step per dab). Each is named after what it enables; `occlusion` is the editor's default.
pub const ROWS: [(&str, Tool, bool, bool, bool); 7] = [
    ("occlusion", Tool::Paint, true, true, false),
    ("occlusion_first_dab", Tool::Paint, true, true, true),
    ("paint", Tool::Paint, false, false, false),
    ("first_dab", Tool::Paint, false, false, true),
    ("culling", Tool::Paint, true, false, false),
    ("blur", Tool::Blur, false, false, false),
    ("blur_occlusion", Tool::Blur, true, true, false),
];

/// The row the headline reports: the editor's defaults.
pub const HEADLINE_ROW: &str = "occlusion";

/// Rows also measured frame-paced (`<row>_frame_paced`): each dab after a [`FRAME`] of
/// idle, as a stroke's dabs come one per frame in the editor, against the back-to-back dabs
/// of the other rows (caches and the idle cores go cold between frames).
pub const FRAME_PACED_ROWS: [&str; 2] = ["occlusion", "blur"];
/// The idle time before each frame-paced dab: one frame at 60 Hz.
const FRAME: std::time::Duration = std::time::Duration::from_micros(16_667);
/// Frame-paced dabs per brush size at most (each costs a frame of wall time).
const FRAME_PACED_DABS: usize = 30;

/// Measures picking and painting on `document` (see `meshpaint bench paint`): BVH build and
/// pick time per preset, dab time and throughput for brushes covering the target sample
/// counts (every row of [`ROWS`]; `headline` repeats [`HEADLINE_ROW`] on the largest brush),
/// bytes a dab would upload, the occlusion depth map's build time, and the repack time.
/// Returns JSON.
pub fn bench_paint(document: &Document, options: &PaintBenchOptions) -> Result<serde_json::Value, BrushError> {
    let positions = &document.positions;
    let triangles = &document.store.topology().face_vertices;
    let [width, height] = options.viewport_px;
    let camera = default_camera(BoundingSphere::of_points(positions), DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None);
    let reference = MeshBvh::build(positions, triangles, BvhPreset::FastBuild);
    let everything = options.rows.is_empty();
    let selected = |name: &str| everything || options.rows.iter().any(|row| row == name);
    let presets = if everything { bvh_presets(positions, triangles, &camera, &reference, options) } else { Vec::new() };

    // Pick latency through the whole cursor path (pixel → ray → BVH), default preset.
    let bvh = reference;
    let mut store = document.store.clone();
    // The base snapshot is the document's own store (the bench paints a copy).
    let base = &document.store;
    let view = PaintView { positions, bvh: &bvh, camera: &camera, viewport_px: options.viewport_px, base: Some(base) };
    let centre_px = [f64::from(width) * 0.5, f64::from(height) * 0.5];
    let (pick_timing, hit) = Timing::measure(options.picks.max(1), || view.pick(centre_px));
    let center = hit.map(|hit| DVec3::from_array(hit.position_world)).unwrap_or(DVec3::from_array(camera.target));

    let mut painter = Painter::new(positions);
    // The occlusion depth map of the view, built once per view (timed apart from the dabs).
    let (depth_timing, built) = Timing::measure(1, || painter.prepare_occlusion(&view, &store, false));
    let mut brushes = Vec::new();
    let scene_radius = camera.scene_radius.max(1e-12);
    let session_first_dab = if everything {
        measure_session_first_dab(&view, &mut store, &mut painter, center, scene_radius, &options.target_samples)?
    } else {
        serde_json::Value::Null
    };
    for &target in &options.target_samples {
        let radius = radius_covering(&view, &store, center, scene_radius, target);
        let mut row = serde_json::json!({ "target_samples": target, "radius_world": radius,
            "radius_px": radius / view.world_per_px_at(center).max(f64::MIN_POSITIVE) });
        let (query, faces) = Timing::measure(options.dabs.max(5), || view.bvh.faces_in_sphere(center, radius));
        row["sphere_query"] = serde_json::json!({ "faces": faces.len(), "timing": query.to_json() });
        for &(name, tool, culling, occlusion, step_per_dab) in &ROWS {
            let settings = BrushSettings {
                tool,
                blend: BlendMode::Mix,
                strength: 0.5,
                falloff: Falloff::Smooth,
                occlusion,
                backface_culling: culling,
                mirror_x: false,
                ..BrushSettings::default()
            };
            if selected(name) {
                let pace = (options.dabs, None);
                row[name] =
                    measure_dabs(&view, &mut store, &mut painter, settings, (center, radius), pace, step_per_dab)?;
            }
            if FRAME_PACED_ROWS.contains(&name) && selected(&format!("{name}_frame_paced")) {
                // As in a stroke: one dab per frame, the machine idle between.
                let pace = (options.dabs.min(FRAME_PACED_DABS), Some(FRAME));
                row[format!("{name}_frame_paced")] =
                    measure_dabs(&view, &mut store, &mut painter, settings, (center, radius), pace, step_per_dab)?;
            }
        }
        brushes.push(row);
    }
    // The headline: the editor's defaults on the largest brush.
    let headline = brushes.last().map_or(serde_json::Value::Null, headline);
    // The editor's whole dab on the largest brush: the dab, then the upload it triggers.
    let gpu_upload = match (everything.then(Gpu::new_headless), options.target_samples.last()) {
        (None, _) => serde_json::Value::Null,
        (Some(Ok(gpu)), Some(&target)) => {
            let radius = radius_covering(&view, &store, center, scene_radius, target);
            let settings = BrushSettings { tool: Tool::Paint, blend: BlendMode::Mix, ..BrushSettings::default() };
            measure_gpu_upload(&view, &mut store, &mut painter, settings, (center, radius), options.dabs, &gpu)?
        }
        (Some(Err(error)), _) => serde_json::json!({ "skipped": error.to_string() }),
        (Some(Ok(_)), None) => serde_json::Value::Null,
    };
    let repack = everything.then(|| {
        let (timing, packed) = Timing::measure(options.pack_runs, || document.pack(ColorFormat::Rgba8Srgb));
        let bytes = packed.map(|p| p.face_record_bytes() + p.color_bytes()).unwrap_or(0);
        serde_json::json!({ "timing": timing.to_json(), "bytes": bytes, "threads": meshpaint_core::packing::packer::pack_threads() })
    });
    Ok(serde_json::json!({
        "bench": "paint",
        "triangles": document.store.topology().face_count(),
        "samples": document.store.sample_count(),
        "threads": rayon::current_num_threads(), "caller_in_pool": meshpaint_core::threads::caller_in_pool(),
        "viewport_px": options.viewport_px,
        "headline": headline,
        "occlusion_depth_map": {
            "build_seconds": depth_timing.best_seconds,
            "maps_built": built,
            "pixels": u64::from(width) * u64::from(height),
            "tolerance_px": meshpaint_core::paint::occlusion::DEPTH_TOLERANCE_PX,
        },
        "bvh_presets": presets,
        "pick_latency": pick_timing.to_json(),
        "brushes": brushes,
        "session_first_dab": session_first_dab,
        "session_first_dab_note": "the first dab after entering paint mode (editor defaults, largest brush): it also copies the store chunks it writes, shared with the base snapshot until then",
        "gpu_upload": gpu_upload,
        "repack_rgba8": repack,
    }))
}

/// The headline of a brush size's `row`: the editor's defaults ([`HEADLINE_ROW`]).
fn headline(row: &serde_json::Value) -> serde_json::Value {
    let dab = &row[HEADLINE_ROW];
    serde_json::json!({
        "row": HEADLINE_ROW,
        "what": "paint with the editor's defaults (occlusion and backface culling on), in a stroke",
        "target_samples": row["target_samples"],
        "samples_per_second_best": dab["samples_per_second_best"],
        "samples_per_second_median": dab["samples_per_second_median"],
        "samples_per_second_median_frame_paced": row[format!("{HEADLINE_ROW}_frame_paced")]["samples_per_second_median"],
    })
}

/// The brush radius (world units, by bisection on the measured footprint) whose dab covers
/// `target` samples around `center`.
fn radius_covering(view: &PaintView, store: &ColorStore, center: DVec3, scene_radius: f64, target: u64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, scene_radius * 2.0);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if samples_within(view, store, center, mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Paint-mode dab throughput of [`bench_paint`]'s `paint_in_stroke` case on `document`, one
/// brush covering about `target_samples` samples at the default view's centre pick (a 1280×720
/// viewport), `dabs` dabs in one stroke. Returns the same JSON object as each case there.
pub fn dab_throughput(document: &Document, target_samples: u64, dabs: usize) -> Result<serde_json::Value, BrushError> {
    let positions = &document.positions;
    let triangles = &document.store.topology().face_vertices;
    let camera = default_camera(BoundingSphere::of_points(positions), DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None);
    let bvh = MeshBvh::build(positions, triangles, BvhPreset::FastBuild);
    let base = document.store.clone();
    let mut store = document.store.clone();
    let viewport_px = [1280, 720];
    let view = PaintView { positions, bvh: &bvh, camera: &camera, viewport_px, base: Some(&base) };
    let hit = view.pick([640.0, 360.0]);
    let center = hit.map(|hit| DVec3::from_array(hit.position_world)).unwrap_or(DVec3::from_array(camera.target));
    let radius = radius_covering(&view, &store, center, camera.scene_radius.max(1e-12), target_samples);
    let settings = BrushSettings {
        tool: Tool::Paint,
        blend: BlendMode::Mix,
        strength: 0.5,
        falloff: Falloff::Smooth,
        occlusion: false,
        backface_culling: false,
        mirror_x: false,
        ..BrushSettings::default()
    };
    let mut painter = Painter::new(positions);
    let mut row = measure_dabs(&view, &mut store, &mut painter, settings, (center, radius), (dabs, None), false)?;
    row["radius_world"] = radius.into();
    Ok(row)
}

/// Rays through a `grid × grid` lattice of pixel centres of a `viewport_px` view from
/// `camera` that hit the mesh (as `reference` finds): the picks every BVH preset is timed on.
pub(crate) fn pick_rays(
    camera: &OrbitCamera,
    viewport_px: [u32; 2],
    grid: u32,
    reference: &MeshBvh,
) -> Vec<(DVec3, DVec3)> {
    let [width, height] = viewport_px;
    let mut on_mesh = Vec::new();
    for gy in 0..grid {
        for gx in 0..grid {
            let cursor = [(f64::from(gx) + 0.5) * f64::from(width) / f64::from(grid), {
                (f64::from(gy) + 0.5) * f64::from(height) / f64::from(grid)
            }];
            let (origin, direction) = camera.ray_through_pixel(cursor[0], cursor[1], width, height);
            if reference.cast(origin, direction, f64::INFINITY).is_some() {
                on_mesh.push((origin, direction));
            }
        }
    }
    on_mesh
}

/// Build and pick time of every BVH preset, and its hits, on rays through a grid of pixels
/// that hit the mesh (found with `reference`).
fn bvh_presets(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    camera: &OrbitCamera,
    reference: &MeshBvh,
    options: &PaintBenchOptions,
) -> Vec<serde_json::Value> {
    // Pixels on the mesh, on a grid over the viewport (for picks).
    let on_mesh = pick_rays(camera, options.viewport_px, 64, reference);
    let mut presets = Vec::new();
    for preset in BvhPreset::ALL {
        let (build, bvh) = Timing::measure(1, || MeshBvh::build(positions, triangles, preset));
        let (pick, hits) = Timing::measure(3, || {
            let mut hits = 0u32;
            for k in 0..options.picks {
                if let Some((origin, direction)) = on_mesh.get(k % on_mesh.len().max(1)) {
                    hits += u32::from(bvh.cast(*origin, *direction, f64::INFINITY).is_some());
                }
            }
            hits
        });
        let picks = options.picks.max(1) as f64;
        presets.push(serde_json::json!({
            "preset": preset.name(),
            "build_seconds": build.best_seconds,
            "pick_seconds_best": pick.best_seconds / picks,
            "pick_seconds_median": pick.median_seconds / picks,
            "picks": options.picks,
            "hits": hits,
        }));
    }

    presets
}

/// Times `dabs` dabs of `settings` at `sphere` (centre, world radius) as the editor paints
/// them (colours alternating, all in one undo step or one step per dab), with the bytes the
/// last dab uploads.
/// The first dab of a paint session, with the editor's defaults on the largest brush of
/// `targets`: `store` still shares every chunk with the base snapshot, so this dab also
/// copies the chunks it writes (once per session).
fn measure_session_first_dab(
    view: &PaintView,
    store: &mut ColorStore,
    painter: &mut Painter,
    center: DVec3,
    scene_radius: f64,
    targets: &[u64],
) -> Result<serde_json::Value, BrushError> {
    let Some(&target) = targets.iter().max() else {
        return Ok(serde_json::Value::Null);
    };
    let radius = radius_covering(view, store, center, scene_radius, target);
    measure_dabs(view, store, painter, BrushSettings::default(), (center, radius), (1, None), true)
}

fn measure_dabs(
    view: &PaintView,
    store: &mut ColorStore,
    painter: &mut Painter,
    settings: BrushSettings,
    (center, radius): (DVec3, f64),
    (dabs, gap): (usize, Option<std::time::Duration>),
    step_per_dab: bool,
) -> Result<serde_json::Value, BrushError> {
    let mut history = UndoHistory::new(meshpaint_core::paint::undo::DEFAULT_CAP_BYTES);
    store.take_dirty();
    let (mut times, mut sync_times) = (Vec::new(), Vec::new());
    let (mut covered, mut upload_bytes, mut upload_ranges) = (0, 0, 0);
    let mut layout = PaintLayout::new(store);
    if !step_per_dab {
        history.begin_step(store, "bench")?;
    }
    for k in 0..dabs.max(1) {
        let color = if k % 2 == 0 { [0.9, 0.2, 0.1, 1.0] } else { [0.1, 0.3, 0.9, 1.0] };
        painter.set_settings(BrushSettings { color, ..settings });
        if step_per_dab {
            history.begin_step(store, "bench")?;
        }
        if let Some(gap) = gap {
            std::thread::sleep(gap);
        }
        let started = Instant::now();
        let stats = painter.dab_at(view, store, &mut history, center, radius)?;
        times.push(started.elapsed().as_secs_f64());
        if step_per_dab {
            history.end_step();
        }
        covered = stats.samples_covered;
        let started = Instant::now();
        (upload_bytes, upload_ranges) = upload_like_the_editor(&mut layout, store);
        sync_times.push(started.elapsed().as_secs_f64());
    }
    history.end_step();
    times.sort_by(f64::total_cmp);
    sync_times.sort_by(f64::total_cmp);
    let (best, median) = (times[0], times[times.len() / 2]);
    Ok(serde_json::json!({
        "samples_covered": covered,
        "dab_seconds_best": best,
        "dab_seconds_median": median,
        "samples_per_second_best": covered as f64 / best,
        "samples_per_second_median": covered as f64 / median,
        "upload_bytes_rgba8": upload_bytes,
        "upload_ranges": upload_ranges,
        "sync_encode_seconds_best": sync_times[0],
        "sync_encode_seconds_median": sync_times[sync_times.len() / 2],
        "dabs": times.len(),
        "dab_gap_seconds": gap.map_or(0.0, |gap| gap.as_secs_f64()),
        "undo_bytes": history.bytes_used(),
    }))
}

/// Bytes the editor's paint mode uploads for the store's dirty elements (RGBA8: the
/// encoded sample ranges of the plan and the patched face records), and the sample ranges
/// (one GPU write each).
fn upload_like_the_editor(layout: &mut PaintLayout, store: &mut ColorStore) -> (u64, usize) {
    let dirty = store.take_dirty();
    let plan = layout.sync(store, &dirty);
    let samples = layout.encode_plan(store, &dirty, &plan, ColorFormat::Rgba8Srgb).len() as u64;
    (samples + plan.faces.len() as u64 * std::mem::size_of::<FaceRecord>() as u64, plan.sample_ranges.len())
}

/// Times `dabs` dabs of `settings` (the editor's defaults) at `sphere` as the editor runs
/// them, each followed by the paint-mode upload it triggers ([`PaintLayout::sync`],
/// [`meshpaint_core::packing::paint_layout::EncodedBuffer::apply`], [`meshpaint_render::GpuMesh::write_paint_upload`] and the
/// queue submitted and waited for): the dab, the encode and the GPU write apart, and the
/// samples per second of the whole.
fn measure_gpu_upload(
    view: &PaintView,
    store: &mut ColorStore,
    painter: &mut Painter,
    settings: BrushSettings,
    (center, radius): (DVec3, f64),
    dabs: usize,
    gpu: &Gpu,
) -> Result<serde_json::Value, BrushError> {
    let format = ColorFormat::Rgba8Srgb;
    let mut layout = PaintLayout::new(store);
    let (mesh, mut encoded) = match gpu.upload_paint_layout(&layout, store, view.positions, format) {
        Ok(upload) => (upload.mesh, upload.encoded),
        Err(error) => return Ok(serde_json::json!({ "skipped": error.to_string() })),
    };
    let mut history = UndoHistory::new(meshpaint_core::paint::undo::DEFAULT_CAP_BYTES);
    store.take_dirty();
    history.begin_step(store, "bench")?;
    let mut rows = Vec::new();
    let mut covered = 0;
    for k in 0..dabs.max(1) {
        let color = if k % 2 == 0 { [0.9, 0.2, 0.1, 1.0] } else { [0.1, 0.3, 0.9, 1.0] };
        painter.set_settings(BrushSettings { color, ..settings });
        let started = Instant::now();
        covered = painter.dab_at(view, store, &mut history, center, radius)?.samples_covered;
        let dabbed = Instant::now();
        let dirty = store.take_dirty();
        let plan = layout.sync(store, &dirty);
        let spans = encoded.apply(&layout, store, &dirty, &plan);
        let encoded_at = Instant::now();
        let records = (plan.faces.as_slice(), layout.records());
        let written = if plan.grown { Err("the layout grew".to_owned()) } else { Ok(()) }.and_then(|()| {
            mesh.write_paint_upload(&gpu.ctx, &spans, encoded.bytes(), records).map_err(|e| e.to_string())
        });
        gpu.ctx.queue.submit([]);
        let _ = gpu.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        if let Err(error) = written {
            return Ok(serde_json::json!({ "skipped": error }));
        }
        let done = Instant::now();
        rows.push([
            (dabbed - started).as_secs_f64(),
            (encoded_at - dabbed).as_secs_f64(),
            (done - encoded_at).as_secs_f64(),
            (done - started).as_secs_f64(),
            plan.sample_ranges.len() as f64,
            spans.len() as f64,
            spans.iter().map(|&(_, n)| f64::from(n)).sum::<f64>(),
        ]);
    }
    history.end_step();
    // The dab with the fastest whole (dab + upload).
    rows.sort_by(|a, b| a[3].total_cmp(&b[3]));
    let best = rows[0];
    let median = rows[rows.len() / 2];
    Ok(serde_json::json!({
        "what": "the editor's defaults on the largest brush, each dab followed by its GPU upload (RGBA8)",
        "samples_covered": covered,
        "dab_seconds": best[0],
        "sync_encode_seconds": best[1],
        "gpu_write_seconds": best[2],
        "total_seconds_best": best[3],
        "total_seconds_median": median[3],
        "upload_ranges": best[4] as u64,
        "upload_spans": best[5] as u64,
        "upload_span_samples": best[6] as u64,
        "max_upload_gap": meshpaint_core::packing::paint_layout::MAX_UPLOAD_GAP,
        "samples_per_second_best": covered as f64 / best[3],
        "samples_per_second_median": covered as f64 / median[3],
    }))
}
