//! Opens a mesh, packs its mesh colors, uploads them and renders one image offscreen on the
//! GPU (lavapipe without one), written as a PNG:
//! `cargo run --example render_offscreen -- [input.glb|.mpk] [output.png]`
//! (default: the Duck, written to render.png).

use std::path::{Path, PathBuf};

use anyhow::Result;
use meshpaint::camera::{BoundingSphere, OrbitCamera};
use meshpaint::colors::format::ColorFormat;
use meshpaint::colors::layout::Resolution;
use meshpaint::io::document::Document;
use meshpaint::render::{DrawItem, GpuContext, GpuMesh, MeshUploadOptions, OFFSCREEN_FORMAT};
use meshpaint::render::{RenderSettings, Renderer};

/// Renders `input` (glTF at R = 8, or packed) lit and trilinear at `width × height` and
/// writes the image to `output` (the format follows the extension). Returns the adapter.
pub fn render_offscreen(input: &Path, output: &Path, width: u32, height: u32) -> Result<String> {
    let document = Document::open(input, Resolution::new(8)?)?;
    let packed = document.pack(ColorFormat::Rgba8Srgb)?;
    let ctx = GpuContext::new_headless()?;
    let renderer = Renderer::new(&ctx, OFFSCREEN_FORMAT)?;
    let mesh = GpuMesh::upload(&ctx, &renderer, &packed, &MeshUploadOptions::default())?;
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&document.positions), 30.0, 20.0);
    let settings = RenderSettings::new(camera);
    let image = renderer.render_image(&ctx, DrawItem::MeshColors(&mesh), &settings, width, height)?;
    image.save(output)?;
    Ok(ctx.describe())
}

fn main() -> Result<()> {
    let mut args = std::env::args_os().skip(1).map(PathBuf::from);
    let duck = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/models/Duck/Duck.glb");
    let input = args.next().unwrap_or(duck);
    let output = args.next().unwrap_or_else(|| PathBuf::from("render.png"));
    let adapter = render_offscreen(&input, &output, 800, 600)?;
    println!("{} → {} ({adapter})", input.display(), output.display());
    Ok(())
}
