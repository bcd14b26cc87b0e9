//! The brushes against independent truths: brute-force distance tests over every stored
//! sample (world positions from `for_each_site`), closed-form falloff and blend values,
//! analytic visibility (occlusion, backface culling), mirror symmetry on an x-symmetric mesh,
//! gap-free fast strokes, blur against its neighbour mean, the resolution brush against a
//! brute-force sphere/triangle test, fill, eyedropper, and repacking after painting. The
//! hard (constant-falloff) brushes here paint at the store's own `R` (`HardEdges::SAMPLED`):
//! their default raise is tested in crates/core/tests/core/hard_edge.rs.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use std::collections::HashMap;

use glam::DVec3;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::packer;
use meshpaint_core::paint::brush::{
    self, BlendMode, BrushRadius, BrushSettings, Falloff, FillScope, HardEdges, PaintView, Painter, PressureResponse,
    ResolutionOp, StrokePoint, Tool,
};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;

use crate::common;
use crate::common::WriteThrough;
use common::{Mesh, Rng, TempDir, icosphere, join, model};

const WIDTH: u32 = 1024;
const HEIGHT: u32 = 768;
const GREY: Rgba = [0.5, 0.5, 0.5, 1.0];
const GREEN: Rgba = [0.1, 0.9, 0.2, 1.0];

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

// ---------------------------------------------------------------- meshes

/// An `n × n` grid of quads (two triangles each) in the plane `z`, over `[x0, x1] × [y0, y1]`,
/// front (counter-clockwise) side towards +z.
fn grid(n: u32, z: f32, [x0, x1]: [f32; 2], [y0, y1]: [f32; 2]) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            positions.push([x0 + (x1 - x0) * u, y0 + (y1 - y0) * v, z]);
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (positions, triangles)
}

// ---------------------------------------------------------------- helpers

fn dvec(p: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

/// A mesh ready to paint: store, BVH and camera.
struct Scene {
    positions: Vec<[f32; 3]>,
    store: ColorStore,
    bvh: MeshBvh,
    camera: OrbitCamera,
}

impl Scene {
    fn new((positions, triangles): Mesh, resolution: u64, color: Rgba, yaw: f64, pitch: f64) -> Self {
        let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
        let store = ColorStore::uniform(topology, r(resolution), color);
        let bvh = MeshBvh::build(&positions, &triangles, BvhPreset::FastBuild);
        let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), yaw, pitch);
        Scene { positions, store, bvh, camera }
    }

    fn view<'a>(&'a self, base: Option<&'a ColorStore>) -> PaintView<'a> {
        PaintView {
            positions: &self.positions,
            bvh: &self.bvh,
            camera: &self.camera,
            viewport_px: [WIDTH, HEIGHT],
            base,
        }
    }

    /// Every stored sample with its world position (brute force, from `for_each_site`).
    fn sites(&self) -> Vec<(SampleRef, DVec3, u32)> {
        let mut out = Vec::new();
        let faces = &self.store.topology().face_vertices;
        self.store.for_each_site(|site| {
            let corners = faces[site.face as usize];
            let p = (0..3).map(|k| dvec(self.positions[corners[k] as usize]) * f64::from(site.barycentric[k])).sum();
            out.push((site.sample, p, site.face));
        });
        out
    }

    /// Replays a stroke with `settings` (one undo step) and returns its dabs.
    fn stroke<P: Copy + Into<StrokePoint>>(&mut self, settings: BrushSettings, points: &[P]) -> Vec<brush::Dab> {
        let mut painter = Painter::new(&self.positions);
        painter.set_settings(settings);
        painter.set_hard_edges(HardEdges::SAMPLED);
        let mut history = UndoHistory::default();
        let mut store = self.store.clone();
        let view = self.view(None);
        let (update, _) = brush::replay_stroke(&mut painter, &view, &mut store, &mut history, points).unwrap();
        self.store = store;
        update.dabs
    }
}

fn plain(tool: Tool, color: Rgba, radius: BrushRadius) -> BrushSettings {
    BrushSettings {
        tool,
        color,
        blend: BlendMode::Mix,
        radius,
        strength: 1.0,
        falloff: Falloff::Constant,
        spacing_percent: 10.0,
        occlusion: false,
        backface_culling: false,
        mirror_x: false,
        follow_resolution: None,
        pressure: PressureResponse::default(),
    }
}

fn bits(color: Rgba) -> [u32; 4] {
    color.map(f32::to_bits)
}

/// The outward unit normal of a face.
fn face_normal(positions: &[[f32; 3]], corners: [u32; 3]) -> DVec3 {
    let [a, b, c] = corners.map(|v| dvec(positions[v as usize]));
    (b - a).cross(c - a).normalize()
}

// ---------------------------------------------------------------- footprint

#[test]
fn a_stroke_changes_exactly_the_samples_inside_its_dabs() {
    let mut scene = Scene::new(icosphere(3), 16, GREY, 30.0, 20.0);
    let before = scene.store.clone();
    let settings = plain(Tool::Paint, GREEN, BrushRadius::Pixels { radius_px: 40.0 });
    let dabs = scene.stroke(settings, &[[400.0, 300.0], [560.0, 420.0], [640.0, 380.0]]);
    assert!(dabs.len() > 20, "{} dabs", dabs.len());
    let (mut inside, mut outside, mut band) = (0, 0, 0);
    for (sample, p, _) in scene.sites() {
        // Signed distance to the union of the dab spheres, relative to the radius.
        let margin = dabs
            .iter()
            .map(|dab| ((p - DVec3::from_array(dab.center_world)).length() - dab.radius_world) / dab.radius_world)
            .fold(f64::INFINITY, f64::min);
        let now = scene.store.get(sample).unwrap();
        if margin.abs() < 1e-6 {
            band += 1;
            continue;
        }
        if margin < 0.0 {
            inside += 1;
            assert_eq!(bits(now), bits(GREEN), "{sample:?} at {p} is inside (margin {margin}) but not painted");
        } else {
            outside += 1;
            assert_eq!(bits(now), bits(before.get(sample).unwrap()), "{sample:?} at {p} is outside but changed");
        }
    }
    assert!(inside > 1000 && outside > 1000, "inside {inside}, outside {outside}, band {band}");
    assert!(band < 10, "{band} samples on the rim");
    // The dab radius is the pixel radius at the hit depth.
    for dab in &dabs {
        let center = DVec3::from_array(dab.center_world);
        let (x, y) = scene.camera.project(center, WIDTH, HEIGHT).unwrap();
        assert!((x - dab.cursor_px[0]).abs() < 1e-6 && (y - dab.cursor_px[1]).abs() < 1e-6);
        let (right, _) = scene.camera.right_up();
        let (x2, _) = scene.camera.project(center + right * dab.radius_world, WIDTH, HEIGHT).unwrap();
        // One screen-parallel radius at the hit projects to 40 px (perspective: to first order).
        assert!(((x2 - x).abs() - 40.0).abs() < 0.5, "{} px", (x2 - x).abs());
        assert!(scene.bvh.faces_in_sphere(center, 1e-9).contains(&dab.face));
    }
}

#[test]
fn each_shared_sample_is_updated_once_per_dab() {
    each_shared_sample_is_updated_once(4, 0.7, 100);
}

/// The same with a dab of more than 8192 samples (the kernels compute it in parallel chunks).
#[test]
fn each_shared_sample_is_updated_once_in_a_large_dab() {
    each_shared_sample_is_updated_once(16, 1.5, 20_000);
}

/// A stroke of large dabs (parallel chunks whose undo records become blocks of their own)
/// at R = 32: every changed sample's element is reported dirty, undo restores the store
/// before the stroke bit for bit, and redo the store after it.
#[test]
fn large_dabs_undo_redo_and_dirty_sets_are_exact() {
    let scene = Scene::new(icosphere(2), 32, [0.2, 0.3, 0.4, 1.0], 0.0, 0.0);
    let mut store = scene.store.clone();
    let before = store.clone();
    store.take_dirty();
    let mut painter = Painter::new(&scene.positions);
    let settings =
        BrushSettings { strength: 0.7, falloff: Falloff::Smooth, ..plain(Tool::Paint, GREEN, BrushRadius::default()) };
    painter.set_settings(settings);
    let mut history = UndoHistory::default();
    history.begin_step(&store, "stroke").unwrap();
    let mut covered = 0;
    for (k, &v) in [0usize, 3, 7].iter().enumerate() {
        let center = DVec3::from_array(scene.positions[v].map(f64::from));
        let radius = 0.6 + 0.1 * k as f64;
        covered += painter.dab_at(&scene.view(None), &mut store, &mut history, center, radius).unwrap().samples_covered;
    }
    let summary = history.end_step().unwrap();
    assert!(covered > 30_000, "{covered} samples covered");
    let after = store.clone();
    let dirty = store.take_dirty();
    let mut all = Vec::new();
    before.for_each_site(|site| all.push(site.sample));
    let mut changed = 0u64;
    for &sample in &all {
        if bits(before.get(sample).unwrap()) == bits(after.get(sample).unwrap()) {
            continue;
        }
        changed += 1;
        let reported = match sample {
            SampleRef::Vertex(v) => dirty.vertices.contains(&v),
            SampleRef::Edge { edge, .. } => dirty.edges.contains(&edge),
            SampleRef::Interior { face, .. } => dirty.faces.contains(&face),
        };
        assert!(reported, "{sample:?} changed but its element is not dirty");
    }
    assert_eq!(summary.samples, changed, "one record per changed sample");
    assert!(history.undo(&mut store).unwrap());
    assert!(all.iter().all(|&s| bits(store.get(s).unwrap()) == bits(before.get(s).unwrap())), "undo");
    assert!(history.redo(&mut store).unwrap());
    assert!(all.iter().all(|&s| bits(store.get(s).unwrap()) == bits(after.get(s).unwrap())), "redo");
}

fn each_shared_sample_is_updated_once(resolution: u64, radius: f64, min_covered: u64) {
    // Add with constant weight 1: a sample updated twice would get the colour twice.
    let scene = Scene::new(icosphere(2), resolution, [0.0, 0.0, 0.0, 1.0], 0.0, 0.0);
    let mut store = scene.store.clone();
    let mut painter = Painter::new(&scene.positions);
    let add = [0.25, 0.125, 0.0625, 0.0];
    painter.set_settings(BrushSettings { blend: BlendMode::Add, ..plain(Tool::Paint, add, BrushRadius::default()) });
    painter.set_hard_edges(HardEdges::SAMPLED);
    let mut history = UndoHistory::default();
    let center = DVec3::from_array(scene.positions[0].map(f64::from));
    let stats = painter.dab_at(&scene.view(None), &mut store, &mut history, center, radius).unwrap();
    let mut covered = 0;
    for (sample, p, _) in scene.sites() {
        let now = store.get(sample).unwrap();
        if (p - center).length() < radius {
            covered += 1;
            assert_eq!(now, [0.25, 0.125, 0.0625, 1.0], "{sample:?}");
        } else {
            assert_eq!(now, [0.0, 0.0, 0.0, 1.0], "{sample:?}");
        }
    }
    assert_eq!(stats.samples_covered, covered);
    assert_eq!(stats.samples_changed, covered);
    assert!(covered > min_covered, "{covered} samples covered");
}

/// The falloff curves' closed forms, written independently of the library.
fn closed_form(falloff: Falloff, x: f64) -> f64 {
    let s = 1.0 - x;
    match falloff {
        Falloff::Smooth => 3.0 * s * s - 2.0 * s * s * s,
        Falloff::Linear => s,
        Falloff::Constant => 1.0,
        Falloff::Sharp => s * s,
    }
}

#[test]
fn strength_falloff_and_blend_follow_the_closed_forms() {
    let scene = Scene::new(grid(8, 0.0, [-1.0, 1.0], [-1.0, 1.0]), 16, GREY, 0.0, 0.0);
    let center = DVec3::new(0.1, -0.05, 0.0);
    let radius = 0.6;
    let strength = 0.7f32;
    let mut base = scene.store.clone();
    base.write_all(|site| [0.2 + 0.1 * site.barycentric[0], 0.3, 0.4, 1.0]);
    let color: Rgba = [0.9, 0.5, 0.25, 0.5];
    for falloff in Falloff::ALL {
        for blend in BlendMode::ALL {
            let mut store = scene.store.clone();
            let mut painter = Painter::new(&scene.positions);
            painter.set_settings(BrushSettings {
                falloff,
                blend,
                strength,
                ..plain(Tool::Paint, color, BrushRadius::World { radius_world: radius })
            });
            let mut history = UndoHistory::default();
            painter.dab_at(&scene.view(Some(&base)), &mut store, &mut history, center, radius).unwrap();
            let mut checked = 0;
            for (sample, p, _) in scene.sites() {
                let x = (p - center).length() / radius;
                let old = GREY;
                let now = store.get(sample).unwrap();
                if x >= 1.0 - 1e-9 {
                    assert_eq!(now, old, "{falloff:?} {blend:?} {sample:?} outside");
                    continue;
                }
                let w = f64::from(strength) * closed_form(falloff, x);
                let b = base.get(sample).unwrap();
                let target: [f64; 4] = std::array::from_fn(|c| {
                    let (o, k) = (f64::from(old[c]), f64::from(color[c]));
                    match blend {
                        BlendMode::Mix => k,
                        BlendMode::Add if c < 3 => o + k,
                        BlendMode::Multiply if c < 3 => o * k,
                        BlendMode::Add | BlendMode::Multiply => o,
                        BlendMode::EraseToBase => f64::from(b[c]),
                    }
                });
                for c in 0..4 {
                    let expected = f64::from(old[c]) * (1.0 - w) + target[c] * w;
                    assert!(
                        (f64::from(now[c]) - expected).abs() < 2e-6,
                        "{falloff:?} {blend:?} {sample:?} x={x}: channel {c} is {} expected {expected}",
                        now[c]
                    );
                }
                checked += 1;
            }
            assert!(checked > 500, "{checked}");
        }
    }
}

#[test]
fn erase_to_base_restores_the_snapshot_even_after_a_resolution_change() {
    let mut scene = Scene::new(icosphere(2), 4, GREY, 0.0, 0.0);
    let mut rng = Rng(7);
    scene.store.write_all(|_| rng.opaque_color());
    let base = scene.store.clone();
    let mut store = scene.store.clone();
    let mut history = UndoHistory::default();
    let mut painter = Painter::new(&scene.positions);
    painter.set_hard_edges(HardEdges::SAMPLED);
    let view = scene.view(Some(&base));
    let center = DVec3::from_array(scene.positions[5].map(f64::from));
    painter.set_settings(plain(Tool::Paint, GREEN, BrushRadius::default()));
    painter.dab_at(&view, &mut store, &mut history, center, 0.8).unwrap();
    // Erase everything painted with weight 1: back to the base bit for bit.
    painter.set_settings(BrushSettings {
        blend: BlendMode::EraseToBase,
        ..plain(Tool::Paint, GREEN, BrushRadius::default())
    });
    painter.dab_at(&view, &mut store, &mut history, center, 0.8).unwrap();
    let mut all = Vec::new();
    store.for_each_site(|site| all.push(site.sample));
    for sample in &all {
        assert_eq!(bits(store.get(*sample).unwrap()), bits(base.get(*sample).unwrap()), "{sample:?}");
    }
    // A face raised after the snapshot: erase samples the base linearly there.
    let face = 3;
    store.write_resolution(face, r(8)).unwrap();
    painter.dab_at(&view, &mut store, &mut history, center, 5.0).unwrap();
    let corners = store.topology().face_vertices[face as usize];
    for i in 0..=8u32 {
        for j in 0..=8 - i {
            let bary = [(8 - i - j) as f32 / 8.0, i as f32 / 8.0, j as f32 / 8.0];
            let expected = meshpaint_core::packing::sampler::sample(
                &base,
                face,
                bary,
                meshpaint_core::packing::sampler::Filter::Linear,
                0,
            )
            .unwrap();
            let now = store.face_sample(face, i, j).unwrap();
            for c in 0..4 {
                assert!((now[c] - expected[c]).abs() < 1e-6, "({i},{j}) of face {face} corners {corners:?}");
            }
        }
    }
    // Without a base, erase is refused.
    let no_base = scene.view(None);
    assert!(matches!(
        painter.begin_stroke(&no_base, &mut store, &mut history, [512.0, 384.0]),
        Err(brush::BrushError::NoBase)
    ));
}

// ---------------------------------------------------------------- visibility

/// Two parallel grids facing the eye (+z): a back plate at z = −0.3 and a front plate at
/// z = +0.3 covering only x < 0. A dab reaching under the front plate must not paint the
/// part of the back plate it hides when occlusion is on.
#[test]
fn occlusion_leaves_hidden_samples_untouched() {
    let back = grid(24, -0.3, [-1.0, 1.0], [-1.0, 1.0]);
    let front = grid(12, 0.3, [-1.0, 0.0], [-1.0, 1.0]);
    let scene = Scene::new(join(back, front), 8, GREY, 0.0, 0.0);
    let eye = scene.camera.eye();
    let center = DVec3::new(0.25, 0.0, -0.3);
    let radius = 0.7;
    let back_vertices = 25 * 25;
    for (occlusion, culling) in [(true, false), (false, true), (false, false), (true, true)] {
        let mut store = scene.store.clone();
        let mut painter = Painter::new(&scene.positions);
        painter.set_settings(BrushSettings {
            occlusion,
            backface_culling: culling,
            ..plain(Tool::Paint, GREEN, BrushRadius::World { radius_world: radius })
        });
        let mut history = UndoHistory::default();
        painter.dab_at(&scene.view(None), &mut store, &mut history, center, radius).unwrap();
        let (mut hidden, mut visible) = (0, 0);
        for (sample, p, face) in scene.sites() {
            let d = (p - center).length();
            if (d - radius).abs() < 1e-9 {
                continue;
            }
            let on_back = scene.store.topology().face_vertices[face as usize][0] < back_vertices;
            // Analytic visibility: where the eye→sample segment crosses z = 0.3.
            let t = (0.3 - eye.z) / (p.z - eye.z);
            let crossing = eye + (p - eye) * t;
            let blocked = on_back && crossing.x < 0.0 && crossing.y.abs() < 1.0;
            if on_back && d < radius && (crossing.x.abs() < 1e-6 || (crossing.y.abs() - 1.0).abs() < 1e-6) {
                continue;
            }
            let painted = store.get(sample).unwrap() != GREY;
            let expected = d < radius && !(occlusion && blocked);
            assert_eq!(painted, expected, "occlusion {occlusion} culling {culling}: {sample:?} at {p}");
            if d < radius && blocked {
                hidden += 1;
            } else if d < radius {
                visible += 1;
            }
        }
        assert!(hidden > 100 && visible > 100, "{hidden} hidden, {visible} visible");
    }
}

/// On a closed convex mesh, a dab larger than the mesh: with occlusion or backface culling
/// only the side facing the eye is painted (occlusion, from the view's depth map, may reach
/// past the silhouette by its tolerance: a pixel; samples within two pixels of it are not
/// judged).
#[test]
fn occlusion_and_culling_keep_the_far_side_of_a_closed_mesh_unpainted() {
    let scene = Scene::new(icosphere(3), 4, GREY, 30.0, 20.0);
    let eye = scene.camera.eye();
    let center = DVec3::from_array(scene.camera.target) + scene.camera.eye_direction();
    for (occlusion, culling) in [(true, false), (false, true)] {
        let mut store = scene.store.clone();
        let mut painter = Painter::new(&scene.positions);
        painter.set_settings(BrushSettings {
            occlusion,
            backface_culling: culling,
            ..plain(Tool::Paint, GREEN, BrushRadius::World { radius_world: 2.5 })
        });
        let mut history = UndoHistory::default();
        painter.dab_at(&scene.view(None), &mut store, &mut history, center, 2.5).unwrap();
        let (mut front, mut back) = (0, 0);
        for (sample, p, face) in scene.sites() {
            // Facing: the face normal against the direction to the eye (every face of a
            // sample agrees away from the silhouette).
            let normal = face_normal(&scene.positions, scene.store.topology().face_vertices[face as usize]);
            let facing = normal.dot((eye - p).normalize());
            let painted = store.get(sample).unwrap() != GREY;
            if facing > 0.15 {
                assert!(painted, "occlusion {occlusion} culling {culling}: visible {sample:?} unpainted");
                front += 1;
            } else if facing < -0.15 {
                if occlusion && near_silhouette(&scene, p) {
                    continue;
                }
                assert!(!painted, "occlusion {occlusion} culling {culling}: hidden {sample:?} painted");
                back += 1;
            }
        }
        assert!(front > 1000 && back > 1000, "{front} {back}");
    }
}

/// Whether a pixel ray within two pixels of `p`'s projection misses the mesh.
fn near_silhouette(scene: &Scene, p: DVec3) -> bool {
    let Some((x, y)) = scene.camera.project(p, WIDTH, HEIGHT) else {
        return true;
    };
    (-2..=2).any(|a| {
        (-2..=2).any(|b| {
            let (origin, direction) = scene.camera.ray_through_pixel(x + f64::from(a), y + f64::from(b), WIDTH, HEIGHT);
            scene.bvh.cast(origin, direction, f64::INFINITY).is_none()
        })
    })
}

// ---------------------------------------------------------------- mirror

#[test]
fn mirror_paints_the_mirrored_samples() {
    // yaw 90: the eye is on +x; the mirrored dab on −x is seen from the mirrored eye.
    for (occlusion, culling) in [(false, false), (true, true)] {
        let mut scene = Scene::new(icosphere(3), 8, GREY, 90.0, 10.0);
        let painter = Painter::new(&scene.positions);
        assert_eq!(painter.mirror_plane_x(), 0.0);
        let settings = BrushSettings {
            mirror_x: true,
            occlusion,
            backface_culling: culling,
            falloff: Falloff::Smooth,
            strength: 0.8,
            ..plain(Tool::Paint, GREEN, BrushRadius::Pixels { radius_px: 60.0 })
        };
        let dabs = scene.stroke(settings, &[[470.0, 340.0], [560.0, 420.0]]);
        assert!(!dabs.is_empty());
        let key = |p: DVec3| (p * 1e5).round().as_i64vec3().to_array();
        let sites = scene.sites();
        let by_position: HashMap<[i64; 3], Rgba> =
            sites.iter().map(|&(sample, p, _)| (key(p), scene.store.get(sample).unwrap())).collect();
        let eye = scene.camera.eye();
        let (mut painted, mut mirrored_side) = (0, 0);
        for &(sample, p, face) in &sites {
            let now = scene.store.get(sample).unwrap();
            let mirror = DVec3::new(-p.x, p.y, p.z);
            let other = by_position[&key(mirror)];
            // Skip the rims: distance to a sphere ≈ radius, or facing ≈ 0 (either eye).
            let near_rim = dabs.iter().any(|dab| {
                let c = DVec3::from_array(dab.center_world);
                let d = (p - c).length().min((mirror - DVec3::new(-c.x, c.y, c.z)).length());
                (d - dab.radius_world).abs() < 1e-3 * dab.radius_world
                    || ((p - DVec3::new(-c.x, c.y, c.z)).length() - dab.radius_world).abs() < 1e-3 * dab.radius_world
            });
            let normal = face_normal(&scene.positions, scene.store.topology().face_vertices[face as usize]);
            let mirrored_eye = DVec3::new(-eye.x, eye.y, eye.z);
            let grazing =
                normal.dot((eye - p).normalize()).abs() < 0.1 || normal.dot((mirrored_eye - p).normalize()).abs() < 0.1;
            if near_rim || ((occlusion || culling) && grazing) {
                continue;
            }
            for c in 0..4 {
                assert!((now[c] - other[c]).abs() < 1e-5, "{sample:?} at {p}: {now:?} vs mirror {other:?}");
            }
            if now != GREY {
                painted += 1;
                if p.x < -0.1 {
                    mirrored_side += 1;
                }
            }
        }
        assert!(painted > 500 && mirrored_side > 200, "{painted} painted, {mirrored_side} on the mirrored side");
    }
}

// ---------------------------------------------------------------- strokes

/// Distance from `p` to the segment `a..b`.
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

#[test]
fn fast_strokes_leave_no_gaps() {
    // A plane facing the eye; two cursor events 424 px apart with a 10 px brush.
    for radius in [BrushRadius::Pixels { radius_px: 10.0 }, BrushRadius::World { radius_world: 0.03 }] {
        let mut scene = Scene::new(grid(32, 0.0, [-1.0, 1.0], [-1.0, 1.0]), 8, GREY, 0.0, 0.0);
        let settings =
            BrushSettings { spacing_percent: 25.0, falloff: Falloff::Smooth, ..plain(Tool::Paint, GREEN, radius) };
        let dabs = scene.stroke(settings, &[[300.0, 384.0], [724.0, 390.0]]);
        let radius_world = dabs[0].radius_world;
        let radius_px = radius_world / (scene.camera.world_per_pixel(f64::from(HEIGHT)));
        let length_px = 424f64.hypot(6.0);
        assert!(
            dabs.len() as f64 >= length_px / (0.25 * radius_px),
            "{} dabs for {length_px} px at spacing {} px",
            dabs.len(),
            0.25 * radius_px
        );
        for pair in dabs.windows(2) {
            let step = (pair[1].cursor_px[0] - pair[0].cursor_px[0]).hypot(pair[1].cursor_px[1] - pair[0].cursor_px[1]);
            assert!(step <= 0.25 * radius_px * 1.001, "{step} px between dabs");
        }
        let a = DVec3::from_array(dabs[0].center_world);
        let b = DVec3::from_array(dabs[dabs.len() - 1].center_world);
        let mut band = 0;
        for (sample, p, _) in scene.sites() {
            let d = segment_distance(p, a, b);
            let painted = scene.store.get(sample).unwrap() != GREY;
            if d <= 0.9 * radius_world {
                assert!(painted, "{sample:?} at {p}, {d} from the stroke (radius {radius_world}), has no paint");
                band += 1;
            } else if d > radius_world * (1.0 + 1e-6) {
                assert!(!painted, "{sample:?} at {p}, {d} from the stroke, was painted");
            }
        }
        assert!(band > 1000, "{band}");
    }
}

#[test]
fn a_stroke_is_one_undo_step_and_misses_place_no_dabs() {
    let scene = Scene::new(icosphere(2), 4, GREY, 0.0, 0.0);
    let mut store = scene.store.clone();
    let mut history = UndoHistory::default();
    let mut painter = Painter::new(&scene.positions);
    painter.set_settings(plain(Tool::Paint, GREEN, BrushRadius::Pixels { radius_px: 20.0 }));
    let view = scene.view(None);
    // Starts off the mesh (corner of the view), crosses it, ends off it.
    let first = painter.begin_stroke(&view, &mut store, &mut history, [5.0, 5.0]).unwrap();
    assert!(first.dabs.is_empty());
    let mut dabs = 0;
    for point in [[512.0, 384.0], [1000.0, 760.0]] {
        dabs += painter.stroke_to(&view, &mut store, &mut history, point).unwrap().dabs.len();
    }
    assert!(dabs > 10);
    assert!(painter.is_stroking() && history.is_recording());
    let summary = painter.end_stroke(&mut history).unwrap();
    assert!(summary.kept && summary.samples > 0);
    assert_eq!(history.undo_len(), 1);
    assert_eq!(history.undo_label(), Some("paint stroke"));
    // Every dirty sample was recorded, and the dirty elements are exactly the changed ones.
    let dirty = store.take_dirty();
    assert!(!dirty.is_empty());
    history.undo(&mut store).unwrap();
    let mut all = Vec::new();
    store.for_each_site(|site| all.push(site.sample));
    assert!(all.iter().all(|&s| store.get(s) == Some(GREY)));
}

// ---------------------------------------------------------------- blur

#[test]
fn blur_moves_samples_towards_their_neighbour_mean() {
    let mut scene = Scene::new(grid(4, 0.0, [-1.0, 1.0], [-1.0, 1.0]), 16, GREY, 0.0, 0.0);
    let mut rng = Rng(3);
    scene.store.write_all(|_| rng.opaque_color());
    let before = scene.store.clone();
    let mut store = scene.store.clone();
    let mut painter = Painter::new(&scene.positions);
    let strength = 0.6;
    painter.set_settings(BrushSettings {
        strength,
        falloff: Falloff::Linear,
        ..plain(Tool::Blur, GREEN, BrushRadius::World { radius_world: 0.6 })
    });
    let center = DVec3::new(0.05, 0.1, 0.0);
    let mut history = UndoHistory::default();
    painter.dab_at(&scene.view(None), &mut store, &mut history, center, 0.6).unwrap();
    // Interior samples: their six neighbours are all in their face.
    let mut checked = 0;
    for (sample, p, face) in scene.sites() {
        let d = (p - center).length();
        let now = store.get(sample).unwrap();
        let old = before.get(sample).unwrap();
        if d >= 0.6 {
            assert_eq!(now, old, "{sample:?} outside changed");
            continue;
        }
        let SampleRef::Interior { offset, .. } = sample else {
            continue;
        };
        let (i, j) = meshpaint_core::colors::layout::interior_sample_at(r(16), offset).unwrap();
        let neighbours = [(i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1), (i + 1, j - 1), (i - 1, j + 1)];
        let w = f64::from(strength) * (1.0 - d / 0.6);
        for c in 0..4 {
            let mean: f64 =
                neighbours.iter().map(|&(a, b)| f64::from(before.face_sample(face, a, b).unwrap()[c])).sum::<f64>()
                    / 6.0;
            let expected = f64::from(old[c]) * (1.0 - w) + mean * w;
            assert!((f64::from(now[c]) - expected).abs() < 1e-5, "{sample:?} channel {c}");
        }
        checked += 1;
    }
    assert!(checked > 300, "{checked}");
    // A constant colour stays (nearly bit-) constant under blur.
    let mut flat = scene.store.clone();
    flat.write_all(|_| [0.25, 0.5, 0.75, 1.0]);
    painter.dab_at(&scene.view(None), &mut flat, &mut history, center, 0.6).unwrap();
    flat.for_each_site(|site| {
        let color = flat.get(site.sample).unwrap();
        assert!((color[0] - 0.25).abs() < 1e-6 && (color[2] - 0.75).abs() < 1e-6);
    });
}

/// The blur brush against a brute-force blur written from its definition: every lattice
/// point of every face with a positive weight (the dab's weight formula at the point as that
/// face computes it) contributes the sum and count of its six lattice neighbours in that face
/// (read one by one with `face_sample`); each sample moves towards the mean over all its
/// faces by the largest weight. Mixed resolutions (shared edges read with stride), random
/// colours, one dab; equal within float rounding, everything else bit-identical.
#[test]
fn blur_matches_a_brute_force_blur_on_mixed_resolutions() {
    blur_against_brute_force(4, 0.55, 500);
}

/// The same with a dab of more than 8192 samples (computed in parallel chunks of faces).
#[test]
fn blur_matches_a_brute_force_blur_in_a_large_dab() {
    blur_against_brute_force(5, 1.2, 10_000);
}

/// The blur of one dab (R from 2 to `2^levels` at random, sphere radius `radius` on the unit
/// icosphere) against the brute force; at least `min_terms` samples covered.
fn blur_against_brute_force(levels: u64, radius: f64, min_terms: usize) {
    let (positions, triangles) = icosphere(2);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut rng = Rng(11);
    let resolutions: Vec<Resolution> = (0..triangles.len()).map(|_| r(1 << (1 + rng.next() % levels))).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, GREY).unwrap();
    store.write_all(|_| rng.opaque_color());
    let bvh = MeshBvh::build(&positions, &triangles, BvhPreset::FastBuild);
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 0.0, 0.0);
    let view =
        PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [WIDTH, HEIGHT], base: None };
    let before = store.clone();
    let (center, strength) = (DVec3::new(0.3, 0.5, 0.8).normalize(), 0.7f32);
    let mut painter = Painter::new(&positions);
    painter.set_settings(BrushSettings {
        strength,
        falloff: Falloff::Smooth,
        ..plain(Tool::Blur, GREEN, BrushRadius::World { radius_world: radius })
    });
    let mut history = UndoHistory::default();
    history.begin_step(&store, "blur").unwrap();
    let stats = painter.dab_at(&view, &mut store, &mut history, center, radius).unwrap();
    history.end_step();
    // Brute force: (neighbour sum, count, largest weight) per sample.
    let mut terms: HashMap<SampleRef, ([f32; 4], u32, f32)> = HashMap::new();
    let inv_radius = 1.0 / radius;
    for face in 0..before.topology().face_count() {
        let res = before.face_resolution(face).unwrap().get();
        let [p0, p1, p2] = before.topology().face_vertices[face as usize].map(|v| dvec(positions[v as usize]));
        let inv = 1.0 / f64::from(res);
        let (e1, e2) = ((p1 - p0) * inv, (p2 - p0) * inv);
        for i in 0..=res {
            let a = p0 + e1 * f64::from(i);
            for j in 0..=res - i {
                let d2 = (a + e2 * f64::from(j) - center).length_squared();
                if d2 > radius * radius {
                    continue;
                }
                let weight = strength * Falloff::Smooth.weight_of_squared((d2 * inv_radius * inv_radius) as f32);
                if weight <= 0.0 {
                    continue;
                }
                let (mut sum, mut count) = ([0.0f32; 4], 0);
                for (di, dj) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)] {
                    let (ni, nj) = (i64::from(i) + di, i64::from(j) + dj);
                    if ni < 0 || nj < 0 || ni + nj > i64::from(res) {
                        continue;
                    }
                    let color = before.face_sample(face, ni as u32, nj as u32).unwrap();
                    for c in 0..4 {
                        sum[c] += color[c];
                    }
                    count += 1;
                }
                let entry = terms.entry(before.face_sample_ref(face, i, j).unwrap()).or_insert(([0.0; 4], 0, 0.0));
                for c in 0..4 {
                    entry.0[c] += sum[c];
                }
                entry.1 += count;
                entry.2 = entry.2.max(weight);
            }
        }
    }
    let mut all = Vec::new();
    before.for_each_site(|site| all.push(site.sample));
    let mut shared = 0;
    for sample in all {
        let (old, now) = (before.get(sample).unwrap(), store.get(sample).unwrap());
        let Some(&(sum, count, weight)) = terms.get(&sample) else {
            assert_eq!(bits(now), bits(old), "{sample:?} outside the brush changed");
            continue;
        };
        shared += usize::from(!matches!(sample, SampleRef::Interior { .. }));
        let mean = sum.map(|s| s / count as f32);
        let expected = BlendMode::Mix.blend(old, mean, old, weight);
        for c in 0..4 {
            assert!((now[c] - expected[c]).abs() < 2e-6, "{sample:?} channel {c}: {} vs {}", now[c], expected[c]);
        }
    }
    assert_eq!(stats.samples_covered, terms.len() as u64);
    assert!(terms.len() > min_terms && shared > 100, "{} samples, {shared} on edges or vertices", terms.len());
    // Undo restores every sample bit for bit.
    assert!(history.undo(&mut store).unwrap());
    let mut all = Vec::new();
    before.for_each_site(|site| all.push(site.sample));
    assert!(all.iter().all(|&s| store.get(s).map(bits) == before.get(s).map(bits)));
}

// ---------------------------------------------------------------- resolution brush

/// Whether triangle `t` has a point within `radius` of `c`: dense barycentric sampling plus
/// the corners and edge points (a brute force independent of the library's closest point).
fn triangle_within(t: [DVec3; 3], c: DVec3, radius: f64) -> Option<bool> {
    let n = 200;
    let mut min = f64::INFINITY;
    for i in 0..=n {
        for j in 0..=n - i {
            let (u, v) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            let p = t[0] * (1.0 - u - v) + t[1] * u + t[2] * v;
            min = min.min((p - c).length());
        }
    }
    // Undecided within the sampling error (the grid spacing bounds it).
    let spacing = (t[1] - t[0]).length().max((t[2] - t[0]).length()) / f64::from(n);
    if (min - radius).abs() < spacing {
        return None;
    }
    Some(min < radius)
}

#[test]
fn the_resolution_brush_changes_the_faces_the_sphere_touches_once_per_stroke() {
    let mut scene = Scene::new(icosphere(2), 4, GREY, 30.0, 20.0);
    let before = scene.store.clone();
    let settings = BrushSettings {
        spacing_percent: 2.0,
        ..plain(Tool::Resolution(ResolutionOp::Raise), GREEN, BrushRadius::World { radius_world: 0.35 })
    };
    // Many overlapping dabs: each face is raised once.
    let dabs = scene.stroke(settings, &[[512.0, 384.0], [530.0, 384.0], [512.0, 400.0], [540.0, 370.0]]);
    assert!(dabs.len() >= 20, "{} dabs", dabs.len());
    let topology = scene.store.topology();
    let mut raised = 0;
    for face in 0..topology.face_count() {
        let corners = topology.face_vertices[face as usize].map(|v| dvec(scene.positions[v as usize]));
        let touched: Vec<Option<bool>> = dabs
            .iter()
            .map(|dab| triangle_within(corners, DVec3::from_array(dab.center_world), dab.radius_world))
            .collect();
        let now = scene.store.face_resolution(face).unwrap();
        if touched.contains(&Some(true)) {
            assert_eq!(now, r(8), "face {face} touched but not raised once");
            raised += 1;
        } else if touched.iter().all(|t| *t == Some(false)) {
            assert_eq!(now, r(4), "face {face} untouched but changed");
        }
    }
    assert!(raised > 5, "{raised}");
    // Lower and set work the same way, and samples follow the store's resampling.
    let mut store = before.clone();
    let mut history = UndoHistory::default();
    let mut painter = Painter::new(&scene.positions);
    painter.set_settings(plain(Tool::Resolution(ResolutionOp::Set(r(1))), GREEN, BrushRadius::default()));
    let center = DVec3::from_array(scene.positions[0].map(f64::from));
    let stats = painter.dab_at(&scene.view(None), &mut store, &mut history, center, 0.2).unwrap();
    assert!(stats.faces_resized > 0);
    let mut expected = before.clone();
    for face in scene.bvh.faces_in_sphere(center, 0.2) {
        expected.write_resolution(face, r(1)).unwrap();
    }
    assert_eq!(store.face_resolutions(), expected.face_resolutions());
    let mut all = Vec::new();
    expected.for_each_site(|site| all.push(site.sample));
    for s in all {
        assert_eq!(store.get(s), expected.get(s));
    }
}

#[test]
fn set_resolution_for_all_or_a_selection() {
    let scene = Scene::new(icosphere(1), 4, GREY, 0.0, 0.0);
    let mut store = scene.store.clone();
    let mut history = UndoHistory::default();
    assert_eq!(brush::set_resolution(&mut store, &mut history, Some(&[1, 3, 5]), r(16), None).unwrap(), 3);
    assert_eq!(store.face_resolution(3), Some(r(16)));
    assert_eq!(store.face_resolution(2), Some(r(4)));
    assert_eq!(brush::set_resolution(&mut store, &mut history, None, r(2), None).unwrap(), 80);
    assert!(store.face_resolutions().iter().all(|&x| x == r(2)));
    assert!(brush::set_resolution(&mut store, &mut history, Some(&[999]), r(2), None).is_err());
    assert_eq!(history.undo_len(), 2);
}

// ---------------------------------------------------------------- fill and eyedropper

#[test]
fn fill_covers_the_whole_mesh_or_the_connected_part() {
    let two = join(grid(3, 0.0, [-1.0, -0.1], [-1.0, 1.0]), grid(3, 0.0, [0.1, 1.0], [-1.0, 1.0]));
    let scene = Scene::new(two, 4, GREY, 0.0, 0.0);
    let half = scene.store.topology().face_count() / 2;
    assert_eq!(brush::connected_faces(&scene.store, 2), (0..half).collect::<Vec<_>>());
    let mut store = scene.store.clone();
    let mut history = UndoHistory::default();
    let stats =
        brush::fill(&mut store, &mut history, FillScope::Connected { face: 2 }, GREEN, BlendMode::Mix, 1.0, None)
            .unwrap();
    let mut left = 0;
    for (sample, _, face) in scene.sites() {
        let expected = if face < half { GREEN } else { GREY };
        assert_eq!(store.get(sample), Some(expected), "{sample:?}");
        left += u64::from(face < half);
    }
    assert_eq!(stats.samples_changed, left);
    brush::fill(&mut store, &mut history, FillScope::All, GREEN, BlendMode::Mix, 1.0, None).unwrap();
    for (sample, _, _) in scene.sites() {
        assert_eq!(store.get(sample), Some(GREEN));
    }
    assert_eq!(history.undo_len(), 2);
    assert!(
        brush::fill(&mut store, &mut history, FillScope::Connected { face: 9999 }, GREEN, BlendMode::Mix, 1.0, None)
            .is_err()
    );
}

#[test]
fn the_eyedropper_reads_the_linear_colour_under_the_cursor() {
    let mut scene = Scene::new(grid(4, 0.0, [-1.0, 1.0], [-1.0, 1.0]), 8, GREY, 0.0, 0.0);
    // A linear field in x is reproduced exactly by linear filtering (up to rounding).
    let positions = scene.positions.clone();
    let faces = scene.store.topology().face_vertices.clone();
    scene.store.write_all(|site| {
        let c = faces[site.face as usize];
        let x: f32 = (0..3).map(|k| positions[c[k] as usize][0] * site.barycentric[k]).sum();
        [0.5 + 0.25 * x, 0.3, 0.2, 1.0]
    });
    let view = scene.view(None);
    for cursor in [[512.0, 384.0], [420.0, 300.0], [600.0, 500.0]] {
        let hit = view.pick(cursor).unwrap();
        let color = brush::eyedropper(&view, &scene.store, cursor).unwrap();
        let expected = 0.5 + 0.25 * hit.position_world[0] as f32;
        assert!((color[0] - expected).abs() < 1e-5, "{color:?} vs {expected}");
        assert!((color[1] - 0.3).abs() < 1e-6);
    }
    assert_eq!(brush::eyedropper(&view, &scene.store, [2.0, 2.0]), None);
}

// ---------------------------------------------------------------- repacking

#[test]
fn repacking_after_painting_matches_packing_the_same_colours_directly() {
    let mut scene = Scene::new(icosphere(2), 8, GREY, 30.0, 20.0);
    let mut rng = Rng(11);
    scene.store.write_all(|_| rng.opaque_color());
    scene.stroke(
        BrushSettings {
            falloff: Falloff::Smooth,
            strength: 0.6,
            ..plain(Tool::Paint, GREEN, BrushRadius::Pixels { radius_px: 50.0 })
        },
        &[[450.0, 350.0], [600.0, 420.0]],
    );
    scene.stroke(
        plain(Tool::Resolution(ResolutionOp::Raise), GREEN, BrushRadius::Pixels { radius_px: 30.0 }),
        &[[520.0, 380.0]],
    );
    scene.stroke(plain(Tool::Blur, GREEN, BrushRadius::Pixels { radius_px: 40.0 }), &[[500.0, 390.0], [540.0, 360.0]]);
    let painted = scene.store.clone();
    assert!(painted.face_resolutions().iter().any(|&x| x == r(16)));
    // The same colours written into a fresh store with the same resolutions.
    let mut direct =
        ColorStore::with_resolutions(painted.topology().clone(), painted.face_resolutions().to_vec(), [0.0; 4])
            .unwrap();
    let mut writes = Vec::new();
    painted.for_each_site(|site| writes.push((site.sample, painted.get(site.sample).unwrap())));
    for (sample, color) in writes {
        assert!(direct.write_sample(sample, color));
    }
    for format in ColorFormat::ALL {
        let packed = packer::pack(&painted, &scene.positions, format).unwrap();
        assert_eq!(packed, packer::pack(&direct, &scene.positions, format).unwrap(), "{format:?}");
        // unpack(pack) repacks byte for byte.
        let unpacked = meshpaint_core::packing::unpack::unpack(&packed).unwrap();
        assert_eq!(packer::pack(&unpacked, &scene.positions, format).unwrap(), packed, "{format:?} round trip");
    }
}

// ---------------------------------------------------------------- parsing

#[test]
fn strokes_and_colours_parse() {
    let point = |x, y, pressure| StrokePoint { px: [x, y], pressure };
    assert_eq!(brush::parse_stroke("1,2  3.5,-4").unwrap(), vec![point(1.0, 2.0, 1.0), point(3.5, -4.0, 1.0)]);
    assert_eq!(brush::parse_stroke("1,2,0.5 3,4,0").unwrap(), vec![point(1.0, 2.0, 0.5), point(3.0, 4.0, 0.0)]);
    for bad in ["", "1;2", "1,x", "1,2,1.5", "1,2,-0.1", "1,2,0.5,1", "1,2,nan"] {
        assert!(brush::parse_stroke(bad).is_err(), "{bad:?} accepted");
    }
    assert_eq!(brush::parse_hex_color("#ffffff"), Some([1.0, 1.0, 1.0, 1.0]));
    let c = brush::parse_hex_color("808080").unwrap();
    assert!((c[0] - 0.21586).abs() < 1e-4, "{c:?}");
    // `#rgb` doubles each digit; spaces around are ignored.
    assert_eq!(brush::parse_hex_color("#f80"), brush::parse_hex_color("#ff8800"));
    assert_eq!(brush::parse_hex_color(" ff8800 "), brush::parse_hex_color("#ff8800"));
    for bad in ["#12345", "#gg0000", "#ff88", "", "#", "+f80", "#ff88000"] {
        assert_eq!(brush::parse_hex_color(bad), None, "{bad:?}");
    }
    for response in
        [PressureResponse::NONE, PressureResponse::default(), PressureResponse { radius: true, strength: true }]
    {
        assert_eq!(PressureResponse::from_name(response.name()), Some(response));
    }
    for falloff in Falloff::ALL {
        assert_eq!(Falloff::from_name(falloff.name()), Some(falloff));
        assert_eq!(falloff.weight(0.0), 1.0);
        assert_eq!(falloff.weight(1.5), 0.0);
        assert_eq!(falloff.weight(f32::NAN), 0.0);
    }
    let invalid = BrushSettings { strength: 1.5, ..BrushSettings::default() };
    assert!(invalid.validate().is_err());
}

// ---------------------------------------------------------------- pen pressure

/// A one-point stroke at pressure 0.5 with pressure → radius places a dab of exactly half the
/// full-pressure radius, and paints exactly the samples a brute-force distance test over
/// every stored sample puts within that radius: about a quarter as many as at pressure 1.
#[test]
fn pressure_scales_the_dab_radius() {
    let settings = plain(Tool::Paint, GREEN, BrushRadius::Pixels { radius_px: 60.0 });
    let mut radii = Vec::new();
    let mut counts = Vec::new();
    for pressure in [1.0f32, 0.5] {
        let mut scene = Scene::new(icosphere(3), 16, GREY, 30.0, 20.0);
        let dabs = scene.stroke(settings, &[StrokePoint { px: [512.0, 384.0], pressure }]);
        assert_eq!(dabs.len(), 1);
        assert_eq!(dabs[0].pressure, pressure);
        let (center, radius) = (DVec3::from_array(dabs[0].center_world), dabs[0].radius_world);
        let mut inside = 0u64;
        for (sample, p, _) in scene.sites() {
            let margin = ((p - center).length() - radius) / radius;
            if margin.abs() < 1e-6 {
                continue;
            }
            let painted = bits(scene.store.get(sample).unwrap()) == bits(GREEN);
            assert_eq!(painted, margin < 0.0, "pressure {pressure}: {sample:?} at margin {margin}");
            inside += u64::from(margin < 0.0);
        }
        radii.push(radius);
        counts.push(inside);
    }
    assert!((radii[1] / radii[0] - 0.5).abs() < 1e-9, "radii {radii:?}");
    assert!(counts[1] > 100 && counts[1] * 3 < counts[0] && counts[1] * 5 > counts[0], "counts {counts:?}");
}

/// With pressure → strength the weight follows the pressure (Mix at constant falloff: half
/// way to the brush colour at 0.5) and the radius does not; along a stroke the pressure is
/// interpolated linearly between its points.
#[test]
fn pressure_scales_the_strength_and_is_interpolated_along_a_stroke() {
    let mut settings = plain(Tool::Paint, GREEN, BrushRadius::Pixels { radius_px: 40.0 });
    settings.pressure = PressureResponse { radius: false, strength: true };
    let mut full = Scene::new(icosphere(3), 8, GREY, 30.0, 20.0);
    let full_dab = full.stroke(settings, &[[512.0, 384.0]])[0];
    let mut half = Scene::new(icosphere(3), 8, GREY, 30.0, 20.0);
    let dab = half.stroke(settings, &[StrokePoint { px: [512.0, 384.0], pressure: 0.5 }])[0];
    assert_eq!(dab.radius_world, full_dab.radius_world);
    let center = DVec3::from_array(dab.center_world);
    let mut checked = 0;
    for (sample, p, _) in half.sites() {
        if (p - center).length() < dab.radius_world * (1.0 - 1e-6) {
            let now = half.store.get(sample).unwrap();
            for c in 0..4 {
                let expected = 0.5 * GREY[c] + 0.5 * GREEN[c];
                assert!((now[c] - expected).abs() < 1e-6, "{sample:?}: {now:?}");
            }
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked} samples inside");

    let mut scene = Scene::new(icosphere(3), 4, GREY, 30.0, 20.0);
    let (a, b) = ([400.0, 384.0], [640.0, 384.0]);
    let dabs = scene.stroke(settings, &[StrokePoint { px: a, pressure: 1.0 }, StrokePoint { px: b, pressure: 0.2 }]);
    assert!(dabs.len() > 10, "{} dabs", dabs.len());
    for dab in &dabs {
        let t = (dab.cursor_px[0] - a[0]) / (b[0] - a[0]);
        let expected = 1.0 - 0.8 * t;
        assert!((f64::from(dab.pressure) - expected).abs() < 1e-5, "at t = {t}: {}", dab.pressure);
    }
}

// ---------------------------------------------------------------- headless replay (CLI)

/// `meshpaint paint` replays a stroke through the same camera, picking and brush code as the
/// library: its output equals a replay done here with `camera::default_camera`.
#[test]
fn the_paint_command_replays_strokes_like_the_library() {
    let dir = TempDir::new("paint-cli");
    let input = model("Duck/Duck.glb");
    let output = dir.join("painted.mpk");
    // With pen pressure on two points (pressure → radius, the default).
    let stroke = "300,300 700,400,0.5 500,600,0.8";
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["paint", input.to_str().unwrap(), "--stroke", stroke, "--color", "#00ff00", "--radius-px", "20"])
        .args(["--strength", "0.8", "--width", "800", "--height", "600", "--yaw", "40", "--pitch", "-10"])
        .args(["--resolution", "4", "--format", "rgba32f", "-o", output.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(status.success());
    let from_cli = meshpaint_core::packing::file::read_file(&output).unwrap();

    let mut document = meshpaint_core::io::document::Document::open(&input, r(4)).unwrap();
    let camera = meshpaint_core::camera::default_camera(
        meshpaint_core::camera::BoundingSphere::of_points(&document.positions),
        40.0,
        -10.0,
        None,
    );
    let bvh = MeshBvh::build(&document.positions, &document.store.topology().face_vertices, BvhPreset::FastBuild);
    let base = document.store.clone();
    let view = PaintView {
        positions: &document.positions,
        bvh: &bvh,
        camera: &camera,
        viewport_px: [800, 600],
        base: Some(&base),
    };
    let mut painter = Painter::new(&document.positions);
    painter.set_settings(BrushSettings {
        color: brush::parse_hex_color("#00ff00").unwrap(),
        radius: BrushRadius::Pixels { radius_px: 20.0 },
        strength: 0.8,
        ..BrushSettings::default()
    });
    let mut history = UndoHistory::default();
    let points = brush::parse_stroke(stroke).unwrap();
    let (update, _) = brush::replay_stroke(&mut painter, &view, &mut document.store, &mut history, &points).unwrap();
    assert!(update.dabs.len() > 50 && update.stats.samples_changed > 1000);
    assert_eq!(from_cli, document.pack(ColorFormat::Rgba32F).unwrap(), "CLI and library replays differ");

    // .glb output, and refusals.
    let glb = dir.join("painted.glb");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["paint", input.to_str().unwrap(), "--stroke", stroke, "-o", glb.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(status.success());
    assert!(meshpaint_core::mesh::import::import_gltf(&glb).is_ok());
    for bad in [
        vec!["--stroke", "1,2,3"],
        vec!["--stroke", "1,2,0.5,1"],
        vec!["--stroke", "1,2", "--pressure", "sideways"],
        vec!["--stroke", "1,2", "--color", "red"],
        vec!["--stroke", "1,2", "--strength", "2"],
        vec!["--stroke", "1,2", "--tool", "set"],
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
            .arg("paint")
            .arg(&input)
            .args(&bad)
            .arg("-o")
            .arg(dir.join("never.mpk"))
            .output()
            .unwrap();
        assert!(!out.status.success(), "{bad:?} accepted");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("error"), "{bad:?}: {stderr}");
        assert!(!dir.join("never.mpk").exists());
    }
}

#[test]
fn bench_paint_reports_every_measurement() {
    let input = model("Duck/Duck.glb");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["bench", "paint", input.to_str().unwrap(), "--resolution", "4", "--dabs", "2", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["bench"], "paint");
    assert_eq!(report["bvh_presets"].as_array().unwrap().len(), 6);
    for preset in report["bvh_presets"].as_array().unwrap() {
        assert!(preset["build_seconds"].as_f64().unwrap() > 0.0);
        assert!(preset["pick_seconds_best"].as_f64().unwrap() > 0.0);
        assert_eq!(preset["hits"], preset["picks"]);
    }
    let brushes = report["brushes"].as_array().unwrap();
    assert_eq!(brushes.len(), 3);
    for (row, target) in brushes.iter().zip([1_000u64, 10_000]) {
        let covered = row["paint"]["samples_covered"].as_u64().unwrap();
        assert!(covered * 100 >= target * 99 && covered < target + target / 5, "{covered} for {target}");
        assert!(row["paint"]["upload_bytes_rgba8"].as_u64().unwrap() >= 4 * covered);
    }
    // Every row on every brush, with positive rates; the headline is the defaults' row.
    for row in brushes {
        for name in ["occlusion", "occlusion_first_dab", "paint", "first_dab", "culling", "blur", "blur_occlusion"] {
            for key in ["samples_per_second_best", "samples_per_second_median"] {
                assert!(row[name][key].as_f64().unwrap() > 0.0, "{name} {key}");
            }
            assert!(row[name]["samples_covered"].as_u64().unwrap() > 0, "{name}");
        }
        // Frame-paced: each dab after a frame of idle.
        for name in ["occlusion_frame_paced", "blur_frame_paced"] {
            assert!(row[name]["samples_per_second_median"].as_f64().unwrap() > 0.0, "{name}");
            assert!((row[name]["dab_gap_seconds"].as_f64().unwrap() - 1.0 / 60.0).abs() < 1e-4, "{name}");
        }
        assert_eq!(row["occlusion"]["dab_gap_seconds"].as_f64(), Some(0.0));
    }
    let first = &report["session_first_dab"];
    assert!(first["samples_per_second_best"].as_f64().unwrap() > 0.0, "{first}");
    assert!(first["samples_covered"].as_u64().unwrap() > 0, "{first}");
    assert_eq!(report["headline"]["row"], "occlusion");
    assert_eq!(report["headline"]["target_samples"], 100_000);
    assert!(report["headline"]["samples_per_second_median"].as_f64().unwrap() > 0.0);
    assert!(report["headline"]["samples_per_second_median_frame_paced"].as_f64().unwrap() > 0.0);
    assert!(report["occlusion_depth_map"]["build_seconds"].as_f64().unwrap() > 0.0);
    assert_eq!(report["occlusion_depth_map"]["maps_built"], 1);
    assert!(report["threads"].as_u64().unwrap() >= 1);
    // The editor's whole dab with its GPU upload: spans merged from the ranges, every
    // planned sample inside them.
    let upload = &report["gpu_upload"];
    assert!(upload["samples_per_second_best"].as_f64().unwrap() > 0.0, "{upload}");
    assert!(upload["gpu_write_seconds"].as_f64().unwrap() > 0.0);
    let (ranges, spans) = (upload["upload_ranges"].as_u64().unwrap(), upload["upload_spans"].as_u64().unwrap());
    assert!(spans >= 1 && spans <= ranges, "{spans} spans for {ranges} ranges");
    assert!(upload["upload_span_samples"].as_u64().unwrap() >= upload["samples_covered"].as_u64().unwrap());
    // `--subdivide 1`: four times the triangles, the same rows.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["bench", "paint", input.to_str().unwrap(), "-r", "2", "--subdivide", "1", "--dabs", "1"])
        .args(["--dab-samples", "1000", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let subdivided: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(subdivided["triangles"].as_u64().unwrap(), 4 * report["triangles"].as_u64().unwrap());
    assert!(subdivided["headline"]["samples_per_second_best"].as_f64().unwrap() > 0.0);
    assert!(report["repack_rgba8"]["timing"]["best_seconds"].as_f64().unwrap() > 0.0);
    assert!(report["pick_latency"]["best_seconds"].as_f64().unwrap() > 0.0);
}

/// `bench paint --rows`: only the named dab rows run (what a profiler should see), an unknown
/// name is refused.
#[test]
fn bench_paint_rows_measures_only_the_named_rows() {
    let input = model("Duck/Duck.glb");
    let run = |rows: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
            .args(["bench", "paint", input.to_str().unwrap(), "-r", "4", "--dabs", "2", "--dab-samples", "1000"])
            .args(["--json", "--rows", rows])
            .output()
            .unwrap()
    };
    let out = run("blur,occlusion_frame_paced");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let row = &report["brushes"][0];
    assert!(row["blur"]["samples_per_second_median"].as_f64().unwrap() > 0.0, "{row}");
    assert!(row["occlusion_frame_paced"]["samples_per_second_median"].as_f64().unwrap() > 0.0, "{row}");
    for name in
        ["occlusion", "occlusion_first_dab", "paint", "first_dab", "culling", "blur_occlusion", "blur_frame_paced"]
    {
        assert!(row.get(name).is_none(), "{name} ran: {row}");
    }
    assert_eq!(report["bvh_presets"].as_array().unwrap().len(), 0);
    assert!(
        report["repack_rgba8"].is_null() && report["gpu_upload"].is_null() && report["session_first_dab"].is_null()
    );
    let out = run("bluur");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("bluur"));
}
