//! Texture conversion: a glTF base-colour texture becomes mesh colors.
//!
//! Every stored sample is evaluated once, in its *owner* face (the lowest face id that
//! contains it, see [`crate::colors::store::SampleSite`]): the owner's corner UVs are interpolated
//! with the sample's barycentric coordinates and the owner's material is evaluated there,
//! `base_color_factor × texture` in linear light. Across a UV seam the two faces of an edge
//! map it to different texels; the owner's mapping wins, so the result is deterministic.
//!
//! # Texture conventions (glTF 2.0)
//!
//! - texels are RGBA8 with sRGB-encoded colour and linear alpha; they are decoded to linear
//!   light before any filtering;
//! - UV `(0, 0)` is the top-left corner of the image (`u` to the right, `v` down the rows);
//!   texel `(x, y)` has its centre at `((x + ½)/W, (y + ½)/H)`;
//! - wrapping is `REPEAT` on both axes (the importer does not keep samplers);
//! - faces without a material use the glTF default material (white), faces whose material
//!   has no texture get `base_color_factor`.
//!
//! # Filtering
//!
//! A mesh-colors sample stands for the area around it, so point-sampling a texture finer
//! than the sample spacing would alias. Each texture gets a MIP pyramid built in linear
//! light with an exact box filter (area weights, so odd sizes are handled), and each
//! sample is read trilinearly at
//!
//! ```text
//! lod = log2( max(1, second-longest UV edge of the owner face in texels / R) )
//! ```
//!
//! where `R` is the resolution the sample lives at (the face's, or the edge's for edge
//! samples). `edge / R` is the lattice's spacing along that edge; the second-longest edge
//! is the longer vector of the lattice's reduced basis (a right triangle's lattice is a
//! square grid of its legs' spacing; a sliver's lattice is fine across and coarse along
//! it, and its second-longest edge is one of the two long ones), which is what a GPU's
//! isotropic level takes: the larger of the two axes' footprints. The longest edge (the
//! rule before) is √2 too coarse on right triangles — a 0.5-level blur that cost
//! BoxTextured's faces (every one a right triangle carrying the whole texture) about 1 dB
//! at R = 256 (docs/ADAPTIVE.md). Pyramids are built once per texture and only for
//! textures in use.

use crate::colors::format::{Rgba, srgb_to_linear};
use crate::colors::store::{ColorStore, SampleRef, SampleSite};
use crate::mesh::scene::{Scene, Texture};
use crate::mesh::weld::WeldedMesh;

/// One level of a [`TexturePyramid`]: linear RGBA texels, rows top to bottom.
#[derive(Debug, Clone, PartialEq)]
pub struct MipLevel {
    /// Width in texels (at least 1).
    pub width: u32,
    /// Height in texels (at least 1).
    pub height: u32,
    /// `width * height` linear RGBA texels.
    pub texels: Vec<Rgba>,
}

impl MipLevel {
    /// The texel at `(x, y)`, both already wrapped into the level.
    fn texel(&self, x: i64, y: i64) -> Rgba {
        self.texels.get(y as usize * self.width as usize + x as usize).copied().unwrap_or([0.0; 4])
    }

    /// Bilinear sample at `uv` (glTF convention, `REPEAT`).
    pub fn sample_bilinear(&self, uv: [f32; 2]) -> Rgba {
        let x = f64::from(uv[0]) * f64::from(self.width) - 0.5;
        let y = f64::from(uv[1]) * f64::from(self.height) - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        // The two columns and rows, wrapped once (`REPEAT`): one division per axis, not one
        // per texel read.
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let (x0, y0) = ((x0 as i64).rem_euclid(w), (y0 as i64).rem_euclid(h));
        let columns = [x0, if x0 + 1 == w { 0 } else { x0 + 1 }];
        let rows = [y0, if y0 + 1 == h { 0 } else { y0 + 1 }];
        let mut out = [0.0; 4];
        for (dx, dy, weight) in
            [(0, 0, (1.0 - fx) * (1.0 - fy)), (1, 0, fx * (1.0 - fy)), (0, 1, (1.0 - fx) * fy), (1, 1, fx * fy)]
        {
            if weight == 0.0 {
                continue;
            }
            let texel = self.texel(columns[dx], rows[dy]);
            add_scaled(&mut out, weight, texel);
        }
        out
    }
}

/// A texture's MIP pyramid in linear light: level 0 is the image, each next level halves
/// both sides (rounding down, at least 1) with an exact box filter, down to 1 × 1.
#[derive(Debug, Clone, PartialEq)]
pub struct TexturePyramid {
    levels: Vec<MipLevel>,
}

impl TexturePyramid {
    /// Builds the pyramid of `texture`, or `None` when its size and data disagree or a
    /// side is zero.
    pub fn new(texture: &Texture) -> Option<Self> {
        let (width, height) = (texture.width, texture.height);
        let count = (width as usize).checked_mul(height as usize)?;
        if count == 0 || texture.rgba8_srgb.len() != count.checked_mul(4)? {
            return None;
        }
        // sRGB decoding through a 256-entry table.
        let table: Vec<f32> = (0..=255u8).map(|b| srgb_to_linear(f32::from(b) / 255.0)).collect();
        let texels = texture
            .rgba8_srgb
            .chunks_exact(4)
            .map(|p| [table[p[0] as usize], table[p[1] as usize], table[p[2] as usize], f32::from(p[3]) / 255.0])
            .collect();
        let mut levels = vec![MipLevel { width, height, texels }];
        while let Some(last) = levels.last()
            && (last.width > 1 || last.height > 1)
        {
            let next = downsample(last);
            levels.push(next);
        }
        Some(TexturePyramid { levels })
    }

    /// The levels, finest first.
    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }

    /// Width and height of level 0.
    pub fn size(&self) -> (u32, u32) {
        self.levels.first().map_or((0, 0), |l| (l.width, l.height))
    }

    /// Trilinear sample at `uv` and level-of-detail `lod` (clamped to the pyramid):
    /// bilinear on the two nearest levels, linearly blended.
    pub fn sample_trilinear(&self, uv: [f32; 2], lod: f32) -> Rgba {
        let last = self.levels.len().saturating_sub(1);
        let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, last as f32) };
        let lower = (lod.floor() as usize).min(last);
        let upper = (lower + 1).min(last);
        let t = lod - lower as f32;
        let Some(a) = self.levels.get(lower).map(|l| l.sample_bilinear(uv)) else {
            return [0.0; 4];
        };
        if t == 0.0 || upper == lower {
            return a;
        }
        let b = self.levels.get(upper).map_or(a, |l| l.sample_bilinear(uv));
        crate::colors::format::lerp(a, b, t)
    }
}

/// Box weights that map `source` texels onto `target` (≤ source) texels along one axis:
/// target texel `i` covers source interval `[i·s/t, (i+1)·s/t)`, each source texel weighted
/// by its overlap, normalised.
fn box_weights(source: u32, target: u32) -> Vec<Vec<(usize, f32)>> {
    let ratio = f64::from(source) / f64::from(target);
    (0..target)
        .map(|i| {
            let (lo, hi) = (f64::from(i) * ratio, f64::from(i + 1) * ratio);
            let mut weights = Vec::new();
            let mut x = lo.floor() as u32;
            while f64::from(x) < hi && x < source {
                let overlap = (hi.min(f64::from(x + 1)) - lo.max(f64::from(x))).max(0.0);
                if overlap > 0.0 {
                    weights.push((x as usize, (overlap / ratio) as f32));
                }
                x += 1;
            }
            weights
        })
        .collect()
}

/// The next MIP level: sides halved (at least 1), exact box filter, separable.
fn downsample(level: &MipLevel) -> MipLevel {
    let (w, h) = (level.width, level.height);
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let wx = box_weights(w, nw);
    let wy = box_weights(h, nh);
    // Horizontal pass: h rows of nw texels.
    let mut rows = vec![[0.0f32; 4]; nw as usize * h as usize];
    for y in 0..h as usize {
        for (x, weights) in wx.iter().enumerate() {
            let mut sum = [0.0; 4];
            for &(sx, weight) in weights {
                let texel = level.texels[y * w as usize + sx];
                add_scaled(&mut sum, weight, texel);
            }
            rows[y * nw as usize + x] = sum;
        }
    }
    // Vertical pass.
    let mut texels = vec![[0.0f32; 4]; nw as usize * nh as usize];
    for (y, weights) in wy.iter().enumerate() {
        for x in 0..nw as usize {
            let mut sum = [0.0; 4];
            for &(sy, weight) in weights {
                let texel = rows[sy * nw as usize + x];
                add_scaled(&mut sum, weight, texel);
            }
            texels[y * nw as usize + x] = sum;
        }
    }
    MipLevel { width: nw, height: nh, texels }
}

/// `sum += weight · color` per channel.
fn add_scaled(sum: &mut Rgba, weight: f32, color: Rgba) {
    for (s, c) in sum.iter_mut().zip(color) {
        *s += weight * c;
    }
}

/// What a face's material needs at bake time.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FaceMaterial {
    pub(crate) factor: Rgba,
    /// Index into the pyramid cache, if the material has a usable texture.
    pub(crate) texture: Option<usize>,
    /// Longest UV edge of the face in texels of level 0 (0 without a texture).
    pub(crate) longest_uv_edge_texels: f32,
    /// Second-longest UV edge of the face in texels of level 0 (0 without a texture): the
    /// lattice spacing at `R` is this over `R` (module docs, Filtering).
    pub(crate) spacing_uv_edge_texels: f32,
    /// Area of the face's UV triangle in texels of level 0 (0 without a texture).
    pub(crate) uv_area_texels: f32,
}

/// Each face's material (by face id, `face_count` of them) and the pyramids of the
/// textures in use (by texture index; `None` where unused or unreadable).
pub(crate) fn face_materials(
    mesh: &WeldedMesh,
    scene: &Scene,
    face_count: usize,
) -> (Vec<FaceMaterial>, Vec<Option<TexturePyramid>>) {
    // Pyramids, built once per texture in use.
    let mut pyramids: Vec<Option<Option<TexturePyramid>>> = vec![None; scene.textures.len()];
    let faces: Vec<FaceMaterial> = (0..face_count)
        .map(|face| {
            let material =
                mesh.triangle_materials.get(face).copied().flatten().and_then(|m| scene.materials.get(m as usize));
            let Some(material) = material else {
                return FaceMaterial {
                    factor: [1.0; 4],
                    texture: None,
                    longest_uv_edge_texels: 0.0,
                    spacing_uv_edge_texels: 0.0,
                    uv_area_texels: 0.0,
                };
            };
            let texture = material.base_color_texture.map(|t| t as usize).filter(|&t| {
                let Some(slot) = pyramids.get_mut(t) else {
                    return false;
                };
                slot.get_or_insert_with(|| scene.textures.get(t).and_then(TexturePyramid::new)).is_some()
            });
            let ([_, second, longest], area) = match (texture, mesh.corner_uvs.get(face)) {
                (Some(t), Some(uvs)) => {
                    let (w, h) = scene.textures.get(t).map_or((0, 0), |tex| (tex.width, tex.height));
                    (uv_edges_texels(*uvs, w, h), uv_area_texels(*uvs, w, h))
                }
                _ => ([0.0; 3], 0.0),
            };
            FaceMaterial {
                factor: material.base_color_factor,
                texture,
                longest_uv_edge_texels: longest,
                spacing_uv_edge_texels: second,
                uv_area_texels: area,
            }
        })
        .collect();
    (faces, pyramids.into_iter().map(Option::flatten).collect())
}

/// The base colour of a face with `material` at `uv` for samples of resolution
/// `resolution` (the texture read trilinearly at the level matched to the sample spacing,
/// module docs).
pub(crate) fn material_color(
    material: &FaceMaterial,
    pyramids: &[Option<TexturePyramid>],
    uv: [f32; 2],
    resolution: u32,
) -> Rgba {
    let Some(pyramid) = material.texture.and_then(|t| pyramids.get(t)).and_then(Option::as_ref) else {
        return material.factor;
    };
    let spacing = material.spacing_uv_edge_texels / resolution.max(1) as f32;
    let lod = if spacing > 1.0 { spacing.log2() } else { 0.0 };
    let texel = pyramid.sample_trilinear(uv, lod);
    std::array::from_fn(|c| material.factor[c] * texel[c])
}

/// Whether the materials of `mesh` carry a colour signal worth baking: a base-colour
/// texture on any face, or base-colour factors that differ between faces (e.g. Cubes).
/// One uniform factor over the whole mesh (Bunny's flat grey) is not a signal: such a mesh
/// counts as texture-less and gets the position colour, so it shows visible variation.
pub fn has_base_color(mesh: &WeldedMesh, scene: &Scene) -> bool {
    let material = |m: &Option<u32>| m.and_then(|m| scene.materials.get(m as usize));
    if mesh.triangle_materials.iter().any(|m| material(m).is_some_and(|m| m.base_color_texture.is_some())) {
        return true;
    }
    let factor = |m: &Option<u32>| material(m).map_or([1.0; 4], |m| m.base_color_factor);
    let mut factors = mesh.triangle_materials.iter().map(factor);
    let Some(first) = factors.next() else {
        return false;
    };
    factors.any(|f| f != first)
}

/// Sets every sample of `store` to the base colour of its owner face at the sample's
/// UV (`base_color_factor × texture`, linear light, trilinear MIP filtering matched to the
/// sample spacing). `store` must be the store of `mesh` (same faces); faces the mesh does
/// not describe get white. Marks everything dirty.
pub fn bake_texture(store: &mut ColorStore, mesh: &WeldedMesh, scene: &Scene) {
    let (faces, pyramids) = face_materials(mesh, scene, store.topology().face_count() as usize);
    let edge_resolution: Vec<u32> =
        (0..store.topology().edge_count()).map(|e| store.edge_resolution(e).map_or(1, |r| r.get())).collect();
    let face_resolution: Vec<u32> = store.face_resolutions().iter().map(|r| r.get()).collect();

    store.fill_with(|site: SampleSite| {
        let face = site.face as usize;
        let Some(material) = faces.get(face) else {
            return [1.0; 4];
        };
        let resolution = match site.sample {
            SampleRef::Edge { edge, .. } => edge_resolution.get(edge as usize).copied(),
            _ => face_resolution.get(face).copied(),
        }
        .unwrap_or(1);
        let uv = mesh.corner_uvs.get(face).map_or([0.0; 2], |uvs| interpolate_uv(*uvs, site.barycentric));
        material_color(material, &pyramids, uv, resolution)
    });
}

/// `w0·uv0 + w1·uv1 + w2·uv2`, non-finite UVs read as `(0, 0)`. Evaluated as
/// `uv0 + w1·(uv1 − uv0) + w2·(uv2 − uv0)` in `f64` and rounded once, so that equal corner
/// UVs (a face with zero UV area) give exactly that UV, and UVs far from 0 (wrapped, e.g.
/// `u + 1000`) lose nothing beyond their own rounding (assuming `w0 + w1 + w2 = 1`).
pub(crate) fn interpolate_uv(uvs: [[f32; 2]; 3], w: [f32; 3]) -> [f32; 2] {
    let clean = |x: f32| if x.is_finite() { f64::from(x) } else { 0.0 };
    std::array::from_fn(|a| {
        let base = clean(uvs[0][a]);
        (base + f64::from(w[1]) * (clean(uvs[1][a]) - base) + f64::from(w[2]) * (clean(uvs[2][a]) - base)) as f32
    })
}

/// The edges of a UV triangle measured in texels of a `width × height` image, shortest
/// first (non-finite lengths read as 0).
fn uv_edges_texels(uvs: [[f32; 2]; 3], width: u32, height: u32) -> [f32; 3] {
    let (w, h) = (width as f32, height as f32);
    let mut edges = [0, 1, 2].map(|k| {
        let (a, b) = (uvs[k], uvs[(k + 1) % 3]);
        let (du, dv) = ((b[0] - a[0]) * w, (b[1] - a[1]) * h);
        let length = (du * du + dv * dv).sqrt();
        if length.is_finite() { length } else { 0.0 }
    });
    edges.sort_by(f32::total_cmp);
    edges
}

/// The area of a UV triangle in texels of a `width × height` image (0 when not finite).
fn uv_area_texels(uvs: [[f32; 2]; 3], width: u32, height: u32) -> f32 {
    let (w, h) = (f64::from(width), f64::from(height));
    let d = |k: usize, a: usize| f64::from(uvs[k][a]) - f64::from(uvs[0][a]);
    let area = 0.5 * ((d(1, 0) * w) * (d(2, 1) * h) - (d(2, 0) * w) * (d(1, 1) * h)).abs();
    if area.is_finite() { area as f32 } else { 0.0 }
}

/// World-space area of `face` of `mesh` (0 for a missing face).
pub(crate) fn world_area(mesh: &WeldedMesh, face: usize) -> f64 {
    let Some(t) = mesh.triangles.get(face) else { return 0.0 };
    let p = |k: usize| mesh.positions_world.get(t[k] as usize).map_or([0.0; 3], |p| p.map(f64::from));
    let (a, b, c) = (p(0), p(1), p(2));
    let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
    let cross = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    0.5 * (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt()
}
