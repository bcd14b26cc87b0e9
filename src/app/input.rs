//! All input handling in one place: keyboard shortcuts ([`SHORTCUTS`], also the help
//! window's table) and the 3D view's pointer (camera navigation with Blender's habits).
//!
//! Input arrives through egui (egui-winit translates the window's events), so the same
//! code runs in the window and under egui_kittest. A later paint mode adds its tools in
//! [`viewport_input`], keyed on [`super::editor::Mode`].

use egui::{Key, Modifiers, PointerButton};

use meshpaint_render::{FilterMode, Shading};

use super::editor::Editor;
use super::file_dialog::DialogPurpose;
use super::paint_session::GestureKind;
use super::state::{Action, Mode};

/// In which mode a shortcut works.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// Everywhere.
    Any,
    /// In view mode only.
    View,
    /// In paint mode only.
    Paint,
}

impl Scope {
    /// Whether the shortcut works in `mode`.
    pub fn includes(self, mode: Mode) -> bool {
        match self {
            Scope::Any => true,
            Scope::View => mode == Mode::View,
            Scope::Paint => mode == Mode::Paint,
        }
    }

    /// How the help window writes it.
    pub fn name(self) -> &'static str {
        match self {
            Scope::Any => "",
            Scope::View => "view",
            Scope::Paint => "paint",
        }
    }
}

/// Degrees of orbit per point of pointer travel.
pub const ORBIT_DEGREES_PER_POINT: f64 = 0.4;
/// Zoom factor per wheel line (wheel forward zooms in).
pub const ZOOM_PER_WHEEL_LINE: f64 = 0.85;
/// Points of a wheel "line" for wheels that report points.
const POINTS_PER_LINE: f32 = 50.0;

/// A keyboard shortcut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shortcut {
    /// Modifiers (extra Shift and Alt are ignored, so more specific shortcuts come first).
    pub modifiers: Modifiers,
    /// The key.
    pub key: Key,
    /// How the help window writes it.
    pub keys: &'static str,
    /// What it does.
    pub action: Action,
    /// Description for the help window.
    pub description: &'static str,
    /// The mode it works in.
    pub scope: Scope,
}

const fn shortcut(
    modifiers: Modifiers,
    key: Key,
    keys: &'static str,
    action: Action,
    description: &'static str,
) -> Shortcut {
    Shortcut { modifiers, key, keys, action, description, scope: Scope::Any }
}

const fn scoped(scope: Scope, shortcut: Shortcut) -> Shortcut {
    Shortcut { scope, ..shortcut }
}

const CTRL_SHIFT: Modifiers = Modifiers { alt: false, ctrl: false, shift: true, mac_cmd: false, command: true };

/// Every keyboard shortcut, most specific first (the help window lists them in this order).
pub const SHORTCUTS: &[Shortcut] = &[
    scoped(Scope::Paint, shortcut(CTRL_SHIFT, Key::Z, "Ctrl+Shift+Z", Action::Redo, "Redo the last undone stroke")),
    scoped(Scope::Paint, shortcut(Modifiers::COMMAND, Key::Z, "Ctrl+Z", Action::Undo, "Undo the last stroke")),
    shortcut(Modifiers::NONE, Key::Tab, "Tab", Action::TogglePaintMode, "Enter / leave paint mode"),
    scoped(
        Scope::Paint,
        shortcut(Modifiers::SHIFT, Key::F, "Shift+F", Action::StrengthGesture, "Brush strength: move, click / Enter"),
    ),
    scoped(
        Scope::Paint,
        shortcut(
            Modifiers::NONE,
            Key::F,
            "F",
            Action::RadiusGesture,
            "Brush radius: move, click / Enter (Esc cancels)",
        ),
    ),
    scoped(
        Scope::Paint,
        shortcut(Modifiers::NONE, Key::S, "S", Action::Eyedropper, "Pick the colour under the cursor"),
    ),
    shortcut(CTRL_SHIFT, Key::S, "Ctrl+Shift+S", Action::SaveAs, "Save as… (packed file)"),
    shortcut(CTRL_SHIFT, Key::E, "Ctrl+Shift+E", Action::ExportPacked, "Export packed buffers…"),
    shortcut(Modifiers::COMMAND, Key::O, "Ctrl+O", Action::Open, "Open a .glb / .gltf / packed file…"),
    shortcut(Modifiers::COMMAND, Key::S, "Ctrl+S", Action::Save, "Save the project (packed file)"),
    shortcut(Modifiers::COMMAND, Key::E, "Ctrl+E", Action::ExportGltf, "Export glTF (.glb, vertex colours)…"),
    shortcut(Modifiers::COMMAND, Key::Q, "Ctrl+Q", Action::Quit, "Quit"),
    shortcut(Modifiers::COMMAND, Key::Num1, "Ctrl+1", Action::ViewBack, "View from the back"),
    shortcut(Modifiers::COMMAND, Key::Num3, "Ctrl+3", Action::ViewLeft, "View from the left"),
    shortcut(Modifiers::COMMAND, Key::Num7, "Ctrl+7", Action::ViewBottom, "View from below"),
    shortcut(Modifiers::NONE, Key::Home, "Home", Action::FrameAll, "Frame the whole mesh"),
    scoped(
        Scope::View,
        shortcut(
            Modifiers::NONE,
            Key::F,
            "F",
            Action::FrameUnderCursor,
            "Centre on the point under the cursor, move closer (also Alt + middle click)",
        ),
    ),
    shortcut(Modifiers::NONE, Key::Num1, "1", Action::ViewFront, "View from the front"),
    shortcut(Modifiers::NONE, Key::Num3, "3", Action::ViewRight, "View from the right"),
    shortcut(Modifiers::NONE, Key::Num7, "7", Action::ViewTop, "View from above"),
    shortcut(Modifiers::NONE, Key::W, "W", Action::ToggleWireframe, "Wireframe overlay on / off"),
    shortcut(Modifiers::NONE, Key::H, "H", Action::ToggleHeatmap, "Resolution heat map on / off"),
    shortcut(Modifiers::NONE, Key::L, "L", Action::ToggleShading, "Lit / unlit shading"),
    shortcut(Modifiers::NONE, Key::M, "M", Action::CycleFilter, "Next filter: nearest, linear, trilinear"),
    shortcut(Modifiers::NONE, Key::F1, "F1", Action::ToggleHelp, "This help"),
];

/// The pointer gestures of the 3D view, for the help window.
pub const POINTER_HELP: &[(&str, &str)] = &[
    ("Middle drag", "Orbit"),
    ("Shift + middle drag", "Pan"),
    ("Ctrl + middle drag", "Zoom"),
    ("Wheel", "Zoom"),
    ("Alt + left drag", "Orbit (trackpads)"),
    ("Alt + Shift + left drag", "Pan (trackpads)"),
    ("Alt + Ctrl + left drag", "Zoom (trackpads)"),
    ("Alt + middle click", "Centre on the point under the cursor"),
    ("Left drag (paint mode)", "Paint with the brush"),
    ("Drop a file on the window", "Open it"),
];

/// The shortcut of `action`, as the help window and menus write it.
pub fn shortcut_text(action: Action) -> Option<&'static str> {
    SHORTCUTS.iter().find(|s| s.action == action).map(|s| s.keys)
}

/// Carries out `action` on `editor`: the one place every menu entry and shortcut ends.
pub fn perform(editor: &mut Editor, action: Action) {
    match action {
        Action::Open => editor.open_dialog(DialogPurpose::Open),
        Action::Save => match editor.document.as_ref().and_then(|d| Some((d.project_path.clone()?, d.format))) {
            Some((path, format)) => editor.save_to(path, format),
            None => editor.open_dialog(DialogPurpose::SaveAs),
        },
        Action::SaveAs => editor.open_dialog(DialogPurpose::SaveAs),
        Action::ExportGltf => editor.open_dialog(DialogPurpose::ExportGltf),
        Action::ExportPacked => editor.open_dialog(DialogPurpose::ExportPacked),
        Action::FrameAll => editor.frame_all(),
        Action::FrameUnderCursor => {
            if let Some(pos) = editor.viewport_pointer {
                editor.frame_under(pos);
            }
        }
        Action::ViewFront => editor.set_view_angles(0.0, 0.0),
        Action::ViewBack => editor.set_view_angles(180.0, 0.0),
        Action::ViewRight => editor.set_view_angles(90.0, 0.0),
        Action::ViewLeft => editor.set_view_angles(-90.0, 0.0),
        Action::ViewTop => editor.set_view_angles(0.0, 89.0),
        Action::ViewBottom => editor.set_view_angles(0.0, -89.0),
        Action::ToggleWireframe => editor.view.overlays.wireframe = !editor.view.overlays.wireframe,
        Action::ToggleHeatmap => editor.view.overlays.heatmap = !editor.view.overlays.heatmap,
        Action::ToggleShading => {
            editor.view.shading = match editor.view.shading {
                Shading::Lit | Shading::Smooth => Shading::Unlit,
                Shading::Unlit => Shading::Smooth,
            }
        }
        Action::CycleFilter => {
            editor.view.filter = match editor.view.filter {
                FilterMode::Nearest | FilterMode::NearestMipLevel(_) => FilterMode::Linear,
                FilterMode::Linear | FilterMode::MipLevel(_) => FilterMode::Trilinear,
                FilterMode::Trilinear => FilterMode::Nearest,
            }
        }
        Action::ToggleHelp => editor.show_help = !editor.show_help,
        Action::Quit => editor.quit_requested = true,
        Action::TogglePaintMode => editor.toggle_paint_mode(),
        Action::Undo => editor.undo(),
        Action::Redo => editor.redo(),
        Action::Eyedropper => editor.eyedropper(),
        Action::RadiusGesture => editor.start_gesture(GestureKind::Radius),
        Action::StrengthGesture => editor.start_gesture(GestureKind::Strength),
    }
}

/// Keyboard shortcuts and dropped files, for the whole window. Keys go to a focused text
/// field (the file dialog) rather than to shortcuts; F1 always works.
pub fn global_input(editor: &mut Editor, ctx: &egui::Context) {
    let dropped: Vec<std::path::PathBuf> =
        ctx.input(|i| i.raw.dropped_files.iter().map(|file| file.path().to_owned()).collect());
    if let Some(path) = dropped.into_iter().next() {
        editor.open(meshpaint_core::io::document::Source::File(path));
    }
    if editor.gesture_input(ctx) {
        return;
    }
    // Only a text field keeps keys from the shortcuts (Tab may have focused a button).
    let typing = ctx.text_edit_focused();
    if !typing && let Some(id) = ctx.memory(|m| m.focused()) {
        ctx.memory_mut(|m| m.surrender_focus(id));
    }
    let mut actions = Vec::new();
    for shortcut in SHORTCUTS {
        if typing && shortcut.key != Key::F1 {
            continue;
        }
        if !shortcut.scope.includes(editor.mode) {
            continue;
        }
        if editor.dialog.is_some() && !matches!(shortcut.action, Action::ToggleHelp | Action::Quit) {
            continue;
        }
        if ctx.input_mut(|i| i.consume_key(shortcut.modifiers, shortcut.key)) {
            actions.push(shortcut.action);
        }
    }
    for action in actions {
        perform(editor, action);
    }
}

/// Navigation in the 3D view from `response` (the view's area, sensing clicks and drags).
pub fn viewport_input(editor: &mut Editor, ui: &egui::Ui, response: &egui::Response) {
    editor.viewport_pointer = response.hover_pos();
    let modifiers = ui.input(|i| i.modifiers);
    if editor.mode == Mode::Paint {
        paint_input(editor, ui, response, modifiers);
    }
    let height = f64::from(response.rect.height().max(1.0));
    let navigating =
        response.dragged_by(PointerButton::Middle) || (modifiers.alt && response.dragged_by(PointerButton::Primary));
    let mut moved = false;
    if navigating {
        let delta = response.drag_delta();
        let (dx, dy) = (f64::from(delta.x), f64::from(delta.y));
        if modifiers.shift {
            editor.camera.pan_pixels(dx, dy, height);
        } else if modifiers.ctrl || modifiers.command {
            editor.camera.zoom((dy * 0.01).exp());
        } else {
            editor.camera.orbit(-dx * ORBIT_DEGREES_PER_POINT, dy * ORBIT_DEGREES_PER_POINT);
        }
        moved = delta != egui::Vec2::ZERO;
    }
    if modifiers.alt
        && response.clicked_by(PointerButton::Middle)
        && let Some(pos) = response.interact_pointer_pos()
    {
        editor.frame_under(pos);
    }
    if response.hovered() {
        let lines: f32 = ui.input(|i| {
            i.events
                .iter()
                .filter_map(|event| match event {
                    egui::Event::MouseWheel { unit, delta, modifiers, .. } if !modifiers.command => Some(match unit {
                        egui::MouseWheelUnit::Point => delta.y / POINTS_PER_LINE,
                        egui::MouseWheelUnit::Line => delta.y,
                        egui::MouseWheelUnit::Page => delta.y * 10.0,
                    }),
                    _ => None,
                })
                .sum()
        });
        let pinch = ui.input(|i| i.zoom_delta());
        if lines != 0.0 {
            editor.camera.zoom(ZOOM_PER_WHEEL_LINE.powf(f64::from(lines)));
            moved = true;
        }
        if pinch != 1.0 && pinch.is_finite() && pinch > 0.0 {
            editor.camera.zoom(1.0 / f64::from(pinch));
            moved = true;
        }
    }
    if moved && let Some(open) = &editor.document {
        editor.camera.fit_depth_to(open.bounds);
    }
}

/// The brush in paint mode: the left button paints (not with Alt, which navigates).
fn paint_input(editor: &mut Editor, ui: &egui::Ui, response: &egui::Response, modifiers: Modifiers) {
    let (pressed, down, latest) =
        ui.input(|i| (i.pointer.primary_pressed(), i.pointer.primary_down(), i.pointer.latest_pos()));
    let Some(session) = editor.paint.as_mut() else {
        return;
    };
    if let Some(pos) = response.hover_pos() {
        session.last_pointer = Some(pos);
    }
    if session.swallow_primary {
        session.swallow_primary = down;
        return;
    }
    if session.gesture.is_some() || editor.dialog.is_some() {
        return;
    }
    let stroking = session.painter.is_stroking();
    if !stroking && pressed && !modifiers.alt && response.hovered() {
        if let Some(pos) = latest {
            editor.begin_stroke(pos);
        }
    } else if stroking && let Some(pos) = latest {
        editor.stroke_to(pos);
    }
    if !down {
        editor.end_stroke();
    }
    if editor.paint.as_ref().is_some_and(|p| p.painter.is_stroking()) {
        ui.ctx().request_repaint();
    }
}
