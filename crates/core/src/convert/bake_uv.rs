//! Mesh colors → the model's own UV texture: the way back into engines that read only
//! textures.
//!
//! Every face with a UV triangle of non-zero area is rasterised in texture space: each texel
//! whose centre `((x + ½)/W, (y + ½)/H)` lies in the face's UV triangle (glTF convention: UV
//! `(0, 0)` is the image's top-left corner; UVs outside `[0, 1]` wrap, as glTF's default
//! `REPEAT` sampler does) gets the face's mesh colour at that point: the barycentric
//! coordinates of the texel centre in the UV triangle, sampled with the linear filter at
//! level 0 of the CPU reference sampler ([`crate::packing::sampler::sample`]) — exactly what
//! the mesh-colors view shows there at full resolution. Where two faces' UV triangles share a
//! texel (their UV edge), the later face wins.
//!
//! **Padding.** Texels outside every UV island are filled by dilation so that bilinear
//! filtering and MIP maps do not pull in an unrelated colour at island borders: `padding`
//! passes, each giving every empty texel next to a filled one (8-neighbourhood) the mean of its
//! filled neighbours; whatever is still empty then takes the mean colour of the islands.
//!
//! **Overlapping UVs.** Mirrored or stacked islands (the Duck's two sides share one half of
//! its texture) give one texel to several faces; it keeps the last face's colour. Texels
//! strictly inside two faces' UV triangles are counted, and those whose colours differ by more
//! than 32 steps (paint on one side only) reported, in [`UvBake::conflicting_texels`].
//!
//! **Faces without UVs.** A face whose three corner UVs are equal (which is what an import
//! without texture coordinates gives: all zero) or span no area has no place in the texture;
//! such faces are listed in [`UvBake::faces_without_uvs`], never silently dropped.

use crate::colors::format::{Rgba, decode_rgba8_srgb, encode_rgba8_srgb};
use crate::colors::store::ColorStore;
use crate::packing::sampler::{self, Filter};

/// The largest texture side baked (8192² RGBA8 is 256 MiB, plus a coverage byte per texel).
pub const MAX_TEXTURE_SIZE: u32 = 8192;

/// Errors of baking to a UV texture.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BakeUvError {
    /// A texture side of zero or above [`MAX_TEXTURE_SIZE`].
    #[error("texture size {0} is outside 1..={MAX_TEXTURE_SIZE}")]
    Size(u32),
    /// The UVs do not belong to the store's faces.
    #[error("{uvs} faces have UVs but the mesh has {faces} faces")]
    FaceCount {
        /// Faces with corner UVs.
        uvs: usize,
        /// Faces in the store.
        faces: usize,
    },
}

/// A baked texture.
#[derive(Debug, Clone, PartialEq)]
pub struct UvBake {
    /// Width = height in texels.
    pub size: u32,
    /// `size² · 4` bytes, RGBA8 with sRGB-encoded colour and linear alpha, rows top to bottom.
    pub rgba8_srgb: Vec<u8>,
    /// Texels some face covered (before padding).
    pub covered_texels: u64,
    /// Faces with no UV area (see the module docs), ascending.
    pub faces_without_uvs: Vec<u32>,
    /// Texels strictly inside the UV triangles of two or more faces (mirrored or stacked
    /// islands): one texel cannot hold both faces' colours.
    pub overlapping_texels: u64,
    /// Of those, texels where the faces' colours differ by more than 32 steps in some 8-bit
    /// channel: the texture keeps the last face's colour and loses the others'.
    pub conflicting_texels: u64,
}

/// The default padding for a `size` texture: enough for MIP levels down to 1/32 of it.
pub fn default_padding(size: u32) -> u32 {
    (size / 32).clamp(4, 64)
}

/// Bakes `store`'s colours into a `size × size` texture through the faces' `corner_uvs` (one
/// `[uv; 3]` per face, as [`crate::mesh::weld::WeldedMesh::corner_uvs`]), with `padding`
/// dilation passes. See the module docs.
pub fn bake_uv_texture(
    store: &ColorStore,
    corner_uvs: &[[[f32; 2]; 3]],
    size: u32,
    padding: u32,
) -> Result<UvBake, BakeUvError> {
    if size == 0 || size > MAX_TEXTURE_SIZE {
        return Err(BakeUvError::Size(size));
    }
    let faces = store.topology().face_count() as usize;
    if corner_uvs.len() != faces {
        return Err(BakeUvError::FaceCount { uvs: corner_uvs.len(), faces });
    }
    let texels = size as usize * size as usize;
    let mut rgba = vec![0u8; texels * 4];
    let mut covered = vec![false; texels];
    let mut faces_without_uvs = Vec::new();
    let mut overlaps = Overlaps::default();
    for (face, uvs) in corner_uvs.iter().enumerate() {
        let target = Target { size, rgba: &mut rgba, covered: &mut covered, overlaps: &mut overlaps };
        if !rasterise_face(store, face as u32, uvs, target) {
            faces_without_uvs.push(face as u32);
        }
    }
    let covered_texels = covered.iter().filter(|&&c| c).count() as u64;
    dilate(&mut rgba, &mut covered, size, padding);
    Ok(UvBake {
        size,
        rgba8_srgb: rgba,
        covered_texels,
        faces_without_uvs,
        overlapping_texels: overlaps.texels,
        conflicting_texels: overlaps.conflicts,
    })
}

/// Texels written twice (see [`UvBake::overlapping_texels`]).
#[derive(Debug, Default)]
struct Overlaps {
    texels: u64,
    conflicts: u64,
}

/// The texture being written.
struct Target<'a> {
    size: u32,
    rgba: &'a mut [u8],
    covered: &'a mut [bool],
    overlaps: &'a mut Overlaps,
}

/// Texels of a `width × height` texture whose centre lies in some face's UV triangle (UVs
/// wrapped, as glTF's default REPEAT sampler reads them; texels several faces cover count
/// once): the texels a model's UV islands hold.
pub fn uv_island_texels<'a>(corner_uvs: impl IntoIterator<Item = &'a [[f32; 2]; 3]>, [width, height]: [u32; 2]) -> u64 {
    let mut covered = vec![false; width as usize * height as usize];
    for uvs in corner_uvs {
        for_each_texel(uvs, [width, height], |texel, _| covered[texel] = true);
    }
    covered.iter().filter(|&&c| c).count() as u64
}

/// Like [`uv_island_texels`], but a texel counts once per face whose UV triangle holds its
/// centre: the texels the surface shows, where faces that reuse the same texels (a box
/// whose six sides each map the whole image) count each use.
pub fn uv_face_texels<'a>(corner_uvs: impl IntoIterator<Item = &'a [[f32; 2]; 3]>, [width, height]: [u32; 2]) -> u64 {
    let mut count = 0u64;
    for uvs in corner_uvs {
        for_each_texel(uvs, [width, height], |_, _| count += 1);
    }
    count
}

/// Bytes a `size × size` bake holds at once: the RGBA8 texels, a coverage flag per texel,
/// and as much again for the PNG encoding (an upper bound; check it against a memory budget
/// before baking).
pub fn bake_bytes(size: u32) -> u64 {
    let texels = u64::from(size) * u64::from(size);
    texels * (4 + 1 + 4)
}

/// How faces' UV triangles share a `size × size` texture, counted as [`bake_uv_texture`]
/// counts them, without sampling any colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UvCoverage {
    /// Texels some face covers.
    pub covered_texels: u64,
    /// Texels strictly inside the UV triangles of two or more faces.
    pub overlapping_texels: u64,
    /// Faces whose UV triangle has no area.
    pub faces_without_uvs: u64,
}

/// The [`UvCoverage`] of `corner_uvs` in a `size × size` texture.
pub fn uv_coverage(corner_uvs: &[[[f32; 2]; 3]], size: u32) -> UvCoverage {
    let mut covered = vec![false; size as usize * size as usize];
    let mut out = UvCoverage::default();
    for uvs in corner_uvs {
        let has_area = for_each_texel(uvs, [size, size], |texel, [w0, w1, w2]| {
            if covered[texel] && w0.min(w1).min(w2) > 1e-6 {
                out.overlapping_texels += 1;
            }
            covered[texel] = true;
        });
        if !has_area {
            out.faces_without_uvs += 1;
        }
    }
    out.covered_texels = covered.iter().filter(|&&c| c).count() as u64;
    out
}

/// Calls `visit(texel, barycentric)` for each texel of a `width × height` texture whose
/// centre lies in the UV triangle `uvs` (texel index wrapped into the texture); false when
/// it has no area.
fn for_each_texel(uvs: &[[f32; 2]; 3], [width, height]: [u32; 2], mut visit: impl FnMut(usize, [f64; 3])) -> bool {
    let (nx, ny) = (f64::from(width), f64::from(height));
    // Corners in texel units (texel centres at k + ½).
    let p = uvs.map(|uv| [f64::from(uv[0]) * nx, f64::from(uv[1]) * ny]);
    if !p.iter().flatten().all(|x| x.is_finite()) {
        return false;
    }
    let area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if area.abs() < 1e-12 {
        return false;
    }
    let min = |a: usize| p.iter().map(|c| c[a]).fold(f64::INFINITY, f64::min);
    let max = |a: usize| p.iter().map(|c| c[a]).fold(f64::NEG_INFINITY, f64::max);
    // Texels whose centre can be inside; a triangle wider than the texture is clipped to one
    // repetition around its first corner (such UVs would overlap themselves anyway).
    let (x0, x1) = ((min(0) - 0.5).ceil() as i64, (max(0) - 0.5).floor() as i64);
    let (y0, y1) = ((min(1) - 0.5).ceil() as i64, (max(1) - 0.5).floor() as i64);
    let (span_x, span_y) = (i64::from(width), i64::from(height));
    let (x1, y1) = (x1.min(x0 + span_x - 1), y1.min(y0 + span_y - 1));
    for y in y0..=y1 {
        for x in x0..=x1 {
            let c = [x as f64 + 0.5, y as f64 + 0.5];
            // Barycentric coordinates of the centre (edge functions over the signed area).
            let w1 = ((c[0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (c[1] - p[0][1])) / area;
            let w2 = ((p[1][0] - p[0][0]) * (c[1] - p[0][1]) - (c[0] - p[0][0]) * (p[1][1] - p[0][1])) / area;
            let w0 = 1.0 - w1 - w2;
            const EPS: f64 = -1e-9;
            if w0 < EPS || w1 < EPS || w2 < EPS {
                continue;
            }
            visit((y.rem_euclid(span_y) * span_x + x.rem_euclid(span_x)) as usize, [w0, w1, w2]);
        }
    }
    true
}

/// Writes the texels of `face`'s UV triangle; false when it has no area.
fn rasterise_face(store: &ColorStore, face: u32, uvs: &[[f32; 2]; 3], target: Target<'_>) -> bool {
    let Target { size, rgba, covered, overlaps } = target;
    for_each_texel(uvs, [size, size], |texel, [w0, w1, w2]| {
        let bary = [w0 as f32, w1 as f32, w2 as f32];
        let Some(color) = sampler::sample(store, face, bary, Filter::Linear, 0) else {
            return;
        };
        let encoded = encode_rgba8_srgb(color);
        // Strictly inside this face and already written: another face's UVs overlap.
        if covered[texel] && w0.min(w1).min(w2) > 1e-6 {
            overlaps.texels += 1;
            let old = &rgba[texel * 4..texel * 4 + 4];
            if old.iter().zip(encoded).any(|(a, b)| a.abs_diff(b) > 32) {
                overlaps.conflicts += 1;
            }
        }
        rgba[texel * 4..texel * 4 + 4].copy_from_slice(&encoded);
        covered[texel] = true;
    })
}

/// `passes` of 8-neighbour dilation in linear light, then the islands' mean everywhere else.
fn dilate(rgba: &mut [u8], covered: &mut [bool], size: u32, passes: u32) {
    let n = size as usize;
    let decode =
        |rgba: &[u8], t: usize| decode_rgba8_srgb([rgba[4 * t], rgba[4 * t + 1], rgba[4 * t + 2], rgba[4 * t + 3]]);
    let mut frontier: Vec<(usize, Rgba)> = Vec::new();
    for _ in 0..passes {
        frontier.clear();
        for y in 0..n {
            for x in 0..n {
                let t = y * n + x;
                if covered[t] {
                    continue;
                }
                let (mut sum, mut count) = ([0.0f32; 4], 0u32);
                for (dx, dy) in [(-1i64, -1i64), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx < 0 || ny < 0 || nx >= n as i64 || ny >= n as i64 {
                        continue;
                    }
                    let neighbour = ny as usize * n + nx as usize;
                    if covered[neighbour] {
                        let c = decode(rgba, neighbour);
                        (0..4).for_each(|k| sum[k] += c[k]);
                        count += 1;
                    }
                }
                if count > 0 {
                    frontier.push((t, sum.map(|s| s / count as f32)));
                }
            }
        }
        if frontier.is_empty() {
            break;
        }
        for &(t, color) in &frontier {
            rgba[4 * t..4 * t + 4].copy_from_slice(&encode_rgba8_srgb(color));
            covered[t] = true;
        }
    }
    let (mut sum, mut count) = ([0.0f64; 4], 0u64);
    for t in (0..n * n).filter(|&t| covered[t]) {
        let c = decode(rgba, t);
        (0..4).for_each(|k| sum[k] += f64::from(c[k]));
        count += 1;
    }
    let mean: Rgba = if count == 0 { [1.0; 4] } else { sum.map(|s| (s / count as f64) as f32) };
    let fill = encode_rgba8_srgb(mean);
    for t in (0..n * n).filter(|&t| !covered[t]) {
        rgba[4 * t..4 * t + 4].copy_from_slice(&fill);
    }
}
