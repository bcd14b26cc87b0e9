//! `meshpaint synth`: writes a production-like test asset (crates/core/src/synth/production)
//! as a binary glTF and prints one JSON object describing it.

use std::path::PathBuf;

use anyhow::{Context, Result};

use meshpaint_core::synth::production::{AssetClass, Options, generate, glb};

/// Arguments of `meshpaint synth`.
#[derive(Debug, clap::Args)]
pub(super) struct SynthArgs {
    /// truck (large faces with text and a logo), materials (nine materials with and without
    /// textures, vertex colours) or islands (a dense boulder with UV islands 1/8…2× in density).
    #[arg(value_parser = parse_class)]
    class: AssetClass,
    /// Output .glb file.
    #[arg(long, short = 'o')]
    output: PathBuf,
    /// Triangles: exact for islands (even, default 50000), about for truck (default 6000);
    /// materials ignores it.
    #[arg(long)]
    triangles: Option<u32>,
    /// Side of the main texture in texels (truck, islands; a power of two, default 2048).
    #[arg(long)]
    texture_size: Option<u32>,
}

fn parse_class(name: &str) -> Result<AssetClass, String> {
    AssetClass::from_name(name).ok_or_else(|| format!("unknown asset class '{name}' (truck, materials, islands)"))
}

pub(super) fn run(args: SynthArgs) -> Result<()> {
    let SynthArgs { class, output, triangles, texture_size } = args;
    let asset = generate(class, Options { triangles, texture_size })?;
    let bytes = glb(&asset)?;
    meshpaint_core::atomic_write::write_atomically(&output, &bytes)
        .with_context(|| format!("writing {}", output.display()))?;
    let scene = &asset.scene;
    let summary = serde_json::json!({
        "class": class.name(),
        "output": output.display().to_string(),
        "bytes": bytes.len(),
        "triangles": asset.triangles(),
        "meshes": scene.meshes.len(),
        "instances": scene.instances.len(),
        "materials": scene.materials.len(),
        "textures": scene.textures.iter().map(|t| [t.width, t.height]).collect::<Vec<_>>(),
        "regions": asset.regions.iter().map(|r| r.to_json()).collect::<Vec<_>>(),
    });
    println!("{summary}");
    Ok(())
}
