//! Filling the packed texture: every interior texel is the CPU reference sampler's linear
//! filter at its centre and level; every border texel is the neighbour's texel beside the
//! shared edge (its block's row along that side, at the level the neighbour shows at the
//! same level of detail), resampled linearly along the edge where the neighbour's
//! resolution differs. A slice row of blocks (borders included) is a band of texture rows
//! no other block touches, and a border is computed from the neighbour's texels *values*
//! (the same function, quantised the same way) rather than read back, so the bands fill in
//! parallel.

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::sanitize_barycentric;
use crate::mct::strips::EdgeFaces;
use crate::packing::linear::PackedMesh;
use crate::packing::sampler::{Filter, sample};
use crate::ptex::layout::{PtexBlock, PtexLayout, SLICES, half_corners};
use crate::ptex::{PackedPtex, PtexError, PtexStats};
use rayon::prelude::*;

/// Builds the packed Ptex of `packed` in its colour format, in a texture at most
/// `max_dimension` texels on a side and `max_bytes` bytes (checked before allocating).
pub fn build(packed: &PackedMesh, max_dimension: u32, max_bytes: u64) -> Result<PackedPtex, PtexError> {
    let layout = PtexLayout::new(packed, max_dimension)?;
    let format = packed.format;
    let bpp = format.bytes_per_sample() as u64;
    let bytes = layout.texel_count() * bpp;
    if bytes > max_bytes {
        return Err(PtexError::OverBudget { bytes, max_bytes });
    }
    let mut texels = vec![0u8; usize::try_from(bytes).map_err(|_| PtexError::OverBudget { bytes, max_bytes })?];
    let edges = edge_faces(packed);
    let ctx = Ctx { packed, layout: &layout, edges: &edges, format };
    let row_bytes = u64::from(layout.width) * bpp;
    // Bands in y order: slices from the finest down, rows of blocks in each.
    let mut bands = Vec::new();
    for k in (0..SLICES as u32).rev() {
        let first = layout.tables.n_res[k as usize] as usize;
        let count = layout.blocks.len() - first;
        let per_row = layout.tables.per_row[k as usize].max(1) as usize;
        for row in 0..count.div_ceil(per_row) {
            let start = first + row * per_row;
            bands.push((k, start..(start + per_row).min(layout.blocks.len())));
        }
    }
    let band_bytes = |k: u32| ((1u64 << k) + 2) * row_bytes;
    let mut chunks = Vec::with_capacity(bands.len());
    let mut rest: &mut [u8] = &mut texels;
    for (k, _) in &bands {
        let (chunk, tail) = rest.split_at_mut(band_bytes(*k) as usize);
        chunks.push(chunk);
        rest = tail;
    }
    let stats = bands
        .par_iter()
        .zip(chunks.into_par_iter())
        .map(|((k, range), chunk)| {
            let mut stats = PtexStats::default();
            for block in range.clone() {
                fill_block(&ctx, block as u32, *k, chunk, row_bytes, &mut stats)?;
            }
            Ok(stats)
        })
        .try_reduce(PtexStats::default, |a, b| Ok(a.merged(b)))?;
    let vertex_density = crate::packing::lod::VertexLod::of(packed).density;
    Ok(PackedPtex { layout, format, texels, stats, vertex_density })
}

/// The faces of every manifold edge.
fn edge_faces(packed: &PackedMesh) -> EdgeFaces {
    let mut half: Vec<(u64, u32)> = packed
        .indices
        .par_iter()
        .enumerate()
        .flat_map_iter(|(face, c)| {
            (0..3).filter_map(move |k| {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                (a != b).then(|| ((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), face as u32))
            })
        })
        .collect();
    half.par_sort_unstable();
    EdgeFaces::new(half)
}

struct Ctx<'a> {
    packed: &'a PackedMesh,
    layout: &'a PtexLayout,
    edges: &'a EdgeFaces,
    format: ColorFormat,
}

/// A quantised texel: its bytes (at most RGBA32F's 16) and what they decode to.
#[derive(Clone, Copy)]
struct Texel {
    bytes: [u8; 16],
    color: Rgba,
}

impl Ctx<'_> {
    fn quantize(&self, color: Rgba) -> Texel {
        let mut bytes = [0u8; 16];
        let n = self.format.bytes_per_sample();
        let color = self.format.encode_quantized(color, &mut bytes[..n]);
        Texel { bytes, color }
    }

    /// The reference colour of interior texel `(a, c)` of `block` in slice `k`.
    fn interior(&self, block: u32, k: u32, a: u32, c: u32) -> Result<Texel, PtexError> {
        let b = &self.layout.blocks[block as usize];
        let level = b.log2 - k.min(b.log2);
        let n = (1u32 << k) as f32;
        let (u, v) = ((a as f32 + 0.5) / n, (c as f32 + 0.5) / n);
        let second = a + c + 1 > (1u32 << k);
        let (face, w) = half_weights(self.packed, b, second, [u, v]);
        let color = sample(self.packed, face, w, Filter::Linear, level).ok_or(PtexError::BadRecord { face })?;
        Ok(self.quantize(color))
    }
}

/// The face of `block`'s half `second` and its barycentrics at square point `uv` (outside
/// the half, one of them negative).
fn half_weights(packed: &PackedMesh, block: &PtexBlock, second: bool, [u, v]: [f32; 2]) -> (u32, [f32; 3]) {
    let [ct, cp, cq] = half_corners(packed, block, second);
    let mut w = [0.0f32; 3];
    if second {
        w[ct] = u + v - 1.0;
        w[cp] = 1.0 - v;
        w[cq] = 1.0 - u;
    } else {
        w[ct] = 1.0 - u - v;
        w[cp] = u;
        w[cq] = v;
    }
    (block.faces[usize::from(second)], w)
}

/// Sides of a block: bottom, right, top, left. Each: its two square corners (index into
/// `PtexBlock::corners`, from the start of the along-edge parameter to its end), the half
/// owning it, and the interior texel beside it / the border texel of along-edge index `i`.
const SIDES: [([usize; 2], bool); 4] = [([0, 1], false), ([1, 2], true), ([3, 2], true), ([0, 3], false)];

fn side_texel(side: usize, n: i64, i: i64, border: bool) -> [i64; 2] {
    let (lo, hi) = if border { (-1, n) } else { (0, n - 1) };
    match side {
        0 => [i, lo],
        1 => [hi, i],
        2 => [i, hi],
        _ => [lo, i],
    }
}

/// Fills `block`'s slice-`k` interior and border into the band `chunk` (rows of the slice
/// row holding the block).
fn fill_block(
    ctx: &Ctx<'_>,
    block: u32,
    k: u32,
    chunk: &mut [u8],
    row_bytes: u64,
    stats: &mut PtexStats,
) -> Result<(), PtexError> {
    // The block's top row (border included) is the band's first.
    let [x0, _] = ctx.layout.tables.origin(block, k);
    let bpp = ctx.format.bytes_per_sample();
    let n = 1i64 << k;
    let mut put = |[x, y]: [i64; 2], texel: &Texel| {
        let at = ((y + 1) as u64 * row_bytes) as usize + ((x0 + 1 + x) as usize) * bpp;
        chunk[at..at + bpp].copy_from_slice(&texel.bytes[..bpp]);
    };
    for c in 0..n {
        for a in 0..n {
            put([a, c], &ctx.interior(block, k, a as u32, c as u32)?);
        }
    }
    stats.interior_texels += (n * n) as u64;
    let mut sides: [Vec<Texel>; 4] = Default::default();
    for (side, texels) in sides.iter_mut().enumerate() {
        *texels = border_side(ctx, block, k, side, stats)?;
        for (i, texel) in texels.iter().enumerate() {
            put(side_texel(side, n, i as i64, true), texel);
        }
    }
    // Corners: (−1, −1) between bottom and left, (n, −1) bottom and right, (n, n) right and
    // top, (−1, n) left and top.
    let last = (n - 1) as usize;
    let corner_pairs = [
        ([-1, -1], sides[0][0], sides[3][0]),
        ([n, -1], sides[0][last], sides[1][0]),
        ([n, n], sides[1][last], sides[2][last]),
        ([-1, n], sides[3][last], sides[2][0]),
    ];
    for (at, a, b) in corner_pairs {
        let mean: Rgba = std::array::from_fn(|ch| 0.5 * (a.color[ch] + b.color[ch]));
        put(at, &ctx.quantize(mean));
    }
    stats.corner_texels += 4;
    Ok(())
}

/// The `n` border texels of `block`'s `side` in slice `k`, along the side.
fn border_side(ctx: &Ctx<'_>, block: u32, k: u32, side: usize, stats: &mut PtexStats) -> Result<Vec<Texel>, PtexError> {
    let b = &ctx.layout.blocks[block as usize];
    let n = 1i64 << k;
    let ([s0, s1], second) = SIDES[side];
    let (a, z) = (b.corners[s0], b.corners[s1]);
    let owner = b.faces[usize::from(second)];
    let neighbour = ctx.edges.faces(a, z).and_then(|pair| pair.into_iter().find(|&h| h != owner));
    let own_row = |stats: &mut PtexStats| -> Result<Vec<Texel>, PtexError> {
        stats.clamped_border_texels += n as u64;
        (0..n)
            .map(|i| {
                let [x, y] = side_texel(side, n, i, false);
                ctx.interior(block, k, x as u32, y as u32)
            })
            .collect()
    };
    let Some(h) = neighbour else { return own_row(stats) };
    let Some(&record) = ctx.layout.records.get(h as usize) else { return own_row(stats) };
    let other = record.block();
    let ob = &ctx.layout.blocks[other as usize];
    // The neighbour's side along {a, z} that it owns.
    let found = (0..4).find(|&s| {
        let ([t0, t1], sec) = SIDES[s];
        let (c0, c1) = (ob.corners[t0], ob.corners[t1]);
        ob.faces[usize::from(sec)] == h && ((c0 == a && c1 == z) || (c0 == z && c1 == a))
    });
    let level = b.log2 - k.min(b.log2);
    let Some(s) = found else {
        // Across a lone neighbour's diagonal: the reference at the unfolded point.
        stats.unfolded_border_texels += n as u64;
        return (0..n).map(|i| unfolded(ctx, b, side, n, i, h, level)).collect();
    };
    let reversed = ob.corners[SIDES[s].0[0]] != a;
    let k2 = ob.log2 - level.min(ob.log2);
    let n2 = 1i64 << k2;
    let row: Vec<Texel> = (0..n2)
        .map(|j| {
            let [x, y] = side_texel(s, n2, j, false);
            ctx.interior(other, k2, x as u32, y as u32)
        })
        .collect::<Result<_, _>>()?;
    if n2 == n {
        stats.copied_border_texels += n as u64;
        return Ok((0..n as usize).map(|i| row[if reversed { n as usize - 1 - i } else { i }]).collect());
    }
    stats.resampled_border_texels += n as u64;
    Ok((0..n)
        .map(|i| {
            let t = (i as f32 + 0.5) / n as f32;
            let t = if reversed { 1.0 - t } else { t };
            let x = (t * n2 as f32 - 0.5).clamp(0.0, (n2 - 1) as f32);
            let j = (x.floor() as usize).min(n2 as usize - 1);
            let f = x - j as f32;
            let (c0, c1) = (row[j].color, row[(j + 1).min(n2 as usize - 1)].color);
            ctx.quantize(std::array::from_fn(|ch| c0[ch] + (c1[ch] - c0[ch]) * f))
        })
        .collect())
}

/// The reference at border texel `i` of `side` of block `b` (resolution `n`), unfolded
/// across the side's edge into neighbour `h`: the owner's barycentrics there have one
/// negative weight `w₋` (the corner off the edge); `h` takes the shared vertices' weights
/// plus `w₋` and `−w₋` at its own third vertex (the parallelogram across the edge).
fn unfolded(ctx: &Ctx<'_>, b: &PtexBlock, side: usize, n: i64, i: i64, h: u32, level: u32) -> Result<Texel, PtexError> {
    let [x, y] = side_texel(side, n, i, true);
    let uv = [(x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32];
    let second = SIDES[side].1;
    let (owner, w) = half_weights(ctx.packed, b, second, uv);
    let oc = ctx.packed.indices[owner as usize];
    let hc = ctx.packed.indices[h as usize];
    let off = (0..3).min_by(|&p, &q| w[p].total_cmp(&w[q])).unwrap_or(0);
    let neg = w[off].min(0.0);
    let mut wh = [0.0f32; 3];
    for (corner, &v) in hc.iter().enumerate() {
        wh[corner] = match oc.iter().position(|&o| o == v) {
            Some(p) if p != off => w[p] + neg,
            _ => -neg,
        };
    }
    let color = sample(ctx.packed, h, sanitize_barycentric(wh), Filter::Linear, level)
        .ok_or(PtexError::BadRecord { face: h })?;
    Ok(ctx.quantize(color))
}
