//! All input handling in one place: keyboard shortcuts ([`SHORTCUTS`], also the help
//! window's table) and the 3D view's pointer (camera navigation with Blender's habits).
//!
//! Input arrives through egui (egui-winit translates the window's events), so the same
//! code runs in the window and under egui_kittest. A later paint mode adds its tools in
//! [`viewport_input`], keyed on [`super::editor::Mode`].

use egui::{Key, Modifiers, PointerButton};

use super::editor::{Action, Editor};

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
}

const fn shortcut(
    modifiers: Modifiers,
    key: Key,
    keys: &'static str,
    action: Action,
    description: &'static str,
) -> Shortcut {
    Shortcut { modifiers, key, keys, action, description }
}

const CTRL_SHIFT: Modifiers = Modifiers { alt: false, ctrl: false, shift: true, mac_cmd: false, command: true };

/// Every keyboard shortcut, most specific first (the help window lists them in this order).
pub const SHORTCUTS: &[Shortcut] = &[
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
    shortcut(
        Modifiers::NONE,
        Key::F,
        "F",
        Action::FrameUnderCursor,
        "Centre on the point under the cursor, move closer",
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
    ("Drop a file on the window", "Open it"),
];

/// The shortcut of `action`, as the help window and menus write it.
pub fn shortcut_text(action: Action) -> Option<&'static str> {
    SHORTCUTS.iter().find(|s| s.action == action).map(|s| s.keys)
}

/// Keyboard shortcuts and dropped files, for the whole window. Keys go to a focused text
/// field (the file dialog) rather than to shortcuts; F1 always works.
pub fn global_input(editor: &mut Editor, ctx: &egui::Context) {
    let dropped: Vec<std::path::PathBuf> =
        ctx.input(|i| i.raw.dropped_files.iter().map(|file| file.path().to_owned()).collect());
    if let Some(path) = dropped.into_iter().next() {
        editor.open(super::loaded::Source::File(path));
    }
    let typing = ctx.egui_wants_keyboard_input();
    let mut actions = Vec::new();
    for shortcut in SHORTCUTS {
        if typing && shortcut.key != Key::F1 {
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
        editor.perform(action);
    }
}

/// Navigation in the 3D view from `response` (the view's area, sensing clicks and drags).
pub fn viewport_input(editor: &mut Editor, ui: &egui::Ui, response: &egui::Response) {
    editor.viewport_pointer = response.hover_pos();
    let modifiers = ui.input(|i| i.modifiers);
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
