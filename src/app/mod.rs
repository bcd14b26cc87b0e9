//! The desktop editor: a window with the 3D view behind egui panels.
//!
//! `meshpaint` with no argument opens the built-in Duck, `meshpaint FILE` opens FILE.
//! This module is the shell where the library, egui, winit and wgpu meet:
//!
//! The files form layers; each uses only the layers below it (`tests/architecture.rs`
//! checks that no two files import each other):
//!
//! | layer | file | role |
//! |---|---|---|
//! | 5 | [`window`] | winit event loop, surface, egui-winit / egui-wgpu, offscreen 3D view, redraw scheduling |
//! | 4 | [`input`] | all input: shortcuts ([`input::SHORTCUTS`]), 3D-view navigation, [`input::perform`] (every [`Action`]) |
//! | 3 | [`panels`], [`paint`], [`optimize_ui`], [`autosave_ui`] | the `*_ui` panels; paint-mode commands (strokes, live GPU upload, undo / redo, tool panel); Optimize on a worker thread; autosave tick and recovery dialog |
//! | 2 | [`editor`] | the editor: document, camera, view settings, mode, status, jobs (applied by [`jobs::JobKind`]) |
//! | 1 | [`document`], [`autosave`], [`paint_session`] | the open document (store and GPU mesh side by side; open, save, export work); autosave state; paint-mode state |
//! | 0 | [`state`], [`jobs`], [`text`], [`file_dialog`], [`import_settings`] | shared small types and [`Action`]s; one background job at a time with progress; number / error text; an egui file browser; the open dialog's resolution choice |
//!
//! Paint mode is [`Mode::Paint`] (Tab, [`input::SHORTCUTS`]): its tools get the pointer in
//! [`input::viewport_input`], edit the store through `Arc::make_mut` on
//! [`document::OpenDocument::document`] (jobs hold their own snapshot), upload dirty samples
//! with `GpuMesh::write_samples` on the document's `gpu_mesh`, bump
//! [`Editor::scene_generation`] so the view redraws, and repack when the mode is left.

pub mod autosave;
pub mod autosave_ui;
pub mod document;
pub mod editor;
pub mod file_dialog;
pub mod import_settings;
pub mod input;
pub mod jobs;
pub mod optimize_ui;
pub mod paint;
pub mod paint_session;
pub mod panels;
pub mod state;
pub mod text;
pub mod window;

pub use editor::Editor;
pub use state::{Action, Mode, Severity};
pub use window::{AppOptions, run};
