//! The BVH presets of `bench trade`: build time, pick latency and agreement with a
//! brute-force ray cast over every triangle.

use glam::DVec3;

use crate::bench::pack::Timing;
use crate::bench::paint;
use meshpaint_core::camera::{BoundingSphere, default_camera};
use meshpaint_core::io::document::Document;
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};

/// Per BVH preset: build time, pick latency and agreement with brute force (module docs).
pub(super) fn bvh_rows(document: &Document, bounds: BoundingSphere) -> Vec<serde_json::Value> {
    let positions = &document.positions;
    let triangles = &document.store.topology().face_vertices;
    let camera = default_camera(bounds, 30.0, 20.0, None);
    let reference = MeshBvh::build(positions, triangles, BvhPreset::FastBuild);
    let rays = paint::pick_rays(&camera, [1280, 720], 64, &reference);
    let corners: Vec<[DVec3; 3]> =
        triangles.iter().map(|t| t.map(|v| DVec3::from_array(positions[v as usize].map(f64::from)))).collect();
    let brute: Vec<Option<(u32, f64)>> = rays.iter().map(|&(o, d)| brute_force(&corners, o, d)).collect();
    let mut rows = Vec::new();
    for preset in BvhPreset::ALL {
        let (build, bvh) = Timing::measure(1, || MeshBvh::build(positions, triangles, preset));
        let (pick, hits) = Timing::measure(3, || {
            rays.iter().map(|&(o, d)| bvh.cast(o, d, f64::INFINITY).map(|h| (h.face, h.t))).collect::<Vec<_>>()
        });
        let agree = hits
            .iter()
            .zip(&brute)
            .filter(|(hit, truth)| match (hit, truth) {
                (None, None) => true,
                (Some((fa, ta)), Some((fb, tb))) => fa == fb || (ta - tb).abs() <= 1e-9 * tb.abs().max(1e-300),
                _ => false,
            })
            .count();
        let picks = rays.len().max(1) as f64;
        rows.push(serde_json::json!({
            "preset": preset.name(), "build_seconds": build.best_seconds,
            "pick_seconds_best": pick.best_seconds / picks, "pick_seconds_median": pick.median_seconds / picks,
            "picks": rays.len(), "hits": hits.iter().filter(|h| h.is_some()).count(),
            "agree_with_brute_force": agree, "triangles": triangles.len(),
        }));
    }
    rows
}

/// Nearest hit (face, t) of the ray over every triangle, both sides: Möller–Trumbore in `f64`,
/// ties in `t` to the lowest face.
pub fn brute_force(corners: &[[DVec3; 3]], origin: DVec3, direction: DVec3) -> Option<(u32, f64)> {
    let mut best: Option<(u32, f64)> = None;
    for (face, [p0, p1, p2]) in corners.iter().enumerate() {
        let (e1, e2) = (*p1 - *p0, *p2 - *p0);
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            continue;
        }
        let inv = 1.0 / det;
        let s = origin - *p0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = s.cross(e1);
        let v = direction.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let t = e2.dot(q) * inv;
        if t >= 0.0 && best.is_none_or(|(_, bt)| t < bt) {
            best = Some((face as u32, t));
        }
    }
    best
}
