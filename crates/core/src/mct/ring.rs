//! Which corner a pair's tents put their right angle at (level 0), chosen so that RGBA8 ring
//! texels need no clamping where either choice allows it.
//!
//! A tent's faces have their right angle at `p`, one end of the shared edge, so each face's
//! hypotenuse — followed by its ring of texels `c₃ = c₁ + c₂ − c₀` — is the edge from its third
//! corner to `q`. Putting the right angle at `q` instead moves both hypotenuses to the edges
//! ending at `p`: other cells, other extrapolations. An RGBA8 ring texel outside `[0, 1]` is
//! clamped and the hypotenuse then misses mesh colors' linear filter by up to a quarter of the
//! clamp (a seam jump); RGBA16F and RGBA32F store rings as they are, so only RGBA8 chooses.

use crate::colors::format::{ColorFormat, Rgba};
use crate::packing::linear::PackedMesh;
use crate::packing::sampler::{Filter, sample};

/// How far the rings of `faces` (a pair, or a lone face and `u32::MAX`) leave `[0, 1]` with
/// the right angle at vertex `p` and `q` the other end of the shared edge (block resolution
/// `r`): the largest excess, then the sum.
fn ring_excess(packed: &PackedMesh, faces: [u32; 2], p: u32, q: u32, r: u32) -> (f32, f32) {
    let (mut worst, mut sum) = (0.0f32, 0.0f32);
    for &face in faces.iter().filter(|&&f| f != u32::MAX) {
        let Some(corners) = packed.indices.get(face as usize) else { continue };
        let find = |v: u32| corners.iter().position(|&c| c == v);
        let (Some(cp), Some(cq)) = (find(p), find(q)) else { continue };
        let ct = 3 - cp - cq;
        let lattice = |alpha: u32, beta: u32| -> Option<Rgba> {
            let mut w = [0.0f32; 3];
            w[cp] = (r - alpha - beta) as f32 / r as f32;
            w[ct] = alpha as f32 / r as f32;
            w[cq] = beta as f32 / r as f32;
            sample(packed, face, w, Filter::Linear, 0)
        };
        for alpha in 1..=r {
            let beta = r + 1 - alpha;
            let (Some(c00), Some(c10), Some(c01)) =
                (lattice(alpha - 1, beta - 1), lattice(alpha, beta - 1), lattice(alpha - 1, beta))
            else {
                continue;
            };
            for c in 0..4 {
                let ring = c10[c] + c01[c] - c00[c];
                let excess = (-ring).max(ring - 1.0).max(0.0);
                worst = worst.max(excess);
                sum += excess;
            }
        }
    }
    (worst, sum)
}

/// Whether the tents of pair `faces` (shared edge `p → q`, block resolution `r`) should put
/// their right angle at `q` rather than `p`: only in RGBA8, and only when that clamps less.
pub(super) fn right_angle_at_q(packed: &PackedMesh, faces: [u32; 2], p: u32, q: u32, r: u32) -> bool {
    if packed.format != ColorFormat::Rgba8Srgb {
        return false;
    }
    let at_p = ring_excess(packed, faces, p, q, r);
    if at_p.0 <= 0.0 {
        return false;
    }
    let at_q = ring_excess(packed, faces, q, p, r);
    at_q.0 < at_p.0 || (at_q.0 == at_p.0 && at_q.1 < at_p.1)
}
