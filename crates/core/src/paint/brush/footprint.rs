//! Where a dab reaches and how strongly: the [`Coverage`] of a lattice row, the brush
//! spheres of one dab ([`Footprint`]), [`Everywhere`] (fill) and the occlusion test.

use glam::DVec3;

use crate::paint::occlusion::DepthMap;
use crate::paint::picking::MeshBvh;

use super::settings::Falloff;

/// Occlusion tolerance: a hit counts as hiding a sample only if it is nearer than
/// `distance · (1 − OCCLUSION_TOLERANCE)` (the sample's own face is hit at the distance).
pub const OCCLUSION_TOLERANCE: f64 = 1e-6;

/// Where the brush reaches and how strongly: the weight of a point and, for a lattice row
/// `a + b·k`, the range of `k` that can have a positive weight.
pub(super) trait Coverage {
    /// The inclusive range of `k` in `lo..=hi` where `a + b·k` may be covered (a superset:
    /// [`Coverage::weight`] decides).
    fn row_range(&self, a: DVec3, b: DVec3, lo: u32, hi: u32, mask: u8) -> Option<(u32, u32)>;
    /// Weight at `p` for the spheres in `mask`.
    fn weight(&self, p: DVec3, mask: u8) -> f32;
    /// Whether every point of the segment or triangle with these corners is inside a sphere
    /// in `mask` (its rows then need no [`Coverage::row_range`]).
    fn covers(&self, corners: &[DVec3], mask: u8) -> bool;
    /// Whether occlusion cannot hide any point of the segment or triangle with these
    /// corners from the spheres in `mask`: [`Coverage::weight_unoccluded`] then equals
    /// [`Coverage::weight`] there.
    fn unoccluded(&self, _corners: &[DVec3], _mask: u8) -> bool {
        false
    }
    /// [`Coverage::weight`] without the occlusion test (for points of an element
    /// [`Coverage::unoccluded`] cleared).
    fn weight_unoccluded(&self, p: DVec3, mask: u8) -> f32 {
        self.weight(p, mask)
    }
    /// The squared distance from the row `a + b·k` to the brush centre as the quadratic
    /// `c[0] + k·(c[1] + k·c[2])`, when the coverage is one sphere: then the unoccluded weight
    /// of a row point with a non-zero mask is [`Coverage::weight_of_distance_sq`] of it. `None`
    /// otherwise (use [`Coverage::weight_unoccluded`]).
    fn row_distance(&self, _a: DVec3, _b: DVec3) -> Option<[f64; 3]> {
        None
    }
    /// The unoccluded weight at squared distance `d2` from the one sphere's centre (see
    /// [`Coverage::row_distance`]).
    fn weight_of_distance_sq(&self, _d2: f64) -> f32 {
        0.0
    }
    /// [`Coverage::weight_of_distance_sq`] of each squared distance of `d2` into `out`: the
    /// same values, computed in a batch.
    fn weights_of_distance_sq(&self, d2: &[f64], out: &mut [f32]) {
        for (w, &d2) in out.iter_mut().zip(d2) {
            *w = self.weight_of_distance_sq(d2);
        }
    }
}

/// How a dab tests occlusion: the depth map of each sphere's eye where one was built
/// ([`DepthMap::visible`]), the BVH ray ([`visible`], the reference) where the map cannot
/// tell or there is none.
#[derive(Debug, Clone, Copy)]
pub(super) struct Occlusion<'a> {
    pub(super) bvh: &'a MeshBvh,
    pub(super) maps: [Option<&'a DepthMap>; 2],
}

impl Occlusion<'_> {
    /// Whether `point` is visible from `eye`, the eye of sphere `k`.
    #[inline]
    fn visible(&self, k: usize, eye: DVec3, point: DVec3) -> bool {
        if let Some(seen) = self.maps.get(k).copied().flatten().and_then(|map| map.visible(point)) {
            return seen;
        }
        visible(self.bvh, eye, point)
    }
}

/// The brush spheres of one dab (one, or two with mirror).
#[derive(Debug, Clone, Copy)]
pub(super) struct Footprint<'a> {
    pub(super) centers: [DVec3; 2],
    pub(super) eyes: [DVec3; 2],
    count: usize,
    /// The squared radius within which a point can weigh anything (the outer rim with
    /// [`Footprint::with_edge`]).
    radius_sq: f64,
    inv_radius: f64,
    strength: f32,
    falloff: Falloff,
    occlusion: Option<Occlusion<'a>>,
    /// The anti-aliased rim of a constant falloff ([`Footprint::with_edge`]).
    edge: Option<Edge>,
    /// The anti-aliased rims the stroke's earlier dabs painted near this one
    /// ([`Footprint::with_earlier`]).
    earlier: &'a [Rim],
}

/// The anti-aliased rim of one sphere of an earlier dab of the stroke: what it covered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rim {
    center: DVec3,
    edge: Edge,
}

impl Rim {
    /// Whether this rim's sphere can reach within `reach` of `center`.
    pub(super) fn near(&self, center: DVec3, reach: f64) -> bool {
        (self.center - center).length() <= self.edge.outer + reach
    }
}

/// The anti-aliased rim of a constant falloff: the weight ramps from the strength to 0 over
/// `width` centred on the radius, the coverage of a sample's cell of that width by the disc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Edge {
    /// `radius + width / 2`: where the ramp reaches 0.
    outer: f64,
    /// `1 / width`.
    inv_width: f64,
}

impl Edge {
    /// The ramp's coverage at distance `d` (NaN and points past `outer` weigh 0).
    #[inline(always)]
    fn coverage(self, d: f64) -> f32 {
        let c = (self.outer - d) * self.inv_width;
        if c >= 1.0 {
            1.0
        } else if c > 0.0 {
            c as f32
        } else {
            0.0
        }
    }
}

impl<'a> Footprint<'a> {
    /// The footprint of spheres at `centers[..count]` seen from `eyes[..count]`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        centers: [DVec3; 2],
        eyes: [DVec3; 2],
        count: usize,
        radius: f64,
        strength: f32,
        falloff: Falloff,
        occlusion: Option<Occlusion<'a>>,
    ) -> Self {
        Footprint {
            centers,
            eyes,
            count: count.clamp(1, 2),
            radius_sq: radius * radius,
            inv_radius: 1.0 / radius,
            strength,
            falloff,
            occlusion,
            edge: None,
            earlier: &[],
        }
    }

    /// The rims the stroke's earlier dabs painted (from their [`Footprint::rims`]): with an
    /// anti-aliased rim, a point they covered by `a` and this dab covers by `c > a` weighs
    /// `strength · (c − a) / (1 − a)`, and nothing when `c ≤ a`. A stroke's rim then ends at
    /// the largest coverage of its dabs, as one dab shaped like their union would paint it,
    /// instead of building up where dabs overlap (with strength 1 and Mix, exactly).
    pub(super) fn with_earlier<'b>(self, rims: &'b [Rim]) -> Footprint<'b>
    where
        'a: 'b,
    {
        Footprint { earlier: rims, ..self }
    }

    /// This dab's anti-aliased rims (one per sphere), for the stroke's later dabs.
    pub(super) fn rims(&self) -> impl Iterator<Item = Rim> + '_ {
        let edge = self.edge;
        self.centers.iter().take(self.count).filter_map(move |&center| Some(Rim { center, edge: edge? }))
    }

    /// Anti-aliases the rim of a [`Falloff::Constant`] footprint over `width` (one sample
    /// spacing): a point at distance `d` weighs `strength · clamp((radius + width/2 − d) /
    /// width, 0, 1)`, so the weight is ½ on the sphere and the weights integrate to the
    /// disc's area. Other falloffs (already 0 at the rim) and widths that are not positive
    /// and finite are left as they are.
    pub(super) fn with_edge(mut self, width: f64) -> Self {
        if self.falloff != Falloff::Constant || !(width.is_finite() && width > 0.0) {
            return self;
        }
        let radius = 1.0 / self.inv_radius;
        let outer = radius + 0.5 * width;
        self.radius_sq = outer * outer;
        self.edge = Some(Edge { outer, inv_width: 1.0 / width });
        self
    }

    /// The radius within which a point can weigh anything (the outer rim of an anti-aliased
    /// edge): what the dab's face query must reach.
    pub(super) fn reach(&self) -> f64 {
        self.radius_sq.sqrt()
    }

    /// The weight for one sphere and no occlusion: the common case, kept small to inline.
    #[inline(always)]
    fn weight_single(&self, p: DVec3) -> f32 {
        let w = self.weight_single_sq((p - self.centers[0]).length_squared());
        if self.earlier.is_empty() { w } else { self.beyond_earlier(p, w) }
    }

    /// The weight `w = strength · c` of `p` on the anti-aliased rim (`0 < c < 1`) less what
    /// the stroke's earlier dabs covered ([`Footprint::with_earlier`]).
    #[inline(never)]
    fn beyond_earlier(&self, p: DVec3, w: f32) -> f32 {
        if self.strength <= 0.0 {
            return w;
        }
        let c = w / self.strength;
        if !(c > 0.0 && c < 1.0) {
            return w;
        }
        let mut covered = 0.0f32;
        for rim in self.earlier {
            covered = covered.max(rim.edge.coverage((p - rim.center).length()));
            if covered >= c {
                return 0.0;
            }
        }
        self.strength * (c - covered) / (1.0 - covered)
    }

    /// [`Footprint::weight_single`] at squared distance `d2` from the centre.
    #[inline(always)]
    fn weight_single_sq(&self, d2: f64) -> f32 {
        if d2.is_nan() || d2 > self.radius_sq {
            return 0.0;
        }
        if let Some(edge) = self.edge {
            return self.strength * edge.coverage(d2.max(0.0).sqrt());
        }
        self.strength * self.falloff.weight_of_squared((d2 * self.inv_radius * self.inv_radius) as f32)
    }

    /// [`Coverage::weights_of_distance_sq`] with the falloff's `shape`: bit for bit
    /// [`Footprint::weight_single_sq`], branch-free (NaN and points outside weigh 0).
    #[inline(always)]
    fn weights_with(&self, d2: &[f64], out: &mut [f32], shape: impl Fn(f32) -> f32) {
        for (w, &d2) in out.iter_mut().zip(d2) {
            let x2 = (d2 * self.inv_radius * self.inv_radius) as f32;
            let inside = d2 <= self.radius_sq && x2 <= 1.0;
            let weight = self.strength * shape(1.0 - x2.max(0.0).sqrt().max(0.0));
            *w = if inside { weight } else { 0.0 };
        }
    }

    /// [`Coverage::weight`] with mirror or occlusion (`occlusion`: whether to test it).
    #[inline(never)]
    fn weight_general(&self, p: DVec3, mask: u8, occlusion: bool) -> f32 {
        let mut best = 0.0f32;
        for k in 0..self.count {
            if mask & (1 << k) == 0 {
                continue;
            }
            let d2 = (p - self.centers[k]).length_squared();
            let mut w = self.weight_single_sq(d2);
            if !self.earlier.is_empty() && w > best {
                w = self.beyond_earlier(p, w);
            }
            if w <= best {
                continue;
            }
            if let Some(test) = self.occlusion.as_ref().filter(|_| occlusion)
                && !test.visible(k, self.eyes[k], p)
            {
                continue;
            }
            best = w;
        }
        best
    }
}

impl Coverage for Footprint<'_> {
    #[inline]
    fn row_range(&self, a: DVec3, b: DVec3, lo: u32, hi: u32, mask: u8) -> Option<(u32, u32)> {
        if lo > hi {
            return None;
        }
        let bb = b.length_squared();
        let mut range: Option<(f64, f64)> = None;
        for k in 0..self.count {
            if mask & (1 << k) == 0 {
                continue;
            }
            let d = a - self.centers[k];
            let db = d.dot(b);
            let excess = d.length_squared() - self.radius_sq;
            let (k0, k1) = if bb > 0.0 {
                let disc = db * db - bb * excess;
                if disc.is_nan() || disc < 0.0 {
                    continue;
                }
                let root = disc.sqrt();
                ((-db - root) / bb, (-db + root) / bb)
            } else if excess <= 0.0 {
                (f64::from(lo), f64::from(hi))
            } else {
                continue;
            };
            range = Some(range.map_or((k0, k1), |(r0, r1)| (r0.min(k0), r1.max(k1))));
        }
        let (k0, k1) = range?;
        // floor(k0) and ceil(k1) clamped to [lo, hi] (NaN clamps to the bound), without a
        // libm call: above `lo ≥ 0` truncation is the floor.
        let start = if k0 > f64::from(lo) { k0 as u32 } else { lo };
        let end = if k1.is_nan() || k1 >= f64::from(hi) {
            hi
        } else if k1 < 0.0 {
            return None;
        } else {
            let t = k1 as u32;
            if f64::from(t) < k1 { t + 1 } else { t }
        };
        (start <= end).then_some((start, end))
    }

    #[inline(always)]
    fn weight(&self, p: DVec3, mask: u8) -> f32 {
        if self.count == 1 && self.occlusion.is_none() {
            return if mask & 1 != 0 { self.weight_single(p) } else { 0.0 };
        }
        self.weight_general(p, mask, true)
    }

    #[inline]
    fn unoccluded(&self, corners: &[DVec3], mask: u8) -> bool {
        let Some(occlusion) = &self.occlusion else {
            return true;
        };
        (0..self.count).all(|k| {
            mask & (1 << k) == 0
                || occlusion.maps.get(k).copied().flatten().is_some_and(|map| map.region_visible(corners))
        })
    }

    #[inline(always)]
    fn weight_unoccluded(&self, p: DVec3, mask: u8) -> f32 {
        if self.count == 1 {
            return if mask & 1 != 0 { self.weight_single(p) } else { 0.0 };
        }
        self.weight_general(p, mask, false)
    }

    #[inline(always)]
    fn row_distance(&self, a: DVec3, b: DVec3) -> Option<[f64; 3]> {
        // Earlier rims make the weight depend on the point, not only on its distance.
        (self.count == 1 && self.earlier.is_empty()).then(|| {
            let d = a - self.centers[0];
            [d.length_squared(), 2.0 * d.dot(b), b.length_squared()]
        })
    }

    #[inline(always)]
    fn weight_of_distance_sq(&self, d2: f64) -> f32 {
        self.weight_single_sq(d2)
    }

    #[inline]
    fn weights_of_distance_sq(&self, d2: &[f64], out: &mut [f32]) {
        if let Some(edge) = self.edge {
            for (w, &d2) in out.iter_mut().zip(d2) {
                let inside = d2 <= self.radius_sq;
                let weight = self.strength * edge.coverage(d2.max(0.0).sqrt());
                *w = if inside { weight } else { 0.0 };
            }
            return;
        }
        // One loop per falloff, with no branch inside (the compiler vectorises it).
        match self.falloff {
            Falloff::Smooth => self.weights_with(d2, out, |s| Falloff::Smooth.shape(s)),
            Falloff::Linear => self.weights_with(d2, out, |s| Falloff::Linear.shape(s)),
            Falloff::Constant => self.weights_with(d2, out, |s| Falloff::Constant.shape(s)),
            Falloff::Sharp => self.weights_with(d2, out, |s| Falloff::Sharp.shape(s)),
        }
    }

    #[inline]
    fn covers(&self, corners: &[DVec3], mask: u8) -> bool {
        (0..self.count).any(|k| {
            mask & (1 << k) != 0 && corners.iter().all(|&c| (c - self.centers[k]).length_squared() <= self.radius_sq)
        })
    }
}

/// Everything, with one weight (fill).
#[derive(Debug, Clone, Copy)]
pub(super) struct Everywhere(pub(super) f32);

impl Coverage for Everywhere {
    fn row_range(&self, _: DVec3, _: DVec3, lo: u32, hi: u32, _: u8) -> Option<(u32, u32)> {
        (lo <= hi).then_some((lo, hi))
    }

    fn weight(&self, _: DVec3, _: u8) -> f32 {
        self.0
    }

    fn covers(&self, _: &[DVec3], _: u8) -> bool {
        true
    }

    fn unoccluded(&self, _: &[DVec3], _: u8) -> bool {
        true
    }
}

/// Whether nothing lies on the segment from `eye` to `point` (except near `point` itself).
pub fn visible(bvh: &MeshBvh, eye: DVec3, point: DVec3) -> bool {
    let to = point - eye;
    let distance = to.length();
    if distance.is_nan() || distance <= 0.0 {
        return true;
    }
    bvh.cast(eye, to / distance, distance * (1.0 - OCCLUSION_TOLERANCE)).is_none()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batched weights are the point-by-point ones, bit for bit, at the extremes too:
    /// NaN, ±infinity, negative (rounding), zero, the rim and just past it, subnormal radii.
    #[test]
    fn batched_weights_equal_the_point_weights_at_the_extremes() {
        for radius in [1e-300, 1e-20, 0.37, 1.0, 3.0e7, 1e150] {
            let r2: f64 = radius * radius;
            let mut d2 = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0, 0.0, -1e-300, -r2 * 1e-9];
            d2.extend([r2, r2 * (1.0 - 1e-16), r2 * (1.0 + 1e-15), r2.next_up(), r2.next_down(), f64::MAX]);
            d2.extend((0..200).map(|k| r2 * f64::from(k) / 150.0));
            for falloff in Falloff::ALL {
                for strength in [0.0f32, 1e-30, 0.5, 1.0] {
                    let centers = [DVec3::ZERO; 2];
                    let footprint = Footprint::new(centers, centers, 1, radius, strength, falloff, None);
                    let mut batch = vec![-1.0f32; d2.len()];
                    footprint.weights_of_distance_sq(&d2, &mut batch);
                    for (&d2, &w) in d2.iter().zip(&batch) {
                        let one = footprint.weight_of_distance_sq(d2);
                        assert_eq!(
                            w.to_bits(),
                            one.to_bits(),
                            "{falloff:?} r {radius} s {strength} d² {d2}: {w} vs {one}"
                        );
                    }
                }
            }
        }
    }
}
