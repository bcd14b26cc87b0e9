//! One face's error at a resolution (the metric of the module docs in [`super`]): its test
//! points and the truth there, the face alone baked and reconstructed at `R`, or as a store
//! shows it.

use crate::colors::format::{Rgba, linear_to_srgb_table};
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::convert::bake::{FaceMaterial, interpolate_uv, material_color};
use crate::mesh::weld::WeldedMesh;
use crate::packing::sampler::{Filter, sample};

use super::{ROUNDING, power_of_two_at_least};

/// A test point's barycentrics and the truth there, [`encoded`].
pub(super) type TestPoint = ([f32; 3], Rgba);

/// Where a face's shared samples are baked: the UVs and material of each element's owner
/// face (the lowest face id containing it, as [`bake_texture`] bakes), in this face's
/// orientation — across a UV seam the owner maps the element to other texels.
#[derive(Debug, Clone, Copy)]
pub(super) struct SharedUvs {
    /// Per corner: the owner's UV at that vertex and the owner face.
    corners: [([f32; 2], usize); 3],
    /// Per face edge k (corner k → k + 1): the owner's UVs at both ends and the owner face.
    edges: [([f32; 2], [f32; 2], usize); 3],
}

/// The [`SharedUvs`] of every face of `mesh`.
pub(super) fn shared_uvs(mesh: &WeldedMesh) -> Vec<SharedUvs> {
    let mut vertex_owner = vec![usize::MAX; mesh.positions_world.len()];
    let mut edge_owner = std::collections::HashMap::new();
    for (face, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            if let Some(owner) = vertex_owner.get_mut(t[k] as usize) {
                *owner = (*owner).min(face);
            }
            let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
            edge_owner.entry((a, b)).or_insert(face);
        }
    }
    let uv_of = |face: usize, vertex: u32| -> [f32; 2] {
        let (Some(t), Some(uvs)) = (mesh.triangles.get(face), mesh.corner_uvs.get(face)) else { return [0.0; 2] };
        t.iter().position(|&v| v == vertex).map_or([0.0; 2], |k| uvs[k])
    };
    mesh.triangles
        .iter()
        .enumerate()
        .map(|(face, t)| {
            let corners = [0, 1, 2].map(|k| {
                let owner = vertex_owner.get(t[k] as usize).copied().filter(|&o| o != usize::MAX).unwrap_or(face);
                (uv_of(owner, t[k]), owner)
            });
            let edges = [0, 1, 2].map(|k| {
                let (start, end) = (t[k], t[(k + 1) % 3]);
                let owner = edge_owner.get(&(start.min(end), start.max(end))).copied().unwrap_or(face);
                (uv_of(owner, start), uv_of(owner, end), owner)
            });
            SharedUvs { corners, edges }
        })
        .collect()
}

/// One face's texture and test points, for [`FaceFit::error`].
pub(super) struct FaceFit<'a> {
    /// Every face's material (shared samples use their owner's).
    materials: &'a [FaceMaterial],
    shared: SharedUvs,
    material: &'a FaceMaterial,
    pyramids: &'a [Option<crate::convert::bake::TexturePyramid>],
    uvs: [[f32; 2]; 3],
    /// The test lattice from the texture alone ([`dense_lattice`]).
    dense: u32,
    /// Barycentrics of the test points of `dense` and the truth there, encoded as
    /// [`difference`] compares it ([`encoded`]).
    points: std::borrow::Cow<'a, [TestPoint]>,
}

/// The test lattice of a face of `material` from the texture alone: its longest UV edge in
/// texels (a power of two: at least two points a texel the face covers), at least 8, at
/// most `2·max` and at most [`MAX_TEST_LATTICE`].
pub(super) fn dense_lattice(material: &FaceMaterial, max: Resolution) -> u32 {
    let texels = power_of_two_at_least(material.longest_uv_edge_texels, Resolution::MAX).get();
    texels.clamp(8, 2 * max.get()).min(MAX_TEST_LATTICE)
}

/// The test lattice at most (65,536 points a face): a face of thousands of texels a side
/// (a logo on a truck's side) is tested on a sample of its texels, not on every one, so
/// its trials at each level cost what a 256-texel face's do (the seam strips still get
/// their own points at every `R`).
pub(super) const MAX_TEST_LATTICE: u32 = 256;

impl<'a> FaceFit<'a> {
    /// The test points of the `dense` lattice, to give a later fit of the same face.
    pub(super) fn into_points(self) -> Vec<TestPoint> {
        self.points.into_owned()
    }

    /// The fit of face `face`; its test points are `points` when given (computed for the
    /// same face by an earlier fit), else computed here.
    pub(super) fn new(
        materials: &'a [FaceMaterial],
        face: usize,
        shared: SharedUvs,
        pyramids: &'a [Option<crate::convert::bake::TexturePyramid>],
        uvs: [[f32; 2]; 3],
        max: Resolution,
        points: Option<&'a [TestPoint]>,
    ) -> Self {
        let material = &materials[face];
        let dense = dense_lattice(material, max);
        let mut fit = FaceFit {
            materials,
            shared,
            material,
            pyramids,
            uvs,
            dense,
            points: std::borrow::Cow::Borrowed(points.unwrap_or_default()),
        };
        if points.is_none() {
            fit.points = std::borrow::Cow::Owned(fit.test_points(dense));
        }
        fit
    }

    /// The test points for a face shown at `r`: those of `dense`; when `2·r` is finer, every
    /// strip one sample spacing (`1/r`) wide along an edge needs the finer lattice (with the
    /// texture's lattice alone, a face under one texel gets `D = 8`, whose centroids lie at
    /// least 1/24 of the face from each edge, and at `R ≥ 32` the strip where a UV seam's
    /// foreign edge colours fade out — 1/R wide — held none: the fit saw no error there,
    /// random points did, docs/ADAPTIVE.md). Then the strips get the centroids of lattice
    /// `2·r` that lie in them (the strips' borders are lines of that lattice, so its
    /// sub-triangles are wholly in or out) and the inside the centroids of `dense` that lie
    /// in it, each part weighted by its share of the face's area: `O(r)` points for the
    /// strips where the whole lattice `2·r` took `O(r²)`.
    fn points_for(&self, r: Resolution) -> TestPoints<'_> {
        let fine = 2 * r.get();
        if fine <= self.dense {
            return TestPoints { parts: vec![(std::borrow::Cow::Borrowed(&self.points[..]), 1.0)] };
        }
        let n = fine as f32;
        // Strip: the smallest lattice coordinate of the centroid below 2 (one spacing of `r`).
        let strip: Vec<[f32; 3]> =
            strip_centroids(fine).filter(|bary| bary.iter().fold(f32::MAX, |m, &b| m.min(b)) * n < 2.0).collect();
        let inside: Vec<TestPoint> = self
            .points
            .iter()
            .filter(|(bary, _)| bary.iter().fold(f32::MAX, |m, &b| m.min(b)) * n >= 2.0)
            .copied()
            .collect();
        let strip_share = strip.len() as f64 / f64::from(fine).powi(2);
        if inside.is_empty() || strip_share >= 1.0 {
            return TestPoints {
                parts: vec![(std::borrow::Cow::Owned(self.truth_at(layout::sub_triangle_centroids(fine))), 1.0)],
            };
        }
        let inside_share = 1.0 - strip_share;
        let strip_points = self.truth_at(strip.into_iter());
        let (strip_weight, inside_weight) =
            (strip_share / strip_points.len() as f64, inside_share / inside.len() as f64);
        TestPoints {
            parts: vec![
                (std::borrow::Cow::Owned(strip_points), strip_weight),
                (std::borrow::Cow::Owned(inside), inside_weight),
            ],
        }
    }

    /// The centroids of the `dense²` sub-triangles of a lattice `dense` and the truth there
    /// (the texture's level 0 read bilinearly, times the factor), [`encoded`] once here
    /// rather than at every resolution a face is tried at.
    fn test_points(&self, dense: u32) -> Vec<TestPoint> {
        self.truth_at(layout::sub_triangle_centroids(dense))
    }

    /// The truth at `points` (the texture's level 0 read bilinearly, times the factor),
    /// [`encoded`].
    fn truth_at(&self, points: impl Iterator<Item = [f32; 3]>) -> Vec<TestPoint> {
        let material = self.material;
        let level0 = material
            .texture
            .and_then(|t| self.pyramids.get(t))
            .and_then(Option::as_ref)
            .and_then(|p| p.levels().first());
        points
            .map(|bary| {
                let uv = interpolate_uv(self.uvs, bary);
                let texel = level0.map_or([1.0; 4], |level| level.sample_bilinear(uv));
                (bary, encoded(std::array::from_fn(|c| material.factor[c] * texel[c])))
            })
            .collect()
    }

    /// The error (module docs) of the colours `shown` returns at the test points of a face
    /// shown at `r`.
    pub(super) fn error_of(&self, r: Resolution, shown: impl Fn([f32; 3]) -> Rgba) -> f32 {
        self.points_for(r).rms(|bary, truth| difference(shown(bary), truth))
    }

    /// The colour baked at lattice point `(i, j)` of resolution `res`: corners and edge
    /// points from their owner's UVs and material, interior points from the face's own.
    fn lattice_color(&self, i: u32, j: u32, res: u32) -> Rgba {
        let n = res as f32;
        let owner = |face: usize| self.materials.get(face).unwrap_or(self.material);
        let lerp = |a: [f32; 2], b: [f32; 2], t: f32| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
        let corner = match (i, j) {
            (0, 0) => Some(0),
            (i, 0) if i == res => Some(1),
            (0, j) if j == res => Some(2),
            _ => None,
        };
        if let Some(k) = corner {
            let (uv, face) = self.shared.corners[k];
            return material_color(owner(face), self.pyramids, uv, res);
        }
        let edge = if j == 0 {
            Some((0, i as f32 / n))
        } else if i + j == res {
            Some((1, j as f32 / n))
        } else if i == 0 {
            Some((2, (res - j) as f32 / n))
        } else {
            None
        };
        if let Some((k, t)) = edge {
            let (start, end, face) = self.shared.edges[k];
            return material_color(owner(face), self.pyramids, lerp(start, end, t), res);
        }
        let bary = [(n - i as f32 - j as f32) / n, i as f32 / n, j as f32 / n];
        material_color(self.material, self.pyramids, interpolate_uv(self.uvs, bary), res)
    }

    /// The error (module docs) of face `face` at each `R = 2^l` up to `max` that a budget
    /// allocation predicts: measured on the calibration store of that level where there is
    /// one; elsewhere the point bake's error scaled by the gain the fit made at the nearest
    /// calibrated level (the finer one of two as near); the point bake's error where nothing
    /// is calibrated.
    pub(super) fn predicted_errors(&self, face: u32, max: Resolution, calibration: &[Option<ColorStore>]) -> Vec<f32> {
        // Past the face's content cap, no level removes more error: each predicts its cap's.
        let top = content_cap(self.material, max).log2() as usize;
        let resolutions: Vec<Resolution> =
            (0..=top).map(|l| Resolution::from_log2(l as u32).unwrap_or(Resolution::ONE)).collect();
        let point: Vec<f32> = resolutions.iter().map(|&r| self.error(r)).collect();
        // (level, measured error, gain) of every calibrated level.
        let calibrated: Vec<(usize, f32, f32)> = (0..resolutions.len())
            .filter_map(|l| {
                let store = calibration.get(l)?.as_ref()?;
                let error = self.error_in(store, face, resolutions[l]);
                let gain = if point[l] > ROUNDING { error / point[l] } else { 1.0 };
                Some((l, error, gain))
            })
            .collect();
        let levels = max.log2() as usize + 1;
        (0..levels)
            .map(|l| l.min(top))
            .map(|l| match calibrated.iter().find(|c| c.0 == l) {
                Some(&(_, error, _)) => error,
                None => {
                    let nearest = calibrated.iter().min_by_key(|c| (c.0.abs_diff(l), std::cmp::Reverse(c.0)));
                    nearest.map_or(1.0, |c| c.2) * point[l]
                }
            })
            .collect()
    }

    /// The error (module docs) of the face alone, baked and reconstructed at `r`. When the
    /// lattice has more points than three per test point (a large face at a fine `R`: up to
    /// `R²/2` texture reads where the test points are at most a 256² lattice plus the seam
    /// strips), only the lattice points the test points' sub-triangles use are baked, each
    /// where it is used: the same values (a lattice point's colour depends on `(i, j, R)`
    /// alone), so the same error, at a cost that follows the test points, not `R²`.
    pub(super) fn error(&self, r: Resolution) -> f32 {
        let res = r.get();
        let points = self.points_for(r);
        let lattice_points = u64::from(res + 1) * u64::from(res + 2) / 2;
        if lattice_points > 3 * points.len() as u64 {
            return Self::error_at(r, &points, |i, j| self.lattice_color(i, j, res));
        }
        let mut lattice = Vec::with_capacity(((res + 1) * (res + 2) / 2) as usize);
        for j in 0..=res {
            for i in 0..=res - j {
                lattice.push(self.lattice_color(i, j, res));
            }
        }
        self.error_of_lattice(r, &points, &lattice)
    }

    /// The error (module docs) of face `face` as `store` shows it at its resolution `r`
    /// there. When its three edges hold `r` too, no sub-triangle has a finer side, so the
    /// reference sampler's linear filter is eq. 2.4 on the face's lattice (bit for bit,
    /// [`crate::packing::sampler`]): the lattice is read from the store once and
    /// interpolated here. Otherwise (fans towards finer edges) every point goes through the
    /// sampler.
    pub(super) fn error_in(&self, store: &ColorStore, face: u32, r: Resolution) -> f32 {
        let through_sampler =
            || self.error_of(r, |bary| sample(store, face, bary, Filter::Linear, 0).unwrap_or([0.0; 4]));
        let topology = store.topology();
        let plain = topology
            .face_edges
            .get(face as usize)
            .is_some_and(|edges| edges.iter().all(|&e| store.edge_resolution(e) == Some(r)));
        if !plain {
            return through_sampler();
        }
        let res = r.get();
        let mut lattice = Vec::with_capacity(((res + 1) * (res + 2) / 2) as usize);
        for j in 0..=res {
            for i in 0..=res - j {
                match store.face_sample_ref(face, i, j).and_then(|s| store.get(s)) {
                    Some(color) => lattice.push(color),
                    None => return through_sampler(),
                }
            }
        }
        self.error_of_lattice(r, &self.points_for(r), &lattice)
    }

    /// The error of the lattice of resolution `r` (`(i, j)` row by row, `j` outer),
    /// reconstructed with eq. 2.4 at the test points of a face shown at `r`.
    fn error_of_lattice(&self, r: Resolution, points: &TestPoints<'_>, lattice: &[Rgba]) -> f32 {
        let res = r.get();
        let row = |j: u32| (j * (2 * res + 3 - j) / 2) as usize;
        Self::error_at(r, points, |i, j| lattice[row(j) + i as usize])
    }

    /// The error at `points` of the lattice of resolution `r` whose point `(i, j)` is
    /// `color_at(i, j)`, reconstructed with eq. 2.4.
    fn error_at(r: Resolution, points: &TestPoints<'_>, color_at: impl Fn(u32, u32) -> Rgba) -> f32 {
        points.rms(|bary, truth| {
            let mut shown = [0.0f32; 4];
            for s in layout::linear_samples(r, bary) {
                let color = color_at(s.i, s.j);
                for c in 0..4 {
                    shown[c] += s.weight * color[c];
                }
            }
            difference(shown, truth)
        })
    }
}

/// The centroids of [`layout::sub_triangle_centroids`]`(n)` that can lie within two lattice
/// spacings of an edge, in its order: the cells of the rows `j ≤ 1`, and of the others those
/// with `i ≤ 1` or `i + j ≥ n − 3` (a centroid's coordinates are its cell's plus 1/3 or 2/3).
/// `O(n)` of the `n²`, so a face's strips at a fine `R` cost no full lattice.
fn strip_centroids(n: u32) -> impl Iterator<Item = [f32; 3]> {
    let nf = n as f32;
    (0..n).flat_map(move |j| {
        let row = n - j;
        let cells: Box<dyn Iterator<Item = u32>> = if j <= 1 || row <= 5 {
            Box::new(0..row)
        } else {
            Box::new((0..2).chain(row.saturating_sub(3).max(2)..row))
        };
        cells.flat_map(move |i| {
            let (u, v) = (i as f32, j as f32);
            let upper = (i + j + 2 <= n).then_some((u + 2.0 / 3.0, v + 2.0 / 3.0));
            std::iter::once((u + 1.0 / 3.0, v + 1.0 / 3.0))
                .chain(upper)
                .map(move |(cu, cv)| [(nf - cu - cv) / nf, cu / nf, cv / nf])
        })
    })
}

/// The finest `R` worth trying on a face of `material` (at most `max`): two samples a texel
/// along its longest UV edge, at least 8. Finer, a sample spacing is under half a texel of
/// a bilinear texture, and the error cannot fall by more than rounding; without this bound
/// every face would be tried at every level up to `max` (up to [`Resolution::MAX`]), whose
/// lattices grow as `R²`.
pub(super) fn content_cap(material: &FaceMaterial, max: Resolution) -> Resolution {
    let texels = power_of_two_at_least(material.longest_uv_edge_texels, Resolution::MAX).get();
    Resolution::new(u64::from((2 * texels).max(8))).unwrap_or(Resolution::MAX).min(max)
}

/// Test points in parts, each with the weight of one of its points (the weights sum to 1
/// over all points: an area quadrature of the face).
struct TestPoints<'a> {
    parts: Vec<(std::borrow::Cow<'a, [TestPoint]>, f64)>,
}

impl TestPoints<'_> {
    /// Points over all parts.
    fn len(&self) -> usize {
        self.parts.iter().map(|(points, _)| points.len()).sum()
    }

    /// The root of the weighted mean of `squared(bary, truth)` (summed over the four
    /// channels) per channel.
    fn rms(&self, squared: impl Fn([f32; 3], Rgba) -> f64) -> f32 {
        let (mut sum, mut weights) = (0.0f64, 0.0f64);
        for (points, weight) in &self.parts {
            let part: f64 = points.iter().map(|(bary, truth)| squared(*bary, *truth)).sum();
            sum += part * weight;
            weights += weight * points.len() as f64;
        }
        (sum / (4.0 * weights.max(f64::MIN_POSITIVE))).sqrt() as f32
    }
}

/// A colour as the error compares it: RGB sRGB-encoded (module docs; by the table, within
/// 2·10⁻⁷ of the formula), alpha as is.
fn encoded(color: Rgba) -> Rgba {
    [linear_to_srgb_table(color[0]), linear_to_srgb_table(color[1]), linear_to_srgb_table(color[2]), color[3]]
}

/// Squared differences summed over the channels of `shown` [`encoded`] and `truth`, already
/// encoded.
fn difference(shown: Rgba, truth: Rgba) -> f64 {
    let shown = encoded(shown);
    (0..4).map(|c| f64::from(shown[c] - truth[c]).powi(2)).sum()
}
