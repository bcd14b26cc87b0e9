//! Resolution follows the brush: a scripted stroke on an untextured mesh at R = 1 raises
//! exactly the faces the dabs touch to the R that resolves the radius (checked against the
//! rule's closed form), leaves every other face at R = 1, and holds far fewer samples than
//! the same stroke at uniform R = 8.

use glam::DVec3;

use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::paint::brush::{BlendMode, BrushRadius, BrushSettings, Falloff, PaintView, Painter, Tool};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;

use crate::common;
use common::icosphere;

const GREY: [f32; 4] = [0.5, 0.5, 0.5, 1.0];

/// The painted store, the mesh (positions, triangles) and the dab centres.
type Stroke = (ColorStore, Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<DVec3>);

/// Paints a stroke of dabs along the equator's front on an icosphere at uniform `start` R
/// (`follow`: the follow-the-brush cap). Returns the store and the dab centres.
fn stroke(start: u32, follow: Option<Resolution>, radius: f64) -> Stroke {
    let (positions, triangles) = icosphere(4);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::new(u64::from(start)).unwrap(), GREY);
    let bvh = MeshBvh::build(&positions, &triangles, BvhPreset::FastBuild);
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 0.0, 0.0);
    let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
    let mut painter = Painter::new(&positions);
    painter.set_settings(BrushSettings {
        tool: Tool::Paint,
        color: [1.0, 0.0, 0.0, 1.0],
        blend: BlendMode::Mix,
        radius: BrushRadius::World { radius_world: radius },
        strength: 1.0,
        falloff: Falloff::Constant,
        spacing_percent: 10.0,
        occlusion: false,
        backface_culling: true,
        mirror_x: false,
        follow_resolution: follow,
        pressure: meshpaint_core::paint::brush::PressureResponse::default(),
    });
    // This is resolution-follows-the-brush's rule alone, not a hard brush's own raise.
    painter.set_hard_edges(meshpaint_core::paint::brush::HardEdges::SAMPLED);
    let mut history = UndoHistory::default();
    let centers: Vec<DVec3> = (0..8)
        .map(|k| {
            let angle = -0.6 + 1.2 * f64::from(k) / 7.0;
            DVec3::new(angle.sin(), 0.0, angle.cos())
        })
        .collect();
    for &center in &centers {
        painter.dab_at(&view, &mut store, &mut history, center, radius).unwrap();
    }
    (store, positions, triangles, centers)
}

#[test]
fn a_stroke_raises_only_the_faces_it_touches_to_the_resolution_that_resolves_it() {
    let radius = 0.05;
    let max = Resolution::new(64).unwrap();
    let (store, positions, triangles, centers) = stroke(1, Some(max), radius);
    let p = |v: u32| DVec3::from_array(positions[v as usize].map(f64::from));
    let (mut raised, mut untouched) = (0, 0);
    for (face, tri) in triangles.iter().enumerate() {
        let r = store.face_resolution(face as u32).unwrap().get();
        let [a, b, c] = tri.map(p);
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        // The rule in closed form: the smallest power of two with longest / R ≤ radius / 4.
        let mut want = 1u32;
        while f64::from(want) * radius < 4.0 * longest && want < 64 {
            want *= 2;
        }
        // Touched: the face comes within the radius of a dab centre (closest point on the
        // triangle, brute force over a fine barycentric grid) and faces the eye (+z).
        let normal = (b - a).cross(c - a);
        let touched = normal.dot(DVec3::Z) > 0.0
            && centers.iter().any(|&center| {
                (0..=40).any(|i| {
                    (0..=40 - i).any(|j| {
                        let (u, v) = (f64::from(i) / 40.0, f64::from(j) / 40.0);
                        (a * (1.0 - u - v) + b * u + c * v - center).length() < radius * 0.97
                    })
                })
            });
        if touched {
            assert_eq!(r, want, "face {face} under the stroke");
            raised += 1;
        } else if r == 1 {
            untouched += 1;
        } else {
            // Faces within the last 3 % of the radius (the grid's tolerance) may be either.
            assert!(r == want, "face {face} away from the stroke has R = {r}");
        }
    }
    assert!(raised > 20 && untouched > 4000, "{raised} raised, {untouched} at R = 1");
    // Painted samples exist on the raised faces; the rest stays grey.
    let mut painted = 0;
    store.for_each_site(|site| painted += usize::from(store.get(site.sample).unwrap() != GREY));
    assert!(painted > 300, "{painted}");

    // Memory against the same stroke at uniform R = 8.
    let (uniform, ..) = stroke(8, None, radius);
    eprintln!(
        "follow the brush: {} samples ({} faces raised) vs {} at uniform R = 8 ({:.1} %)",
        store.sample_count(),
        raised,
        uniform.sample_count(),
        100.0 * store.sample_count() as f64 / uniform.sample_count() as f64
    );
    assert!(store.sample_count() * 5 < uniform.sample_count());
}
