//! The desktop editor: a window with the 3D view behind egui panels.
//!
//! `meshpaint` with no argument opens the built-in Duck, `meshpaint FILE` opens FILE.
//! This module is the shell where the library, egui, winit and wgpu meet:
//!
//! | file | role |
//! |---|---|
//! | [`window`] | winit event loop, surface, egui-winit / egui-wgpu, offscreen 3D view, redraw scheduling |
//! | [`editor`] | editor state: document, camera, view settings, mode, status, jobs; [`Action`]s |
//! | [`panels`] | the `*_ui` functions: menu bar, file / view / scene panels, status line, help |
//! | [`input`] | all input: shortcuts ([`input::SHORTCUTS`]) and 3D-view navigation |
//! | [`loaded`] | the open document (store and GPU mesh side by side); open, save, export work |
//! | [`jobs`] | one background job at a time with progress; panics become messages |
//! | [`file_dialog`] | an egui file browser (works under Xvfb, keyboard-drivable) |
//! | [`paint`] | paint mode: brush strokes, live GPU upload, undo / redo, tool panel |
//! | [`autosave_ui`] | periodic autosave and the recovery offer |
//!
//! Paint mode is [`Mode::Paint`] (Tab, [`input::SHORTCUTS`]): its tools get the pointer in
//! [`input::viewport_input`], edit the store through `Arc::make_mut` on
//! [`loaded::OpenDocument::document`] (jobs hold their own snapshot), upload dirty samples
//! with `GpuMesh::write_samples` on the document's `gpu_mesh`, bump
//! [`Editor::scene_generation`] so the view redraws, and repack when the mode is left.

pub mod autosave_ui;
pub mod editor;
pub mod file_dialog;
pub mod input;
pub mod jobs;
pub mod loaded;
pub mod paint;
pub mod panels;
pub mod window;

pub use editor::{Action, Editor, Mode, Severity};
pub use window::{AppOptions, run};
