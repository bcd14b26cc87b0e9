//! The editor's tests in one binary: its UI driven without a window (egui_kittest) and the
//! real window under Xvfb.

mod common;

mod app_ui;
mod app_ui_convert;
mod app_ui_tools;
mod app_window;
mod partial_redraw;
