//! Seams of a Mesh Color Texture at level 0, per colour format: the largest jump between the
//! two sides of every edge (both evaluated with the CPU evaluation of hardware bilinear,
//! `MeshColorTexture::sample_level`) and the largest difference from the CPU reference
//! sampler along edges, in 8-bit steps (linear colour × 255), with the ring texels the build
//! clamped (docs/MCT.md, "RGBA8 rings").
//! `cargo run -p meshpaint-core --example mct_seams -- assets/models/Duck/Duck.glb`

use std::collections::HashMap;
use std::path::PathBuf;

use anyhow::{Context, Result};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::Document;
use meshpaint_core::mct;
use meshpaint_core::packing::sampler::{Filter, sample};

/// Points per edge.
const SEGMENTS: u32 = 128;

fn main() -> Result<()> {
    let path = std::env::args_os().nth(1).map(PathBuf::from).context("usage: mct_seams FILE")?;
    println!(
        "| R | format | ring texels clamped | largest clamp | largest jump across an edge | largest difference from the reference on edges |"
    );
    println!("|---|---|---|---|---|---|");
    for log2 in 0..=3u32 {
        let document = Document::open(&path, Resolution::new(1 << log2).context("resolution")?)?;
        for format in [ColorFormat::Rgba8Srgb, ColorFormat::Rgba16F, ColorFormat::Rgba32F] {
            let packed = document.pack(format)?;
            let texture = mct::build(&packed, 16384, u64::MAX)?;
            let mut sides: HashMap<(u32, u32), Vec<(u32, usize)>> = HashMap::new();
            for (face, c) in packed.indices.iter().enumerate() {
                for k in 0..3 {
                    let (a, b) = (c[k], c[(k + 1) % 3]);
                    sides.entry((a.min(b), a.max(b))).or_default().push((face as u32, k));
                }
            }
            let (mut jump, mut off) = (0.0f32, 0.0f32);
            for ((lo, _), faces) in &sides {
                for n in 0..=SEGMENTS {
                    let t = n as f32 / SEGMENTS as f32;
                    let mut colors = Vec::with_capacity(2);
                    for &(face, k) in faces {
                        let c = packed.indices[face as usize];
                        let from_lo = c[k] == *lo;
                        let mut w = [0.0; 3];
                        w[k] = if from_lo { 1.0 - t } else { t };
                        w[(k + 1) % 3] = if from_lo { t } else { 1.0 - t };
                        let (Some(m), Some(reference)) =
                            (texture.sample_level(face, w, 0), sample(&packed, face, w, Filter::Linear, 0))
                        else {
                            continue;
                        };
                        off = off.max((0..4).map(|i| (m[i] - reference[i]).abs()).fold(0.0, f32::max));
                        colors.push(m);
                    }
                    if let [a, b] = colors[..] {
                        jump = jump.max((0..4).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max));
                    }
                }
            }
            println!(
                "| {} | {} | {} of {} | {:.3} | {:.2} | {:.2} |",
                1 << log2,
                format.name(),
                texture.stats.clamped_ring_texels,
                texture.stats.ring_texels,
                texture.stats.max_ring_clamp,
                jump * 255.0,
                off * 255.0
            );
        }
    }
    Ok(())
}
