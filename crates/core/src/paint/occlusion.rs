//! Occlusion without a ray per sample: a depth map of the view, rasterised on the CPU once
//! per view, against which each brush sample's depth is tested.
//!
//! # What it computes
//!
//! [`DepthMap::build`] rasterises every triangle (both sides, as [`MeshBvh::cast`] counts
//! both) seen from an eye into a `width × height` grid of pixel centres, keeping the
//! nearest surface's reciprocal view depth `1 / z` per pixel (`1 / z` is affine in screen
//! space over a triangle, so it is interpolated exactly). Triangles crossing the near plane
//! are clipped against it. Triangles are split into one chunk per thread (rayon), each
//! rasterised into its own map, and the maps merged by the nearest surface.
//!
//! [`DepthMap::visible`] projects a point and reads the four pixel centres around it. The
//! point is visible when its depth `z` is at most the *farthest* of those four depths plus
//! the tolerance `z · (DEPTH_TOLERANCE_PX / focal + DEPTH_TOLERANCE_RELATIVE)` (a centre
//! with nothing behind it counts as infinitely far). Over a visible planar piece of
//! surface the point's depth is a convex combination of the four (the depth of a plane is
//! affine in `1 / z`), so it passes; a hidden point fails unless one of the four centres
//! sees past the occluder, i.e. unless the point lies within about one pixel of the
//! occluder's silhouette, or the occluder is nearer than the tolerance. Points outside the
//! map (off screen, behind the near plane) get `None`: the caller casts a ray
//! ([`crate::paint::brush::visible`], the reference).
//!
//! `crates/core/tests/core/occlusion.rs` compares it with the ray on every sample of Bunny144k and the Duck
//! and checks that each disagreement lies near a depth discontinuity of the ray-cast image.

use glam::DVec3;
use rayon::prelude::*;

use crate::camera::OrbitCamera;

/// Depth tolerance in pixels: a point counts as hidden only if the surface in front of it is
/// nearer by more than this many pixel widths (world size of a pixel at the point's depth).
pub const DEPTH_TOLERANCE_PX: f64 = 1.0;
/// Depth tolerance relative to the depth (covers the `f32` storage of `1 / z`).
pub const DEPTH_TOLERANCE_RELATIVE: f64 = 1e-5;
/// The largest screen box [`DepthMap::region_visible`] reads, pixels.
pub const MAX_REGION_PIXELS: f64 = 256.0;
/// The largest map built (pixels); a larger viewport falls back to rays.
pub const MAX_PIXELS: u64 = 1 << 26;

/// A depth map of one view (see the module documentation).
#[derive(Debug, Clone)]
pub struct DepthMap {
    eye: DVec3,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    /// Pixels per unit of `x / z`.
    focal: f64,
    width: u32,
    height: u32,
    near: f64,
    /// `1 / z` of the nearest surface at each pixel centre (row-major, top row first), 0
    /// where nothing is.
    inv_depth: Vec<f32>,
    /// What the map was built from: camera, viewport, positions (address and length).
    key: Key,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    eye: [f64; 3],
    target: [f64; 3],
    fov_y_degrees: f64,
    viewport: [u32; 2],
    positions: (usize, usize),
    triangles: (usize, usize),
}

/// One vertex in view space and on screen.
#[derive(Debug, Clone, Copy, Default)]
struct ViewVertex {
    /// View-space coordinates (x right, y up, z forward).
    view: DVec3,
    /// Screen x, y (pixels, origin top-left) and `1 / z`, when in front of the near plane.
    screen: [f64; 3],
    valid: bool,
}

impl DepthMap {
    /// The depth map of `triangles` over `positions` seen from `eye` looking at `target`
    /// with `camera`'s vertical field of view, at `viewport` pixels. `None` when the
    /// viewport is empty or larger than [`MAX_PIXELS`], or the view is degenerate.
    pub fn build(
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        camera: &OrbitCamera,
        eye: DVec3,
        target: DVec3,
        viewport: [u32; 2],
    ) -> Option<DepthMap> {
        let [width, height] = viewport;
        let pixels = u64::from(width) * u64::from(height);
        if pixels == 0 || pixels > MAX_PIXELS {
            return None;
        }
        let forward = (target - eye).normalize_or_zero();
        // Any up that is not along `forward` gives the same depths; the camera's keeps the
        // map's frame upright (and defined when looking straight down Y with Z up).
        let right = forward.cross(camera.up.vector()).normalize_or_zero();
        let up = right.cross(forward);
        let tan_half = (camera.fov_y_degrees.to_radians() * 0.5).tan();
        if forward == DVec3::ZERO || right == DVec3::ZERO || !(tan_half.is_finite() && tan_half > 0.0) {
            return None;
        }
        let focal = f64::from(height) * 0.5 / tan_half;
        let near = camera.near_far().0 * 1e-3;
        let key = Key {
            eye: eye.to_array(),
            target: target.to_array(),
            fov_y_degrees: camera.fov_y_degrees,
            viewport,
            positions: (positions.as_ptr() as usize, positions.len()),
            triangles: (triangles.as_ptr() as usize, triangles.len()),
        };
        let mut map = DepthMap { eye, right, up, forward, focal, width, height, near, inv_depth: Vec::new(), key };
        let vertices: Vec<ViewVertex> = positions.par_iter().map(|&p| map.view_vertex(p)).collect();
        let threads = rayon::current_num_threads().clamp(1, 8);
        let chunk = triangles.len().div_ceil(threads).max(1);
        let merged = triangles
            .par_chunks(chunk)
            .map(|chunk| {
                let mut inv_depth = vec![0.0f32; pixels as usize];
                for corners in chunk {
                    map.raster_triangle(&vertices, corners, &mut inv_depth);
                }
                inv_depth
            })
            .reduce_with(|mut a, b| {
                a.par_iter_mut().zip(b.par_iter()).for_each(|(x, &y)| *x = x.max(y));
                a
            });
        map.inv_depth = merged.unwrap_or_else(|| vec![0.0; pixels as usize]);
        Some(map)
    }

    /// Whether this map was built for exactly this view of this mesh.
    pub fn is_for(
        &self,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        camera: &OrbitCamera,
        eye: DVec3,
        target: DVec3,
        viewport: [u32; 2],
    ) -> bool {
        self.key
            == Key {
                eye: eye.to_array(),
                target: target.to_array(),
                fov_y_degrees: camera.fov_y_degrees,
                viewport,
                positions: (positions.as_ptr() as usize, positions.len()),
                triangles: (triangles.as_ptr() as usize, triangles.len()),
            }
    }

    /// Width and height, pixels.
    pub fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    /// Pixels where some surface is.
    pub fn covered_pixels(&self) -> usize {
        self.inv_depth.iter().filter(|&&d| d > 0.0).count()
    }

    /// Whether `point` is visible from the eye (see the module documentation); `None` when
    /// the map cannot tell (outside it or behind the near plane).
    #[inline]
    pub fn visible(&self, point: DVec3) -> Option<bool> {
        let d = point - self.eye;
        let z = d.dot(self.forward);
        if z.is_nan() || z < self.near {
            return None;
        }
        let inv_z = 1.0 / z;
        let fx = f64::from(self.width) * 0.5 + self.focal * d.dot(self.right) * inv_z - 0.5;
        let fy = f64::from(self.height) * 0.5 - self.focal * d.dot(self.up) * inv_z - 0.5;
        let (i0, j0) = (fx.floor(), fy.floor());
        if !(i0 >= 0.0 && j0 >= 0.0 && i0 + 1.0 < f64::from(self.width) && j0 + 1.0 < f64::from(self.height)) {
            return None;
        }
        let (i0, j0, w) = (i0 as usize, j0 as usize, self.width as usize);
        let at = |i: usize, j: usize| self.inv_depth.get(j * w + i).copied().unwrap_or(0.0);
        let farthest = at(i0, j0).min(at(i0 + 1, j0)).min(at(i0, j0 + 1)).min(at(i0 + 1, j0 + 1));
        if farthest <= 0.0 {
            return Some(true);
        }
        let tolerance = z * (DEPTH_TOLERANCE_PX / self.focal + DEPTH_TOLERANCE_RELATIVE);
        Some(z <= 1.0 / f64::from(farthest) + tolerance)
    }

    /// Whether every point of the segment or triangle with these corners passes
    /// [`DepthMap::visible`], when that is certain from the map alone: all corners in front
    /// of the near plane, the pixels any point's four can be inside the map, and at each of
    /// them the map no nearer than the element allows. For a triangle that is its plane's
    /// `1 / z` there (affine on screen; the points' own `1 / z` are convex combinations of
    /// it at their four pixels), for a segment or point the farthest corner, both less the
    /// tolerance at the nearest corner. Lets a brush skip the per-sample test on faces
    /// nothing covers. Boxes over [`MAX_REGION_PIXELS`] give `false`.
    pub fn region_visible(&self, corners: &[DVec3]) -> bool {
        let mut screen = [[0.0f64; 3]; 3];
        let (mut min_x, mut max_x, mut min_y, mut max_y) =
            (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        let (mut z_min, mut z_max) = (f64::INFINITY, 0.0f64);
        for (k, &corner) in corners.iter().enumerate() {
            let d = corner - self.eye;
            let z = d.dot(self.forward);
            if z.is_nan() || z < self.near {
                return false;
            }
            let inv_z = 1.0 / z;
            // Coordinates with pixel centres at integers.
            let x = f64::from(self.width) * 0.5 + self.focal * d.dot(self.right) * inv_z - 0.5;
            let y = f64::from(self.height) * 0.5 - self.focal * d.dot(self.up) * inv_z - 0.5;
            if let Some(slot) = screen.get_mut(k) {
                *slot = [x, y, inv_z];
            }
            (min_x, max_x, min_y, max_y) = (min_x.min(x), max_x.max(x), min_y.min(y), max_y.max(y));
            (z_min, z_max) = (z_min.min(z), z_max.max(z));
        }
        let (i0, i1, j0, j1) = (min_x.floor(), max_x.floor() + 1.0, min_y.floor(), max_y.floor() + 1.0);
        if !(i0 >= 0.0 && j0 >= 0.0 && i1 < f64::from(self.width) && j1 < f64::from(self.height)) {
            return false;
        }
        if (i1 - i0 + 1.0) * (j1 - j0 + 1.0) > MAX_REGION_PIXELS {
            return false;
        }
        let e = DEPTH_TOLERANCE_PX / self.focal + DEPTH_TOLERANCE_RELATIVE;
        // The allowed map value at pixel (x, y): an affine bound on `1 / z` (α x + β y + γ),
        // divided by (1 − e).
        let (alpha, beta, gamma) = if corners.len() == 3 {
            let [a, b, c] = screen;
            let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            if det.is_nan() || det.abs() <= 1e-9 {
                return false;
            }
            let alpha = ((b[2] - a[2]) * (c[1] - a[1]) - (c[2] - a[2]) * (b[1] - a[1])) / det;
            let beta = ((c[2] - a[2]) * (b[0] - a[0]) - (b[2] - a[2]) * (c[0] - a[0])) / det;
            (alpha, beta, a[2] - alpha * a[0] - beta * a[1])
        } else {
            (0.0, 0.0, 1.0 / z_max)
        };
        let scale = if corners.len() == 3 { 1.0 / (1.0 - e) } else { 1.0 / (1.0 - e * z_min / z_max) };
        if !(scale.is_finite() && scale > 0.0) {
            return false;
        }
        let w = self.width as usize;
        for j in j0 as usize..=j1 as usize {
            let Some(row) = self.inv_depth.get(j * w + i0 as usize..=j * w + i1 as usize) else {
                return false;
            };
            for (i, &inv) in (i0 as usize..).zip(row) {
                let plane = alpha * i as f64 + beta * j as f64 + gamma;
                if plane.is_nan() || plane <= 0.0 || f64::from(inv) > plane * scale {
                    return false;
                }
            }
        }
        true
    }

    fn view_vertex(&self, p: [f32; 3]) -> ViewVertex {
        if !p.iter().all(|c| c.is_finite()) {
            return ViewVertex::default();
        }
        let d = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - self.eye;
        let view = DVec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward));
        ViewVertex { view, screen: self.project(view), valid: true }
    }

    /// Screen position and `1 / z` of a view-space point with `z > 0`.
    #[inline]
    fn project(&self, view: DVec3) -> [f64; 3] {
        let inv_z = 1.0 / view.z;
        [
            f64::from(self.width) * 0.5 + self.focal * view.x * inv_z,
            f64::from(self.height) * 0.5 - self.focal * view.y * inv_z,
            inv_z,
        ]
    }

    /// Rasterises one triangle (clipped against the near plane when it crosses it).
    fn raster_triangle(&self, vertices: &[ViewVertex], corners: &[u32; 3], inv_depth: &mut [f32]) {
        let vertex = |k: usize| vertices.get(corners[k] as usize).filter(|v| v.valid);
        let (Some(a), Some(b), Some(c)) = (vertex(0), vertex(1), vertex(2)) else {
            return;
        };
        let in_front = |x: &ViewVertex| x.view.z >= self.near;
        if in_front(a) && in_front(b) && in_front(c) {
            self.raster_screen([a.screen, b.screen, c.screen], inv_depth);
            return;
        }
        // Sutherland–Hodgman against z = near, then a fan.
        let mut polygon: Vec<DVec3> = Vec::with_capacity(4);
        let points = [a.view, b.view, c.view];
        for k in 0..3 {
            let (p, q) = (points[k], points[(k + 1) % 3]);
            let (p_in, q_in) = (p.z >= self.near, q.z >= self.near);
            if p_in {
                polygon.push(p);
            }
            if p_in != q_in {
                let t = (self.near - p.z) / (q.z - p.z);
                let mut x = p + (q - p) * t;
                x.z = self.near;
                polygon.push(x);
            }
        }
        for k in 1..polygon.len().saturating_sub(1) {
            let tri = [polygon[0], polygon[k], polygon[k + 1]].map(|p| self.project(p));
            self.raster_screen(tri, inv_depth);
        }
    }

    /// Rasterises a screen-space triangle (x, y, `1 / z` per corner) at the pixel centres it
    /// covers, edges included, keeping the nearest `1 / z`.
    #[inline]
    fn raster_screen(&self, [a, b, c]: [[f64; 3]; 3], inv_depth: &mut [f32]) {
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if !(area.is_finite() && area != 0.0) {
            return;
        }
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let min_x = a[0].min(b[0]).min(c[0]);
        let max_x = a[0].max(b[0]).max(c[0]);
        let min_y = a[1].min(b[1]).min(c[1]);
        let max_y = a[1].max(b[1]).max(c[1]);
        let i0 = (min_x - 0.5).ceil().max(0.0);
        let i1 = (max_x - 0.5).floor().min(w - 1.0);
        let j0 = (min_y - 0.5).ceil().max(0.0);
        let j1 = (max_y - 0.5).floor().min(h - 1.0);
        if !(i0 <= i1 && j0 <= j1) {
            return;
        }
        let inv_area = 1.0 / area;
        // Barycentric weights (edge functions over the signed area: positive inside); a tiny
        // slack keeps pixel centres on a shared edge inside both triangles (no holes).
        const SLACK: f64 = -1e-7;
        let edge = |p: [f64; 3], q: [f64; 3], x: f64, y: f64| {
            ((q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0])) * inv_area
        };
        let width = self.width as usize;
        for j in j0 as usize..=j1 as usize {
            let y = j as f64 + 0.5;
            for i in i0 as usize..=i1 as usize {
                let x = i as f64 + 0.5;
                let wa = edge(b, c, x, y);
                let wb = edge(c, a, x, y);
                let wc = edge(a, b, x, y);
                if wa < SLACK || wb < SLACK || wc < SLACK {
                    continue;
                }
                let inv_z = (wa * a[2] + wb * b[2] + wc * c[2]) as f32;
                if let Some(slot) = inv_depth.get_mut(j * width + i)
                    && inv_z > *slot
                {
                    *slot = inv_z;
                }
            }
        }
    }
}
