//! Partial redraws while painting ([`meshpaint::app::view_draw`]): after a stroke drawn
//! frame by frame as the window does (only the faces each dab changed, over the previous
//! frame), the 3D view holds exactly the pixels of a full redraw of the same view.

use std::sync::Arc;
use std::time::Duration;

use meshpaint::app::view_draw::{OffscreenView, ViewDraw, ViewDrawer};
use meshpaint::app::{Action, Command, Editor, Mode};
use meshpaint_core::io::document::Source;
use meshpaint_render::Gpu;

const SIZE: [u32; 2] = [480, 360];

/// Pixels that differ between two RGBA8 images, and the largest channel difference.
fn differences(a: &[u8], b: &[u8]) -> (usize, u8) {
    let mut count = 0;
    let mut max = 0;
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let d = p.iter().zip(q).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
        count += usize::from(d > 0);
        max = max.max(d);
    }
    (count, max)
}

#[test]
fn partial_redraws_during_a_stroke_give_the_pixels_of_a_full_redraw() {
    let gpu = Arc::new(Gpu::new_headless().expect("GPU tests need an adapter (lavapipe)"));
    let ctx = Arc::clone(&gpu.ctx);
    let mut editor = Editor::new(Some(Arc::clone(&gpu)), Arc::new(|| {}));
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(Duration::from_secs(120)), "opening the Duck timed out");
    editor.viewport.rect = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(SIZE[0] as f32, SIZE[1] as f32));
    editor.viewport.pixels_per_point = 1.0;
    editor.frame_all();
    editor.perform(Action::TogglePaintMode);
    assert_eq!(editor.mode(), Mode::Paint, "{:?}", editor.status);
    editor.panels.paint.brush.color = [0.9, 0.05, 0.6, 1.0];
    let view = OffscreenView::new(&ctx, SIZE);
    let mut drawer = ViewDrawer::new();
    let draw = |editor: &mut Editor, drawer: &mut ViewDrawer| view.draw_and_wait((&ctx, &gpu), drawer, editor).unwrap();
    assert_eq!(draw(&mut editor, &mut drawer), ViewDraw::Full);
    let before = view.read(&ctx).unwrap();
    // A stroke across the middle, a frame after every pointer move (two moves per frame once).
    let at = |k: f32| egui::pos2(SIZE[0] as f32 * (0.3 + 0.05 * k), SIZE[1] as f32 * (0.45 + 0.02 * k));
    editor.apply(Command::BeginStroke(at(0.0)));
    let mut kinds = vec![draw(&mut editor, &mut drawer)];
    for k in 1..=8 {
        editor.apply(Command::StrokeTo(at(k as f32)));
        if k != 4 {
            kinds.push(draw(&mut editor, &mut drawer));
        }
    }
    editor.apply(Command::EndStroke);
    kinds.push(draw(&mut editor, &mut drawer));
    let partial = kinds.iter().filter(|kind| matches!(kind, ViewDraw::Partial { .. })).count();
    assert!(partial >= 6, "the dabs' frames were not partial redraws: {kinds:?}");
    let painted = view.read(&ctx).unwrap();
    let (changed, _) = differences(&before, &painted);
    assert!(changed > 500, "the stroke changed only {changed} pixels");
    // The same view drawn whole.
    drawer.invalidate();
    assert_eq!(draw(&mut editor, &mut drawer), ViewDraw::Full);
    let full = view.read(&ctx).unwrap();
    let (count, max) = differences(&painted, &full);
    assert_eq!((count, max), (0, 0), "partial redraws differ from a full redraw ({changed} pixels painted)");
}
