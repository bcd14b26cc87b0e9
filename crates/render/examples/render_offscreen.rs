//! Opens a mesh for display (packed with MIP chains), uploads it and renders one image offscreen on the
//! GPU (lavapipe without one), written as a PNG:
//! `cargo run -p meshpaint-render --example render_offscreen -- [input.glb|.mpk] [output.png]`
//! (default: the Duck, written to render.png).

use std::path::{Path, PathBuf};

use anyhow::Result;
use meshpaint_core::camera::{DEFAULT_PITCH_DEGREES, DEFAULT_YAW_DEGREES, default_camera};
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::display::{OpenOptions, open_for_display};
use meshpaint_core::io::document::Source;
use meshpaint_core::progress::Reporter;
use meshpaint_render::{DrawItem, Gpu, RenderSettings};

/// Renders `input` (glTF at R = 8, or packed; in its own colour format) lit and trilinear at `width × height` and
/// writes the image to `output` (the format follows the extension). Returns the adapter.
pub fn render_offscreen(input: &Path, output: &Path, width: u32, height: u32) -> Result<String> {
    let source = Source::File(input.to_owned());
    let gpu = Gpu::new_headless()?;
    let options = OpenOptions::new(Resolution::new(8)?, Budget::from_environment().with_gpu(gpu.budget_limits()));
    let mesh = open_for_display(&source, &options, Reporter::silent().progress(), |packed| gpu.upload(packed))?.upload;
    let camera = default_camera(mesh.bounds, DEFAULT_YAW_DEGREES, DEFAULT_PITCH_DEGREES, None);
    let image = gpu.render_image(DrawItem::MeshColors(&mesh), &RenderSettings::new(camera), width, height)?;
    image.save(output)?;
    Ok(gpu.describe())
}

fn main() -> Result<()> {
    let mut args = std::env::args_os().skip(1).map(PathBuf::from);
    let duck = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/models/Duck/Duck.glb");
    let input = args.next().unwrap_or(duck);
    let output = args.next().unwrap_or_else(|| PathBuf::from("render.png"));
    let adapter = render_offscreen(&input, &output, 800, 600)?;
    println!("{} → {} ({adapter})", input.display(), output.display());
    Ok(())
}
