//! Hard brushes (constant falloff) and their rim (issue 43, "hard edges"), on a flat triangle
//! seen from above. By default a hard dab raises the faces under it to the `R` whose spacing
//! is at most radius / 16 (up to 64), also when resolution-follows-the-brush is off (textured
//! documents), and within the budget: a face the budget refuses keeps its `R` and the stroke
//! still paints. With anti-aliasing (an option, measured against raising in
//! docs/PAINT_MODE.md) the paint a dab leaves, reconstructed as the renderer does (linear
//! interpolation of the samples), integrates to the disc's area (π r², closed form), and a
//! stroke's to the area of the union of its dabs' discs (brute force on a fine grid), so
//! overlapping dabs do not build the rim up. With neither, every sample is either untouched
//! or fully painted, exactly those inside the sphere.

use glam::DVec3;

use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::budget::{Budget, MemorySource};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::sampler::{self, Filter};
use meshpaint_core::paint::brush::{
    BrushRadius, BrushSettings, Dab, Falloff, HardEdges, PaintView, Painter, replay_stroke,
};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;

/// One triangle in the plane z = 0, facing +z (the camera's side).
const CORNERS: [[f32; 3]; 3] = [[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [0.0, 2.5, 0.0]];
/// The triangle's area.
const AREA: f64 = 0.5 * 4.0 * 4.5;
/// Its uniform R: the lattice spacing along the base is 4 / 16 = 0.25.
const R: u64 = 16;

/// The hard brush: constant falloff, strength 1, white over black, no occlusion.
fn hard(radius_world: f64) -> BrushSettings {
    BrushSettings {
        color: [1.0; 4],
        radius: BrushRadius::World { radius_world },
        strength: 1.0,
        falloff: Falloff::Constant,
        spacing_percent: 10.0,
        occlusion: false,
        ..BrushSettings::default()
    }
}

/// A black store on the triangle, its BVH and a camera looking down at it.
fn scene() -> (ColorStore, MeshBvh, OrbitCamera) {
    let positions = CORNERS.to_vec();
    let topology = Topology::build(3, &[[0, 1, 2]]).unwrap();
    let store = ColorStore::uniform(topology, Resolution::new(R).unwrap(), [0.0, 0.0, 0.0, 1.0]);
    let bvh = MeshBvh::build(&positions, &[[0, 1, 2]], BvhPreset::FastBuild);
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 0.0, 0.0);
    (store, bvh, camera)
}

/// The painted coverage: the red channel, linearly interpolated as rendered, integrated
/// over the triangle (midpoint rule on `n²` barycentric cells).
fn painted_area(store: &ColorStore, n: u32) -> f64 {
    let mut sum = 0.0;
    let mut cells = 0u64;
    for i in 0..n {
        for j in 0..n - i {
            // Two sub-triangles per (i, j) except on the diagonal; their centroids.
            let mut add = |u: f64, v: f64| {
                let bary = [(1.0 - u - v) as f32, u as f32, v as f32];
                sum += f64::from(sampler::sample(store, 0, bary, Filter::Linear, 0).unwrap()[0]);
                cells += 1;
            };
            let (fi, fj, fnn) = (f64::from(i), f64::from(j), f64::from(n));
            add((fi + 1.0 / 3.0) / fnn, (fj + 1.0 / 3.0) / fnn);
            if i + j + 1 < n {
                add((fi + 2.0 / 3.0) / fnn, (fj + 2.0 / 3.0) / fnn);
            }
        }
    }
    sum / cells as f64 * AREA
}

/// The area of the union of the dabs' discs within the plane, brute force on a grid of
/// `step` (each dab's sphere meets the plane z = 0 in a disc of its radius: the centres lie
/// on it).
fn union_area(dabs: &[Dab], step: f64) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for dab in dabs {
        for k in 0..2 {
            lo[k] = lo[k].min(dab.center_world[k] - dab.radius_world);
            hi[k] = hi[k].max(dab.center_world[k] + dab.radius_world);
        }
    }
    let mut inside = 0u64;
    let mut y = lo[1] + step / 2.0;
    while y < hi[1] {
        let mut x = lo[0] + step / 2.0;
        while x < hi[0] {
            let covered = dabs.iter().any(|dab| {
                let (dx, dy) = (x - dab.center_world[0], y - dab.center_world[1]);
                dx * dx + dy * dy <= dab.radius_world * dab.radius_world
            });
            inside += u64::from(covered);
            x += step;
        }
        y += step;
    }
    inside as f64 * step * step
}

/// Anti-aliased over one sample spacing, not raised.
const ANTIALIASED: HardEdges = HardEdges { raise_to: None, antialias_spacings: Some(1.0), ..HardEdges::SAMPLED };

/// Paints one dab at `center` with `radius` with `hard_edges`; returns the store.
fn one_dab(center: DVec3, radius: f64, hard_edges: HardEdges) -> ColorStore {
    let (mut store, bvh, camera) = scene();
    let positions = CORNERS.to_vec();
    let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
    let mut painter = Painter::new(&positions);
    painter.set_settings(hard(radius));
    painter.set_hard_edges(hard_edges);
    painter.dab_at(&view, &mut store, &mut UndoHistory::default(), center, radius).unwrap();
    store
}

/// The smallest power of two `R` with `longest / R ≤ radius / 16`, at most 64 (closed form).
fn resolving(longest: f64, radius: f64) -> u32 {
    let mut r = 1u32;
    while f64::from(r) * radius < 16.0 * longest && r < 64 {
        r *= 2;
    }
    r
}

#[test]
fn a_hard_dab_raises_its_face_to_resolve_a_sixteenth_of_its_radius_by_default() {
    // The two slanted edges, √(2² + 4.5²) ≈ 4.92, are longer than the base (4).
    let longest = (DVec3::new(0.0, 2.5, 0.0) - DVec3::new(-2.0, -2.0, 0.0)).length();
    assert_eq!(Painter::new(&CORNERS).hard_edges(), HardEdges::default());
    for (radius, want) in [(0.55, resolving(longest, 0.55)), (1.5, resolving(longest, 1.5)), (3.0, 32)] {
        let store = one_dab(DVec3::new(0.0, -0.3, 0.0), radius, HardEdges::default());
        assert_eq!(store.face_resolution(0).unwrap().get(), want.max(R as u32), "radius {radius}");
    }
    // A soft brush keeps the face's R (resolution follows the brush is off here).
    let (mut store, bvh, camera) = scene();
    let positions = CORNERS.to_vec();
    let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
    let mut painter = Painter::new(&positions);
    painter.set_settings(BrushSettings { falloff: Falloff::Smooth, ..hard(0.55) });
    painter.dab_at(&view, &mut store, &mut UndoHistory::default(), DVec3::new(0.0, -0.3, 0.0), 0.55).unwrap();
    assert_eq!(store.face_resolution(0).unwrap().get(), R as u32);
}

#[test]
fn a_hard_dab_over_the_budget_keeps_the_face_resolution_and_still_paints() {
    let (mut store, bvh, camera) = scene();
    let positions = CORNERS.to_vec();
    let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
    let mut painter = Painter::new(&positions);
    painter.set_settings(hard(0.55));
    // Room for the triangle at R = 16 (153 samples) but not at R = 64 (2 145).
    let mut budget = Budget::with_memory(1 << 30, MemorySource::Environment);
    budget.max_samples = 400;
    painter.set_budget(Some((budget, ColorFormat::Rgba8Srgb)));
    let stats =
        painter.dab_at(&view, &mut store, &mut UndoHistory::default(), DVec3::new(0.0, -0.3, 0.0), 0.55).unwrap();
    assert_eq!(store.face_resolution(0).unwrap().get(), R as u32);
    assert!(stats.samples_changed > 0);
}

#[test]
fn an_anti_aliased_dab_paints_the_area_of_its_disc() {
    // Radius 0.55 = 2.2 lattice spacings: small against the spacing, where a hard rim's
    // staircase is worst. Centres at several offsets against the lattice.
    let radius = 0.55;
    let exact = std::f64::consts::PI * radius * radius;
    let mut worst_hard: f64 = 0.0;
    for (k, offset) in [[0.0, 0.0], [0.07, 0.03], [0.125, 0.11], [-0.05, 0.19], [0.2, -0.09]].iter().enumerate() {
        let center = DVec3::new(offset[0], offset[1] - 0.3, 0.0);
        let aa = painted_area(&one_dab(center, radius, ANTIALIASED), 600);
        let hard = painted_area(&one_dab(center, radius, HardEdges::SAMPLED), 600);
        // The ramp adds π h² / 12 (h = 0.25 along the base): 0.016, 2.7 % of the disc.
        assert!((aa - exact).abs() / exact < 0.04, "offset {k}: anti-aliased {aa:.4} vs π r² {exact:.4}");
        worst_hard = worst_hard.max((hard - exact).abs() / exact);
    }
    // Not a requirement, the reason for the feature: a hard rim's area depends on where the
    // lattice falls.
    assert!(worst_hard > 0.04, "the hard dab's worst relative area error {worst_hard:.3}");
}

#[test]
fn an_anti_aliased_stroke_paints_the_area_of_its_dabs_union_without_building_up() {
    let radius = 0.45;
    let (mut store, bvh, camera) = scene();
    let positions = CORNERS.to_vec();
    let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
    let at = |x: f64, y: f64| {
        let (px, py) = camera.project(DVec3::new(x, y, 0.0), 640, 480).unwrap();
        [px, py]
    };
    let points = [at(-0.9, -0.6), at(0.0, -0.35), at(0.8, -0.7)];
    let mut painter = Painter::new(&positions);
    painter.set_settings(hard(radius));
    painter.set_hard_edges(ANTIALIASED);
    let (update, _) = replay_stroke(&mut painter, &view, &mut store, &mut UndoHistory::default(), &points).unwrap();
    assert!(update.dabs.len() > 30, "{} dabs", update.dabs.len());
    let exact = union_area(&update.dabs, 0.002);
    let painted = painted_area(&store, 600);
    // The rim (length ≈ 4.5) adds at most a few π h² / 12 at its round ends.
    assert!((painted - exact).abs() / exact < 0.03, "painted {painted:.4} vs the union's area {exact:.4}");
    // No sample ends above full coverage.
    let max = store.interior_samples(0).iter().map(|c| c[0]).fold(0.0f32, f32::max);
    assert!(max <= 1.0 + 1e-6);
}

#[test]
fn without_anti_aliasing_a_hard_dab_paints_exactly_the_samples_inside_its_sphere() {
    let radius = 0.55;
    let center = DVec3::new(0.07, -0.27, 0.0);
    let store = one_dab(center, radius, HardEdges::SAMPLED);
    let positions = CORNERS.map(|p| DVec3::from_array(p.map(f64::from)));
    let r = R as u32;
    // Interior lattice point (i, j), i + j < R, i, j ≥ 1, stored row by row (i, then j).
    let mut index = 0usize;
    for i in 1..r - 1 {
        for j in 1..r - i {
            let (u, v) = (f64::from(i) / f64::from(r), f64::from(j) / f64::from(r));
            let p = positions[0] + (positions[1] - positions[0]) * u + (positions[2] - positions[0]) * v;
            let inside = (p - center).length() <= radius;
            let value = store.interior_samples(0)[index][0];
            assert_eq!(value, if inside { 1.0 } else { 0.0 }, "sample ({i}, {j}) at {p}");
            index += 1;
        }
    }
}
