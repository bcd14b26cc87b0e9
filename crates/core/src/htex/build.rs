//! Filling the pages: every texel is the CPU reference sampler's linear filter of the
//! packed mesh colors at the texel's point and level; with corner equalisation, the four
//! corner texels of every block are the reference at the corner itself (a mesh vertex or
//! a face centroid), so that every block meeting at a corner holds the same value there
//! (paper §4.4, "Corner pre-processing"). Quads fill in parallel.

use crate::colors::format::Rgba;
use crate::htex::halfedge::{NONE, face_barycentric};
use crate::htex::layout::{HtexLayout, weight_block_x};
use crate::htex::{HtexError, HtexOptions, HtexTexture};
use crate::packing::linear::PackedMesh;
use crate::packing::sampler::{Filter, sample};
use rayon::prelude::*;

/// Builds the Htex of `packed` in `packed`'s colour format.
pub fn build(packed: &PackedMesh, options: &HtexOptions) -> Result<HtexTexture, HtexError> {
    let layout = HtexLayout::new(packed, options.max_dimension, options.max_pages)?;
    let format = packed.format;
    let bpp = format.bytes_per_sample() as u64;
    let bytes = layout.texel_count() * bpp;
    if bytes > options.max_bytes {
        return Err(HtexError::OverBudget { bytes, max_bytes: options.max_bytes });
    }
    let over = || HtexError::OverBudget { bytes, max_bytes: options.max_bytes };
    let mut texels = vec![0u8; usize::try_from(bytes).map_err(|_| over())?];
    let blocks: Vec<Vec<(u32, Vec<u8>)>> = (0..layout.halfedges.quads.len() as u32)
        .into_par_iter()
        .map(|q| fill_quad(packed, &layout, q, options.equalize_corners))
        .collect::<Result<_, _>>()?;
    let (page, height) = (u64::from(layout.page_size), u64::from(layout.page_height));
    for (q, levels) in blocks.iter().enumerate() {
        for (level, data) in levels {
            let n = u64::from(layout.size(q as u32, *level));
            let o = layout.origin(q as u32, *level);
            let row_bytes = (n * bpp) as usize;
            for j in 0..n {
                let texel = (u64::from(o.page) * height + u64::from(o.y) + 1 + j) * page + u64::from(o.x) + 1;
                let at = (texel * bpp) as usize;
                let src = (j as usize) * row_bytes;
                texels[at..at + row_bytes].copy_from_slice(&data[src..src + row_bytes]);
            }
        }
    }
    let weights = weight_texels(&layout);
    let vertex_density = crate::packing::lod::VertexLod::of(packed).density;
    Ok(HtexTexture { layout, format, texels, weights, vertex_density, equalized: options.equalize_corners })
}

/// The weight texture (R8): per resolution `2^s`, a block of 1s (255) framed by 0s.
pub fn weight_texels(layout: &HtexLayout) -> Vec<u8> {
    let [w, h] = layout.weight_size;
    let mut out = vec![0u8; (w * h) as usize];
    for s in 0..layout.levels {
        let (x0, n) = (weight_block_x(s), 1u32 << s);
        for j in 0..n {
            let start = ((j + 1) * w + x0 + 1) as usize;
            out[start..start + n as usize].fill(255);
        }
    }
    out
}

/// The halfedge and intrinsic `(u, v)` of quad point `p` of quad `[lower, upper]`: the
/// lower-left triangle is `lower`'s, the upper-right `upper`'s (`(1 − x, 1 − y)`), or for a
/// self-paired quad the mirror of the lower-left across the diagonal, `(1 − y, 1 − x)`.
pub fn quad_point_owner(quad: [u32; 2], p: [f32; 2]) -> (u32, [f32; 2]) {
    let [lower, upper] = quad;
    if p[0] + p[1] <= 1.0 {
        (lower, p)
    } else if upper != NONE {
        (upper, [1.0 - p[0], 1.0 - p[1]])
    } else {
        (lower, [1.0 - p[1], 1.0 - p[0]])
    }
}

/// The reference colour at quad point `p` of quad `q` at `level`.
pub fn reference_at(packed: &PackedMesh, layout: &HtexLayout, q: u32, p: [f32; 2], level: u32) -> Option<Rgba> {
    let (h, uv) = quad_point_owner(layout.halfedges.quads[q as usize], p);
    sample(packed, h / 3, face_barycentric(h, uv), Filter::Linear, level)
}

/// Quad point of texel `(i, j)` at side `n`, or the corner itself for a corner texel when
/// `equalize` (and `n ≥ 2`).
pub fn texel_point(i: u32, j: u32, n: u32, equalize: bool) -> [f32; 2] {
    let corner = |k: u32| {
        if k == 0 {
            Some(0.0)
        } else if k == n - 1 {
            Some(1.0)
        } else {
            None
        }
    };
    if equalize
        && n >= 2
        && let (Some(x), Some(y)) = (corner(i), corner(j))
    {
        return [x, y];
    }
    let nf = n as f32;
    [(i as f32 + 0.5) / nf, (j as f32 + 0.5) / nf]
}

/// Every level of quad `q`, encoded rows of `n_l` texels.
fn fill_quad(
    packed: &PackedMesh,
    layout: &HtexLayout,
    q: u32,
    equalize: bool,
) -> Result<Vec<(u32, Vec<u8>)>, HtexError> {
    let format = packed.format;
    let bpp = format.bytes_per_sample();
    let bad = || HtexError::BadRecord { face: layout.halfedges.quads[q as usize][0] / 3 };
    (0..layout.levels)
        .map(|level| {
            let n = layout.size(q, level);
            let mut data = vec![0u8; (n * n) as usize * bpp];
            for j in 0..n {
                for i in 0..n {
                    let p = texel_point(i, j, n, equalize);
                    let color = reference_at(packed, layout, q, p, level).ok_or_else(bad)?;
                    let at = ((j * n + i) as usize) * bpp;
                    format.encode_quantized(color, &mut data[at..at + bpp]);
                }
            }
            Ok((level, data))
        })
        .collect()
}
