//! All input handling in one place: keyboard shortcuts ([`SHORTCUTS`], also the help
//! window's table), dropped files, and the 3D view's pointer: camera navigation with
//! Blender's habits ([`navigate`], [`frame_all`], [`frame_under`]) and, in paint mode, the
//! brush ([`paint_input`]).
//!
//! Input arrives through egui (egui-winit translates the window's events), so the same
//! code runs in the window and under egui_kittest. What input asks of the editor comes back
//! as [`Action`]s and [`Command`]s; the camera it moves directly.

use std::path::PathBuf;

use egui::{Key, Modifiers, PointerButton};
use glam::DVec3;

use meshpaint_core::camera::{BoundingSphere, OrbitCamera, UpAxis};

use super::command::Command;
use super::document::OpenDocument;
use super::paint_session::PaintSession;
use super::state::{Action, Mode, Severity, Status, ViewportState};

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
    shortcut(
        Modifiers::NONE,
        Key::T,
        "T",
        Action::ToggleRepresentation,
        "Mesh colors (software filter) / Mesh Color Textures (hardware filter)",
    ),
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

/// The first file dropped on the window this frame, if any.
pub fn dropped_file(ctx: &egui::Context) -> Option<PathBuf> {
    ctx.input(|i| i.raw.dropped_files.first().map(|file| file.path().to_owned()))
}

/// The shortcuts pressed this frame that work in `mode` (consumed from the input). Keys go
/// to a focused text field (the file dialog) rather than to shortcuts; F1 always works;
/// while a dialog is open (`dialog_open`) only the help and Quit do.
pub fn shortcuts(ctx: &egui::Context, mode: Mode, dialog_open: bool) -> Vec<Action> {
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
        if !shortcut.scope.includes(mode) {
            continue;
        }
        if dialog_open && !matches!(shortcut.action, Action::ToggleHelp | Action::Quit) {
            continue;
        }
        if ctx.input_mut(|i| i.consume_key(shortcut.modifiers, shortcut.key)) {
            actions.push(shortcut.action);
        }
    }
    actions
}

/// Navigation in the 3D view from `response` (the view's area, sensing clicks and drags):
/// orbit, pan and zoom `camera` (the wheel and pinch towards the pointer when
/// `zoom_to_cursor`, else towards the orbit centre); Alt + middle click frames the surface of
/// `document` under the pointer (a miss is reported on `status`).
pub fn navigate(
    ui: &egui::Ui,
    response: &egui::Response,
    camera: &mut OrbitCamera,
    document: Option<&OpenDocument>,
    viewport: &ViewportState,
    zoom_to_cursor: bool,
    status: &mut Status,
) {
    let modifiers = ui.input(|i| i.modifiers);
    let height = f64::from(response.rect.height().max(1.0));
    let navigating =
        response.dragged_by(PointerButton::Middle) || (modifiers.alt && response.dragged_by(PointerButton::Primary));
    let mut moved = false;
    if navigating {
        let delta = response.drag_delta();
        let (dx, dy) = (f64::from(delta.x), f64::from(delta.y));
        if modifiers.shift {
            camera.pan_pixels(dx, dy, height);
        } else if modifiers.ctrl || modifiers.command {
            camera.zoom((dy * 0.01).exp());
        } else {
            camera.orbit(-dx * ORBIT_DEGREES_PER_POINT, dy * ORBIT_DEGREES_PER_POINT);
        }
        moved = delta != egui::Vec2::ZERO;
    }
    if modifiers.alt
        && response.clicked_by(PointerButton::Middle)
        && let Some(pos) = response.interact_pointer_pos()
    {
        frame_under(camera, document, viewport, pos, status);
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
        let pointer = ui.input(|i| i.pointer.hover_pos()).filter(|_| zoom_to_cursor);
        let mut zoom = |factor: f64| match pointer {
            Some(pos) => {
                let [x, y] = viewport.view_px(pos);
                let [w, h] = viewport.size_px();
                camera.zoom_towards_pixel(factor, x, y, w, h);
            }
            None => camera.zoom(factor),
        };
        if lines != 0.0 {
            zoom(ZOOM_PER_WHEEL_LINE.powf(f64::from(lines)));
            moved = true;
        }
        if pinch != 1.0 && pinch.is_finite() && pinch > 0.0 {
            zoom(1.0 / f64::from(pinch));
            moved = true;
        }
    }
    if moved && let Some(open) = document {
        camera.fit_depth_to(open.bounds);
    }
}

/// The brush in paint mode: the left button paints (not with Alt, which navigates).
/// Records the pointer in `session`; returns the stroke's commands. Nothing paints while a
/// gesture runs or a dialog is open (`dialog_open`).
pub fn paint_input(
    ui: &egui::Ui,
    response: &egui::Response,
    session: &mut PaintSession,
    dialog_open: bool,
) -> Vec<Command> {
    let (pressed, down, latest, alt) =
        ui.input(|i| (i.pointer.primary_pressed(), i.pointer.primary_down(), i.pointer.latest_pos(), i.modifiers.alt));
    if let Some(pos) = response.hover_pos() {
        session.last_pointer = Some(pos);
    }
    if session.swallow_primary {
        session.swallow_primary = down;
        return Vec::new();
    }
    if session.gesture.is_some() || dialog_open {
        return Vec::new();
    }
    let mut commands = Vec::new();
    let stroking = session.painter.is_stroking();
    if !stroking && pressed && !alt && response.hovered() {
        if let Some(pos) = latest {
            commands.push(Command::BeginStroke(pos));
        }
    } else if stroking && let Some(pos) = latest {
        commands.push(Command::StrokeTo(pos));
    }
    if !down {
        commands.push(Command::EndStroke);
    }
    commands
}

/// Frames the whole of `bounds` with `camera`, keeping the viewing angles; the sphere fits
/// the narrower of the 3D view's two fields of view.
pub fn frame_all(camera: &mut OrbitCamera, bounds: BoundingSphere, viewport: &ViewportState) {
    let (yaw, pitch) = (camera.yaw_degrees, camera.pitch_degrees);
    let mut framed = OrbitCamera { up: camera.up, ..OrbitCamera::framing(bounds, yaw, pitch) };
    let [w, h] = viewport.size_px();
    let aspect = f64::from(w) / f64::from(h.max(1));
    if aspect < 1.0 {
        let half_y = (framed.fov_y_degrees.to_radians() * 0.5).tan();
        let half_x = (half_y * aspect).atan();
        framed.distance = bounds.radius / half_x.sin() * 1.1;
    }
    *camera = framed;
}

/// Turns `camera` to `up` when it has another up axis, framing `bounds` (the open mesh's)
/// again.
pub fn follow_up_axis(camera: &mut OrbitCamera, up: UpAxis, bounds: Option<BoundingSphere>, viewport: &ViewportState) {
    if camera.up != up {
        camera.up = up;
        if let Some(bounds) = bounds {
            frame_all(camera, bounds, viewport);
        }
    }
}

/// Centres `camera` on the surface point of `document` under `pos` (points, window
/// coordinates) and halves the distance to it. Reports a miss on `status`.
pub fn frame_under(
    camera: &mut OrbitCamera,
    document: Option<&OpenDocument>,
    viewport: &ViewportState,
    pos: egui::Pos2,
    status: &mut Status,
) {
    let Some((open, hit)) = document.and_then(|open| Some((open, pick(open, camera, viewport, pos)?))) else {
        status.set(Severity::Info, "Nothing under the cursor to frame.");
        return;
    };
    let distance = (camera.eye() - hit).length() * 0.5;
    camera.look_at_point(hit, distance);
    camera.fit_depth_to(open.bounds);
}

/// The surface point of `open` under `pos` (points, window coordinates) seen through
/// `camera`, if the ray hits the mesh.
pub fn pick(open: &OpenDocument, camera: &OrbitCamera, viewport: &ViewportState, pos: egui::Pos2) -> Option<DVec3> {
    if !viewport.rect.contains(pos) {
        return None;
    }
    let [x, y] = viewport.view_px(pos);
    let [w, h] = viewport.size_px();
    let (origin, direction) = camera.ray_through_pixel(x, y, w, h);
    let hit = open.bvh.cast(origin, direction, f64::INFINITY)?;
    Some(DVec3::from_array(hit.position_world))
}
