//! glTF export against independent truths: the Khronos glTF-Validator (npm package
//! `gltf-validator`, pinned in tools/validate-gltf), the importer reading the file back
//! (closed-form vertex and triangle counts, colours bit for bit, positions), the CPU
//! reference sampler's linear filter against plain barycentric interpolation of COLOR_0
//! over the exported triangles found by geometry, determinism, and COLOR_0 import.

// Colour channels and coordinates are indexed in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use std::collections::{BTreeSet, HashMap};
use std::process::Command;

use glam::Mat4;
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::io::document::Document;
use meshpaint_core::io::export_gltf::{ExportError, GENERATOR, export_tessellated_glb, write_tessellated_glb};
use meshpaint_core::mesh::import::{import_gltf, import_gltf_slice};
use meshpaint_core::mesh::scene::SourceMesh;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::sampler::{Filter, sample};
use serde_json::{Value, json};

use crate::common;
use crate::common::WriteThrough;
use common::{SplitMix64, TempDir, model};

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

// ---------------------------------------------------------------------------------------
// Test meshes

/// A document's positions and store.
struct Painted {
    name: String,
    positions: Vec<[f32; 3]>,
    store: ColorStore,
}

fn open_model(relative: &str, resolution: u64) -> Painted {
    let document = Document::open(&model(relative), r(resolution)).unwrap();
    Painted { name: format!("{relative}@R{resolution}"), positions: document.positions, store: document.store }
}

/// The resolutions of the mixed stores, in a pattern that puts different ones side by side.
const MIXED: [u64; 4] = [1, 2, 8, 32];

/// A wavy 4 × 4 quad grid (32 faces, open boundary, reversed edges on both diagonals)
/// with faces at R = 1, 2, 8 and 32 next to each other and random colours.
fn mixed_grid(seed: u64) -> Painted {
    const N: u32 = 4;
    let mut positions = Vec::new();
    for y in 0..=N {
        for x in 0..=N {
            let (fx, fy) = (x as f32 * 0.5, y as f32 * 0.5);
            positions.push([fx, fy, 0.1 * (3.0 * fx).sin() * (2.0 * fy).cos()]);
        }
    }
    let at = |x: u32, y: u32| y * (N + 1) + x;
    let mut triangles = Vec::new();
    for y in 0..N {
        for x in 0..N {
            let (a, b, c, d) = (at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1));
            if (x + y) % 2 == 0 {
                triangles.extend([[a, b, d], [a, d, c]]);
            } else {
                triangles.extend([[a, b, c], [b, d, c]]);
            }
        }
    }
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let resolutions = (0..triangles.len()).map(|f| r(MIXED[(f + f / (2 * N as usize)) % 4])).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [1.0; 4]).unwrap();
    let mut rng = SplitMix64(seed);
    store.write_all(|_| rng.color());
    Painted { name: "mixed grid".into(), positions, store }
}

/// BoxTextured (closed, 12 faces) with faces at R = 1, 2, 8, 32 and random colours.
fn mixed_box(seed: u64) -> Painted {
    let mut painted = open_model("BoxTextured/BoxTextured.glb", 1);
    for face in 0..painted.store.topology().face_count() {
        painted.store.write_resolution(face, r(MIXED[face as usize % 4])).unwrap();
    }
    let mut rng = SplitMix64(seed);
    painted.store.write_all(|_| rng.color());
    painted.name = "mixed box".into();
    painted
}

/// Pairs of different resolutions that meet at an edge.
fn unequal_neighbours(store: &ColorStore) -> BTreeSet<(u32, u32)> {
    let topology = store.topology();
    let mut pairs = BTreeSet::new();
    for edge in 0..topology.edge_count() {
        let rs: Vec<u32> =
            topology.faces_of_edge(edge).iter().map(|&(f, _)| store.face_resolution(f).unwrap().get()).collect();
        for &a in &rs {
            for &b in &rs {
                if a < b {
                    pairs.insert((a, b));
                }
            }
        }
    }
    pairs
}

// ---------------------------------------------------------------------------------------
// Independent counts

/// Samples the faces read: every used vertex, `max_f R_f − 1` per edge (the finest face
/// reads them all, coarser faces a subset), `(R − 1)(R − 2)/2` per face interior.
fn expected_vertices(store: &ColorStore) -> u64 {
    let topology = store.topology();
    let used: BTreeSet<u32> = topology.face_vertices.iter().flatten().copied().collect();
    let mut count = used.len() as u64;
    for edge in 0..topology.edge_count() {
        let finest = topology
            .faces_of_edge(edge)
            .iter()
            .map(|&(f, _)| u64::from(store.face_resolution(f).unwrap().get()))
            .max()
            .unwrap();
        count += finest - 1;
    }
    for face in 0..topology.face_count() {
        let res = u64::from(store.face_resolution(face).unwrap().get());
        count += (res - 1) * res.saturating_sub(2) / 2;
        // One centroid vertex per fanned sub-triangle.
        count += fanned(store, face);
    }
    count
}

/// `R_e / R_f` of each face edge of `face` (> 1: a fine side, fanned sub-triangles).
fn ratios(store: &ColorStore, face: u32) -> [u32; 3] {
    let rf = store.face_resolution(face).unwrap().get();
    store.topology().face_edges[face as usize].map(|e| store.edge_resolution(e).unwrap().get() / rf)
}

/// Fanned sub-triangles of `face` by inclusion–exclusion: `R_f` lower sub-triangles along
/// each fine edge, minus the corner sub-triangles counted twice (R_f ≥ 2); at R_f = 1
/// the single sub-triangle when any edge is fine.
fn fanned(store: &ColorStore, face: u32) -> u64 {
    let rf = u64::from(store.face_resolution(face).unwrap().get());
    let fine = ratios(store, face).map(|m| m > 1);
    if rf == 1 {
        return u64::from(fine.iter().any(|&f| f));
    }
    let along: u64 = fine.iter().map(|&f| u64::from(f) * rf).sum();
    // Corner c0 joins edges 2 and 0, c1 edges 0 and 1, c2 edges 1 and 2.
    let corners = [(2, 0), (0, 1), (1, 2)].iter().filter(|&&(a, b)| fine[a] && fine[b]).count() as u64;
    along - corners
}

/// Triangles: `R_f²` per face; a fan replaces one sub-triangle by 3 triangles plus one
/// per extra segment of its fine sides: `R_f² + 2·fanned + Σ_k (R_e − R_f)`.
fn expected_face_triangles(store: &ColorStore, face: u32) -> u64 {
    let rf = u64::from(store.face_resolution(face).unwrap().get());
    let extra: u64 = ratios(store, face).iter().map(|&m| rf * (u64::from(m) - 1)).sum();
    rf * rf + 2 * fanned(store, face) + extra
}

fn expected_triangles(store: &ColorStore) -> u64 {
    (0..store.topology().face_count()).map(|f| expected_face_triangles(store, f)).sum()
}

use crate::validator::validate;

fn assert_valid(bytes: &[u8], dir: &TempDir, name: &str) {
    let path = dir.join(&format!("{}.glb", name.replace(['/', ' ', '@'], "_")));
    std::fs::write(&path, bytes).unwrap();
    let report = validate(&path);
    assert_eq!(report["numErrors"], 0, "{name}: the validator found errors: {report}");
    assert_eq!(report["numWarnings"], 0, "{name}: the validator found warnings: {report}");
}

#[test]
fn khronos_validator_accepts_the_exports() {
    let dir = TempDir::new("validator");
    let mut cases = vec![
        open_model("BoxTextured/BoxTextured.glb", 4),
        open_model("Duck/Duck.glb", 8),
        mixed_grid(1),
        mixed_box(2),
        open_model("BoxTextured/BoxTextured.glb", 1),
    ];
    // Out-of-range colours are clamped (the validator refuses COLOR_0 outside [0, 1]).
    let mut overshoot = mixed_grid(3);
    overshoot.store.write_sample(SampleRef::Vertex(0), [1.5, -0.25, 0.5, 2.0]);
    overshoot.name = "overshooting colours".into();
    cases.push(overshoot);
    assert!(unequal_neighbours(&cases[2].store).len() >= 5, "the mixed grid mixes resolutions");
    assert!(unequal_neighbours(&cases[3].store).contains(&(1, 32)), "the mixed box has R=1 next to R=32");
    for case in &cases {
        let bytes = export_tessellated_glb(&case.positions, &case.store).unwrap();
        assert_valid(&bytes, &dir, &case.name);
    }
}

// ---------------------------------------------------------------------------------------
// Round trip through the importer

/// Exports, imports the .glb back, and checks counts, triangles, colours and positions.
fn check_round_trip(case: &Painted) -> SourceMesh {
    let store = &case.store;
    let name = &case.name;
    let bytes = export_tessellated_glb(&case.positions, store).unwrap();
    let scene = import_gltf_slice(&bytes, None, &format!("{name}.glb")).unwrap();
    assert_eq!(scene.meshes.len(), 1, "{name}");
    assert_eq!(scene.instances.len(), 1, "{name}");
    assert_eq!(scene.instances[0].world_from_local, Mat4::IDENTITY, "{name}");
    let mesh = scene.meshes.into_iter().next().unwrap();
    let vertices = mesh.positions_local.len();
    assert_eq!(vertices as u64, expected_vertices(store), "{name}: one vertex per sample the faces read");
    assert_eq!(mesh.triangles.len() as u64, expected_triangles(store), "{name}: Σ R²");
    assert_eq!(mesh.colors.len(), vertices, "{name}: COLOR_0 on every vertex");

    let topology = store.topology();
    let mut vertex_of: HashMap<SampleRef, u32> = HashMap::new();
    let mut sample_of: HashMap<u32, SampleRef> = HashMap::new();
    let mut t = 0usize;
    let mut centroids = 0usize;
    for face in 0..topology.face_count() {
        let res = store.face_resolution(face).unwrap().get();
        let corners = topology.face_vertices[face as usize].map(|v| case.positions[v as usize]);
        let fine = ratios(store, face);
        for i in 0..res {
            for j in 0..res - i {
                let on_side = [j == 0, i + j + 1 == res, i == 0];
                if (0..3).any(|k| on_side[k] && fine[k] > 1) {
                    // A fan from the centroid G: per side (i,j)→(i+1,j)→(i,j+1)→(i,j), one
                    // triangle (G, a, b) per segment; a fine side's segments join the
                    // edge's consecutive samples.
                    let g = mesh.triangles[t][0];
                    let ends = [(i, j), (i + 1, j), (i, j + 1)];
                    let end_colors = ends.map(|(a, b)| store.face_sample(face, a, b).unwrap());
                    let mean: [f32; 4] =
                        std::array::from_fn(|c| (end_colors[0][c] + end_colors[1][c] + end_colors[2][c]) / 3.0);
                    assert_eq!(mesh.colors[g as usize], mean, "{name}: face {face} ({i}, {j}) centroid colour");
                    assert!(!sample_of.contains_key(&g), "{name}: the centroid is a vertex of its own");
                    centroids += 1;
                    for side in 0..3 {
                        let m = if on_side[side] { fine[side] } else { 1 };
                        let edge = topology.face_edges[face as usize][side];
                        let r_edge = store.edge_resolution(edge).unwrap();
                        let q = [i, j, res - j - 1][side];
                        for n in 0..m {
                            let got = mesh.triangles[t];
                            t += 1;
                            assert_eq!(got[0], g, "{name}: face {face} ({i}, {j}): one centroid per fan");
                            for (slot, k) in [(1usize, n), (2, n + 1)] {
                                let sample = if k == 0 {
                                    store.face_sample_ref(face, ends[side].0, ends[side].1).unwrap()
                                } else if k == m {
                                    let (a, b) = ends[(side + 1) % 3];
                                    store.face_sample_ref(face, a, b).unwrap()
                                } else {
                                    let p = q * m + k;
                                    let reversed = topology.is_reversed(face, side);
                                    SampleRef::Edge { edge, offset: layout::edge_storage_offset(r_edge, p, reversed) }
                                };
                                let vertex = got[slot];
                                assert_eq!(*vertex_of.entry(sample).or_insert(vertex), vertex, "{name}: {sample:?}");
                                assert_eq!(*sample_of.entry(vertex).or_insert(sample), sample, "{name}: {vertex}");
                                assert_eq!(mesh.colors[vertex as usize], store.get(sample).unwrap(), "{name}");
                            }
                        }
                    }
                    if i + j + 2 <= res {
                        // The upper neighbour follows as usual.
                        let got = mesh.triangles[t];
                        t += 1;
                        for (k, (a, b)) in [(i + 1, j), (i + 1, j + 1), (i, j + 1)].into_iter().enumerate() {
                            let sample = store.face_sample_ref(face, a, b).unwrap();
                            assert_eq!(*vertex_of.entry(sample).or_insert(got[k]), got[k], "{name}: {sample:?}");
                        }
                    }
                    continue;
                }
                let mut expected = vec![[(i, j), (i + 1, j), (i, j + 1)]];
                if i + j + 2 <= res {
                    expected.push([(i + 1, j), (i + 1, j + 1), (i, j + 1)]);
                }
                for triangle in expected {
                    let got = mesh.triangles[t];
                    t += 1;
                    for k in 0..3 {
                        let (a, b) = triangle[k];
                        let vertex = got[k];
                        let sample = store.face_sample_ref(face, a, b).unwrap();
                        assert_eq!(
                            *vertex_of.entry(sample).or_insert(vertex),
                            vertex,
                            "{name}: {sample:?} is one vertex"
                        );
                        assert_eq!(
                            *sample_of.entry(vertex).or_insert(sample),
                            sample,
                            "{name}: vertex {vertex} is one sample"
                        );
                        let color = store.face_sample(face, a, b).unwrap();
                        assert_eq!(
                            mesh.colors[vertex as usize].map(f32::to_bits),
                            color.map(f32::to_bits),
                            "{name}: face {face} sample ({a}, {b}) colour"
                        );
                        let w = [f64::from(res - a - b), f64::from(a), f64::from(b)].map(|w| w / f64::from(res));
                        let position: [f32; 3] = std::array::from_fn(|c| {
                            (0..3).map(|k| w[k] * f64::from(corners[k][c])).sum::<f64>() as f32
                        });
                        assert_eq!(mesh.positions_local[vertex as usize], position, "{name}: face {face} ({a}, {b})");
                    }
                }
            }
        }
    }
    assert_eq!(t, mesh.triangles.len());
    assert_eq!(sample_of.len() + centroids, vertices, "{name}: every vertex is used");
    mesh
}

#[test]
fn round_trip_at_uniform_resolution_matches_the_closed_form() {
    // (model, R, welded V, E, F as listed in assets/SOURCES.md)
    for (relative, res, v, e, f) in [
        ("BoxTextured/BoxTextured.glb", 4u64, 8u64, 18u64, 12u64),
        ("Duck/Duck.glb", 8, 2108, 6318, 4212),
        ("Suzanne/monkey.glb", 2, 505, 1473, 968),
    ] {
        let case = open_model(relative, res);
        let topology = case.store.topology();
        assert_eq!((u64::from(topology.vertex_count), u64::from(topology.edge_count())), (v, e), "{relative}");
        assert_eq!(u64::from(topology.face_count()), f, "{relative}");
        let mesh = check_round_trip(&case);
        let closed_form = v + e * (res - 1) + f * (res - 1) * (res - 2) / 2;
        assert_eq!(mesh.positions_local.len() as u64, closed_form, "{relative}: V + E(R−1) + F(R−1)(R−2)/2");
        assert_eq!(mesh.triangles.len() as u64, f * res * res, "{relative}: F·R²");
    }
}

#[test]
fn round_trip_with_mixed_resolutions() {
    for case in [mixed_grid(11), mixed_box(12)] {
        let mesh = check_round_trip(&case);
        let centroids: u64 = (0..case.store.topology().face_count()).map(|f| fanned(&case.store, f)).sum();
        assert!(centroids > 0, "{}: the mixed stores have fine sides", case.name);
        assert_eq!(
            mesh.positions_local.len() as u64,
            case.store.sample_count() + centroids,
            "{}: every stored sample is read, plus one centroid per fan",
            case.name
        );
    }
}

#[test]
fn resolution_one_exports_the_vertex_colours() {
    let mut case = open_model("BoxTextured/BoxTextured.glb", 1);
    let mut rng = SplitMix64(5);
    case.store.write_all(|_| rng.color());
    let mesh = check_round_trip(&case);
    let topology = case.store.topology();
    assert_eq!(mesh.positions_local.len(), topology.vertex_count as usize);
    assert_eq!(mesh.triangles.len(), topology.face_count() as usize);
    // The mesh itself, with its own positions, winding and vertex colours.
    let mut vertex_of = HashMap::new();
    for (face, triangle) in mesh.triangles.iter().enumerate() {
        let corners = topology.face_vertices[face];
        for k in 0..3 {
            let (exported, original) = (triangle[k], corners[k]);
            assert_eq!(*vertex_of.entry(original).or_insert(exported), exported);
            assert_eq!(mesh.positions_local[exported as usize], case.positions[original as usize]);
            assert_eq!(mesh.colors[exported as usize], case.store.vertex_color(original).unwrap());
        }
    }
}

// ---------------------------------------------------------------------------------------
// Linear filter = interpolation of COLOR_0 over the exported triangles

/// Lattice coordinates `(u, v) = (R·w1, R·w2)` of `p` on the face with `corners`
/// (least squares in the face plane, f64).
fn lattice_coords(p: [f32; 3], corners: [[f32; 3]; 3], res: u32) -> (f64, f64) {
    let c = corners.map(|c| c.map(f64::from));
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (e1, e2, d) = (sub(c[1], c[0]), sub(c[2], c[0]), sub(p.map(f64::from), c[0]));
    let (a11, a12, a22, b1, b2) = (dot(e1, e1), dot(e1, e2), dot(e2, e2), dot(d, e1), dot(d, e2));
    let det = a11 * a22 - a12 * a12;
    let s = (b1 * a22 - b2 * a12) / det;
    let t = (a11 * b2 - a12 * b1) / det;
    (s * f64::from(res), t * f64::from(res))
}

/// Whether the face is well enough shaped for recovering lattice coordinates from f32
/// positions (sliver faces of real models are skipped).
fn well_shaped(corners: [[f32; 3]; 3]) -> bool {
    let c = corners.map(|c| glam::DVec3::from_array(c.map(f64::from)));
    let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
    let area2 = e1.cross(e2).length();
    let longest = e1.length().max(e2.length()).max((c[2] - c[1]).length());
    area2 > 1e-3 * longest * longest
}

/// An exported triangle in lattice coordinates `(u, v)`, with its glTF vertices.
type LatticeTriangle = ([(f64, f64); 3], [u32; 3]);

/// The exported triangles of one face in lattice coordinates (recovered from geometry,
/// rounded to the lattice and checked to be lattice points), with their vertices.
fn face_triangles(
    mesh: &SourceMesh,
    range: std::ops::Range<usize>,
    corners: [[f32; 3]; 3],
    res: u32,
    grid: u32,
) -> Vec<LatticeTriangle> {
    let g = f64::from(grid);
    mesh.triangles[range]
        .iter()
        .map(|triangle| {
            let coords = triangle.map(|vertex| {
                let (u, v) = lattice_coords(mesh.positions_local[vertex as usize], corners, res);
                let (ru, rv) = ((u * g).round() / g, (v * g).round() / g);
                assert!(
                    (u - ru).abs() < 1e-3 && (v - rv).abs() < 1e-3,
                    "vertex {vertex} at ({u}, {v}) is not a lattice point"
                );
                (ru, rv)
            });
            (coords, *triangle)
        })
        .collect()
}

/// Barycentric coordinates of `(x, y)` in the 2D triangle `t`, and its signed double area.
fn barycentric_2d(t: [(f64, f64); 3], x: f64, y: f64) -> ([f64; 3], f64) {
    let area = (t[1].0 - t[0].0) * (t[2].1 - t[0].1) - (t[2].0 - t[0].0) * (t[1].1 - t[0].1);
    let l1 = ((x - t[0].0) * (t[2].1 - t[0].1) - (t[2].0 - t[0].0) * (y - t[0].1)) / area;
    let l2 = ((t[1].0 - t[0].0) * (y - t[0].1) - (x - t[0].0) * (t[1].1 - t[0].1)) / area;
    ([1.0 - l1 - l2, l1, l2], area)
}

fn check_linear_filter(case: &Painted, points: usize, seed: u64) {
    let store = &case.store;
    let name = &case.name;
    let bytes = export_tessellated_glb(&case.positions, store).unwrap();
    let mesh = import_gltf_slice(&bytes, None, "linear.glb").unwrap().meshes.remove(0);
    let topology = store.topology();
    let mut starts = vec![0usize];
    for face in 0..topology.face_count() {
        starts.push(starts.last().unwrap() + expected_face_triangles(store, face) as usize);
    }
    let mut rng = SplitMix64(seed);
    let mut checked = 0;
    let mut cache: HashMap<u32, Vec<LatticeTriangle>> = HashMap::new();
    while checked < points {
        let face = rng.below(u64::from(topology.face_count())) as u32;
        let res = store.face_resolution(face).unwrap().get();
        let corners = topology.face_vertices[face as usize].map(|v| case.positions[v as usize]);
        if !well_shaped(corners) {
            continue;
        }
        let fine = ratios(store, face);
        let grid = 3 * fine.iter().copied().max().unwrap();
        let triangles = cache.entry(face).or_insert_with(|| {
            let range = starts[face as usize]..starts[face as usize + 1];
            // Without fine sides: lattice points; with them, fan centroids sit at thirds and
            // fine edge samples at 1/m of the lattice.
            let triangles = face_triangles(&mesh, range, corners, res, if grid == 3 { 1 } else { grid });
            // The triangles tile the face with its winding: all positive, total R²/2.
            let mut total = 0.0;
            for (coords, _) in &triangles {
                let (_, area) = barycentric_2d(*coords, 0.0, 0.0);
                if grid == 3 {
                    assert_eq!(area, 1.0, "{name}: face {face}: a unit sub-triangle with the face's winding");
                } else {
                    assert!(area > 0.0, "{name}: face {face}: a fan triangle with the face's winding");
                }
                total += area / 2.0;
            }
            assert!(
                (total - f64::from(res * res) / 2.0).abs() < 1e-9 * f64::from(res * res),
                "{name}: face {face}: the sub-triangles cover the face"
            );
            triangles
        });
        // Dyadic barycentrics (20 bits) sum to 1 exactly in f32, so sanitising leaves them.
        const ONE: u64 = 1 << 20;
        let (mut k1, mut k2) = (rng.below(ONE + 1), rng.below(ONE + 1));
        if k1 + k2 > ONE {
            (k1, k2) = (ONE - k1, ONE - k2);
        }
        // Some points exactly on lattice points, lattice lines and the face's edges.
        match checked % 8 {
            0 => k1 -= k1 % (ONE / u64::from(res)),
            1 => k2 -= k2 % (ONE / u64::from(res)),
            2 => k2 = ONE - k1,
            _ => {}
        }
        let bary = [(ONE - k1 - k2) as f32, k1 as f32, k2 as f32].map(|k| k / ONE as f32);
        let expected = sample(store, face, bary, Filter::Linear, 0).unwrap();
        let (x, y) = (f64::from(bary[1]) * f64::from(res), f64::from(bary[2]) * f64::from(res));
        let (lambda, vertices) = triangles
            .iter()
            .map(|(coords, vertices)| (barycentric_2d(*coords, x, y).0, *vertices))
            .max_by(|a, b| {
                let min = |l: &[f64; 3]| l[0].min(l[1]).min(l[2]);
                min(&a.0).total_cmp(&min(&b.0))
            })
            .unwrap();
        assert!(lambda.iter().all(|&l| l >= -1e-12), "{name}: face {face}: no exported triangle contains ({x}, {y})");
        for c in 0..4 {
            let got: f64 = (0..3).map(|k| lambda[k] * f64::from(mesh.colors[vertices[k] as usize][c])).sum();
            assert!(
                (got - f64::from(expected[c])).abs() <= 1e-6,
                "{name}: face {face} at {bary:?}: sampler {expected:?}, COLOR_0 interpolation gives {got} in channel {c}"
            );
        }
        checked += 1;
    }
}

#[test]
fn linear_filter_equals_interpolated_vertex_colours() {
    check_linear_filter(&mixed_grid(21), 3000, 1);
    check_linear_filter(&mixed_box(22), 3000, 2);
    check_linear_filter(&open_model("Duck/Duck.glb", 8), 2000, 3);
    check_linear_filter(&open_model("BoxTextured/BoxTextured.glb", 4), 500, 4);
}

// ---------------------------------------------------------------------------------------
// Determinism, files, refusals

#[test]
fn export_is_deterministic_and_written_atomically() {
    let dir = TempDir::new("determinism");
    for (case, again) in [
        (mixed_grid(31), mixed_grid(31)),
        (mixed_box(32), mixed_box(32)),
        (open_model("Duck/Duck.glb", 4), open_model("Duck/Duck.glb", 4)),
    ] {
        let first = export_tessellated_glb(&case.positions, &case.store).unwrap();
        assert_eq!(first, export_tessellated_glb(&case.positions, &case.store).unwrap(), "{}", case.name);
        assert_eq!(first, export_tessellated_glb(&again.positions, &again.store).unwrap(), "{}", case.name);
        let path = dir.join("out.glb");
        std::fs::write(&path, b"old contents").unwrap();
        let summary = write_tessellated_glb(&path, &case.positions, &case.store).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), first, "{}", case.name);
        assert_eq!(summary.bytes, first.len() as u64);
        assert_eq!(summary.vertices, expected_vertices(&case.store));
        assert_eq!(summary.triangles, expected_triangles(&case.store));
        // The file reads back through the file importer too.
        assert_eq!(import_gltf(&path).unwrap().meshes[0].triangles.len() as u64, summary.triangles);
    }
    let names: Vec<_> = std::fs::read_dir(&dir.0).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("out.glb")], "no temporary file is left behind");
    // A path in a missing directory is an error naming the path.
    let missing = dir.join("no/such/dir/out.glb");
    let case = mixed_grid(33);
    let error = write_tessellated_glb(&missing, &case.positions, &case.store).unwrap_err();
    assert!(matches!(error, ExportError::Io { .. }), "{error}");
    assert!(error.to_string().contains("no/such/dir"), "{error}");
}

/// The GLB container and the JSON the exporter writes.
fn glb_json(bytes: &[u8]) -> Value {
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32::from_le_bytes(bytes[4..8].try_into().unwrap()), 2);
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, bytes.len());
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let bin_at = 20 + json_len;
    let bin_len = u32::from_le_bytes(bytes[bin_at..bin_at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0, "the BIN chunk is padded to 4 bytes");
    assert_eq!(bin_at + 8 + bin_len, bytes.len());
    let json: Value = serde_json::from_slice(&bytes[20..bin_at]).unwrap();
    let declared = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    assert!(declared <= bin_len && bin_len - declared < 4);
    json
}

#[test]
fn file_structure_bounds_and_index_width() {
    for (case, index_type) in [
        (open_model("BoxTextured/BoxTextured.glb", 4), 5123), // UNSIGNED_SHORT
        (open_model("Duck/Duck.glb", 8), 5125),               // UNSIGNED_INT (134,786 vertices)
    ] {
        let bytes = export_tessellated_glb(&case.positions, &case.store).unwrap();
        let json = glb_json(&bytes);
        assert_eq!(json["asset"]["generator"], GENERATOR);
        assert_eq!(json["asset"]["version"], "2.0");
        assert_eq!(json["meshes"].as_array().unwrap().len(), 1);
        assert_eq!(json["nodes"].as_array().unwrap().len(), 1);
        assert_eq!(json["scenes"].as_array().unwrap().len(), 1);
        let primitive = &json["meshes"][0]["primitives"][0];
        let accessor = |index: &Value| &json["accessors"][index.as_u64().unwrap() as usize];
        assert_eq!(accessor(&primitive["indices"])["componentType"], index_type, "{}", case.name);
        let colors = accessor(&primitive["attributes"]["COLOR_0"]);
        assert_eq!((colors["type"].as_str(), colors["componentType"].as_u64()), (Some("VEC4"), Some(5126)));
        let positions = accessor(&primitive["attributes"]["POSITION"]);
        let mesh = import_gltf_slice(&bytes, None, "x.glb").unwrap().meshes.remove(0);
        for a in 0..3 {
            let min = mesh.positions_local.iter().map(|p| p[a]).fold(f32::INFINITY, f32::min);
            let max = mesh.positions_local.iter().map(|p| p[a]).fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(positions["min"][a].as_f64().unwrap() as f32, min);
            assert_eq!(positions["max"][a].as_f64().unwrap() as f32, max);
        }
    }
}

#[test]
fn an_empty_store_is_refused_with_a_clear_error() {
    let store = ColorStore::uniform(Topology::build(0, &[]).unwrap(), r(4), [1.0; 4]);
    let error = export_tessellated_glb(&[], &store).unwrap_err();
    assert!(matches!(error, ExportError::Empty), "{error}");
    assert!(error.to_string().contains("no faces"), "{error}");
    // Vertices without faces are not enough either.
    let store = ColorStore::uniform(Topology::build(3, &[]).unwrap(), r(1), [1.0; 4]);
    assert!(matches!(export_tessellated_glb(&[[0.0; 3]; 3], &store), Err(ExportError::Empty)));
}

#[test]
fn bad_inputs_are_refused() {
    let case = mixed_grid(41);
    let short = &case.positions[1..];
    assert!(matches!(
        export_tessellated_glb(short, &case.store),
        Err(ExportError::PositionCount { expected: 25, got: 24 })
    ));
    let mut positions = case.positions.clone();
    positions[7][1] = f32::NAN;
    assert!(matches!(
        export_tessellated_glb(&positions, &case.store),
        Err(ExportError::NonFinitePosition { vertex: 7 })
    ));
    // The store holds finite colours only (docs/FORMAT.md "Colour values"): an infinite
    // write is stored as the largest finite value, so export and pack agree on one rule and
    // the export's own non-finite check is a second line of defence.
    let mut store = case.store.clone();
    let sample = SampleRef::Interior { face: 3, offset: 0 };
    store.write_sample(sample, [0.5, f32::INFINITY, f32::NAN, 1.0]);
    assert_eq!(store.get(sample).unwrap(), [0.5, meshpaint_core::colors::format::MAX_CHANNEL, 0.0, 1.0]);
    assert!(export_tessellated_glb(&case.positions, &store).is_ok());
}

#[test]
fn out_of_range_colours_are_clamped() {
    let mut case = mixed_grid(51);
    case.store.write_sample(SampleRef::Vertex(0), [1.5, -0.25, 0.5, 2.0]);
    let bytes = export_tessellated_glb(&case.positions, &case.store).unwrap();
    let mesh = import_gltf_slice(&bytes, None, "x.glb").unwrap().meshes.remove(0);
    let vertex = mesh.positions_local.iter().position(|&p| p == case.positions[0]).unwrap();
    assert_eq!(mesh.colors[vertex], [1.0, 0.0, 0.5, 1.0]);
}

// ---------------------------------------------------------------------------------------
// The command line

#[test]
fn cli_exports_glb_and_packed_files() {
    use meshpaint_core::packing::file as packed_file;
    const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");
    let dir = TempDir::new("cli");
    let input = model("BoxTextured/BoxTextured.glb");
    let glb = dir.join("box.glb");
    let run = |args: &[&std::ffi::OsStr]| Command::new(BIN).args(args).output().unwrap();
    let output = run(&[
        "export".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        glb.as_os_str(),
        "--resolution".as_ref(),
        "4".as_ref(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let expected = open_model("BoxTextured/BoxTextured.glb", 4);
    assert_eq!(std::fs::read(&glb).unwrap(), export_tessellated_glb(&expected.positions, &expected.store).unwrap());

    // Any other extension: a packed file, RGBA8 unless --format says otherwise.
    let packed = dir.join("box.mpk");
    let output =
        run(&["export".as_ref(), input.as_os_str(), "-o".as_ref(), packed.as_os_str(), "-r".as_ref(), "2".as_ref()]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let mesh = packed_file::read_file(&packed).unwrap();
    assert_eq!(mesh.format, meshpaint_core::colors::format::ColorFormat::Rgba8Srgb);
    assert_eq!(mesh.face_records.len(), 12);
    let packed16 = dir.join("box16.mpk");
    let args = [
        "export".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        packed16.as_os_str(),
        "--format".as_ref(),
        "rgba16f".as_ref(),
    ];
    assert!(run(&args).status.success());
    assert_eq!(packed_file::read_file(&packed16).unwrap().format, meshpaint_core::colors::format::ColorFormat::Rgba16F);

    // A packed file exports to .glb too (its own per-face resolutions, here R = 2).
    let from_packed = dir.join("from_packed.glb");
    assert!(run(&["export".as_ref(), packed.as_os_str(), "-o".as_ref(), from_packed.as_os_str()]).status.success());
    let scene = import_gltf(&from_packed).unwrap();
    assert_eq!(scene.meshes[0].positions_local.len(), 8 + 18);
    assert_eq!(scene.meshes[0].triangles.len(), 12 * 4);

    // Refusals: .gltf output, --format with .glb, a missing input; nothing is written.
    let (x, y, z, missing) = (dir.join("x.gltf"), dir.join("y.glb"), dir.join("z.glb"), dir.join("missing.glb"));
    let refusals: [(Vec<&std::ffi::OsStr>, &str); 3] = [
        (vec![input.as_os_str(), "-o".as_ref(), x.as_os_str()], ".glb"),
        (vec![input.as_os_str(), "-o".as_ref(), y.as_os_str(), "--format".as_ref(), "rgba8".as_ref()], "--format"),
        (vec![missing.as_os_str(), "-o".as_ref(), z.as_os_str()], "missing.glb"),
    ];
    for (args, message) in refusals {
        let mut full = vec!["export".as_ref()];
        full.extend(args);
        let output = run(&full);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success() && stderr.contains(message), "{stderr}");
    }
    for name in ["x.gltf", "y.glb", "z.glb"] {
        assert!(!dir.join(name).exists());
    }
}

/// `--representation mct`: the Duck as an MCT file, read back with the core's reader and
/// compared with the texture built in this process from the same document; the default is
/// still the packed file, and glTF names are refused.
#[test]
fn cli_exports_a_mesh_color_texture_file() {
    use meshpaint_core::colors::format::ColorFormat;
    use meshpaint_core::mct::file::read_mct;
    use meshpaint_core::mct::{self, MctStats, MeshColorTexture};
    const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");
    let dir = TempDir::new("cli-mct");
    let input = model("Duck/Duck.glb");
    let export = |extra: &[&str], out: &std::path::Path| {
        Command::new(BIN).arg("export").arg(&input).args(["-r", "4"]).args(extra).arg("-o").arg(out).output().unwrap()
    };
    let out = dir.join("duck.mct");
    let output = export(&["--representation", "mct"], &out);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("atlas in rgba8"), "{stderr}");
    let file = read_mct(&out).unwrap();
    let document = Document::open(&input, r(4)).unwrap();
    let packed = document.pack(ColorFormat::Rgba8Srgb).unwrap();
    let expected = mct::build(&packed, 16384, u64::MAX).unwrap();
    assert_eq!(file.positions, packed.positions);
    assert_eq!(file.indices, packed.indices);
    assert_eq!(file.indices.len(), 4212, "the Duck's triangles");
    assert_eq!(file.mct.layout.levels, 3, "R = 4: levels 0, 1, 2");
    assert_eq!(file.mct, MeshColorTexture { stats: MctStats::default(), ..expected.clone() });
    for face in (0..file.indices.len() as u32).step_by(97) {
        for w in [[1.0, 0.0, 0.0], [0.25, 0.25, 0.5], [0.0, 0.5, 0.5]] {
            assert_eq!(file.mct.sample_trilinear(face, w, 0.7), expected.sample_trilinear(face, w, 0.7));
        }
    }
    // --format chooses the atlas's texel format.
    let out16 = dir.join("duck16.mct");
    assert!(export(&["--representation", "mct", "--format", "rgba16f"], &out16).status.success());
    assert_eq!(read_mct(&out16).unwrap().mct.format, ColorFormat::Rgba16F);
    // The default (and --representation mesh-colors) is still the packed file.
    let (default, explicit) = (dir.join("default.mpk"), dir.join("explicit.mpk"));
    assert!(export(&[], &default).status.success());
    assert!(export(&["--representation", "mesh-colors"], &explicit).status.success());
    assert_eq!(std::fs::read(&default).unwrap(), std::fs::read(&explicit).unwrap());
    assert!(meshpaint_core::packing::file::read_file(&default).is_ok());
    // Refusals: a glTF name, and flags of the glTF exports; nothing is written.
    for (extra, name, message) in [
        (&["--representation", "mct"][..], "x.glb", "--representation mct writes an MCT file"),
        (&["--representation", "mct", "--level", "1"][..], "y.mct", "--representation"),
        (&["--representation", "mct", "--texture", "64"][..], "z.mct", "--representation"),
    ] {
        let output = export(extra, &dir.join(name));
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success() && stderr.contains(message), "{stderr}");
        assert!(!dir.join(name).exists());
    }
}

// ---------------------------------------------------------------------------------------
// COLOR_0 import

/// A COLOR_0 accessor for a test triangle: type, componentType, normalized, count, bytes.
struct ColorAttribute {
    ty: &'static str,
    component: u32,
    normalized: bool,
    count: usize,
    bytes: Vec<u8>,
}

fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A .glb with one mesh of one triangle primitive (3 vertices) per entry, each with the
/// given COLOR_0 or none.
fn triangle_glb(primitives: &[Option<ColorAttribute>]) -> Vec<u8> {
    let mut bin = Vec::new();
    let (mut views, mut accessors, mut json_primitives) = (Vec::new(), Vec::new(), Vec::new());
    let mut add_view = |bin: &mut Vec<u8>, bytes: &[u8]| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend_from_slice(bytes);
        views.len() - 1
    };
    for (p, color) in primitives.iter().enumerate() {
        let x = p as f32 * 2.0;
        let positions = f32_bytes(&[x, 0.0, 0.0, x + 1.0, 0.0, 0.0, x, 1.0, 0.0]);
        let view = add_view(&mut bin, &positions);
        accessors.push(json!({"bufferView": view, "componentType": 5126, "count": 3, "type": "VEC3",
            "min": [x, 0.0, 0.0], "max": [x + 1.0, 1.0, 0.0]}));
        let mut attributes = json!({"POSITION": accessors.len() - 1});
        if let Some(color) = color {
            let view = add_view(&mut bin, &color.bytes);
            accessors.push(json!({"bufferView": view, "componentType": color.component, "count": color.count,
                "type": color.ty, "normalized": color.normalized}));
            attributes["COLOR_0"] = json!(accessors.len() - 1);
        }
        json_primitives.push(json!({"attributes": attributes}));
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let root = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
        "meshes": [{"primitives": json_primitives}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    });
    let mut json_bytes = serde_json::to_vec(&root).unwrap();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let mut glb = Vec::new();
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((12 + 8 + json_bytes.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json_bytes);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    glb
}

fn import_colors(primitives: &[Option<ColorAttribute>]) -> Result<(Vec<[f32; 4]>, Vec<String>), String> {
    import_gltf_slice(&triangle_glb(primitives), None, "colors.glb")
        .map(|scene| (scene.meshes[0].colors.clone(), scene.warnings))
        .map_err(|error| error.to_string())
}

#[test]
fn color_0_is_imported_as_linear_rgba() {
    let float4 = ColorAttribute {
        ty: "VEC4",
        component: 5126,
        normalized: false,
        count: 3,
        bytes: f32_bytes(&[0.1, 0.2, 0.3, 0.4, 1.0, 0.0, 0.5, 1.0, 0.25, 0.75, 0.125, 0.0]),
    };
    let (colors, warnings) = import_colors(&[Some(float4)]).unwrap();
    assert_eq!(colors, vec![[0.1, 0.2, 0.3, 0.4], [1.0, 0.0, 0.5, 1.0], [0.25, 0.75, 0.125, 0.0]]);
    assert!(warnings.is_empty(), "{warnings:?}");

    let float3 = ColorAttribute {
        ty: "VEC3",
        component: 5126,
        normalized: false,
        count: 3,
        bytes: f32_bytes(&[0.1, 0.2, 0.3, 1.0, 0.0, 0.5, 0.25, 0.75, 0.125]),
    };
    let (colors, _) = import_colors(&[Some(float3)]).unwrap();
    assert_eq!(colors, vec![[0.1, 0.2, 0.3, 1.0], [1.0, 0.0, 0.5, 1.0], [0.25, 0.75, 0.125, 1.0]]);

    // Normalized integers: c / 255 and c / 65535 (glTF 2.0, 3.11), still linear.
    let u8x4 = ColorAttribute {
        ty: "VEC4",
        component: 5121,
        normalized: true,
        count: 3,
        bytes: vec![0, 255, 51, 128, 255, 0, 0, 255, 1, 2, 3, 4],
    };
    let (colors, _) = import_colors(&[Some(u8x4)]).unwrap();
    assert_eq!(colors[0], [0.0, 1.0, 51.0 / 255.0, 128.0 / 255.0]);
    assert_eq!(colors[1], [1.0, 0.0, 0.0, 1.0]);
    assert_eq!(colors[2], [1.0 / 255.0, 2.0 / 255.0, 3.0 / 255.0, 4.0 / 255.0]);

    let u16x3: Vec<u8> = [0u16, 65535, 13107, 65535, 0, 1, 32768, 2, 3].iter().flat_map(|v| v.to_le_bytes()).collect();
    let u16x3 = ColorAttribute { ty: "VEC3", component: 5123, normalized: true, count: 3, bytes: u16x3 };
    let (colors, _) = import_colors(&[Some(u16x3)]).unwrap();
    assert_eq!(colors[0], [0.0, 1.0, 0.2, 1.0]);
    assert_eq!(colors[1], [1.0, 0.0, 1.0 / 65535.0, 1.0]);
    assert_eq!(colors[2], [32768.0 / 65535.0, 2.0 / 65535.0, 3.0 / 65535.0, 1.0]);

    // No COLOR_0 anywhere: empty. Only on the second primitive: the first's vertices are white.
    assert_eq!(import_colors(&[None, None]).unwrap().0, Vec::<[f32; 4]>::new());
    let second = ColorAttribute {
        ty: "VEC3",
        component: 5121,
        normalized: true,
        count: 3,
        bytes: vec![0, 0, 0, 255, 0, 0, 0, 255, 0],
    };
    let (colors, _) = import_colors(&[None, Some(second), None]).unwrap();
    assert_eq!(colors.len(), 9);
    assert_eq!(&colors[0..3], &[[1.0; 4]; 3]);
    assert_eq!(&colors[3..6], &[[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0]]);
    assert_eq!(&colors[6..9], &[[1.0; 4]; 3]);

    // Non-finite colours become white and out-of-range ones are clamped, with warnings.
    let odd = ColorAttribute {
        ty: "VEC4",
        component: 5126,
        normalized: false,
        count: 3,
        bytes: f32_bytes(&[f32::NAN, 0.0, 0.0, 1.0, 1.5, -0.5, 0.5, 1.0, 0.5, 0.5, 0.5, 0.5]),
    };
    let (colors, warnings) = import_colors(&[Some(odd)]).unwrap();
    assert_eq!(colors, vec![[1.0; 4], [1.0, 0.0, 0.5, 1.0], [0.5; 4]]);
    assert!(warnings.iter().any(|w| w.contains("non-finite vertex colour")), "{warnings:?}");
    assert!(warnings.iter().any(|w| w.contains("clamped")), "{warnings:?}");
}

#[test]
fn bad_color_0_accessors_are_refused() {
    let cases = [
        // (type, componentType, normalized, count, bytes, expected message part)
        ("VEC4", 5121, false, 3, vec![0u8; 12], "wrong accessor type"),
        ("VEC3", 5120, true, 3, vec![0u8; 12], "wrong accessor type"),
        ("VEC4", 5125, true, 3, vec![0u8; 48], "wrong accessor type"),
        ("VEC2", 5126, false, 3, vec![0u8; 24], "expected VEC3 or VEC4"),
        ("SCALAR", 5126, false, 3, vec![0u8; 12], "expected VEC3 or VEC4"),
        ("VEC4", 5126, false, 2, vec![0u8; 32], "COLOR_0 has 2 elements"),
        ("VEC4", 5126, false, 3, vec![0u8; 40], "out of bounds"),
    ];
    for (ty, component, normalized, count, bytes, message) in cases {
        let attribute = ColorAttribute { ty, component, normalized, count, bytes };
        let error = import_colors(&[Some(attribute)]).unwrap_err();
        assert!(error.contains(message) && error.contains("colors.glb"), "{ty} {component}: {error}");
        if message == "wrong accessor type" || message == "out of bounds" {
            assert!(error.contains("COLOR_0"), "{error}");
        }
    }
}

#[test]
fn exported_glb_reopens_in_meshpaint_with_the_sample_colours_at_its_vertices() {
    use meshpaint_core::colors::layout::Resolution;
    use meshpaint_core::io::document::Document;
    let source = Document::open(&model("Duck/Duck.glb"), Resolution::new(4).unwrap()).unwrap();
    let tessellation = meshpaint_core::io::export_gltf::tessellate(&source.positions, &source.store).unwrap();
    let path = std::env::temp_dir().join(format!("meshpaint-reopen-{}.glb", std::process::id()));
    meshpaint_core::io::export_gltf::write_tessellated_glb(&path, &source.positions, &source.store).unwrap();
    let reopened = Document::open(&path, Resolution::ONE).unwrap();
    std::fs::remove_file(&path).ok();
    // The exporter writes one vertex per sample; welding keeps them apart (distinct positions).
    assert_eq!(reopened.positions.len(), tessellation.positions.len());
    let color_at: std::collections::HashMap<[u32; 3], [f32; 4]> =
        tessellation.positions.iter().zip(&tessellation.colors).map(|(p, c)| (p.map(f32::to_bits), *c)).collect();
    for (v, p) in reopened.positions.iter().enumerate() {
        let expected = color_at[&p.map(f32::to_bits)];
        assert_eq!(reopened.store.vertex_color(v as u32), Some(expected), "vertex {v}");
    }
    // Sampling the reopened mesh at R = 1 with the linear filter is what the source shows.
    assert_eq!(reopened.store.topology().face_count() as usize, tessellation.triangles.len());
}

/// Seams, independently of the sampler: for every exported triangle edge, every exported
/// vertex lying on it (a T-junction) must carry the colour the edge shows there — the
/// linear interpolation of the edge's endpoint colours. The seamless export has no such
/// vertex at all (no T-junctions); colours are checked for any that would exist.
#[test]
fn exported_triangle_edges_have_no_t_junctions_and_show_their_endpoint_interpolation() {
    use meshpaint_core::io::export_gltf::tessellate;
    let fins = {
        let topology =
            meshpaint_core::mesh::topology::Topology::build(6, &[[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]]).unwrap();
        let positions =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 0.0, 1.0], [1.5, 1.0, 0.0]];
        let mut store = ColorStore::with_resolutions(topology, [2, 32, 8, 1].map(r).to_vec(), [0.0; 4]).unwrap();
        let mut rng = SplitMix64(31);
        store.write_all(|_| rng.color());
        Painted { name: "fins".into(), positions, store }
    };
    for case in [mixed_grid(41), mixed_box(42), fins] {
        let t = tessellate(&case.positions, &case.store).unwrap();
        let p = |v: u32| glam::DVec3::from_array(t.positions[v as usize].map(f64::from));
        // Spatial hash of the vertices (cells of 1/64 of the bounding box).
        let (mut lo, mut hi) = (glam::DVec3::splat(f64::INFINITY), glam::DVec3::splat(f64::NEG_INFINITY));
        for v in 0..t.positions.len() as u32 {
            lo = lo.min(p(v));
            hi = hi.max(p(v));
        }
        let cell = ((hi - lo).max_element() / 64.0).max(1e-9);
        let key = |q: glam::DVec3| ((q - lo) / cell).floor().as_ivec3();
        let mut grid: HashMap<glam::IVec3, Vec<u32>> = HashMap::new();
        for v in 0..t.positions.len() as u32 {
            grid.entry(key(p(v))).or_default().push(v);
        }
        let mut edges = BTreeSet::new();
        for tri in &t.triangles {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        let (mut on_edges, mut worst) = (0usize, 0.0f64);
        for &(a, b) in &edges {
            let (pa, pb) = (p(a), p(b));
            let (k0, k1) = (key(pa.min(pb)), key(pa.max(pb)));
            let length2 = (pb - pa).length_squared();
            for x in k0.x..=k1.x {
                for y in k0.y..=k1.y {
                    for z in k0.z..=k1.z {
                        for &v in grid.get(&glam::IVec3::new(x, y, z)).map_or(&[][..], Vec::as_slice) {
                            if v == a || v == b {
                                continue;
                            }
                            let s = (p(v) - pa).dot(pb - pa) / length2;
                            let off = (pa + (pb - pa) * s - p(v)).length_squared();
                            if s <= 1e-9 || s >= 1.0 - 1e-9 || off > 1e-12 * length2 {
                                continue;
                            }
                            on_edges += 1;
                            for c in 0..4 {
                                let (ca, cb) = (f64::from(t.colors[a as usize][c]), f64::from(t.colors[b as usize][c]));
                                let want = ca + (cb - ca) * s;
                                worst = worst.max((f64::from(t.colors[v as usize][c]) - want).abs());
                            }
                        }
                    }
                }
            }
        }
        println!(
            "{}: {} triangle edges, {on_edges} vertices on them, worst colour difference {worst:.3e}",
            case.name,
            edges.len()
        );
        assert!(worst <= 1e-6, "{}: a vertex on an edge shows another colour ({worst})", case.name);
        assert_eq!(on_edges, 0, "{}: T-junctions", case.name);
    }
}

/// The tessellated export carries smooth normals (viewers would shade it faceted without):
/// every NORMAL is unit length; at the mesh's own vertices it is the welded vertex's
/// area-weighted normal (`mesh::normals::vertex_normals`, computed here from the document);
/// inside faces it varies (the normals of a sub-triangle's corners differ on a curved
/// surface), and it points out of the surface the way the face does.
#[test]
fn the_tessellated_export_has_smooth_unit_normals() {
    let document = Document::open(&model("Duck/Duck.glb"), r(4)).unwrap();
    let bytes = export_tessellated_glb(&document.positions, &document.store).unwrap();
    let (gltf, buffers, _) = gltf::import_slice(&bytes).unwrap();
    let primitive = gltf.meshes().next().unwrap().primitives().next().unwrap();
    let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(|b| &b.0[..]));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let normals: Vec<[f32; 3]> = reader.read_normals().expect("no NORMAL").collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    assert_eq!(normals.len(), positions.len());
    let length = |n: &[f32; 3]| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    assert!(normals.iter().all(|n| (length(n) - 1.0).abs() < 1e-5), "a normal is not unit length");
    let expected =
        meshpaint_core::mesh::normals::vertex_normals(&document.positions, &document.store.topology().face_vertices);
    let vertex_of: HashMap<[u32; 3], usize> =
        document.positions.iter().enumerate().map(|(v, p)| (p.map(f32::to_bits), v)).collect();
    let mut at_vertices = 0;
    for (p, n) in positions.iter().zip(&normals) {
        if let Some(&v) = vertex_of.get(&p.map(f32::to_bits)) {
            let e = expected[v];
            assert!((0..3).all(|a| (f64::from(n[a]) - e[a]).abs() < 1e-5), "vertex {v}: {n:?} vs {e:?}");
            at_vertices += 1;
        }
    }
    assert_eq!(at_vertices, document.positions.len());
    let (mut varying, mut outward) = (0usize, 0usize);
    let triangles = indices.chunks_exact(3).collect::<Vec<_>>();
    for t in &triangles {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| glam::Vec3::from(positions[i as usize]));
        let face = (b - a).cross(c - a).normalize_or_zero();
        let n = [t[0], t[1], t[2]].map(|i| glam::Vec3::from(normals[i as usize]));
        varying += usize::from(n[0].dot(n[1]).min(n[1].dot(n[2])) < 0.99999);
        outward += usize::from(n.iter().all(|n| n.dot(face) > 0.0));
    }
    eprintln!("{} of {} triangles with varying normals, {} facing with them", varying, triangles.len(), outward);
    assert!(varying * 2 > triangles.len(), "normals hardly vary: faceted");
    assert!(outward * 100 >= triangles.len() * 99, "normals against the faces");
}
