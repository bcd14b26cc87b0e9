//! Winding: `Orientation` (closed components, signed volume, inconsistent edges) against
//! closed forms, and the brush's backface culling on inside-out and mixed-winding meshes
//! against the geometric truth (a sphere's outward normal is its position).

use glam::DVec3;

use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::Rgba;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::orientation::{Orientation, face_flips};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::paint::brush::{self, BlendMode, BrushRadius, BrushSettings, Falloff, PaintView, Painter, Tool};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;

use crate::common;
use common::{Mesh, icosphere, join, octahedron_mesh};

const GREY: Rgba = [0.5, 0.5, 0.5, 1.0];
const GREEN: Rgba = [0.0, 1.0, 0.0, 1.0];

fn topology(mesh: &Mesh) -> Topology {
    Topology::build(mesh.0.len() as u32, &mesh.1).unwrap()
}

/// The mesh with every face's winding reversed (`flip(face)` true) or kept.
fn rewound((positions, triangles): &Mesh, flip: impl Fn(usize) -> bool) -> Mesh {
    let triangles = triangles.iter().enumerate().map(|(f, &[a, b, c])| if flip(f) { [a, c, b] } else { [a, b, c] });
    (positions.clone(), triangles.collect())
}

fn translated((positions, triangles): Mesh, by: [f32; 3]) -> Mesh {
    (positions.into_iter().map(|p| [p[0] + by[0], p[1] + by[1], p[2] + by[2]]).collect(), triangles)
}

#[test]
fn orientation_reports_volume_inversion_and_inconsistent_edges() {
    // The unit octahedron |x| + |y| + |z| <= 1 has volume 4/3.
    let octahedron = octahedron_mesh();
    let o = Orientation::of(&topology(&octahedron), &octahedron.0);
    assert_eq!((o.components, o.closed_components, o.inverted_components, o.inconsistent_edges), (1, 1, 0, 0));
    assert!((o.closed_signed_volume - 4.0 / 3.0).abs() < 1e-6, "{o:?}");

    let inverted = rewound(&octahedron, |_| true);
    let o = Orientation::of(&topology(&inverted), &inverted.0);
    assert_eq!((o.closed_components, o.inverted_components, o.inconsistent_edges), (1, 1, 0));
    assert!((o.closed_signed_volume + 4.0 / 3.0).abs() < 1e-6, "{o:?}");

    // One face flipped: its three edges are walked the same way by both faces.
    let mixed = rewound(&octahedron, |f| f == 3);
    let o = Orientation::of(&topology(&mixed), &mixed.0);
    assert_eq!((o.components, o.inconsistent_edges), (1, 3));

    // Two components, one inside out (volume is translation invariant for closed surfaces);
    // an open component (one face removed) is not closed.
    let two = join(octahedron.clone(), translated(rewound(&octahedron, |_| true), [5.0, 0.0, 0.0]));
    let o = Orientation::of(&topology(&two), &two.0);
    assert_eq!((o.components, o.closed_components, o.inverted_components), (2, 2, 1));
    assert!(o.closed_signed_volume.abs() < 1e-5, "{o:?}");
    let (positions, mut triangles) = octahedron.clone();
    triangles.pop();
    let open = (positions, triangles);
    let o = Orientation::of(&topology(&open), &open.0);
    assert_eq!((o.components, o.closed_components), (1, 0));
}

#[test]
fn face_flips_undo_a_random_rewinding() {
    let sphere = icosphere(2);
    let mut state = 0x1234_5678_u64;
    let mut coin = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state & 1 == 1
    };
    let flipped: Vec<bool> = (0..sphere.1.len()).map(|_| coin()).collect();
    let mixed = rewound(&sphere, |f| flipped[f]);
    let flips = face_flips(&topology(&mixed));
    // Relative to face 0, each face is flipped exactly when its rewinding differs from face 0's.
    for (face, &(component, flip)) in flips.iter().enumerate() {
        assert_eq!(component, 0);
        assert_eq!(flip, flipped[face] != flipped[0], "face {face}");
    }
}

/// Paints one dab with backface culling (no occlusion) at the point of the unit sphere that
/// faces the eye, on `mesh` (a unit icosphere, any winding), and checks it against the
/// geometry: samples facing the eye are painted, samples facing away are not.
fn culling_paints_the_visible_side(mesh: Mesh, what: &str) {
    let (positions, triangles) = mesh;
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::new(4).unwrap(), GREY);
    let bvh = MeshBvh::build(&positions, &triangles, BvhPreset::FastBuild);
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 30.0, 20.0);
    let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
    let mut painter = Painter::new(&positions);
    painter.set_settings(BrushSettings {
        tool: Tool::Paint,
        color: GREEN,
        blend: BlendMode::Mix,
        radius: BrushRadius::World { radius_world: 2.5 },
        strength: 1.0,
        falloff: Falloff::Constant,
        spacing_percent: 10.0,
        occlusion: false,
        backface_culling: true,
        mirror_x: false,
        follow_resolution: None,
        pressure: meshpaint_core::paint::brush::PressureResponse::default(),
    });
    let eye = camera.eye();
    let center = DVec3::from_array(camera.target) + camera.eye_direction();
    let mut history = UndoHistory::default();
    painter.dab_at(&view, &mut store, &mut history, center, 2.5).unwrap();
    let faces = store.topology().face_vertices.clone();
    let (mut front, mut back) = (0, 0);
    store.for_each_site(|site| {
        let corners = faces[site.face as usize];
        let p: DVec3 = (0..3)
            .map(|k| {
                let q = positions[corners[k] as usize];
                DVec3::new(f64::from(q[0]), f64::from(q[1]), f64::from(q[2])) * f64::from(site.barycentric[k])
            })
            .sum();
        // On a sphere the outward normal is the position, whatever the triangles' winding.
        let facing = p.normalize().dot((eye - p).normalize());
        let painted = store.get(site.sample).unwrap() != GREY;
        if facing > 0.15 {
            assert!(painted, "{what}: visible sample {:?} unpainted", site.sample);
            front += 1;
        } else if facing < -0.15 {
            assert!(!painted, "{what}: hidden sample {:?} painted", site.sample);
            back += 1;
        }
    });
    assert!(front > 1000 && back > 1000, "{what}: {front} {back}");
}

#[test]
fn backface_culling_paints_what_the_cursor_shows_on_any_winding() {
    let sphere = icosphere(3);
    culling_paints_the_visible_side(sphere.clone(), "outward winding");
    culling_paints_the_visible_side(rewound(&sphere, |_| true), "inside out");
    culling_paints_the_visible_side(rewound(&sphere, |f| f % 3 == 0), "mixed winding");
}

#[test]
fn a_stroke_on_an_inside_out_mesh_changes_the_samples_it_changes_on_the_outward_one() {
    // Same geometry, opposite winding: the stroke sees the same surface, so the painted
    // positions (not the sample ids, which follow the winding) are the same.
    let sphere = icosphere(3);
    let painted_positions = |mesh: Mesh| -> Vec<[i64; 3]> {
        let (positions, triangles) = mesh;
        let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
        let mut store = ColorStore::uniform(topology, Resolution::new(4).unwrap(), GREY);
        let bvh = MeshBvh::build(&positions, &triangles, BvhPreset::FastBuild);
        let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 10.0, 5.0);
        let view = PaintView { positions: &positions, bvh: &bvh, camera: &camera, viewport_px: [640, 480], base: None };
        let mut painter = Painter::new(&positions);
        let settings =
            BrushSettings { color: GREEN, radius: BrushRadius::Pixels { radius_px: 45.0 }, ..BrushSettings::default() };
        assert!(settings.backface_culling && settings.occlusion, "the editor's defaults cull and occlude");
        painter.set_settings(settings);
        let mut history = UndoHistory::default();
        let stroke = [[250.0, 240.0], [320.0, 230.0], [390.0, 250.0]];
        brush::replay_stroke(&mut painter, &view, &mut store, &mut history, &stroke).unwrap();
        let faces = store.topology().face_vertices.clone();
        let mut out = Vec::new();
        store.for_each_site(|site| {
            if store.get(site.sample).unwrap() != GREY {
                let corners = faces[site.face as usize];
                let p: [f64; 3] = std::array::from_fn(|a| {
                    (0..3).map(|k| f64::from(positions[corners[k] as usize][a]) * f64::from(site.barycentric[k])).sum()
                });
                out.push(p.map(|x| (x * 1e5).round() as i64));
            }
        });
        out.sort_unstable();
        out
    };
    let outward = painted_positions(sphere.clone());
    let inside_out = painted_positions(rewound(&sphere, |_| true));
    assert!(outward.len() > 100, "the stroke paints: {}", outward.len());
    assert_eq!(outward, inside_out);
}

/// The lit render of `mesh` (a grey icosphere, any winding) from a fixed camera.
fn lit_render(mesh: &Mesh) -> image::RgbaImage {
    shaded_render(mesh, meshpaint_render::Shading::Lit)
}

/// The camera of [`shaded_render`].
fn render_camera(mesh: &Mesh) -> OrbitCamera {
    OrbitCamera::framing(BoundingSphere::of_points(&mesh.0), 30.0, 20.0)
}

/// `mesh` in uniform grey 0.6 (linear) with `shading`, 128 × 128, from [`render_camera`].
fn shaded_render(mesh: &Mesh, shading: meshpaint_render::Shading) -> image::RgbaImage {
    use meshpaint_render::{DrawItem, GpuMesh, MeshUploadOptions, RenderSettings};
    let gpu = common::gpu::shared();
    let (positions, triangles) = mesh;
    let store = ColorStore::uniform(topology(mesh), Resolution::new(2).unwrap(), [0.6, 0.6, 0.6, 1.0]);
    let packed =
        meshpaint_core::packing::packer::pack(&store, positions, meshpaint_core::colors::format::ColorFormat::Rgba32F)
            .unwrap();
    let uploaded = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions::default()).unwrap();
    let _ = triangles;
    let mut settings = RenderSettings::new(render_camera(mesh));
    settings.shading = shading;
    settings.background = [0.0; 4];
    gpu.renderer.render_image(&gpu.ctx, DrawItem::MeshColors(&uploaded), &settings, 128, 128).unwrap()
}

#[test]
fn the_lit_view_shades_an_inside_out_mesh_like_the_outward_one() {
    // Two-sided Lambert: the side the eye sees is lit with the normal that faces the eye,
    // whatever the winding, so the inside-out copy renders the same image (up to rounding).
    let sphere = icosphere(3);
    let outward = lit_render(&sphere);
    let inside_out = lit_render(&rewound(&sphere, |_| true));
    let mixed = lit_render(&rewound(&sphere, |f| f % 3 == 0));
    let lit: Vec<u8> = outward.pixels().filter(|p| p[3] > 0).map(|p| p[0]).collect();
    assert!(lit.len() > 4000, "the sphere covers the image: {}", lit.len());
    let (darkest, brightest) = (lit.iter().min().unwrap(), lit.iter().max().unwrap());
    assert!(brightest - darkest > 40, "the lighting varies over the sphere: {darkest}..{brightest}");
    for (what, image) in [("inside out", &inside_out), ("mixed winding", &mixed)] {
        let differing = outward
            .pixels()
            .zip(image.pixels())
            .filter(|(a, b)| a.0.iter().zip(b.0.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
            .count();
        assert!(differing <= 16, "{what}: {differing} pixels differ by more than 2 steps");
    }
}

/// Smooth shading, pixel by pixel, against the lighting computed on the CPU: a ray through
/// each pixel centre finds the face and its barycentrics (perspective-correct, as the GPU
/// interpolates), each corner takes its vertex normal within 45° of the face normal
/// (`mesh::normals`), and `grey × (ambient + (1 − ambient) · max(±Σ wₖ n̂ₖ · l, 0))` is
/// encoded to sRGB. Flat shading differs from it by many steps, so the test can fail.
#[test]
fn smooth_shading_matches_the_interpolated_corner_lighting_for_any_winding() {
    use meshpaint_core::colors::format::linear_to_srgb;
    use meshpaint_core::mesh::normals::{smooth_corner_normal, vertex_normals};
    use meshpaint_render::{RenderSettings, Shading};
    let sphere = icosphere(2);
    for (what, mesh) in [("outward", sphere.clone()), ("inside out", rewound(&sphere, |_| true))] {
        let (positions, triangles) = &mesh;
        let camera = render_camera(&mesh);
        let settings = RenderSettings::new(camera);
        let light = settings.light_direction();
        let ambient = f64::from(settings.ambient);
        let normals = vertex_normals(positions, triangles);
        let bvh = MeshBvh::build(positions, triangles, BvhPreset::FastBuild);
        let expected_at = |x: u32, y: u32| -> Option<u8> {
            let (origin, direction) = camera.ray_through_pixel(f64::from(x) + 0.5, f64::from(y) + 0.5, 128, 128);
            let hit = bvh.cast(origin, direction, f64::INFINITY)?;
            let corners = triangles[hit.face as usize];
            let p = corners.map(|v| DVec3::from_array(positions[v as usize].map(f64::from)));
            let face_normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize().as_vec3().to_array();
            let mut d = 0.0;
            for k in 0..3 {
                let vertex = normals[corners[k] as usize].map(|x| x as f32);
                let n = DVec3::from_array(smooth_corner_normal(vertex, face_normal).map(f64::from));
                d += f64::from(hit.barycentric[k]) * n.dot(light);
            }
            let d = if hit.front_facing { d } else { -d };
            let linear = 0.6 * (ambient + (1.0 - ambient) * d.max(0.0));
            Some((linear_to_srgb(linear as f32) * 255.0).round() as u8)
        };
        for (shading, must_match) in [(Shading::Smooth, true), (Shading::Lit, false)] {
            let image = shaded_render(&mesh, shading);
            let (mut compared, mut off) = (0usize, 0usize);
            let mut worst = 0u8;
            for (x, y, pixel) in image.enumerate_pixels() {
                // Silhouette pixels are partly covered: only pixels whose neighbours all hit.
                let inside = [(0i32, 0i32), (-1, 0), (1, 0), (0, -1), (0, 1)].iter().all(|&(dx, dy)| {
                    let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                    (0..128).contains(&nx) && (0..128).contains(&ny) && image.get_pixel(nx as u32, ny as u32)[3] > 0
                });
                let Some(expected) = expected_at(x, y).filter(|_| inside) else { continue };
                compared += 1;
                let difference = pixel[0].abs_diff(expected);
                worst = worst.max(difference);
                off += usize::from(difference > 2);
            }
            eprintln!("{what} {shading:?}: {off} of {compared} px differ by more than 2 steps (worst {worst})");
            assert!(compared > 4000, "{what}: the sphere covers the image ({compared} px)");
            if must_match {
                assert!(
                    off * 200 <= compared,
                    "{what}: {off} of {compared} px differ by more than 2 steps (worst {worst})"
                );
            } else {
                assert!(off * 10 > compared, "{what}: flat shading should differ from smooth ({off} of {compared} px)");
            }
        }
    }
}

#[test]
fn info_reports_an_inside_out_mesh_in_text_and_json() {
    // The octahedron at R = 1 written as a .glb, with the winding of the file reversed.
    let inverted = rewound(&octahedron_mesh(), |_| true);
    let store = ColorStore::uniform(topology(&inverted), Resolution::ONE, GREY);
    let path = common::output_dir().join("winding_inverted_octahedron.glb");
    meshpaint_core::io::export_gltf::write_tessellated_glb(&path, &inverted.0, &store).unwrap();
    let bin = env!("CARGO_BIN_EXE_meshpaint");
    let output = std::process::Command::new(bin).args(["info", path.to_str().unwrap(), "--json"]).output().unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let info: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(info["closed_components"], 1);
    assert_eq!(info["inverted_components"], 1);
    assert_eq!(info["inconsistent_edges"], 0);
    assert!((info["closed_signed_volume"].as_f64().unwrap() + 4.0 / 3.0).abs() < 1e-5, "{info}");
    let output = std::process::Command::new(bin).args(["info", path.to_str().unwrap()]).output().unwrap();
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(text.contains("orientation:") && text.contains("inside out"), "{text}");
}
