//! The least-squares bake against independent truths: the objective integrated by brute
//! force through the CPU reference sampler against the analytic function the texture
//! holds (the fit lowers it, and no single sample can be moved to lower it further, on a
//! mesh whose coarse face fans towards a finer edge), a constant kept exactly, faces no
//! quadrature point sees kept at the point bake, and the sample limit.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use meshpaint_core::colors::format::{Rgba, linear_to_srgb};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::convert::bake::bake_texture;
use meshpaint_core::convert::least_squares::{MAX_SAMPLES, refine};
use meshpaint_core::mesh::scene::{Material, Scene, Texture};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::mesh::weld::WeldedMesh;
use meshpaint_core::packing::sampler::{Filter, sample};

use crate::common;
use crate::common::WriteThrough;
use common::Rng;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// The signal the texture holds, linear light, every channel inside (0.1, 0.9) so the fit
/// never reaches the store's clamp.
fn signal(u: f64, v: f64) -> [f64; 4] {
    [
        0.5 + 0.3 * (7.0 * u).sin() * (5.0 * v).cos(),
        0.45 + 0.25 * (11.0 * u + 3.0 * v).sin(),
        0.3 + 0.4 * u * v,
        0.6 + 0.2 * (9.0 * v).cos(),
    ]
}

fn srgb_byte(linear: f64) -> u8 {
    (f64::from(linear_to_srgb(linear as f32)) * 255.0).round() as u8
}

/// `signal` sampled at the texel centres of a `size`² RGBA8 texture (sRGB colour, linear alpha).
fn signal_texture(size: u32) -> Texture {
    let mut rgba8_srgb = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let s = signal((f64::from(x) + 0.5) / f64::from(size), (f64::from(y) + 0.5) / f64::from(size));
            rgba8_srgb.extend_from_slice(&[
                srgb_byte(s[0]),
                srgb_byte(s[1]),
                srgb_byte(s[2]),
                (s[3] * 255.0).round() as u8,
            ]);
        }
    }
    Texture { width: size, height: size, rgba8_srgb }
}

fn scene_with(texture: Texture) -> Scene {
    Scene {
        materials: vec![Material { base_color_factor: [1.0; 4], base_color_texture: Some(0) }],
        textures: vec![texture],
        ..Scene::default()
    }
}

/// The unit quad as faces `[0, 1, 2]` and `[0, 2, 3]`, UV = `0.1 + 0.8 · position`, plus
/// `extra` triangles (UVs from the same map).
fn quad_mesh(extra_positions: &[[f32; 3]], extra: &[[u32; 3]]) -> WeldedMesh {
    let mut positions_world = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    positions_world.extend_from_slice(extra_positions);
    let mut triangles = vec![[0, 1, 2], [0, 2, 3]];
    triangles.extend_from_slice(extra);
    let uv = |p: [f32; 3]| [0.1 + 0.8 * p[0], 0.1 + 0.8 * p[1]];
    let corner_uvs = triangles.iter().map(|t| t.map(|v| uv(positions_world[v as usize]))).collect();
    WeldedMesh {
        corner_normals_world: vec![[[0.0, 0.0, 1.0]; 3]; triangles.len()],
        triangle_materials: vec![Some(0); triangles.len()],
        positions_world,
        triangles,
        corner_uvs,
        ..WeldedMesh::default()
    }
}

fn store_of(mesh: &WeldedMesh, resolutions: &[u64]) -> ColorStore {
    let topology = Topology::build(mesh.positions_world.len() as u32, &mesh.triangles).unwrap();
    ColorStore::with_resolutions(topology, resolutions.iter().map(|&v| r(v)).collect(), [f32::NAN; 4]).unwrap()
}

/// `Σ_f area_f ∫_f |shown − signal|²` over the quad's two faces (world area ½ each), by the
/// centroids of a 128² lattice on each face, `shown` from the reference sampler.
fn objective(store: &ColorStore, mesh: &WeldedMesh) -> f64 {
    const N: u32 = 128;
    let n = f64::from(N);
    let mut sum = 0.0;
    for face in 0..2u32 {
        let uvs = mesh.corner_uvs[face as usize];
        for j in 0..N {
            for i in 0..N - j {
                let mut centroids = vec![(f64::from(i) + 1.0 / 3.0, f64::from(j) + 1.0 / 3.0)];
                if i + j + 2 <= N {
                    centroids.push((f64::from(i) + 2.0 / 3.0, f64::from(j) + 2.0 / 3.0));
                }
                for (cu, cv) in centroids {
                    let w = [(n - cu - cv) / n, cu / n, cv / n];
                    let uv: [f64; 2] = std::array::from_fn(|a| (0..3).map(|k| w[k] * f64::from(uvs[k][a])).sum());
                    let truth = signal(uv[0], uv[1]);
                    let shown = sample(store, face, w.map(|x| x as f32), Filter::Linear, 0).unwrap();
                    sum += (0..4).map(|c| (f64::from(shown[c]) - truth[c]).powi(2)).sum::<f64>() * 0.5 / (n * n);
                }
            }
        }
    }
    sum
}

fn all_samples(store: &ColorStore) -> Vec<SampleRef> {
    let mut out = Vec::new();
    store.for_each_site(|site| out.push(site.sample));
    out
}

/// On a quad whose face 0 (R = 2) fans towards the shared diagonal at face 1's R = 8, the
/// fit lowers the brute-force objective by more than a quarter from the point bake's (0.029 → 0.016), and moving any single
/// sample by ±0.05 in any channel raises it: the fit is the minimum of what the sampler
/// shows, fans included.
#[test]
fn the_fit_is_the_minimum_of_the_objective_the_sampler_shows() {
    let mesh = quad_mesh(&[], &[]);
    let scene = scene_with(signal_texture(256));
    let mut point = store_of(&mesh, &[2, 8]);
    bake_texture(&mut point, &mesh, &scene);
    let mut fitted = point.clone();
    let report = refine(&mut fitted, &mesh, &scene).expect("within the sample limit");
    assert_eq!(report.faces, 2);
    assert_eq!(report.samples, fitted.sample_count());
    let (before, after) = (objective(&point, &mesh), objective(&fitted, &mesh));
    assert!(after < 0.75 * before, "objective {before} → {after}");
    let samples = all_samples(&fitted);
    let mut rng = Rng(0x5eed_1234);
    for _ in 0..24 {
        let s = samples[(rng.next() % samples.len() as u64) as usize];
        let c = (rng.next() % 4) as usize;
        for delta in [-0.05f32, 0.05] {
            let mut moved = fitted.clone();
            let mut color = moved.get(s).unwrap();
            color[c] += delta;
            assert!(moved.write_sample(s, color));
            let j = objective(&moved, &mesh);
            assert!(j > after, "{s:?} channel {c} {delta:+}: {after} → {j}");
        }
    }
}

/// A constant texture is kept exactly on every sample, across a fanned mixed edge.
#[test]
fn a_constant_texture_is_kept_exactly() {
    let mesh = quad_mesh(&[], &[]);
    let texel = [180u8, 40, 90, 200];
    let scene = scene_with(Texture { width: 1, height: 1, rgba8_srgb: texel.to_vec() });
    for resolutions in [[1u64, 16], [4, 4], [2, 64]] {
        let mut store = store_of(&mesh, &resolutions);
        bake_texture(&mut store, &mesh, &scene);
        let expected = store.vertex_color(0).unwrap();
        refine(&mut store, &mesh, &scene).unwrap();
        for s in all_samples(&store) {
            let got: Rgba = store.get(s).unwrap();
            for c in 0..4 {
                assert!((got[c] - expected[c]).abs() <= 1e-6, "{resolutions:?} {s:?}: {got:?} vs {expected:?}");
            }
        }
    }
}

/// A triangle of zero world area (its third corner on the quad's edge 1–2) is seen by no
/// quadrature point: its interior and its own edges keep the point bake bit for bit.
#[test]
fn samples_no_quadrature_point_sees_keep_the_point_bake() {
    let mesh = quad_mesh(&[[1.0, 0.5, 0.0]], &[[1, 2, 4]]);
    let scene = scene_with(signal_texture(64));
    let mut point = store_of(&mesh, &[4, 4, 4]);
    bake_texture(&mut point, &mesh, &scene);
    let mut fitted = point.clone();
    refine(&mut fitted, &mesh, &scene).unwrap();
    let topology = fitted.topology().clone();
    let own_edges: Vec<u32> =
        topology.face_edges[2].iter().copied().filter(|&e| topology.faces_of_edge(e).len() == 1).collect();
    assert_eq!(own_edges.len(), 2);
    let mut checked = 0;
    for s in all_samples(&fitted) {
        let own = match s {
            SampleRef::Interior { face, .. } => face == 2,
            SampleRef::Edge { edge, .. } => own_edges.contains(&edge),
            SampleRef::Vertex(v) => v == 4,
        };
        if own {
            assert_eq!(fitted.get(s), point.get(s), "{s:?}");
            checked += 1;
        }
    }
    // Three interior samples, three on each own edge, vertex 4.
    assert_eq!(checked, 3 + 2 * 3 + 1);
    // The quad's samples did move.
    assert_ne!(fitted.interior_samples(1), point.interior_samples(1));
}

/// Past [`MAX_SAMPLES`] the fit does not run and the store is untouched.
#[test]
fn documents_over_the_sample_limit_keep_the_point_bake() {
    let mesh = quad_mesh(&[], &[]);
    let scene = scene_with(signal_texture(4));
    let mut store = store_of(&mesh, &[2048, 2048]);
    assert!(store.sample_count() > MAX_SAMPLES, "{} samples", store.sample_count());
    store.write_sample(SampleRef::Vertex(0), [0.25; 4]);
    let before = store.clone();
    assert!(refine(&mut store, &mesh, &scene).is_none());
    assert_eq!(store.vertex_color(0), before.vertex_color(0));
    assert_eq!(store.interior_samples(0), before.interior_samples(0));
}
