//! A long conversion in the editor: its progress on the status line advances and never goes
//! back, and Cancel stops it with the open document kept (issue 42).

use std::sync::Arc;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshpaint::app::Editor;
use meshpaint::app::import_settings::ImportMode;
use meshpaint_core::io::document::Source;

use crate::common::workspace_path;

/// Opens the Duck with an error bound far below what R ≤ 64 reaches (every face to the
/// finest R, verification rounds and all: many seconds even on a fast machine), watches
/// the status line's progress, cancels once the conversion is under way, and checks that
/// the built-in Duck is still the document, the job has ended and nothing else changed.
#[test]
fn cancelling_a_conversion_keeps_the_open_document() {
    let mut editor = Editor::new(None, Arc::new(|| {}));
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(Duration::from_secs(60)), "opening the built-in Duck timed out");
    let before = editor.document.open.as_ref().expect("the built-in Duck is open").document.clone();
    let title = editor.document.open.as_ref().map(|open| open.title.clone());

    editor.panels.import.mode = ImportMode::ErrorBound;
    editor.panels.import.error_bound = 0.0;
    editor.open(Source::File(workspace_path("assets/models/Duck/Duck.glb")));
    let mut harness =
        Harness::builder().with_size([1280.0, 900.0]).build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor);
    // The progress the status line shows, frame by frame, until the conversion is under way.
    let mut seen = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        harness.run_steps(1);
        let Some((_, fraction, stage, _)) = harness.state().jobs.status() else {
            panic!("the conversion ended before it could be cancelled (seen: {seen:?})");
        };
        seen.push((fraction, stage.clone()));
        if fraction >= 0.1 && stage.contains("faces") {
            break;
        }
        assert!(Instant::now() < deadline, "the conversion showed no progress past 10 %: {seen:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0), "progress went back: {seen:?}");
    harness.get_by_label("Cancel").click();
    harness.run_steps(1);
    assert!(harness.state().jobs.is_cancelling(), "Cancel did not reach the job");
    let cancelled = Instant::now();
    let editor = harness.state_mut();
    assert!(editor.wait_for_job(Duration::from_secs(60)), "the cancelled job did not end");
    assert!(!editor.jobs.is_busy(), "a job is still running after Cancel");
    eprintln!("cancel took effect in {:.2} s", cancelled.elapsed().as_secs_f64());
    let open = editor.document.open.as_ref().expect("a document is still open");
    assert_eq!(Some(open.title.clone()), title, "the open document changed");
    assert_eq!(open.document.store.face_resolutions(), before.store.face_resolutions());
    assert!(editor.status.text.starts_with("Cancelled"), "status: {:?}", editor.status);
    // The editor is free for the next job: a new open starts and finishes.
    editor.panels.import.mode = ImportMode::Automatic;
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(Duration::from_secs(60)), "the next open did not finish");
    assert!(editor.document.open.is_some());
}
