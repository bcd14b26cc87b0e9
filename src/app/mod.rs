//! The desktop editor: a window with the 3D view behind egui panels.
//!
//! `meshpaint` with no argument opens the built-in Duck, `meshpaint FILE` opens FILE.
//! This module is the shell where the library, egui, winit and wgpu meet:
//!
//! The files form layers; each uses only the layers below it (`tests/app/architecture.rs`
//! checks that no two files import each other). Panels and input never reach into the
//! editor: they get what they read as arguments and return [`Action`]s and
//! [`Command`](command::Command)s, which the editor carries out in one place.
//!
//! | layer | file | role |
//! |---|---|---|
//! | 7 | [`window`] | winit event loop, surface, egui-winit / egui-wgpu, offscreen 3D view, redraw scheduling |
//! | 6 | [`view_draw`] | the 3D view drawn into its offscreen target: whole, or after paint uploads only the faces that changed (partial redraw) |
//! | 5 | [`editor`], [`editor_settings`], [`editor_export`], [`editor_jobs`] | [`Editor`]: the document, camera, panels, 3D view state, status, jobs; one frame of UI ([`Editor::ui`]); every [`Action`] ([`Editor::perform`]) and [`command::Command`] ([`Editor::apply`]) carried out; finished jobs applied by [`jobs::JobKind`] (a failed or cancelled one: [`editor_jobs`]); open and quit ask Save / Don't save / Cancel while changes are unsaved; the settings remembered between runs read from and written to the panels; File → Export… carried out |
//! | 4 | [`paint`] | paint-mode commands on the document: strokes, live GPU upload, undo / redo, eyedropper, fill, resolution, Optimize, radius / strength gestures, brush cursor |
//! | 3 | [`panels`], [`job_output`] | each panel a type that owns its state and draws itself, returning commands (menu, status line, file, export, import settings, autosave, view, paint, optimize, undo, scene, help, 3D view area); what jobs produce |
//! | 2 | [`session`], [`input`], [`autosave`], [`file_dialog`] | the document being edited ([`session::DocumentState`]: open document, paint session, undo history); all input (shortcuts [`input::SHORTCUTS`], 3D-view navigation, the brush's pointer); autosave state; an egui file browser |
//! | 1 | [`document`], [`export`], [`command`], [`import_settings`], [`settings`] | the open document (store and GPU mesh side by side; open, save, export work); File → Export…'s choices, their costs and work (baked texture, tessellated glTF, packed file); the commands panels return; the import settings panel (the open dialog's resolution choice, the up axis); the settings file |
//! | 0 | [`state`], [`jobs`], [`text`], [`widgets`], [`paint_session`], [`unsaved`], [`recent_colors`], [`presets`] | shared small types and [`Action`]s; one background job at a time with progress; number / error text; the resolution combo box; paint-mode state; the actions that wait for "save changes first?"; the recent colours; the brush presets |
//!
//! Paint mode is [`Mode::Paint`] (Tab, [`input::SHORTCUTS`]): its tools get the pointer in
//! [`input::paint_input`], edit the store through `Arc::make_mut` on
//! [`document::OpenDocument::document`] (jobs hold their own snapshot), upload dirty samples
//! with `GpuMesh::write_samples` on the document's `gpu_mesh`, bump
//! [`state::ViewportState::scene_generation`] so the view redraws, and repack when the mode
//! is left.

pub mod autosave;
pub mod command;
pub mod document;
pub mod editor;
pub mod editor_export;
pub mod editor_jobs;
pub mod editor_settings;
pub mod export;
pub mod file_dialog;
pub mod import_settings;
pub mod input;
pub mod job_output;
pub mod jobs;
pub mod paint;
pub mod paint_session;
pub mod panels;
pub mod presets;
pub mod recent_colors;
pub mod session;
pub mod settings;
pub mod state;
pub mod text;
pub mod unsaved;
pub mod view_draw;
pub mod widgets;
pub mod window;

pub use command::Command;
pub use editor::Editor;
pub use state::{Action, Mode, Severity};
pub use window::{AppOptions, run};
