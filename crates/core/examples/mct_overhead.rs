//! GPU bytes of the Mesh Color Texture against the mesh-colors buffers, per uniform `R`
//! (docs/MCT.md, "GPU bytes"), lone faces, and the share of atlas texels some block uses.
//! `cargo run -p meshpaint-core --example mct_overhead -- assets/models/Duck/Duck.glb`

use std::path::PathBuf;

use anyhow::{Context, Result};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::Document;
use meshpaint_core::mct;

fn main() -> Result<()> {
    let path = std::env::args_os().nth(1).map(PathBuf::from).context("usage: mct_overhead FILE [FORMAT]")?;
    let format = match std::env::args().nth(2).as_deref() {
        Some("16f") => ColorFormat::Rgba16F,
        Some("32f") => ColorFormat::Rgba32F,
        _ => ColorFormat::Rgba8Srgb,
    };
    println!("| R | faces | lone faces | atlas | MCT bytes | mesh colors bytes | ratio | texels used |");
    println!("|---|---|---|---|---|---|---|---|");
    for log2 in 0..=6u32 {
        let resolution = Resolution::new(1 << log2).context("resolution")?;
        let document = Document::open(&path, resolution)?;
        let packed = document.pack(format)?;
        let texture = mct::build(&packed, 16384, u64::MAX)?;
        let mesh_colors = packed.face_record_bytes() + packed.color_bytes();
        let used = occupied_texels(&texture);
        println!(
            "| {} | {} | {} | {}×{} | {} | {} | {:.3} | {:.3} |",
            1 << log2,
            packed.indices.len(),
            texture.layout.pairs.iter().flatten().filter(|p| p[1] == u32::MAX).count(),
            texture.layout.width,
            texture.layout.height,
            texture.gpu_bytes(),
            mesh_colors,
            texture.gpu_bytes() as f64 / mesh_colors as f64,
            used as f64 / texture.layout.texel_count() as f64,
        );
    }
    Ok(())
}

/// Distinct atlas texels some block's lattice or ring covers, at every level.
fn occupied_texels(texture: &mct::MeshColorTexture) -> u64 {
    let layout = &texture.layout;
    let mut used = vec![false; layout.texel_count() as usize];
    for list in &layout.pairs {
        for pair in list {
            let lone = pair[1] == u32::MAX;
            for &face in pair.iter().filter(|&&f| f != u32::MAX) {
                for level in 0..layout.levels {
                    let Some(frame) = layout.frame(face, level) else { continue };
                    let ring = level == 0 || lone;
                    for beta in 0..=frame.r + 1 {
                        for alpha in 0..=frame.r + 1 - beta {
                            if alpha + beta == frame.r + 1 && (!ring || alpha == 0 || beta == 0) {
                                continue;
                            }
                            let [x, y] = frame.texel(alpha, beta);
                            used[(y as u64 * u64::from(layout.width) + x as u64) as usize] = true;
                        }
                    }
                }
            }
        }
    }
    used.iter().filter(|&&u| u).count() as u64
}
