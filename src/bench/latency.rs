//! `meshpaint bench latency`: how long a dab takes to show, as the editor does it.
//!
//! The file is opened by the editor ([`Editor::open`], uniform `R`), paint mode entered
//! (Tab's action), and a stroke drawn across the middle of a `width × height` 3D view, one
//! pointer move per frame: each move waits one frame at 60 Hz, then the editor applies it
//! ([`Command::StrokeTo`]: the dab, the store write, the GPU upload — the paint loop of
//! `src/app`), then the 3D view is drawn as the window does ([`ViewDrawer`]) and the clock
//! stops when the GPU has finished that frame. Reported per pointer move: `dab_seconds`
//! (the command), `frame_seconds` (the drawing, submitted and finished) and
//! `latency_seconds` (both: the move to the frame that shows it), median and p90, once
//! with partial redraws (the editor's) and once drawing every frame whole (`full`, as before
//! partial redraws), with a plain full redraw of the view beside them. Not included: egui's
//! own pass and the present to the window (a few ms at this size).

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use crate::app::command::Command;
use crate::app::editor::Editor;
use crate::app::import_settings::ImportMode;
use crate::app::state::{Action, Mode};
use crate::app::view_draw::{OffscreenView, ViewDraw, ViewDrawer};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::Source;
use meshpaint_render::Gpu;

/// One frame at 60 Hz: the idle time before each pointer move.
const FRAME: Duration = Duration::from_micros(16_667);

/// Options of [`bench_latency`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencyOptions {
    /// Uniform face resolution.
    pub resolution: Resolution,
    /// The 3D view, pixels.
    pub size: [u32; 2],
    /// Pointer moves per stroke.
    pub moves: usize,
    /// Brush radius, pixels (`None`: the editor's default brush).
    pub radius_px: Option<f64>,
}

/// Median and 90th percentile of `seconds`.
fn spread(seconds: &mut [f64]) -> serde_json::Value {
    seconds.sort_by(f64::total_cmp);
    let at = |q: f64| seconds.get(((seconds.len() as f64 - 1.0) * q).round() as usize).copied().unwrap_or(0.0);
    serde_json::json!({ "median": at(0.5), "p90": at(0.9), "max": at(1.0), "count": seconds.len() })
}

/// Opens `path` in an editor on a headless GPU, enters paint mode and measures strokes.
pub fn bench_latency(path: &Path, options: &LatencyOptions) -> Result<serde_json::Value> {
    let gpu = Arc::new(Gpu::new_headless()?);
    let ctx = Arc::clone(&gpu.ctx);
    let mut editor = Editor::new(Some(Arc::clone(&gpu)), Arc::new(|| {}));
    editor.panels.import.mode = ImportMode::Uniform;
    editor.panels.import.resolution = options.resolution;
    let opened = Instant::now();
    editor.open(Source::File(path.to_owned()));
    anyhow::ensure!(editor.wait_for_job(Duration::from_secs(900)), "opening timed out");
    let open_seconds = opened.elapsed().as_secs_f64();
    let triangles = match &editor.document.open {
        Some(open) => open.document.store.topology().face_count(),
        None => anyhow::bail!("could not open {}: {}", path.display(), editor.status.text),
    };
    let [w, h] = options.size;
    editor.viewport.rect = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(w as f32, h as f32));
    editor.viewport.pixels_per_point = 1.0;
    editor.frame_all();
    if let Some(radius_px) = options.radius_px {
        editor.panels.paint.brush.radius = meshpaint_core::paint::brush::BrushRadius::Pixels { radius_px };
    }
    let entered = Instant::now();
    editor.perform(Action::TogglePaintMode);
    anyhow::ensure!(editor.mode() == Mode::Paint, "could not enter paint mode: {}", editor.status.text);
    let enter_seconds = entered.elapsed().as_secs_f64();
    let view = OffscreenView::new(&ctx, options.size);
    let mut drawer = ViewDrawer::new();
    let mut full_frames = Vec::new();
    for _ in 0..5 {
        drawer.invalidate();
        let started = Instant::now();
        view.draw_and_wait((&ctx, &gpu), &mut drawer, &mut editor)?;
        full_frames.push(started.elapsed().as_secs_f64());
    }
    let mut rows = serde_json::Map::new();
    // Across the view's middle, a different row per run (fresh colours each time).
    for (run, (name, always_full)) in [("partial", false), ("full", true), ("partial_again", false)].iter().enumerate()
    {
        drawer.always_full = *always_full;
        let y = h as f32 * (0.45 + 0.05 * run as f32);
        rows.insert((*name).to_owned(), stroke(&mut editor, &view, &mut drawer, (&ctx, &gpu), (y, options.moves))?);
    }
    Ok(serde_json::json!({
        "bench": "latency",
        "file": path.display().to_string(),
        "resolution": options.resolution.get(),
        "triangles": triangles,
        "store_samples": editor.document.open.as_ref().map(|open| open.document.store.sample_count()),
        "view": [w, h],
        "brush": format!("{:?}", editor.panels.paint.brush.radius),
        "open_seconds": open_seconds,
        "enter_paint_seconds": enter_seconds,
        "full_redraw_seconds": spread(&mut full_frames),
        "strokes": rows,
        "note": "per pointer move, one frame (1/60 s) apart: dab = the editor's StrokeTo (dab, store, upload); frame = the 3D view drawn (partial or whole) and finished on the GPU; latency = both",
    }))
}

/// One stroke of `moves` pointer moves along the row `y`: times per move.
fn stroke(
    editor: &mut Editor,
    view: &OffscreenView,
    drawer: &mut ViewDrawer,
    gpu: (&meshpaint_render::GpuContext, &Gpu),
    (y, moves): (f32, usize),
) -> Result<serde_json::Value> {
    let w = view.size[0] as f32;
    let at = |k: usize| egui::pos2(w * (0.3 + 0.4 * k as f32 / moves.max(1) as f32), y);
    editor.apply(Command::BeginStroke(at(0)));
    view.draw_and_wait(gpu, drawer, editor).context("drawing")?;
    let (mut dab, mut frame, mut latency) = (Vec::new(), Vec::new(), Vec::new());
    let (mut partial, mut faces, mut pixels, mut unchanged) = (0u64, 0u64, 0u64, 0u64);
    for k in 1..=moves {
        std::thread::sleep(FRAME);
        let started = Instant::now();
        editor.apply(Command::StrokeTo(at(k)));
        let applied = Instant::now();
        let drawn = view.draw_and_wait(gpu, drawer, editor).context("drawing")?;
        let done = Instant::now();
        if drawn == ViewDraw::Unchanged {
            // The move changed nothing (off the mesh, or within the dab spacing).
            unchanged += 1;
            continue;
        }
        dab.push((applied - started).as_secs_f64());
        frame.push((done - applied).as_secs_f64());
        latency.push((done - started).as_secs_f64());
        if let ViewDraw::Partial { faces: f, scissor } = drawn {
            partial += 1;
            faces += u64::from(f);
            pixels += u64::from(scissor[2]) * u64::from(scissor[3]);
        }
    }
    editor.apply(Command::EndStroke);
    Ok(serde_json::json!({
        "moves": moves,
        "moves_that_changed_nothing": unchanged,
        "partial_frames": partial,
        "mean_faces_per_partial_frame": faces as f64 / partial.max(1) as f64,
        "mean_scissor_pixels_per_partial_frame": pixels as f64 / partial.max(1) as f64,
        "dab_seconds": spread(&mut dab),
        "frame_seconds": spread(&mut frame),
        "latency_seconds": spread(&mut latency),
    }))
}
