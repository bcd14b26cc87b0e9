//! UI logic of the editor without a window: egui_kittest drives `Editor::ui` (panels,
//! shortcuts, help window, file dialog, status line) and the editor's open/save/export
//! paths, with no GPU (the 3D view is covered by tests/app_window.rs under Xvfb).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshpaint::app::editor::{Action, Editor, Severity};
use meshpaint::app::loaded::Source;
use meshpaint::render::{FilterMode, Shading};

const JOB_TIMEOUT: Duration = Duration::from_secs(60);

fn crate_path(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

fn new_editor() -> Editor {
    Editor::new(None, Arc::new(|| {}))
}

/// An editor with the built-in Duck open (no GPU).
fn editor_with_duck() -> Editor {
    let mut editor = new_editor();
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(JOB_TIMEOUT), "opening the Duck timed out");
    assert!(editor.document.is_some(), "the Duck did not open: {:?}", editor.status);
    editor
}

fn harness(editor: Editor) -> Harness<'static, Editor> {
    Harness::builder().with_size([1280.0, 800.0]).build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor)
}

#[test]
fn view_panel_changes_the_render_settings() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert!(!harness.state().view.overlays.wireframe);
    harness.get_by_label("Wireframe").click();
    harness.run_steps(2);
    assert!(harness.state().view.overlays.wireframe);
    assert!(harness.state().render_settings().overlays.wireframe);

    harness.get_by_label("Resolution heat map").click();
    harness.run_steps(2);
    assert!(harness.state().render_settings().overlays.heatmap);

    harness.get_by_label("Unlit").click();
    harness.run_steps(2);
    assert_eq!(harness.state().render_settings().shading, Shading::Unlit);
    harness.get_by_label("Lit").click();
    harness.run_steps(2);
    assert_eq!(harness.state().view.shading, Shading::Lit);
}

#[test]
fn filter_combo_box_selects_the_filter() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert_eq!(harness.state().view.filter, FilterMode::Trilinear);
    harness.get_by_value("Trilinear (auto MIP)").click();
    harness.run_steps(2);
    harness.get_by_label("Nearest").click();
    harness.run_steps(2);
    assert_eq!(harness.state().render_settings().filter, FilterMode::Nearest);
}

#[test]
fn shortcuts_toggle_overlays_shading_and_filter() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::W);
    harness.run_steps(2);
    assert!(harness.state().view.overlays.wireframe);
    harness.key_press(egui::Key::H);
    harness.run_steps(2);
    assert!(harness.state().view.overlays.heatmap);
    harness.key_press(egui::Key::L);
    harness.run_steps(2);
    assert_eq!(harness.state().view.shading, Shading::Unlit);
    harness.key_press(egui::Key::M);
    harness.run_steps(2);
    assert_eq!(harness.state().view.filter, FilterMode::Nearest);
    // The checkbox shows the state the shortcut set.
    harness.get_by_label("Wireframe").click();
    harness.run_steps(2);
    assert!(!harness.state().view.overlays.wireframe);
}

#[test]
fn f1_opens_the_help_window_listing_every_shortcut() {
    let mut harness = harness(new_editor());
    harness.run_steps(2);
    assert!(harness.query_by_label("Keyboard and mouse").is_none());
    harness.key_press(egui::Key::F1);
    harness.run_steps(3);
    assert!(harness.state().show_help);
    assert!(harness.query_by_label("Keyboard and mouse").is_some(), "no help window");
    for shortcut in meshpaint::app::input::SHORTCUTS {
        assert!(harness.query_by_label(shortcut.keys).is_some(), "help lacks {}", shortcut.keys);
        assert!(harness.query_by_label(shortcut.description).is_some(), "help lacks {}", shortcut.description);
    }
    for (gesture, _) in meshpaint::app::input::POINTER_HELP {
        assert!(harness.query_by_label(gesture).is_some(), "help lacks {gesture}");
    }
    harness.key_press(egui::Key::F1);
    harness.run_steps(3);
    assert!(harness.query_by_label("Keyboard and mouse").is_none());
}

#[test]
fn every_shortcut_performs_a_distinct_action() {
    let shortcuts = meshpaint::app::input::SHORTCUTS;
    let mut actions: Vec<Action> = shortcuts.iter().map(|s| s.action).collect();
    actions.sort_by_key(|a| format!("{a:?}"));
    actions.dedup();
    assert_eq!(actions.len(), shortcuts.len(), "two shortcuts share an action");
    for (i, a) in shortcuts.iter().enumerate() {
        for b in &shortcuts[i + 1..] {
            assert!(!(a.key == b.key && a.modifiers == b.modifiers), "{} is bound twice", a.keys);
        }
    }
}

#[test]
fn middle_drag_orbits_shift_pans_and_the_wheel_zooms() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let center = harness.state().viewport.rect.center();
    let start = harness.state().camera;
    let drag = |harness: &mut Harness<'_, Editor>, modifiers: egui::Modifiers| {
        harness.event(egui::Event::PointerMoved(center));
        harness.run_steps(1);
        harness.event(egui::Event::PointerButton {
            pos: center,
            button: egui::PointerButton::Middle,
            pressed: true,
            modifiers,
        });
        harness.run_steps(1);
        for step in 1..=5 {
            harness.event(egui::Event::PointerMoved(center + egui::vec2(10.0 * step as f32, 4.0 * step as f32)));
            harness.run_steps(1);
        }
        let end = center + egui::vec2(50.0, 20.0);
        harness.event(egui::Event::PointerButton {
            pos: end,
            button: egui::PointerButton::Middle,
            pressed: false,
            modifiers,
        });
        harness.run_steps(2);
    };
    drag(&mut harness, egui::Modifiers::NONE);
    let orbited = harness.state().camera;
    assert!(orbited.yaw_degrees < start.yaw_degrees - 5.0, "{} → {}", start.yaw_degrees, orbited.yaw_degrees);
    assert!(orbited.pitch_degrees > start.pitch_degrees + 2.0);
    assert_eq!(orbited.target, start.target);

    harness.event(egui::Event::ModifiersChanged(egui::Modifiers::SHIFT));
    drag(&mut harness, egui::Modifiers::SHIFT);
    harness.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    let panned = harness.state().camera;
    assert_ne!(panned.target, orbited.target, "shift + middle drag did not pan");
    assert_eq!(panned.yaw_degrees, orbited.yaw_degrees);

    harness.event(egui::Event::PointerMoved(center));
    harness.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Line,
        delta: egui::vec2(0.0, 2.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers: egui::Modifiers::NONE,
    });
    harness.run_steps(2);
    assert!(harness.state().camera.distance < panned.distance * 0.8, "the wheel did not zoom in");

    harness.key_press(egui::Key::Home);
    harness.run_steps(2);
    let framed = harness.state().camera;
    let bounds = harness.state().document.as_ref().unwrap().bounds;
    assert_eq!(framed.target, bounds.center, "Home did not frame the mesh");
}

#[test]
fn frame_under_cursor_centres_on_the_surface() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let center = harness.state().viewport.rect.center();
    let before = harness.state().camera;
    harness.event(egui::Event::PointerMoved(center + egui::vec2(20.0, 10.0)));
    harness.run_steps(1);
    harness.key_press(egui::Key::F);
    harness.run_steps(2);
    let after = harness.state().camera;
    assert_ne!(after.target, before.target, "F did not move the target: {:?}", harness.state().status);
    assert!(after.distance < before.distance);
    // Over empty background nothing moves and the status line says so.
    harness.event(egui::Event::PointerMoved(harness.state().viewport.rect.left_top() + egui::vec2(5.0, 5.0)));
    harness.run_steps(1);
    harness.key_press(egui::Key::F);
    harness.run_steps(2);
    assert_eq!(harness.state().camera, after);
    assert!(harness.state().status.text.contains("Nothing under the cursor"));
}

#[test]
fn file_dialog_opens_and_escape_cancels() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::O);
    harness.run_steps(3);
    assert!(harness.state().dialog.is_some());
    assert!(harness.query_by_label("Up").is_some(), "no file list");
    // Shortcuts are off while the dialog is open (its field has the keyboard).
    harness.key_press(egui::Key::W);
    harness.run_steps(2);
    assert!(!harness.state().view.overlays.wireframe);
    harness.key_press(egui::Key::Escape);
    harness.run_steps(2);
    assert!(harness.state().dialog.is_none());
}

#[test]
fn export_gltf_through_the_dialog_writes_a_glb() {
    let dir = std::env::temp_dir().join(format!("meshpaint_app_ui_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("duck_export.glb");
    let _ = std::fs::remove_file(&out);

    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.get_by_label("Export glTF…").click();
    harness.run_steps(3);
    assert!(harness.state().dialog.is_some(), "no export dialog");
    harness.state_mut().dialog.as_mut().unwrap().file_name = out.display().to_string();
    harness.run_steps(1);
    harness.get_by_label("Export").click();
    harness.run_steps(2);
    assert!(harness.state().dialog.is_none());
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "export timed out");
    harness.run_steps(2);
    let bytes = std::fs::read(&out).expect("no exported file");
    assert_eq!(&bytes[..4], b"glTF");
    assert!(bytes.len() > 100_000, "{} bytes", bytes.len());
    assert_eq!(harness.state().status.severity, Severity::Info, "{:?}", harness.state().status);
    assert!(harness.query_by_label_contains("Exported").is_some(), "status line does not report the export");

    // Save as a packed file, then open it again: same triangles, Save now writes there.
    let project = dir.join("duck.mpk");
    let _ = std::fs::remove_file(&project);
    harness.state_mut().save_to(project.clone(), meshpaint::color::ColorFormat::Rgba16F);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    assert_eq!(harness.state().document.as_ref().unwrap().project_path.as_deref(), Some(project.as_path()));
    harness.state_mut().open(Source::File(project.clone()));
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    let open = harness.state().document.as_ref().unwrap();
    assert_eq!(open.triangles(), 4212);
    assert_eq!(open.format, meshpaint::color::ColorFormat::Rgba16F);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every file below `dir`, sorted.
fn files_below(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            files_below(&path, out);
        } else {
            out.push(path);
        }
    }
    out.sort();
}

#[test]
fn opening_every_invalid_fixture_keeps_the_document_and_shows_the_error() {
    let mut files = Vec::new();
    files_below(&crate_path("tests/fixtures/invalid"), &mut files);
    assert!(files.len() > 100, "expected the invalid fixtures, found {}", files.len());
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let mut refused = 0;
    for file in &files {
        let before = harness.state().document.as_ref().map(|d| Arc::clone(&d.document));
        harness.state_mut().open(Source::File(file.clone()));
        harness.run_steps(1);
        assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "{}: opening timed out", file.display());
        harness.run_steps(2);
        let editor = harness.state();
        let now = editor.document.as_ref().map(|d| Arc::clone(&d.document));
        match editor.status.severity {
            Severity::Error => {
                refused += 1;
                // The document shown before is still there, untouched.
                let (Some(before), Some(now)) = (before, now) else {
                    panic!("{}: the document was lost", file.display());
                };
                assert!(Arc::ptr_eq(&before, &now), "{}: the document changed on error", file.display());
                let name = file.file_name().unwrap().to_string_lossy().to_string();
                assert!(editor.status.text.contains(&name), "error does not name the file: {}", editor.status.text);
                assert!(
                    harness.query_by_label_contains("Could not open").is_some(),
                    "{}: the error is not on screen",
                    file.display()
                );
            }
            // Some fixtures are valid files with odd features: they open like any file.
            Severity::Info | Severity::Warning => {
                let open = editor.document.as_ref().expect("opened without a document");
                assert!(open.triangles() > 0);
                assert_eq!(open.path.as_deref(), Some(file.as_path()));
            }
        }
    }
    assert!(refused > files.len() / 2, "only {refused} of {} refused", files.len());
}

#[test]
fn a_bad_start_up_file_falls_back_to_the_duck_with_the_error_shown() {
    let mut editor = new_editor();
    editor.open(Source::File(crate_path("tests/fixtures/invalid/gltf-validator/glb/invalid_magic.glb")));
    assert!(editor.wait_for_job(JOB_TIMEOUT));
    // The failure started the built-in scene.
    assert!(editor.wait_for_job(JOB_TIMEOUT));
    assert_eq!(editor.document.as_ref().map(|d| d.title.as_str()), Some("Duck (built-in)"));
    assert_eq!(editor.status.severity, Severity::Error);
    assert!(editor.status.text.contains("invalid_magic.glb"), "{}", editor.status.text);
    let mut harness = harness(editor);
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("invalid_magic.glb").is_some());
}

#[test]
fn save_without_a_project_file_asks_for_a_name() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    harness.run_steps(3);
    let dialog = harness.state().dialog.as_ref().expect("Save did not ask for a name");
    assert_eq!(dialog.purpose, meshpaint::app::file_dialog::DialogPurpose::SaveAs);
    assert!(dialog.file_name.ends_with(".mpk"));
}
