//! The scene panel: triangles, samples, memory, uploads, fps and the last repack time, and
//! whether the 3D view redraws every frame (to measure fps).

use crate::app::document::OpenDocument;
use crate::app::state::FrameStats;
use crate::app::text::{human_bytes, thousands};

/// What the scene panel reads of the editor.
#[derive(Debug, Clone, Copy)]
pub struct SceneContext<'a> {
    /// The open document, if any.
    pub document: Option<&'a OpenDocument>,
    /// GPU memory in use.
    pub gpu_bytes: u64,
    /// Bytes uploaded to the GPU during the previous frame.
    pub upload_bytes_last_frame: u64,
    /// Frame timing.
    pub frame_stats: &'a FrameStats,
    /// The GPU adapter's name (`None` without a GPU).
    pub gpu_name: Option<&'a str>,
}

/// The scene panel.
#[derive(Debug, Default)]
pub struct ScenePanel {
    /// Redraw every frame (to measure fps) instead of only when something changes.
    pub continuous_redraw: bool,
}

impl ScenePanel {
    /// The statistics grid and the "Redraw continuously" switch.
    pub fn ui(&mut self, ui: &mut egui::Ui, ctx: SceneContext<'_>) {
        egui::Grid::new("scene stats").num_columns(2).spacing([12.0, 4.0]).striped(true).show(ui, |ui| {
            let row = |ui: &mut egui::Ui, name: &str, value: String| {
                ui.label(name);
                ui.label(value);
                ui.end_row();
            };
            match ctx.document {
                Some(open) => {
                    let store = &open.document.store;
                    let resolutions = store.face_resolutions();
                    let min = resolutions.iter().map(|r| r.get()).min().unwrap_or(1);
                    let max = resolutions.iter().map(|r| r.get()).max().unwrap_or(1);
                    row(ui, "Document", open.title.clone());
                    row(ui, "Triangles", thousands(u64::from(open.triangles())));
                    row(ui, "Vertices", thousands(open.document.positions.len() as u64));
                    row(ui, "Resolution R", if min == max { min.to_string() } else { format!("{min} … {max}") });
                    row(ui, "Samples", thousands(open.samples));
                    row(ui, "With MIP chains", thousands(open.samples_with_mips));
                    row(ui, "Colour format", open.format.name().to_owned());
                    row(ui, "Packed size", human_bytes(open.packed_bytes));
                    row(ui, "Last repack", format!("{:.1} ms", open.last_repack.as_secs_f64() * 1000.0));
                }
                None => row(ui, "Document", "none".into()),
            }
            row(ui, "GPU memory", human_bytes(ctx.gpu_bytes));
            row(ui, "Uploaded last frame", human_bytes(ctx.upload_bytes_last_frame));
            let stats = ctx.frame_stats;
            let fps = if stats.fps > 0.0 { format!("{:.1}", stats.fps) } else { "–".into() };
            row(ui, "fps", fps);
            row(ui, "Frame time", format!("{:.1} ms", stats.frame_ms));
            if let Some(name) = ctx.gpu_name {
                row(ui, "GPU", name.to_owned());
            }
        });
        ui.checkbox(&mut self.continuous_redraw, "Redraw continuously")
            .on_hover_text("Redraw every frame to measure fps (otherwise only when something changes)");
    }
}
