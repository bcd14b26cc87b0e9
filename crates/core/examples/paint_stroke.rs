//! Paints one brush stroke on a mesh on the CPU (no GPU) and saves a packed file:
//! `cargo run -p meshpaint-core --example paint_stroke -- [input.glb|.mpk] [output.mpk]`
//! (default: the Duck, written to painted.mpk).

use std::path::{Path, PathBuf};

use anyhow::Result;
use meshpaint_core::camera::{BoundingSphere, DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, default_camera};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::file::write_file;
use meshpaint_core::paint::brush::{BrushSettings, PaintView, Painter, replay_stroke};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;

/// The brush colour (linear RGBA).
pub const COLOR: [f32; 4] = [0.9, 0.05, 0.05, 1.0];

/// Opens `input` (glTF at R = 8, or packed), paints a red stroke across the middle of an
/// 800 × 600 view and writes `output` as a packed RGBA8 file. Returns the samples changed.
pub fn paint_stroke(input: &Path, output: &Path) -> Result<u64> {
    let mut document = Document::open(input, Resolution::new(8)?)?;
    let bvh = MeshBvh::build(&document.positions, &document.store.topology().face_vertices, BvhPreset::default());
    let bounds = BoundingSphere::of_points(&document.positions);
    let camera = default_camera(bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None);
    let base = document.store.clone();
    let view = PaintView {
        positions: &document.positions,
        bvh: &bvh,
        camera: &camera,
        viewport_px: [800, 600],
        base: Some(&base),
    };
    let mut painter = Painter::new(&document.positions);
    painter.set_settings(BrushSettings { color: COLOR, ..BrushSettings::default() });
    let stroke = [[250.0, 300.0], [400.0, 320.0], [550.0, 300.0]];
    let mut history = UndoHistory::default();
    let (update, _) = replay_stroke(&mut painter, &view, &mut document.store, &mut history, &stroke)?;
    write_file(output, &document.pack(ColorFormat::Rgba8Srgb)?)?;
    Ok(update.stats.samples_changed)
}

fn main() -> Result<()> {
    let mut args = std::env::args_os().skip(1).map(PathBuf::from);
    let duck = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/models/Duck/Duck.glb");
    let input = args.next().unwrap_or(duck);
    let output = args.next().unwrap_or_else(|| PathBuf::from("painted.mpk"));
    let changed = paint_stroke(&input, &output)?;
    println!("{} → {}: {changed} samples changed", input.display(), output.display());
    Ok(())
}
