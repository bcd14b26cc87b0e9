//! UI logic of the editor without a window: egui_kittest drives `Editor::ui` (panels,
//! shortcuts, help window, file dialog, status line) and the editor's open/save/export
//! paths, with no GPU (the 3D view is covered by tests/editor/app_window.rs under Xvfb).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use meshpaint::app::{Action, Editor, Mode, Severity};
use meshpaint_core::io::document::Source;
use meshpaint_render::{FilterMode, Shading};

use crate::common;
use common::{psnr_over_foreground as psnr, workspace_path};

const JOB_TIMEOUT: Duration = Duration::from_secs(60);

fn new_editor() -> Editor {
    Editor::new(None, Arc::new(|| {}))
}

/// An editor with the built-in Duck open (no GPU).
fn editor_with_duck() -> Editor {
    let mut editor = new_editor();
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(JOB_TIMEOUT), "opening the Duck timed out");
    assert!(editor.document.open.is_some(), "the Duck did not open: {:?}", editor.status);
    editor
}

fn harness(editor: Editor) -> Harness<'static, Editor> {
    Harness::builder().with_size([1280.0, 1600.0]).build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor)
}

#[test]
fn view_panel_changes_the_render_settings() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert!(!harness.state().panels.view.settings.overlays.wireframe);
    harness.get_by_label("Wireframe").click();
    harness.run_steps(2);
    assert!(harness.state().panels.view.settings.overlays.wireframe);
    assert!(harness.state().render_settings().overlays.wireframe);

    harness.get_by_label("Resolution heat map").click();
    harness.run_steps(2);
    assert!(harness.state().render_settings().overlays.heatmap);

    harness.get_by_label("Unlit").click();
    harness.run_steps(2);
    assert_eq!(harness.state().render_settings().shading, Shading::Unlit);
    harness.get_by_label("Flat").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.view.settings.shading, Shading::Lit);
    harness.get_by_label("Smooth").click();
    harness.run_steps(2);
    assert_eq!(harness.state().render_settings().shading, Shading::Smooth);
}

#[test]
fn filter_combo_box_selects_the_filter() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert_eq!(harness.state().panels.view.settings.filter, FilterMode::Trilinear);
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
    assert!(harness.state().panels.view.settings.overlays.wireframe);
    harness.key_press(egui::Key::H);
    harness.run_steps(2);
    assert!(harness.state().panels.view.settings.overlays.heatmap);
    harness.key_press(egui::Key::L);
    harness.run_steps(2);
    assert_eq!(harness.state().panels.view.settings.shading, Shading::Unlit);
    harness.key_press(egui::Key::M);
    harness.run_steps(2);
    assert_eq!(harness.state().panels.view.settings.filter, FilterMode::Nearest);
    // The checkbox shows the state the shortcut set.
    harness.get_by_label("Wireframe").click();
    harness.run_steps(2);
    assert!(!harness.state().panels.view.settings.overlays.wireframe);
}

#[test]
fn f1_opens_the_help_window_listing_every_shortcut() {
    let mut harness = harness(new_editor());
    harness.run_steps(2);
    assert!(harness.query_by_label("Keyboard and mouse").is_none());
    harness.key_press(egui::Key::F1);
    harness.run_steps(3);
    assert!(harness.state().panels.help.open);
    assert!(harness.query_by_label("Keyboard and mouse").is_some(), "no help window");
    for shortcut in meshpaint::app::input::SHORTCUTS {
        // F is listed twice: once per mode.
        assert!(harness.query_all_by_label(shortcut.keys).next().is_some(), "help lacks {}", shortcut.keys);
        assert!(harness.query_by_label(shortcut.description).is_some(), "help lacks {}", shortcut.description);
    }
    for (gesture, _) in meshpaint::app::input::POINTER_HELP {
        assert!(harness.query_by_label(gesture).is_some(), "help lacks {gesture}");
    }
    harness.key_press(egui::Key::F1);
    harness.run_steps(3);
    assert!(harness.query_by_label("Keyboard and mouse").is_none());
}

/// In a window shorter than the help, the help still fits: its title bar (with the close
/// button) is on screen, the lists scroll, and Esc closes it.
#[test]
fn the_help_fits_a_short_window_and_esc_closes_it() {
    let mut harness = Harness::builder()
        .with_size([1000.0, 420.0])
        .build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), new_editor());
    harness.run_steps(2);
    harness.key_press(egui::Key::F1);
    harness.run_steps(3);
    let title = harness.get_by_label("Keyboard and mouse").rect();
    assert!(title.min.y >= 0.0 && title.max.y <= 420.0, "the title bar is off screen: {title:?}");
    let last = meshpaint::app::input::SHORTCUTS.last().unwrap();
    let row = harness.get_by_label(last.description).rect();
    assert!(row.min.y > 420.0, "the test needs a help taller than the window ({row:?})");
    harness.key_press(egui::Key::Escape);
    harness.run_steps(2);
    assert!(!harness.state().panels.help.open);
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
            let same_mode = [Mode::View, Mode::Paint].iter().any(|&m| a.scope.includes(m) && b.scope.includes(m));
            assert!(!(a.key == b.key && a.modifiers == b.modifiers && same_mode), "{} is bound twice", a.keys);
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
    let bounds = harness.state().document.open.as_ref().unwrap().bounds;
    assert_eq!(framed.target, bounds.center, "Home did not frame the mesh");
}

/// The wheel zooms towards the pointer by default: the point of the orbit centre's view
/// plane under the pointer stays under it (forward projection as the truth); with "Zoom to
/// the pointer" off it zooms towards the orbit centre, which stays put.
#[test]
fn the_wheel_zooms_towards_the_pointer_unless_turned_off() {
    for zoom_to_cursor in [true, false] {
        let mut harness = harness(editor_with_duck());
        harness.run_steps(2);
        harness.state_mut().panels.view.settings.zoom_to_cursor = zoom_to_cursor;
        let rect = harness.state().viewport.rect;
        let pointer = rect.min + egui::vec2(rect.width() * 0.25, rect.height() * 0.3);
        let before = harness.state().camera;
        let [x, y] = harness.state().viewport.view_px(pointer);
        let [w, h] = harness.state().viewport.size_px();
        let (origin, direction) = before.ray_through_pixel(x, y, w, h);
        let target = glam::DVec3::from_array(before.target);
        let normal = before.eye_direction();
        let point = origin + direction * ((target - origin).dot(normal) / direction.dot(normal));
        harness.event(egui::Event::PointerMoved(pointer));
        harness.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Line,
            delta: egui::vec2(0.0, 2.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Wheel,
            modifiers: egui::Modifiers::NONE,
        });
        harness.run_steps(2);
        let after = harness.state().camera;
        assert!(after.distance < before.distance * 0.8, "the wheel did not zoom in");
        if zoom_to_cursor {
            let (px, py) = after.project(point, w, h).unwrap();
            assert!((px - x).abs() < 1e-3 && (py - y).abs() < 1e-3, "the point under the pointer moved to {px},{py}");
        } else {
            assert_eq!(after.target, before.target, "zoom towards the orbit centre moved it");
        }
    }
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
    assert!(harness.state().panels.file.dialog.is_some());
    assert!(harness.query_by_label("Up").is_some(), "no file list");
    // Shortcuts are off while the dialog is open (its field has the keyboard).
    harness.key_press(egui::Key::W);
    harness.run_steps(2);
    assert!(!harness.state().panels.view.settings.overlays.wireframe);
    harness.key_press(egui::Key::Escape);
    harness.run_steps(2);
    assert!(harness.state().panels.file.dialog.is_none());
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
    assert!(harness.state().panels.file.dialog.is_some(), "no export dialog");
    harness.state_mut().panels.file.dialog.as_mut().unwrap().file_name = out.display().to_string();
    harness.run_steps(1);
    harness.get_by_label("Export").click();
    harness.run_steps(2);
    assert!(harness.state().panels.file.dialog.is_none());
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
    harness.state_mut().save_to(project.clone(), meshpaint_core::colors::format::ColorFormat::Rgba16F);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    assert_eq!(harness.state().document.open.as_ref().unwrap().project_path.as_deref(), Some(project.as_path()));
    harness.state_mut().open(Source::File(project.clone()));
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    let open = harness.state().document.open.as_ref().unwrap();
    assert_eq!(open.triangles(), 4212);
    assert_eq!(open.format, meshpaint_core::colors::format::ColorFormat::Rgba16F);
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
    files_below(&workspace_path("tests/fixtures/invalid"), &mut files);
    assert!(files.len() > 100, "expected the invalid fixtures, found {}", files.len());
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let mut refused = 0;
    for file in &files {
        let before = harness.state().document.open.as_ref().map(|d| Arc::clone(&d.document));
        harness.state_mut().open(Source::File(file.clone()));
        harness.run_steps(1);
        assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "{}: opening timed out", file.display());
        harness.run_steps(2);
        let editor = harness.state();
        let now = editor.document.open.as_ref().map(|d| Arc::clone(&d.document));
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
                let open = editor.document.open.as_ref().expect("opened without a document");
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
    editor.open(Source::File(workspace_path("tests/fixtures/invalid/gltf-validator/glb/invalid_magic.glb")));
    assert!(editor.wait_for_job(JOB_TIMEOUT));
    // The failure started the built-in scene.
    assert!(editor.wait_for_job(JOB_TIMEOUT));
    assert_eq!(editor.document.open.as_ref().map(|d| d.title.as_str()), Some("Duck (built-in)"));
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
    let dialog = harness.state().panels.file.dialog.as_ref().expect("Save did not ask for a name");
    assert_eq!(dialog.purpose, meshpaint::app::file_dialog::DialogPurpose::SaveAs);
    assert!(dialog.file_name.ends_with(".mpk"));
}

/// A file dropped on the window, as egui-winit hands it over.
#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn dropping_a_file_on_the_window_opens_it() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let box_glb = workspace_path("assets/models/BoxTextured/BoxTextured.glb");
    harness.input_mut().dropped_files.push(Arc::new(Dropped(box_glb.clone())));
    harness.run_steps(1);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(2);
    let open = harness.state().document.open.as_ref().expect("no document");
    assert_eq!(open.path.as_deref(), Some(box_glb.as_path()));
    assert_eq!(open.triangles(), 12);
    assert!(harness.query_by_label_contains("Opened BoxTextured.glb").is_some());
}

/// The Duck's colours, sample by sample (interiors, edges, vertices).
fn colors_of(editor: &Editor) -> Vec<[f32; 4]> {
    let store = &editor.document.open.as_ref().unwrap().document.store;
    let mut out = Vec::new();
    store.for_each_site(|site| out.push(store.get(site.sample).unwrap()));
    out
}

/// Drags with the left button from `from` to `to` over the 3D view, in a few steps.
pub(crate) fn left_drag(harness: &mut Harness<'static, Editor>, from: egui::Pos2, to: egui::Pos2) {
    harness.event(egui::Event::PointerMoved(from));
    harness.run_steps(1);
    let button = |pos, pressed| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: egui::Modifiers::NONE,
    };
    harness.event(button(from, true));
    harness.run_steps(1);
    for step in 1..=5 {
        harness.event(egui::Event::PointerMoved(from + (to - from) * (step as f32 / 5.0)));
        harness.run_steps(1);
    }
    harness.event(button(to, false));
    harness.run_steps(2);
}

#[test]
fn tab_toggles_paint_mode_and_leaving_repacks() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), Mode::View);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), Mode::Paint, "{:?}", harness.state().status);
    assert!(harness.state().document.paint.is_some());
    assert!(harness.query_by_label("Paint mode").is_some(), "the mode is not shown");
    // The paint layout has level 0 only: trilinear becomes linear.
    assert_eq!(harness.state().panels.view.settings.filter, FilterMode::Trilinear);
    assert_eq!(harness.state().render_settings().filter, FilterMode::Linear);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), Mode::View);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(2);
    assert!(harness.state().status.text.contains("Left paint mode"), "{:?}", harness.state().status);
    assert_eq!(harness.state().render_settings().filter, FilterMode::Trilinear);
    assert!(harness.query_by_label("View mode").is_some());
}

#[test]
fn paint_panel_changes_the_brush_settings() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert!(!harness.state().panels.paint.brush.mirror_x);
    harness.get_by_label("X mirror").click();
    harness.run_steps(2);
    assert!(harness.state().panels.paint.brush.mirror_x);
    harness.get_by_label("Occlusion").click();
    harness.run_steps(2);
    assert!(!harness.state().panels.paint.brush.occlusion);
    harness.get_by_label("Blur").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush.tool, meshpaint_core::paint::brush::Tool::Blur);
    harness.get_by_label("Colour").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush.tool, meshpaint_core::paint::brush::Tool::Paint);
    harness.get_by_value("Mix").click();
    harness.run_steps(2);
    harness.get_by_label("Erase to base").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush.blend, meshpaint_core::paint::brush::BlendMode::EraseToBase);
    harness.get_by_label("world").click();
    harness.run_steps(2);
    assert!(matches!(
        harness.state().panels.paint.brush.radius,
        meshpaint_core::paint::brush::BrushRadius::World { .. }
    ));
}

#[test]
fn a_stroke_paints_and_undo_redo_buttons_and_keys_revert_it() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let original = colors_of(harness.state());
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    let center = harness.state().viewport.rect.center();
    left_drag(&mut harness, center - egui::vec2(60.0, 0.0), center + egui::vec2(60.0, 0.0));
    let painted = colors_of(harness.state());
    let changed = original.iter().zip(&painted).filter(|(a, b)| a != b).count();
    assert!(changed > 100, "the stroke changed {changed} samples: {:?}", harness.state().status);
    assert_eq!(harness.state().document.history.undo_len(), 1);
    assert!(harness.state().document.history.bytes_used() > 0);
    assert!(harness.query_by_label_contains("Undo: 1 steps").is_some(), "undo memory is not shown");

    harness.get_by_label("Undo").click();
    harness.run_steps(2);
    assert_eq!(colors_of(harness.state()), original, "undo did not restore the colours");
    harness.get_by_label("Redo").click();
    harness.run_steps(2);
    assert_eq!(colors_of(harness.state()), painted, "redo did not repaint");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(colors_of(harness.state()), original, "Ctrl+Z did not undo");
    harness.key_press_modifiers(egui::Modifiers::COMMAND | egui::Modifiers::SHIFT, egui::Key::Z);
    harness.run_steps(2);
    assert_eq!(colors_of(harness.state()), painted, "Ctrl+Shift+Z did not redo");
}

#[test]
fn f_and_shift_f_set_radius_and_strength_interactively() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    let center = harness.state().viewport.rect.center();
    harness.event(egui::Event::PointerMoved(center));
    harness.run_steps(1);
    let before = harness.state().panels.paint.brush;
    // F: the radius follows the pointer; Enter confirms.
    harness.key_press(egui::Key::F);
    harness.run_steps(1);
    harness.event(egui::Event::PointerMoved(center + egui::vec2(50.0, 0.0)));
    harness.run_steps(1);
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
    let meshpaint_core::paint::brush::BrushRadius::Pixels { radius_px } = harness.state().panels.paint.brush.radius
    else {
        panic!("the radius is not in pixels");
    };
    assert!((radius_px - 80.0).abs() < 1.0, "radius {radius_px} px after moving 50 px out from 30 px");
    assert_eq!(harness.state().camera, {
        let editor = harness.state();
        editor.camera
    });
    // Shift+F then Esc: the strength comes back.
    harness.key_press_modifiers(egui::Modifiers::SHIFT, egui::Key::F);
    harness.run_steps(1);
    harness.event(egui::Event::PointerMoved(center - egui::vec2(100.0, 0.0)));
    harness.run_steps(1);
    assert!(harness.state().panels.paint.brush.strength < before.strength);
    harness.key_press(egui::Key::Escape);
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush.strength, before.strength);
    assert!(harness.state().document.paint.as_ref().unwrap().gesture.is_none());
}

/// The Duck in paint mode after one stroke of the resolution brush across the view's middle.
fn duck_after_a_resolution_stroke() -> Harness<'static, Editor> {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    harness.get_by_label("Resolution").click();
    harness.run_steps(2);
    assert!(matches!(harness.state().panels.paint.brush.tool, meshpaint_core::paint::brush::Tool::Resolution(_)));
    let center = harness.state().viewport.rect.center();
    left_drag(&mut harness, center - egui::vec2(30.0, 0.0), center + egui::vec2(30.0, 0.0));
    let status = &harness.state().status.text;
    assert!(status.contains("resolution changed on") && !status.contains(" 0 "), "{status}");
    harness
}

#[test]
fn resolution_brush_and_set_r_for_all_change_face_resolutions() {
    let mut harness = duck_after_a_resolution_stroke();
    let resolutions =
        |editor: &Editor| editor.document.open.as_ref().unwrap().document.store.face_resolutions().to_vec();
    let raised = resolutions(harness.state()).iter().filter(|r| r.get() == 16).count();
    assert!(raised > 0, "the resolution brush raised no face: {:?}", harness.state().status);
    harness.get_by_label("Set R for all").click();
    harness.run_steps(2);
    assert!(resolutions(harness.state()).iter().all(|r| r.get() == 8), "{:?}", harness.state().status);
    harness.get_by_label("Undo").click();
    harness.run_steps(2);
    assert_eq!(resolutions(harness.state()).iter().filter(|r| r.get() == 16).count(), raised);
}

/// Leaving paint mode after a resolution stroke lays the packing out anew (moving the
/// chains the stroke did not reach): the packing the view's buffers are uploaded from is a
/// full pack's.
#[test]
fn leaving_paint_mode_after_a_resolution_stroke_gives_the_full_pack() {
    let mut harness = duck_after_a_resolution_stroke();
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(2);
    // The relayout ran (not a full repack after all), and gave a full pack's buffers.
    let open = harness.state().document.open.as_ref().unwrap();
    assert_eq!(open.last_repack_how, Some(meshpaint::app::paint_session::Repack::Relayout));
    let store = &open.document.store;
    assert!(store.face_resolutions().iter().any(|r| r.get() == 16), "the stroke raised no face");
    let full = meshpaint_core::packing::pack(store, &open.document.positions, open.format).unwrap();
    assert!(*open.pack_cache.as_ref().unwrap().packed() == full, "the repacked buffers differ from a full pack");
}

/// The Optimize button (E = 0): fewer samples, every shown colour kept (CPU reference
/// sampler at random points), the memory in the status line, one undo step back.
#[test]
fn optimize_button_lowers_resolutions_losslessly_and_undoes() {
    use meshpaint_core::packing::sampler::{Filter, sample};
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    let store = |editor: &Editor| editor.document.open.as_ref().unwrap().document.store.clone();
    let before = store(harness.state());
    harness.get_by_label("Optimize").click();
    harness.run_steps(2);
    // Optimize plans on a worker thread; its result is applied when the job is noticed.
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "Optimize timed out");
    harness.run_steps(2);
    let after = store(harness.state());
    let status = format!("{:?}", harness.state().status);
    assert!(after.sample_count() * 2 < before.sample_count(), "{status}");
    assert!(status.contains("Optimize") && status.contains("samples") && status.contains("B"), "{status}");
    let mut seed = 0x5eedu64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    for face in 0..before.topology().face_count() {
        let (mut u, mut v) = (next(), next());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let bary = [1.0 - u - v, u, v];
        let (a, b) = (
            sample(&before, face, bary, Filter::Linear, 0).unwrap(),
            sample(&after, face, bary, Filter::Linear, 0).unwrap(),
        );
        assert!((0..4).all(|c| (a[c] - b[c]).abs() <= 2e-6), "face {face}: {a:?} → {b:?}");
    }
    harness.get_by_label("Undo").click();
    harness.run_steps(2);
    assert_eq!(store(harness.state()).face_resolutions(), before.face_resolutions());
    assert_eq!(store(harness.state()).sample_count(), before.sample_count());
}

/// The Duck opened within a memory budget of `bytes`, in paint mode.
fn duck_painting_within(bytes: u64) -> Harness<'static, Editor> {
    let mut editor = new_editor();
    editor.budget_override = Some(meshpaint_core::colors::budget::Budget::with_memory(
        bytes,
        meshpaint_core::colors::budget::MemorySource::Set,
    ));
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(JOB_TIMEOUT), "opening the Duck timed out");
    assert!(editor.document.open.is_some(), "the Duck did not open: {:?}", editor.status);
    let mut harness = harness(editor);
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    assert_eq!(harness.state().mode(), Mode::Paint);
    harness
}

#[test]
fn set_r_for_all_past_the_budget_is_refused_and_the_document_stays_valid() {
    // 100 MB holds the Duck at R = 8 and 16 (about 11 and 37 MB estimated), not at R = 64.
    let mut harness = duck_painting_within(100_000_000);
    let resolutions =
        |editor: &Editor| editor.document.open.as_ref().unwrap().document.store.face_resolutions().to_vec();
    let before = resolutions(harness.state());
    harness.state_mut().panels.paint.resolution_for_all = meshpaint_core::colors::layout::Resolution::new(64).unwrap();
    harness.get_by_label("Set R for all").click();
    harness.run_steps(2);
    let status = harness.state().status.clone();
    assert_eq!(status.severity, Severity::Error, "{status:?}");
    assert!(status.text.contains("R = 64 on every face") && status.text.contains("of memory"), "{status:?}");
    assert_eq!(resolutions(harness.state()), before, "nothing changed");
    assert_eq!(harness.state().document.history.undo_len(), 0, "no step recorded");
    // R = 16 fits; the document still saves and reopens.
    harness.state_mut().panels.paint.resolution_for_all = meshpaint_core::colors::layout::Resolution::new(16).unwrap();
    harness.get_by_label("Set R for all").click();
    harness.run_steps(2);
    assert!(resolutions(harness.state()).iter().all(|r| r.get() == 16), "{:?}", harness.state().status);
    let file = common::TempFile::new("app_ui_budget", "duck16.mpk");
    let document = harness.state().document.open.as_ref().unwrap().document.clone();
    let packed = document.pack(meshpaint_core::colors::format::ColorFormat::Rgba8Srgb).unwrap();
    meshpaint_core::packing::file::write_file(file.path(), &packed).unwrap();
    let reopened =
        meshpaint_core::io::document::Document::open(file.path(), meshpaint_core::colors::layout::Resolution::ONE)
            .unwrap();
    assert_eq!(reopened.store.face_resolutions(), document.store.face_resolutions());
}

#[test]
fn the_resolution_brush_stops_at_the_budget_with_one_message() {
    // Just above the Duck at R = 8 (about 11.1 MB estimated): room for a few raised faces.
    let mut harness = duck_painting_within(11_136_784 + 100_000);
    harness.get_by_label("Resolution").click();
    harness.run_steps(2);
    let center = harness.state().viewport.rect.center();
    left_drag(&mut harness, center - egui::vec2(60.0, 0.0), center + egui::vec2(60.0, 0.0));
    let editor = harness.state();
    let raised = editor
        .document
        .open
        .as_ref()
        .unwrap()
        .document
        .store
        .face_resolutions()
        .iter()
        .filter(|r| r.get() == 16)
        .count();
    assert!(raised > 0, "some faces fit: {:?}", editor.status);
    assert_eq!(editor.status.severity, Severity::Error, "{:?}", editor.status);
    assert!(
        editor.status.text.contains("raising face") && editor.status.text.contains("of memory"),
        "{:?}",
        editor.status
    );
    let store = &editor.document.open.as_ref().unwrap().document.store;
    let counts = meshpaint_core::colors::budget::SampleCounts::of_store(store);
    assert!(counts.estimated_bytes(meshpaint_core::colors::format::ColorFormat::Rgba8Srgb) <= 11_136_784 + 100_000);
}

/// Opens `path` with the editor's current import settings and waits for it.
fn open_and_wait(editor: &mut Editor, path: &Path) {
    editor.open(Source::File(path.to_owned()));
    assert!(editor.wait_for_job(JOB_TIMEOUT), "opening {} timed out", path.display());
    assert!(editor.document.open.is_some(), "{} did not open: {:?}", path.display(), editor.status);
}

/// The open dialog's resolution choice reaches the document: "Automatic" keeps R on the
/// textured Duck and starts an untextured STL at R = 1 with resolution following the brush;
/// "Error ≤ E" gives the Duck exactly the per-face resolutions of the library's rule, and so
/// do "Match texture" and "Samples ≤ N" (the budget, on BoxTextured).
#[test]
fn the_open_dialog_offers_uniform_match_texture_error_bound_and_budget_resolutions() {
    use meshpaint::app::import_settings::ImportMode;
    use meshpaint_core::colors::budget::Budget;
    use meshpaint_core::convert::adaptive::ResolutionRule;
    use meshpaint_core::io::document::Document;
    let duck = workspace_path("assets/models/Duck/Duck.glb");
    let stl = workspace_path("assets/models/AssimpTestModels/sphereWithHole.stl");
    let mut harness = harness(new_editor());
    harness.run_steps(2);
    harness.state_mut().open_dialog(meshpaint::app::file_dialog::DialogPurpose::Open);
    harness.run_steps(2);
    // The dialog shows the choice; picking a mode there is what the editor opens with.
    harness.get_by_label("Mesh resolution:").click();
    harness.run_steps(2);
    harness.get_by_label("Error ≤ E").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.import.mode, ImportMode::ErrorBound, "the dialog's choice is the editor's");
    harness.state_mut().panels.file.dialog = None;

    let resolutions =
        |editor: &Editor| editor.document.open.as_ref().unwrap().document.store.face_resolutions().to_vec();
    let editor = harness.state_mut();
    editor.panels.import.error_bound = 0.02;
    open_and_wait(editor, &duck);
    let rule = ResolutionRule::ErrorBound { bound: 0.02, max: editor.panels.import.max_resolution };
    let expected = Document::open_within(&duck, rule, &Budget::from_environment()).unwrap();
    assert_eq!(resolutions(editor), expected.store.face_resolutions(), "the rule's resolutions, face by face");
    assert!(resolutions(editor).iter().any(|r| r.get() != resolutions(editor)[0].get()), "not uniform");

    editor.panels.import.mode = ImportMode::Automatic;
    open_and_wait(editor, &duck);
    assert!(resolutions(editor).iter().all(|r| r.get() == 8), "the textured Duck keeps R = 8");
    assert_eq!(editor.panels.paint.brush.follow_resolution, None, "textured: resolution does not follow the brush");
    open_and_wait(editor, &stl);
    assert!(resolutions(editor).iter().all(|r| r.get() == 1), "untextured: the lowest R");
    assert!(editor.panels.paint.brush.follow_resolution.is_some(), "untextured: resolution follows the brush");

    editor.panels.import.mode = ImportMode::Uniform;
    editor.panels.import.resolution = meshpaint_core::colors::layout::Resolution::new(4).unwrap();
    open_and_wait(editor, &stl);
    assert!(resolutions(editor).iter().all(|r| r.get() == 4), "uniform R is uniform, textured or not");

    editor.panels.import.mode = ImportMode::MatchTexture;
    open_and_wait(editor, &duck);
    let rule = ResolutionRule::TexelDensity { max: editor.panels.import.max_resolution };
    let expected = Document::open_within(&duck, rule, &Budget::from_environment()).unwrap();
    assert_eq!(resolutions(editor), expected.store.face_resolutions());

    // "Samples ≤ N": the budget rule's resolutions, within N (BoxTextured: 12 faces, fast).
    let box_textured = workspace_path("assets/models/BoxTextured/BoxTextured.glb");
    editor.panels.import.mode = ImportMode::Budget;
    editor.panels.import.sample_budget = 600;
    open_and_wait(editor, &box_textured);
    let rule = ResolutionRule::Budget { samples: 600, max: editor.panels.import.max_resolution };
    let expected = Document::open_within(&box_textured, rule, &Budget::from_environment()).unwrap();
    assert_eq!(resolutions(editor), expected.store.face_resolutions());
    let samples = editor.document.open.as_ref().unwrap().document.store.sample_count();
    assert!(samples <= 600 && samples > 386, "{samples} samples: within N, more than uniform R = 8's 386");
}

/// An editor with a headless GPU (lavapipe) and the built-in Duck.
fn editor_with_gpu_and_duck() -> Editor {
    let gpu = meshpaint_render::Gpu::new_headless().expect("GPU tests need an adapter (lavapipe)");
    let mut editor = Editor::new(Some(Arc::new(gpu)), Arc::new(|| {}));
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(JOB_TIMEOUT), "opening the Duck timed out");
    assert!(editor.document.open.is_some(), "the Duck did not open: {:?}", editor.status);
    editor
}

/// "Show: Source texture" draws the UV-textured source and reports the PSNR of this view
/// (the Duck at R = 8 looks like its texture: tests/app/gpu_render.rs measures a mean below 1
/// step at R = 16); "Position colours" draws a colour field, never the document's colours.
#[test]
fn the_view_compares_mesh_colors_with_the_source_texture_and_shows_the_psnr() {
    use meshpaint_render::DrawItem;
    let mut harness = harness(editor_with_gpu_and_duck());
    harness.run_steps(2);
    assert!(matches!(harness.state().shown_item(), Some(DrawItem::MeshColors(_))));
    harness.get_by_label("Show:").click();
    harness.run_steps(2);
    harness.get_by_label("Source texture").click();
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "building the source texture timed out");
    harness.run_steps(3);
    assert!(matches!(harness.state().shown_item(), Some(DrawItem::Baseline(_))), "{:?}", harness.state().status);
    let psnr = match &harness.state().panels.view.source_psnr {
        Some((_, Ok(db))) => *db,
        other => panic!("no PSNR measured: {other:?}"),
    };
    assert!(psnr > 25.0 && psnr.is_finite(), "Duck R = 8 vs its texture: {psnr} dB");
    harness.get_by_label_contains("PSNR");
    let colors_before = harness.state().document.open.as_ref().unwrap().document.store.clone();
    harness.get_by_label("Show:").click();
    harness.run_steps(2);
    harness.get_by_label("Position colours").click();
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "building the position colours timed out");
    harness.run_steps(2);
    let editor = harness.state();
    let open = editor.document.open.as_ref().unwrap();
    match (editor.shown_item(), open.gpu_mesh.as_ref()) {
        (Some(DrawItem::MeshColors(shown)), Some(own)) => assert!(!std::ptr::eq(shown, own), "a separate mesh"),
        _ => panic!("position colours are not shown"),
    }
    let colors_after = &open.document.store;
    assert_eq!(colors_after.sample_count(), colors_before.sample_count());
    assert!(
        (0..colors_after.topology().face_count())
            .all(|f| colors_after.interior_samples(f) == colors_before.interior_samples(f)),
        "a view option never changes the document's colours"
    );
}

/// A file without a texture cannot be compared: the view says why and keeps the mesh colors.
#[test]
fn comparing_an_untextured_mesh_says_why_and_shows_the_mesh_colors() {
    use meshpaint_render::DrawItem;
    let mut editor = editor_with_gpu_and_duck();
    open_and_wait(&mut editor, &workspace_path("assets/models/AssimpTestModels/sphereWithHole.stl"));
    let mut harness = harness(editor);
    harness.run_steps(2);
    harness.state_mut().panels.view.settings.shown = meshpaint::app::state::Shown::SourceTexture;
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(2);
    assert!(matches!(harness.state().shown_item(), Some(DrawItem::MeshColors(_))));
    assert!(harness.get_all_by_label_contains("no base-colour texture").count() >= 1);
}

/// "Representation: Mesh Color Textures" builds the texture from the packed mesh and draws it,
/// with its cost and its PSNR against the mesh colors' own filter in this view (the Duck at
/// R = 8: MCT's bilinear differs from mesh colors' piecewise-linear filter inside faces
/// only — docs/MCT.md); paint mode draws mesh colors, and leaving it builds the texture again
/// from the repacked colours. T switches on to the packed Ptex, the Htex, then back to mesh
/// colors.
#[test]
fn the_view_switches_to_mesh_color_textures_and_back_live() {
    use meshpaint::app::state::Representation;
    use meshpaint_render::DrawItem;
    // Tall enough that the view panel's last rows are on screen without scrolling.
    let mut harness = Harness::builder()
        .with_size([1280.0, 1700.0])
        .build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor_with_gpu_and_duck());
    harness.run_steps(2);
    harness.get_by_label("Representation:").click();
    harness.run_steps(2);
    harness.get_by_label(Representation::MeshColorTexture.name()).click();
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "building the Mesh Color Texture timed out");
    harness.run_steps(3);
    let first_atlas = match harness.state().shown_item() {
        Some(DrawItem::Mct(mct)) => mct.atlas_size,
        _ => panic!("the Mesh Color Texture is not shown: {:?}", harness.state().status),
    };
    harness.get_by_label_contains("the mesh colors' buffers");
    let psnr = match &harness.state().panels.view.mct_psnr {
        Some((_, Ok(db))) => *db,
        other => panic!("no PSNR measured: {other:?}"),
    };
    assert!(psnr >= 35.0, "Duck R = 8, MCT vs mesh colors in the default view: {psnr} dB");
    assert!(harness.state().gpu_bytes() > harness.state().document.open.as_ref().unwrap().packed_bytes);

    // Paint mode draws the paint layout; a stroke, then leaving repacks and rebuilds.
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    assert!(matches!(harness.state().shown_item(), Some(DrawItem::MeshColors(_))), "paint mode draws mesh colors");
    let rect = harness.state().viewport.rect;
    left_drag(&mut harness, rect.center() - egui::vec2(30.0, 0.0), rect.center() + egui::vec2(30.0, 10.0));
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    for _ in 0..3 {
        assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "repack or rebuild timed out");
        harness.run_steps(2);
    }
    let open = harness.state().document.open.as_ref().unwrap();
    assert!(open.mesh_generation >= 2, "entering and leaving paint mode changed the GPU mesh");
    match harness.state().shown_item() {
        Some(DrawItem::Mct(mct)) => assert_eq!(mct.atlas_size, first_atlas, "same resolutions, same layout"),
        _ => panic!("the texture was not rebuilt after paint mode: {:?}", harness.state().status),
    }
    // T switches on to the packed Ptex (built on a job, its cost shown).
    harness.key_press(egui::Key::T);
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "building the packed Ptex timed out");
    harness.run_steps(3);
    assert!(
        matches!(harness.state().shown_item(), Some(DrawItem::Ptex(_))),
        "the packed Ptex is not shown: {:?}",
        harness.state().status
    );
    harness.get_by_label_contains("the mesh colors' buffers");
    // T switches on to the Htex (built on a job, its cost shown), then back to mesh colors.
    harness.key_press(egui::Key::T);
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "building the Htex timed out");
    harness.run_steps(3);
    assert!(
        matches!(harness.state().shown_item(), Some(DrawItem::Htex(_))),
        "the Htex is not shown: {:?}",
        harness.state().status
    );
    harness.get_by_label_contains("page(s) of");
    harness.key_press(egui::Key::T);
    harness.run_steps(2);
    assert!(matches!(harness.state().shown_item(), Some(DrawItem::MeshColors(_))));
}

/// The prompt's button `label` (the File panel has a "Save" too; the prompt is drawn last).
fn prompt_button<'a>(harness: &'a Harness<'static, Editor>, label: &'a str) -> egui_kittest::Node<'a> {
    harness.get_all_by_label(label).last().expect("no such button")
}

/// A painted Duck in paint mode: one stroke, unsaved.
fn duck_with_a_stroke() -> Harness<'static, Editor> {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert_eq!(harness.state().window_title(), "Duck (built-in) — meshpaint", "just opened: not modified");
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    let center = harness.state().viewport.rect.center();
    left_drag(&mut harness, center - egui::vec2(60.0, 0.0), center + egui::vec2(60.0, 0.0));
    assert_eq!(harness.state().document.history.undo_len(), 1);
    assert!(harness.state().window_title().starts_with('*'), "{}", harness.state().window_title());
    harness
}

/// Opening another file (dialog or drop) or quitting (Ctrl+Q, menu, window close — the
/// window sends Action::Quit) with a stroke unsaved asks first: Cancel keeps the document,
/// its colours and undo history; Don't save carries on.
#[test]
fn open_drop_and_quit_ask_before_losing_unsaved_work() {
    let mut harness = duck_with_a_stroke();
    let painted = colors_of(harness.state());
    let box_glb = workspace_path("assets/models/BoxTextured/BoxTextured.glb");
    type Start<'a> = Box<dyn Fn(&mut Harness<'static, Editor>) + 'a>;
    let replacing: [(&str, Start<'_>); 3] = [
        ("open", Box::new(|h| h.state_mut().apply(meshpaint::app::Command::Open(box_glb.clone())))),
        ("drop", Box::new(|h| h.input_mut().dropped_files.push(Arc::new(Dropped(box_glb.clone()))))),
        ("quit", Box::new(|h| h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q))),
    ];
    for (what, start) in &replacing {
        start(&mut harness);
        harness.run_steps(2);
        assert!(harness.query_by_label_contains("Save changes to Duck").is_some(), "{what}: no prompt");
        harness.get_by_label("Cancel").click();
        harness.run_steps(2);
        assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
        harness.run_steps(1);
        let editor = harness.state();
        assert!(!editor.quit_requested, "{what}: cancelled, yet quitting");
        assert_eq!(editor.document.open.as_ref().unwrap().title, "Duck (built-in)", "{what}: cancelled, yet replaced");
        assert_eq!(colors_of(editor), painted, "{what}: the colours changed");
        assert_eq!(editor.document.history.undo_len(), 1, "{what}: the undo history was lost");
        assert!(harness.query_by_label_contains("Save changes to").is_none(), "{what}: the prompt stayed");
    }
    // Esc cancels too.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    harness.run_steps(2);
    harness.key_press(egui::Key::Escape);
    harness.run_steps(2);
    assert!(!harness.state().quit_requested && harness.query_by_label_contains("Save changes to").is_none());
    // Don't save: the drop opens the box; then nothing is unsaved and quitting asks nothing.
    harness.input_mut().dropped_files.push(Arc::new(Dropped(box_glb.clone())));
    harness.run_steps(2);
    harness.get_by_label("Don't save").click();
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(2);
    assert_eq!(harness.state().document.open.as_ref().unwrap().triangles(), 12);
    assert!(!harness.state().document.is_modified());
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    harness.run_steps(2);
    assert!(harness.state().quit_requested, "nothing unsaved: quit at once");
}

/// "Save" in the prompt saves (asking for a name: a glTF has no project file yet) and only
/// then carries on; the title's modified mark goes with the save and comes back with the
/// next stroke. Cancelling the name dialog cancels the quit.
#[test]
fn save_in_the_prompt_saves_then_quits_and_the_title_follows() {
    let dir = std::env::temp_dir().join(format!("meshpaint_unsaved_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut harness = duck_with_a_stroke();
    // Save, then Esc in the name dialog: no save, no quit.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    harness.run_steps(2);
    prompt_button(&harness, "Save").click();
    harness.run_steps(2);
    assert!(harness.state().panels.file.dialog.is_some(), "no project file yet: the name is asked");
    assert!(harness.state().panels.file.dialog.as_ref().unwrap().file_name.ends_with(".mpk"));
    harness.state_mut().panels.file.dialog = None; // the dialog closed without a name
    harness.run_steps(2);
    assert!(!harness.state().quit_requested);
    assert!(harness.state().status.text.contains("Not quitting"), "{:?}", harness.state().status);
    // Save with a name: saved first, then quit.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    harness.run_steps(2);
    prompt_button(&harness, "Save").click();
    harness.run_steps(2);
    let path = dir.join("saved duck.mpk");
    let format = meshpaint_core::colors::format::ColorFormat::Rgba8Srgb;
    harness.state_mut().panels.file.dialog = None;
    harness.state_mut().apply(meshpaint::app::Command::Write(
        path.clone(),
        format,
        meshpaint::app::jobs::WriteKind::Save,
    ));
    harness.run_steps(1);
    assert!(!harness.state().quit_requested, "not before the save has finished");
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(1);
    assert!(path.is_file(), "not saved");
    assert!(harness.state().quit_requested, "saved: the quit carries on");
    assert_eq!(harness.state().window_title(), "saved duck.mpk — meshpaint");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The recovery prompt says when the file was written (ago, and the UTC time: 1796653800 s
/// after the epoch is 2026-12-07 14:30:00 UTC) and what it holds, from its header.
#[test]
fn the_recovery_prompt_says_when_and_what() {
    use meshpaint::app::panels::autosave::describe_recovery;
    use meshpaint_core::io::autosave::RecoveryInfo;
    use meshpaint_core::packing::file::PackedSummary;
    use std::time::{Duration, UNIX_EPOCH};
    let written = UNIX_EPOCH + Duration::from_secs(1_796_653_800);
    let holds = PackedSummary { face_count: 4212, vertex_count: 2108, sample_count: 154_176, file_size: 2_500_000 };
    let info = RecoveryInfo {
        path: "duck.recovery.mpk".into(),
        modified: Some(written),
        newer_than_document: true,
        holds: Some(holds),
    };
    let text = describe_recovery(&info, written + Duration::from_secs(5 * 60 + 10));
    assert!(text.starts_with("Written 5 min ago (14:30 UTC): 4,212 triangles, 154,176 samples,"), "{text}");
    let text = describe_recovery(&info, written + Duration::from_secs(3 * 86_400));
    assert!(text.starts_with("Written 3 days ago"), "{text}");
    let unknown = RecoveryInfo { modified: None, holds: None, ..info };
    assert_eq!(
        describe_recovery(&unknown, written),
        "Written at an unknown time; its header cannot be read (restoring will say why)."
    );
}

/// Resolution follows the brush for an untextured mesh (R grows where it is painted), never
/// silently for a project: a packed file opens with the resolutions it was saved with.
#[test]
fn opening_a_project_leaves_resolution_following_off() {
    let dir = std::env::temp_dir().join(format!("meshpaint_follow_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut editor = new_editor();
    open_and_wait(&mut editor, &workspace_path("assets/models/AssimpTestModels/sphereWithHole.stl"));
    assert!(editor.panels.paint.brush.follow_resolution.is_some(), "an untextured mesh follows the brush");
    let path = dir.join("sphere.mpk");
    editor.save_to(path.clone(), meshpaint_core::colors::format::ColorFormat::Rgba8Srgb);
    assert!(editor.wait_for_job(JOB_TIMEOUT) && path.is_file(), "{:?}", editor.status);
    open_and_wait(&mut editor, &path);
    assert_eq!(editor.document.open.as_ref().unwrap().path.as_deref(), Some(path.as_path()));
    assert!(editor.panels.paint.brush.follow_resolution.is_none(), "a project opened with following on");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Stroke messages say what changed in plain words: a stroke that misses the mesh changes
/// nothing (and is no undo step), a resolution stroke names its faces.
#[test]
fn stroke_messages_say_what_changed() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    // A stroke in the view's empty corner, off the Duck.
    let corner = harness.state().viewport.rect.min + egui::vec2(15.0, 15.0);
    left_drag(&mut harness, corner, corner + egui::vec2(20.0, 0.0));
    let status = harness.state().status.text.clone();
    assert!(status.contains("nothing changed") && !status.contains("undo memory"), "{status}");
    assert_eq!(harness.state().document.history.undo_len(), 0);
    let center = harness.state().viewport.rect.center();
    left_drag(&mut harness, center - egui::vec2(40.0, 0.0), center + egui::vec2(40.0, 0.0));
    let status = harness.state().status.text.clone();
    assert!(status.starts_with("Paint stroke: ") && status.contains("samples changed"), "{status}");
}

/// Paints the Duck's +X half with the core brush API: dabs of three colours centred on every
/// 16th vertex right of the mirror plane (no occlusion, so each dab's sphere paints through).
fn paint_one_half(editor: &mut Editor) {
    use meshpaint_core::paint::brush::{BrushSettings, PaintView, Painter, Tool};
    let camera = editor.camera;
    let open = editor.document.open.as_mut().unwrap();
    let radius = open.bounds.radius * 0.12;
    let document = Arc::make_mut(&mut open.document);
    let positions = document.positions.clone();
    let mut painter = Painter::new(&positions);
    let plane = painter.mirror_plane_x();
    let mut history = meshpaint_core::paint::undo::UndoHistory::default();
    let view =
        PaintView { positions: &positions, bvh: &open.bvh, camera: &camera, viewport_px: [512, 512], base: None };
    let colors = [[0.9, 0.05, 0.05, 1.0], [0.05, 0.6, 0.1, 1.0], [0.1, 0.1, 0.9, 1.0]];
    let right: Vec<&[f32; 3]> = positions.iter().filter(|p| f64::from(p[0]) > plane + radius).collect();
    for (k, p) in right.iter().step_by(16).enumerate() {
        painter.set_settings(BrushSettings {
            tool: Tool::Paint,
            color: colors[k % 3],
            strength: 1.0,
            occlusion: false,
            backface_culling: false,
            mirror_x: false,
            ..BrushSettings::default()
        });
        let center = glam::DVec3::from_array(p.map(f64::from));
        painter.dab_at(&view, &mut document.store, &mut history, center, radius).unwrap();
    }
    editor.document.edit_generation += 1;
}

/// Drives File → Export… to a baked-texture glTF with `uvs` ("Automatic UVs", "New UVs" or
/// "Model's own UVs") into `out`; returns the automatic choice the dialog showed.
fn export_baked_from_the_menu(harness: &mut Harness<'static, Editor>, uvs: &str, out: &Path) -> String {
    // The menu bar's "File" (drawn before the side panel's "File" section).
    harness.get_all_by_label("File").next().unwrap().click();
    harness.run_steps(2);
    // The menu's entry (the File panel has an "Export…" button too; the menu is drawn last).
    harness.get_all_by_label("Export…").last().unwrap().click();
    harness.run_steps(2);
    assert!(harness.state().panels.export.open, "no export dialog");
    harness.get_by_label("Baked-texture glTF (.glb) — for any engine").click();
    harness.get_by_label(uvs).click();
    harness.run_steps(2);
    // The automatic choice is checked on a job; its reason is shown when it is back.
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "UV check timed out");
    harness.run_steps(2);
    let checked = harness.state().panels.export.uv_check.clone();
    let line = match checked {
        Some((_, Ok(choice))) => format!("Automatic: {}.", choice.reason()),
        _ => String::new(),
    };
    if uvs == "Automatic UVs" {
        assert!(harness.query_by_label(&line).is_some(), "the dialog does not show “{line}”");
    }
    assert!(harness.query_by_label_contains("Cost: about").is_some(), "no cost shown");
    harness.state_mut().panels.export.path = out.display().to_string();
    harness.run_steps(1);
    harness.get_by_label("Export").click();
    harness.run_steps(2);
    assert!(!harness.state().panels.export.open);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT), "export timed out");
    harness.run_steps(2);
    assert_eq!(harness.state().status.severity, Severity::Info, "{:?}", harness.state().status);
    assert!(harness.state().status.text.starts_with("Exported"), "{:?}", harness.state().status);
    line
}

/// The test: the Duck painted on one side, exported from File → Export… as a baked
/// glTF. Its own UVs overlap (mirrored halves), so the automatic choice generates new ones
/// and says why; rendered through the UV baseline (`render --baseline-uv`'s pipeline) it
/// matches the mesh-colors render at ≥ 35 dB from six directions (no paint lost). The same
/// export into the Duck's own UVs loses the paint on one side (printed, and below 30 dB on
/// its worst view).
#[test]
fn the_painted_duck_exported_from_the_menu_with_new_uvs_renders_like_its_mesh_colors() {
    use meshpaint_core::camera::default_camera;
    use meshpaint_render::{DrawItem, Gpu, RenderSettings};
    let dir = common::TempDir::new("export_dialog");
    let mut editor = editor_with_duck();
    paint_one_half(&mut editor);
    let mut harness =
        Harness::builder().with_size([1280.0, 1000.0]).build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor);
    harness.run_steps(2);
    let (new_glb, own_glb) = (dir.join("duck_new_uvs.glb"), dir.join("duck_own_uvs.glb"));
    let line = export_baked_from_the_menu(&mut harness, "Automatic UVs", &new_glb);
    assert!(line.contains("new UVs: the model's UV islands overlap"), "{line}");
    assert!(harness.state().status.text.contains("new UVs"), "{}", harness.state().status.text);
    export_baked_from_the_menu(&mut harness, "Model's own UVs", &own_glb);

    let gpu = Gpu::new_headless().expect("GPU tests need an adapter (lavapipe)");
    let open = harness.state().document.open.as_ref().unwrap();
    let colors = gpu.upload(&open.document.pack(open.document.display_format()).unwrap()).unwrap();
    let baked = |path: &Path| {
        let scene = meshpaint_core::mesh::import::import_gltf(path).unwrap();
        gpu.upload_baseline(&scene).unwrap().expect("the export has a base-colour texture")
    };
    let (new_uvs, own_uvs) = (baked(&new_glb), baked(&own_glb));
    let (mut worst_new, mut worst_own) = (f64::INFINITY, f64::INFINITY);
    for (yaw, pitch) in [(90.0, 0.0), (-90.0, 0.0), (0.0, 20.0), (180.0, 20.0), (30.0, 60.0), (210.0, -40.0)] {
        let mut settings = RenderSettings::new(default_camera(colors.bounds, yaw, pitch, None));
        settings.filter = meshpaint_render::FilterMode::Linear;
        let reference = gpu.render_image(DrawItem::MeshColors(&colors), &settings, 512, 512).unwrap();
        let new = gpu.render_image(DrawItem::Baseline(&new_uvs), &settings, 512, 512).unwrap();
        let own = gpu.render_image(DrawItem::Baseline(&own_uvs), &settings, 512, 512).unwrap();
        let (db_new, db_own) = (psnr(&reference, &new), psnr(&reference, &own));
        eprintln!("view ({yaw}, {pitch}): new UVs {db_new:.1} dB, own UVs {db_own:.1} dB");
        if (yaw, pitch) == (90.0, 0.0) {
            for (image, name) in [(&reference, "mesh_colors"), (&new, "new_uvs"), (&own, "own_uvs")] {
                image.save(common::output_dir().join(format!("export_painted_duck_{name}.png"))).unwrap();
            }
        }
        worst_new = worst_new.min(db_new);
        worst_own = worst_own.min(db_own);
    }
    assert!(worst_new >= 35.0, "generated UVs: worst view {worst_new:.1} dB < 35 dB");
    assert!(worst_own < 30.0, "the own-UV bake was expected to lose paint (worst view {worst_own:.1} dB)");
}

/// File → Export… shows each choice's cost before writing: the tessellated glTF's level,
/// vertices and triangles (a vertex budget picks the level; the file gets smooth normals),
/// the packed file's samples; both are written by a job with a status message.
#[test]
fn the_export_dialog_shows_each_cost_and_writes_tessellated_and_packed_files() {
    let dir = common::TempDir::new("export_dialog_kinds");
    let mut harness = Harness::builder()
        .with_size([1280.0, 1000.0])
        .build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor_with_duck());
    harness.run_steps(2);
    harness.state_mut().perform(Action::Export);
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.get_by_label("Tessellated glTF (.glb) — vertex colours").click();
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("Cost: level 0: ").is_some(), "no tessellation cost");
    harness.get_by_label("At most").click();
    harness.state_mut().panels.export.max_vertices = 20_000;
    harness.run_steps(2);
    // The Duck at R = 8 has 69× its triangles at level 0; 20,000 vertices fit level 2.
    assert!(harness.query_by_label_contains("Cost: level 2: ").is_some(), "the vertex budget does not pick a level");
    let glb = dir.join("duck_tessellated.glb");
    harness.state_mut().panels.export.path = glb.display().to_string();
    harness.run_steps(1);
    harness.get_by_label("Export").click();
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    assert!(harness.state().status.text.contains("level 2") && harness.state().status.text.contains("smooth normals"));
    let (gltf, _, _) = gltf::import(&glb).unwrap();
    let primitive = gltf.meshes().next().unwrap().primitives().next().unwrap();
    assert!(primitive.get(&gltf::Semantic::Normals).is_some(), "no NORMAL");

    harness.state_mut().perform(Action::Export);
    harness.run_steps(2);
    harness.get_by_label("Packed file (.mpk) — mesh colors").click();
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("samples with MIP chains").is_some(), "no packed cost");
    assert!(harness.state().panels.export.path.ends_with(".mpk"), "{}", harness.state().panels.export.path);
    let mpk = dir.join("duck.mpk");
    harness.state_mut().panels.export.path = mpk.display().to_string();
    harness.run_steps(1);
    harness.get_by_label("Export").click();
    harness.run_steps(2);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    assert!(harness.state().status.text.starts_with("Exported"), "{:?}", harness.state().status);
    assert!(std::fs::metadata(&mpk).unwrap().len() > 10_000);
}
