//! The everyday painting tools in the editor's UI without a window (egui_kittest, no GPU):
//! the colour wheel, hex entry and recent colours, brush presets, the heat-map legend,
//! the up axis and the settings remembered between runs. Truths are computed here
//! independently: HSV by its textbook formulas, sRGB by IEC 61966-2-1.

use std::sync::Arc;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use meshpaint::app::Editor;
use meshpaint_core::io::document::Source;

const JOB_TIMEOUT: Duration = Duration::from_secs(60);
/// Tall enough for the whole side panel (the paint section with its wheel, file, view).
const SIZE: [f32; 2] = [1280.0, 1700.0];

fn new_editor() -> Editor {
    Editor::new(None, Arc::new(|| {}))
}

fn editor_with_duck() -> Editor {
    let mut editor = new_editor();
    editor.open(Source::BuiltIn);
    assert!(editor.wait_for_job(JOB_TIMEOUT), "opening the Duck timed out");
    assert!(editor.document.open.is_some(), "the Duck did not open: {:?}", editor.status);
    editor
}

fn harness(editor: Editor) -> Harness<'static, Editor> {
    Harness::builder().with_size(SIZE).build_ui_state(|ui, editor: &mut Editor| editor.ui(ui), editor)
}

/// sRGB-encoded value → linear (IEC 61966-2-1).
fn linear(encoded: f32) -> f32 {
    if encoded <= 0.04045 { encoded / 12.92 } else { ((encoded + 0.055) / 1.055).powf(2.4) }
}

fn click_at(harness: &mut Harness<'static, Editor>, pos: egui::Pos2) {
    harness.event(egui::Event::PointerMoved(pos));
    harness.run_steps(1);
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        harness.run_steps(1);
    }
    harness.run_steps(1);
}

fn brush_color(harness: &Harness<'static, Editor>) -> [f32; 4] {
    harness.state().panels.paint.brush.color
}

fn assert_close(got: [f32; 4], want: [f32; 4], tolerance: f32, what: &str) {
    for c in 0..4 {
        assert!((got[c] - want[c]).abs() <= tolerance, "{what}: got {got:?}, want {want:?}");
    }
}

/// Types `text` into the hex field and presses Enter.
fn enter_hex(harness: &mut Harness<'static, Editor>, text: &str) {
    harness.get_by_label("Hex").click();
    harness.run_steps(1);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.run_steps(1);
    harness.get_by_label("Hex").type_text(text);
    harness.run_steps(1);
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
}

/// The wheel is in the panel without opening anything; a click picks the hue at its angle
/// (counter-clockwise from red at the right) and the saturation at its distance from the
/// centre: HSV(120°, 0.9, 1) is sRGB (0.1, 1, 0.1), checked through the textbook formula.
#[test]
fn the_colour_wheel_is_always_there_and_picks_hue_and_saturation() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let wheel = harness.get_by_label("Colour wheel").rect();
    assert!(wheel.width() >= 100.0 && (wheel.width() - wheel.height()).abs() < 0.5, "{wheel:?}");
    assert!(wheel.max.y < SIZE[1], "the wheel is off screen");
    let radius = wheel.width() * 0.5;
    for (degrees, want) in [(120.0f32, [0.1, 1.0, 0.1]), (0.0, [1.0, 0.1, 0.1]), (240.0, [0.1, 0.1, 1.0])] {
        let angle = degrees.to_radians();
        let pos = wheel.center() + egui::vec2(angle.cos(), -angle.sin()) * (0.9 * radius);
        click_at(&mut harness, pos);
        let want = [linear(want[0]), linear(want[1]), linear(want[2]), 1.0];
        // The click lands within float rounding of 0.9 R: a saturation error of 1e-4 at most.
        assert_close(brush_color(&harness), want, 2e-3, &format!("hue {degrees}°"));
    }
    // Brightness 0 makes black; the hue survives it.
    harness.state_mut().panels.paint.brush.color = [0.0, 0.0, 0.0, 1.0];
    harness.run_steps(2);
    assert!(harness.query_all_by_value("#000000").next().is_some(), "the hex field does not follow the colour");
}

/// `#ff8800`, `ff8800` and `#f80` all give sRGB (255, 136, 0); an invalid entry shows a
/// message and leaves the colour as it was.
#[test]
fn hex_entry_takes_three_spellings_and_refuses_the_rest() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let orange = [1.0, linear(136.0 / 255.0), 0.0, 1.0];
    for (text, start) in [("#ff8800", [0.0, 0.0, 1.0, 1.0]), ("ff8800", [0.0, 1.0, 0.0, 1.0]), ("#f80", [0.2; 4])] {
        harness.state_mut().panels.paint.brush.color = start;
        harness.run_steps(2);
        enter_hex(&mut harness, text);
        let alpha_kept = [orange[0], orange[1], orange[2], start[3]];
        assert_close(brush_color(&harness), alpha_kept, 1e-6, text);
        assert!(harness.state().panels.paint.picker.hex_error.is_none(), "{text}");
        assert!(harness.query_all_by_value("#ff8800").next().is_some(), "{text}: the field does not show #ff8800");
    }
    for bad in ["#ff880", "orange", "#gg8800", "  "] {
        let before = brush_color(&harness);
        enter_hex(&mut harness, bad);
        assert_eq!(brush_color(&harness), before, "{bad:?} changed the colour");
        assert!(harness.query_by_label_contains("is not a colour").is_some(), "{bad:?}: no message");
    }
    enter_hex(&mut harness, "#00f");
    assert!(harness.query_by_label_contains("is not a colour").is_none(), "the message stays after a valid entry");
}

/// Paints a short stroke across the middle of the 3D view.
fn stroke(harness: &mut Harness<'static, Editor>, dy: f32) {
    let center = harness.state().viewport.rect.center() + egui::vec2(0.0, dy);
    crate::app_ui::left_drag(harness, center - egui::vec2(40.0, 0.0), center + egui::vec2(40.0, 0.0));
}

/// Only colours strokes painted with join the row, newest first and without repeats; a
/// colour chosen but never painted with does not; clicking one picks it.
#[test]
fn recent_colours_are_the_colours_painted_with_and_pick_on_click() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("Recent colour #").is_none());
    for hex in ["#ff0000", "#00ff00", "#ff0000", "#0000ff"] {
        enter_hex(&mut harness, hex);
        stroke(&mut harness, 0.0);
    }
    enter_hex(&mut harness, "#123456");
    let recent: Vec<String> = harness
        .state()
        .panels
        .paint
        .recent_colors
        .srgba8()
        .iter()
        .map(|&c| meshpaint::app::recent_colors::hex_of(c))
        .collect();
    assert_eq!(recent, ["#0000ff", "#ff0000", "#00ff00"]);
    assert!(harness.query_by_label("Recent colour #123456").is_none(), "an unused colour is listed");
    harness.get_by_label("Recent colour #00ff00").click();
    harness.run_steps(2);
    assert_eq!(brush_color(&harness), [0.0, 1.0, 0.0, 1.0]);
}

/// Every text the editor shows (paint mode, the wheel and the recent colours on screen, the
/// help open) has its glyphs in the fonts egui ships: no missing-glyph boxes.
#[test]
fn every_label_has_its_glyphs_in_the_default_fonts() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    harness.key_press(egui::Key::Tab);
    harness.run_steps(2);
    stroke(&mut harness, 0.0);
    harness.key_press(egui::Key::F1);
    harness.run_steps(3);
    let mut texts = Vec::new();
    for node in harness.query_all_by(|_| true) {
        let node = node.accesskit_node();
        texts.extend(node.label());
        texts.extend(node.value());
    }
    assert!(texts.len() > 100 && texts.iter().any(|t| t == "Colour wheel"), "{} texts", texts.len());
    let ctx = harness.ctx.clone();
    let font = egui::FontId::proportional(14.0);
    let mono = egui::FontId::monospace(14.0);
    // The check can fail: the clipboard emoji egui's own colour picker shows is missing.
    assert!(!ctx.fonts_mut(|fonts| fonts.has_glyph(&font, '\u{1F4CB}')));
    let missing: Vec<(String, char)> = ctx.fonts_mut(|fonts| {
        texts
            .iter()
            .flat_map(|text| text.chars().map(move |c| (text.clone(), c)))
            .filter(|(_, c)| !(c.is_control() || (fonts.has_glyph(&font, *c) && fonts.has_glyph(&mono, *c))))
            .collect()
    });
    assert!(missing.is_empty(), "glyphs the fonts lack: {missing:?}");
}

// ---------------------------------------------------------------- brush presets

/// The three defaults load their brushes (the colour stays); the current brush saves under
/// a typed name, loads back after changes, updates in place under the same name, and
/// deletes; an empty name is refused with a message.
#[test]
fn brush_presets_save_load_and_delete() {
    use meshpaint_core::paint::brush::{BrushRadius, Falloff, Tool};
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let color = [0.3, 0.2, 0.1, 1.0];
    harness.state_mut().panels.paint.brush.color = color;
    harness.run_steps(1);
    harness.get_by_label("Soft airbrush").click();
    harness.run_steps(2);
    let brush = harness.state().panels.paint.brush;
    assert_eq!((brush.tool, brush.falloff, brush.strength), (Tool::Paint, Falloff::Smooth, 0.15));
    assert_eq!(brush.radius, BrushRadius::Pixels { radius_px: 60.0 });
    assert_eq!(brush.color, color, "loading a preset changed the colour");
    harness.get_by_label("Blur brush").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush.tool, Tool::Blur);
    harness.get_by_label("Hard round").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush.falloff, Falloff::Constant);

    // Save the current brush, change it, load it back.
    harness.state_mut().panels.paint.brush.strength = 0.42;
    harness.run_steps(1);
    harness.get_by_label("Name").click();
    harness.run_steps(1);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("Name").type_text("Glaze");
    harness.run_steps(1);
    harness.get_by_label("Save preset").click();
    harness.run_steps(2);
    assert!(harness.query_by_label("Saved \"Glaze\".").is_some());
    let saved = harness.state().panels.paint.brush;
    harness.state_mut().panels.paint.brush.strength = 0.9;
    harness.state_mut().panels.paint.brush.mirror_x = true;
    harness.run_steps(1);
    harness.get_by_label("Glaze").click();
    harness.run_steps(2);
    assert_eq!(harness.state().panels.paint.brush, saved);
    // Same name: updated in place, not added twice.
    harness.state_mut().panels.paint.brush.strength = 0.5;
    harness.run_steps(1);
    harness.get_by_label("Save preset").click();
    harness.run_steps(2);
    let names: Vec<String> =
        harness.state().panels.paint.presets.presets.list().iter().map(|p| p.name.clone()).collect();
    assert_eq!(names, ["Hard round", "Soft airbrush", "Blur brush", "Glaze"]);
    assert_eq!(harness.state().panels.paint.presets.presets.get("Glaze").unwrap().brush.strength, 0.5);
    harness.get_by_label("Delete preset").click();
    harness.run_steps(2);
    assert!(harness.query_by_label("Glaze").is_none());
    assert!(harness.state().panels.paint.presets.presets.get("Glaze").is_none());
    // An empty name.
    harness.state_mut().panels.paint.presets.name = "  ".into();
    harness.run_steps(1);
    harness.get_by_label("Save preset").click();
    harness.run_steps(2);
    assert!(harness.query_by_label_contains("Type a name").is_some());
    assert_eq!(harness.state().panels.paint.presets.presets.list().len(), 3);
}

// ---------------------------------------------------------------- heat-map legend

/// The legend shows with the heat map and goes with it; it has a swatch per R = 1 … 4096,
/// and the Duck's own R (8) is marked as present.
#[test]
fn the_heat_map_legend_follows_the_heat_map() {
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    assert!(harness.query_by_label("Heat map R = 8").is_none());
    harness.key_press(egui::Key::H);
    harness.run_steps(2);
    for log2 in 0..=12 {
        let label = format!("Heat map R = {}", 1u64 << log2);
        let node = harness.get_by_label(&label);
        assert!(node.rect().max.y < SIZE[1], "{label} is off screen");
    }
    harness.key_press(egui::Key::H);
    harness.run_steps(2);
    assert!(harness.query_by_label("Heat map R = 8").is_none());
}

/// The legend's colour for R is what the renderer draws for a face of that R: the Duck
/// opened at uniform R = 8 and at R = 32, rendered offscreen (lavapipe) with the heat map,
/// unlit: the colour of most mesh pixels equals the legend's swatch for that R within one
/// 8-bit step.
#[test]
fn the_heat_map_legend_has_the_colours_the_renderer_draws() {
    use meshpaint::app::import_settings::ImportMode;
    use meshpaint_core::colors::layout::Resolution;
    use meshpaint_render::Shading;
    let gpu = Arc::new(meshpaint_render::Gpu::new_headless().expect("GPU tests need an adapter (lavapipe)"));
    let legend = meshpaint::app::panels::heat_legend::legend_entries();
    for r in [8u64, 32] {
        let mut editor = Editor::new(Some(Arc::clone(&gpu)), Arc::new(|| {}));
        editor.panels.import.mode = ImportMode::Uniform;
        editor.panels.import.resolution = Resolution::new(r).unwrap();
        editor.open(Source::BuiltIn);
        assert!(editor.wait_for_job(JOB_TIMEOUT));
        editor.panels.view.settings.overlays.heatmap = true;
        editor.panels.view.settings.shading = Shading::Unlit;
        let mut settings = editor.render_settings();
        settings.background = [0.0, 0.0, 0.0, 0.0];
        let image = gpu.render_image(editor.shown_item().unwrap(), &settings, 160, 120).unwrap();
        let mut counts = std::collections::HashMap::<[u8; 4], usize>::new();
        for pixel in image.pixels().filter(|p| p.0[3] == 255) {
            *counts.entry(pixel.0).or_default() += 1;
        }
        let (&drawn, &count) = counts.iter().max_by_key(|(_, n)| **n).unwrap();
        assert!(count > 2000, "R = {r}: only {count} mesh pixels");
        let (_, swatch) = legend.iter().find(|(legend_r, _)| *legend_r == r).unwrap();
        for (c, want) in [swatch.r(), swatch.g(), swatch.b()].into_iter().enumerate() {
            assert!(drawn[c].abs_diff(want) <= 1, "R = {r}: drawn {drawn:?}, legend {swatch:?}");
        }
    }
}

// ---------------------------------------------------------------- up axis

/// Choosing "Z up" turns the view of the open document (its geometry stays as it was):
/// the camera's screen-up is +Z and the mesh is framed again; a document opened afterwards
/// opens Z-up too.
#[test]
fn the_up_axis_turns_the_view_not_the_mesh() {
    use meshpaint_core::camera::UpAxis;
    let mut harness = harness(editor_with_duck());
    harness.run_steps(2);
    let positions = harness.state().document.open.as_ref().unwrap().document.positions.clone();
    assert_eq!(harness.state().camera.up, UpAxis::Y);
    harness.get_by_label("Z up").click();
    harness.run_steps(2);
    let camera = harness.state().camera;
    assert_eq!(camera.up, UpAxis::Z);
    assert!(camera.right_up().1.z > 0.9, "screen-up is {:?}", camera.right_up().1);
    assert_eq!(harness.state().document.open.as_ref().unwrap().document.positions, positions);
    harness.state_mut().open(Source::BuiltIn);
    assert!(harness.state_mut().wait_for_job(JOB_TIMEOUT));
    harness.run_steps(2);
    assert_eq!(harness.state().camera.up, UpAxis::Z);
}

// ---------------------------------------------------------------- settings file

/// Presets, recent colours, up axis, zoom to pointer and shading written by one editor come
/// back in the next; nothing is written while a button is held or nothing changed; the file
/// is TOML in the directory `$MESHPAINT_CONFIG_DIR` names.
#[test]
fn settings_are_remembered_between_runs() {
    use meshpaint::app::settings::{FILE_NAME, settings_path_with};
    use meshpaint_core::camera::UpAxis;
    use meshpaint_render::Shading;
    let dir = crate::common::TempDir::new("settings");
    let path = settings_path_with(Some(dir.join("config").into_os_string())).unwrap();
    assert_eq!(path, dir.join("config").join(FILE_NAME));
    assert_ne!(settings_path_with(Some("".into())), Some(std::path::PathBuf::from(FILE_NAME)));

    let mut editor = new_editor();
    editor.load_settings(Some(path.clone()));
    let defaults = editor.settings();
    assert!(!editor.save_settings_if_changed(false), "nothing changed, yet it wrote");
    assert!(!path.exists());
    let mut brush = editor.panels.paint.brush;
    brush.strength = 0.25;
    brush.radius = meshpaint_core::paint::brush::BrushRadius::World { radius_world: 0.125 };
    editor.panels.paint.presets.presets.save("Mine", brush).unwrap();
    editor.panels.paint.recent_colors.push([1.0, 0.5, 0.0, 0.5]);
    editor.panels.paint.recent_colors.push([0.0, 0.0, 1.0, 1.0]);
    editor.panels.import.up_axis = UpAxis::Z;
    editor.panels.view.settings.zoom_to_cursor = false;
    editor.panels.view.settings.shading = Shading::Unlit;
    assert!(!editor.save_settings_if_changed(true), "it wrote while the pointer was down");
    assert!(editor.save_settings_if_changed(false));
    assert!(!editor.save_settings_if_changed(false), "it wrote the same settings twice");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("up_axis = \"z\"") && text.contains("name = \"Mine\""), "{text}");

    let mut next = new_editor();
    next.load_settings(Some(path.clone()));
    assert_eq!(next.settings(), editor.settings());
    assert_ne!(next.settings(), defaults);
    assert_eq!(next.panels.paint.presets.presets.get("Mine").unwrap().brush, brush);
    assert_eq!(next.panels.import.up_axis, UpAxis::Z);
}

/// A settings file that is not TOML, holds an unknown value or comes from a newer version
/// gives a message and the defaults, and stays as it was until a setting changes; unknown
/// keys are ignored.
#[test]
fn a_bad_settings_file_gives_a_message_and_the_defaults() {
    let dir = crate::common::TempDir::new("settings-bad");
    let path = dir.join("settings.toml");
    let defaults = {
        let mut editor = new_editor();
        editor.load_settings(None);
        editor.settings()
    };
    for (text, says) in [
        ("this is = = not toml", "is not valid"),
        ("up_axis = \"w\"", "unknown up axis"),
        ("version = 99", "newer meshpaint"),
        ("[[presets]]\nname = \"x\"\ntool = \"paint\"", "is not valid"),
        ("recent_colors = [\"red\"]", "recent colour"),
    ] {
        std::fs::write(&path, text).unwrap();
        let mut editor = new_editor();
        editor.load_settings(Some(path.clone()));
        assert_eq!(editor.status.severity, meshpaint::app::Severity::Warning, "{text}");
        assert!(
            editor.status.text.contains(says) && editor.status.text.contains("defaults"),
            "{text}: {:?}",
            editor.status
        );
        assert_eq!(editor.settings(), defaults, "{text}");
        assert!(!editor.save_settings_if_changed(false));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "the bad file was overwritten unchanged");
        // The message is shown again once the first document has opened.
        editor.open(Source::BuiltIn);
        assert!(editor.wait_for_job(JOB_TIMEOUT));
        assert!(editor.status.text.contains(says), "{:?}", editor.status);
    }
    std::fs::write(&path, "future_key = 3\n[view]\nzoom_to_cursor = false\nsomething_new = \"x\"\n").unwrap();
    let mut editor = new_editor();
    editor.load_settings(Some(path.clone()));
    assert!(!editor.panels.view.settings.zoom_to_cursor);
    assert_eq!(editor.status.severity, meshpaint::app::Severity::Info, "{:?}", editor.status);
}
