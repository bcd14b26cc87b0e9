//! The largest colour jump across the intrinsic edges of an Htex, evaluated on both sides
//! with the CPU evaluation ([`crate::htex::sample`]): mesh edges (a halfedge and its twin)
//! and spokes (a halfedge and its `Next`, from the face centroid to a vertex). The paper
//! says Htex is continuous everywhere but at corner texels; this measures it.

use crate::colors::format::{Rgba, linear_to_srgb};
use crate::htex::HtexTexture;
use crate::htex::halfedge::{NONE, next};

/// Largest jump at one level, in 8-bit steps of the sRGB-encoded colour (alpha linear).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jumps {
    /// Across mesh edges (halfedge / twin).
    pub mesh_edges: f32,
    /// Across spokes (halfedge / `Next`).
    pub spokes: f32,
}

/// `|a − b|` in 8-bit steps: RGB sRGB-encoded, alpha linear, largest channel.
pub fn steps(a: Rgba, b: Rgba) -> f32 {
    (0..4)
        .map(|c| {
            let (x, y) = if c < 3 { (linear_to_srgb(a[c]), linear_to_srgb(b[c])) } else { (a[c], b[c]) };
            (x - y).abs() * 255.0
        })
        .fold(0.0, f32::max)
}

impl HtexTexture {
    /// The largest jumps at `level`, on `points` points per edge (both ends included:
    /// `s = i / (points − 1)`), within a corner texel of every end as well.
    pub fn jumps(&self, level: u32, points: u32) -> Jumps {
        use rayon::prelude::*;
        let points = points.max(2);
        let n_max = 1u32 << (self.layout.levels - 1).saturating_sub(level);
        // Uniform points plus points inside the corner texels at each end.
        let mut s: Vec<f32> = (0..points).map(|i| i as f32 / (points - 1) as f32).collect();
        for k in 1..4 {
            let d = k as f32 * 0.125 / n_max as f32;
            s.extend([d, 1.0 - d]);
        }
        let halfedges = self.layout.face_records.len() as u32 * 3;
        (0..halfedges)
            .into_par_iter()
            .map(|h| {
                let mut out = Jumps::default();
                let t = self.layout.halfedges.twin[h as usize];
                let n = next(h);
                for &s in &s {
                    if t != NONE && h > t {
                        let a = self.sample_halfedge(h, [1.0 - s, s], level);
                        let b = self.sample_halfedge(t, [s, 1.0 - s], level);
                        out.mesh_edges = out.mesh_edges.max(steps(a, b));
                    }
                    let a = self.sample_halfedge(h, [0.0, s], level);
                    let b = self.sample_halfedge(n, [s, 0.0], level);
                    out.spokes = out.spokes.max(steps(a, b));
                }
                out
            })
            .reduce(Jumps::default, |a, b| Jumps {
                mesh_edges: a.mesh_edges.max(b.mesh_edges),
                spokes: a.spokes.max(b.spokes),
            })
    }
}
