//! Filling the atlas: every block texel is the CPU reference sampler's linear filter of
//! the packed mesh colors at that lattice point and level (the stored sample itself where
//! the block lattice is the face's own), every ring texel `c₃ = c₁ + c₂ − c₀` of the
//! quantised texels of its cell. Bands of block rows are disjoint, so they fill in
//! parallel.

use crate::colors::format::{ColorFormat, Rgba};
use crate::mct::layout::{BlockFrame, MctLayout, frame_of};
use crate::mct::{MctError, MctStats, MeshColorTexture};
use crate::packing::linear::PackedMesh;
use crate::packing::sampler::{Filter, MeshColorSource, sample};
use half::f16;
use rayon::prelude::*;

/// Texture rows `y0..y0 + height` and the blocks in them: pairs of group `g` at `level`.
/// (A band may start in the free end of the previous band's last row: both are one `Band`.)
struct Band {
    y0: u64,
    height: u64,
    parts: Vec<(usize, u32, std::ops::Range<usize>)>,
}

/// Builds the Mesh Color Texture of `packed` in `packed`'s colour format, in an atlas at
/// most `max_dimension` texels on a side and `max_bytes` bytes (checked before allocating).
pub fn build(packed: &PackedMesh, max_dimension: u32, max_bytes: u64) -> Result<MeshColorTexture, MctError> {
    let layout = MctLayout::new(packed, max_dimension)?;
    let format = packed.format;
    let bpp = format.bytes_per_sample() as u64;
    let bytes = layout.texel_count() * bpp;
    if bytes > max_bytes {
        return Err(MctError::OverBudget { bytes, max_bytes });
    }
    let row_bytes = u64::from(layout.width) * bpp;
    let mut texels = vec![0u8; usize::try_from(bytes).map_err(|_| MctError::OverBudget { bytes, max_bytes })?];
    let bands = bands(&layout);
    // Split the atlas into the bands' rows (in y order, disjoint).
    let mut chunks = Vec::with_capacity(bands.len());
    let mut rest: &mut [u8] = &mut texels;
    let mut cursor = 0u64;
    for band in &bands {
        let skip = ((band.y0 - cursor) * row_bytes) as usize;
        let (_, tail) = rest.split_at_mut(skip);
        let (chunk, tail) = tail.split_at_mut((band.height * row_bytes) as usize);
        chunks.push(chunk);
        rest = tail;
        cursor = band.y0 + band.height;
    }
    let stats = bands
        .par_iter()
        .zip(chunks.into_par_iter())
        .map(|(band, chunk)| fill_band(packed, &layout, band, chunk, row_bytes))
        .try_reduce(MctStats::default, |a, b| Ok(a.merged(b)))?;
    let vertex_density = crate::packing::lod::VertexLod::of(packed).density;
    Ok(MeshColorTexture { layout, format, texels, stats, vertex_density })
}

/// Every row of blocks, in y order, rows that share texture rows merged.
fn bands(layout: &MctLayout) -> Vec<Band> {
    let mut rows = Vec::new();
    for (g, list) in layout.pairs.iter().enumerate() {
        for level in 0..layout.levels {
            if list.is_empty() {
                continue;
            }
            let (y, per_row) = layout.bands.band(g as u32, level);
            let skip = layout.bands.skip(g as u32, level) as usize;
            let (_, log2_row, _) = layout.bands.strip_rows(g as u32);
            let r = 1u64 << (g as u32).saturating_sub(level);
            // Slots: level 0 two tents per period; levels ≥ 1 strip rows of 2^log2_row squares.
            let pairs_per_slot = if level == 0 { 2 } else { 1usize << log2_row };
            let per_row = (per_row as usize).max(1);
            let slots = list.len().div_ceil(pairs_per_slot) + skip;
            for row in 0..slots.div_ceil(per_row) {
                let first = (row * per_row).saturating_sub(skip) * pairs_per_slot;
                let end = (((row + 1) * per_row).saturating_sub(skip) * pairs_per_slot).min(list.len());
                rows.push(Band {
                    y0: u64::from(y) + row as u64 * (r + 1),
                    height: r + 1,
                    parts: vec![(g, level, first..end)],
                });
            }
        }
    }
    rows.sort_by_key(|b| b.y0);
    let mut out: Vec<Band> = Vec::with_capacity(rows.len());
    for row in rows {
        match out.last_mut() {
            Some(last) if row.y0 < last.y0 + last.height => {
                let end = (last.y0 + last.height).max(row.y0 + row.height);
                last.height = end - last.y0;
                last.parts.extend(row.parts);
            }
            _ => out.push(row),
        }
    }
    out
}

fn fill_band(
    packed: &PackedMesh,
    layout: &MctLayout,
    band: &Band,
    chunk: &mut [u8],
    row_bytes: u64,
) -> Result<MctStats, MctError> {
    let mut stats = MctStats::default();
    let mut scratch = Vec::new();
    for (g, level, pairs) in &band.parts {
        for pair in &layout.pairs[*g][pairs.clone()] {
            let lone = pair[1] == u32::MAX;
            for &face in pair.iter().filter(|&&f| f != u32::MAX) {
                let record = layout.records[face as usize];
                let frame = frame_of(record, &layout.bands, &layout.masks, *level);
                // Rings: always at level 0 (tents), only for lone faces in squares.
                let ring = *level == 0 || lone;
                let mut writer = BandWriter { chunk, row_bytes, y0: band.y0 as i64, format: packed.format };
                fill_face(packed, face, *level, &frame, ring, &mut writer, &mut scratch, &mut stats)?;
            }
        }
    }
    Ok(stats)
}

struct BandWriter<'a> {
    chunk: &'a mut [u8],
    row_bytes: u64,
    y0: i64,
    format: ColorFormat,
}

impl BandWriter<'_> {
    /// Byte offset of `texel` (x wraps around the atlas width).
    fn offset(&self, texel: [i64; 2]) -> usize {
        let bpp = self.format.bytes_per_sample() as i64;
        let x = texel[0].rem_euclid(self.row_bytes as i64 / bpp);
        ((texel[1] - self.y0) as u64 * self.row_bytes) as usize + (x * bpp) as usize
    }
    /// Writes a lattice colour; returns what the GPU will read.
    fn write(&mut self, texel: [i64; 2], color: Rgba) -> Rgba {
        let at = self.offset(texel);
        let n = self.format.bytes_per_sample();
        self.format.encode_quantized(color, &mut self.chunk[at..at + n])
    }
    /// Writes a ring colour unclamped where the format can hold it; returns how far it
    /// had to be clamped (0 when stored exactly up to rounding).
    fn write_ring(&mut self, texel: [i64; 2], color: Rgba) -> f32 {
        let at = self.offset(texel);
        let n = self.format.bytes_per_sample();
        let out = &mut self.chunk[at..at + n];
        match self.format {
            ColorFormat::Rgba8Srgb => {
                self.format.encode_quantized(color, out);
                color.iter().map(|&c| (-c).max(c - 1.0).max(0.0)).fold(0.0, f32::max)
            }
            ColorFormat::Rgba16F => {
                for (pair, c) in out.chunks_exact_mut(2).zip(color) {
                    pair.copy_from_slice(&f16::from_f32(c).to_bits().to_le_bytes());
                }
                let limit = f16::MAX.to_f32();
                color.iter().map(|c| (c.abs() - limit).max(0.0)).fold(0.0, f32::max)
            }
            ColorFormat::Rgba32F => {
                for (quad, c) in out.chunks_exact_mut(4).zip(color) {
                    quad.copy_from_slice(&c.to_le_bytes());
                }
                0.0
            }
        }
    }
}

/// Fills one face's block (and ring) at `level`.
#[allow(clippy::too_many_arguments)]
fn fill_face(
    packed: &PackedMesh,
    face: u32,
    level: u32,
    frame: &BlockFrame,
    ring: bool,
    writer: &mut BandWriter<'_>,
    scratch: &mut Vec<Rgba>,
    stats: &mut MctStats,
) -> Result<(), MctError> {
    let r = frame.r;
    let bad = || MctError::BadRecord { face };
    let r_face = packed.face_resolution(face).ok_or_else(bad)?;
    let own = r_face.get() >> level.min(r_face.log2());
    let index = |alpha: u32, beta: u32| (beta * (r + 1) - beta * beta.saturating_sub(1) / 2 + alpha) as usize;
    scratch.clear();
    scratch.resize(((r + 1) * (r + 2) / 2) as usize, [0.0; 4]);
    let rf = r as f32;
    for beta in 0..=r {
        for alpha in 0..=(r - beta) {
            let mut w = [0.0f32; 3];
            w[frame.corners[0]] = (r - alpha - beta) as f32 / rf;
            w[frame.corners[1]] = alpha as f32 / rf;
            w[frame.corners[2]] = beta as f32 / rf;
            let color = if own == r {
                // The block lattice is the face's own: the stored sample.
                let (i, j) = ((w[1] * rf).round() as u32, (w[2] * rf).round() as u32);
                packed.lattice_color(face, level, i, j)
            } else {
                sample(packed, face, w, Filter::Linear, level)
            }
            .ok_or_else(bad)?;
            scratch[index(alpha, beta)] = writer.write(frame.texel(alpha, beta), color);
        }
    }
    stats.lattice_texels += scratch.len() as u64;
    if ring {
        for alpha in 1..=r {
            let beta = r + 1 - alpha;
            let c00 = scratch[index(alpha - 1, beta - 1)];
            let c10 = scratch[index(alpha, beta - 1)];
            let c01 = scratch[index(alpha - 1, beta)];
            let c11: Rgba = std::array::from_fn(|c| c10[c] + c01[c] - c00[c]);
            let excess = writer.write_ring(frame.texel(alpha, beta), c11);
            stats.ring_texels += 1;
            if excess > 1e-6 {
                stats.clamped_ring_texels += 1;
                stats.max_ring_clamp = stats.max_ring_clamp.max(excess);
            }
        }
    }
    Ok(())
}
