//! Welding and topology against brute force and closed-form counts, including the
//! numerical and topological extremes.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};

use glam::{Mat4, Vec3};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::stats::MeshStats;
use meshpaint_core::mesh::scene::{Instance, Scene, SourceMesh};
use meshpaint_core::mesh::topology::{INVALID, Topology, TopologyError};
use meshpaint_core::mesh::weld::{WeldedMesh, weld_scene};

/// Brute force: edges as a map from sorted vertex pair to incident face count.
fn brute_force_edges(triangles: &[[u32; 3]]) -> BTreeMap<(u32, u32), usize> {
    let mut edges = BTreeMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    edges
}

fn assert_matches_brute_force(vertex_count: u32, triangles: &[[u32; 3]]) -> Topology {
    let topology = Topology::build(vertex_count, triangles).unwrap();
    topology.validate().unwrap();
    let edges = brute_force_edges(triangles);
    assert_eq!(topology.edge_count() as usize, edges.len());
    let boundary = edges.values().filter(|&&n| n == 1).count();
    let nonmanifold = edges.values().filter(|&&n| n >= 3).count();
    assert_eq!(topology.boundary_edge_count() as usize, boundary);
    assert_eq!(topology.nonmanifold_edge_count() as usize, nonmanifold);
    for v in 0..vertex_count {
        let valence = edges.keys().filter(|(a, b)| *a == v || *b == v).count();
        assert_eq!(topology.vertex_valence[v as usize] as usize, valence, "vertex {v}");
    }
    for (e, pair) in topology.edge_vertices.iter().enumerate() {
        assert_eq!(topology.faces_of_edge(e as u32).len(), edges[&(pair[0], pair[1])]);
    }
    topology
}

fn cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let positions = (0..8).map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]).collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    (positions, triangles)
}

#[test]
fn closed_cube_has_euler_characteristic_two_and_no_boundary() {
    let (positions, triangles) = cube();
    let topology = assert_matches_brute_force(positions.len() as u32, &triangles);
    let (v, e, f) = (topology.vertex_count as i64, topology.edge_count() as i64, topology.face_count() as i64);
    assert_eq!((v, e, f), (8, 18, 12));
    assert_eq!(v - e + f, 2);
    assert_eq!(topology.boundary_edge_count(), 0);
    // Each interior edge is walked once in each direction by its two faces.
    for edge in 0..topology.edge_count() {
        let faces = topology.faces_of_edge(edge);
        let reversed: Vec<bool> = faces.iter().map(|&(f, k)| topology.is_reversed(f, usize::from(k))).collect();
        assert_eq!(reversed.iter().filter(|&&r| r).count(), 1, "edge {edge}");
    }
}

#[test]
fn single_triangle_has_three_boundary_edges() {
    let topology = assert_matches_brute_force(3, &[[2, 0, 1]]);
    assert_eq!(topology.boundary_edge_count(), 3);
    assert_eq!(topology.edge_vertices, vec![[0, 1], [0, 2], [1, 2]]);
    // Face edge 0 runs 2 → 0: against the canonical 0 → 2 direction.
    assert!(topology.is_reversed(0, 0));
    assert!(!topology.is_reversed(0, 1));
    assert!(!topology.is_reversed(0, 2)); // 1 → 2 is canonical
}

#[test]
fn non_manifold_edge_is_shared_by_all_its_faces() {
    // Three fins around edge (0, 1), and a fourth face elsewhere.
    let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 4, 3]];
    let topology = assert_matches_brute_force(5, &triangles);
    assert_eq!(topology.nonmanifold_edge_count(), 1);
    let edge = topology.face_edges[0][0];
    assert_eq!(topology.edge_vertices[edge as usize], [0, 1]);
    let faces: Vec<u32> = topology.faces_of_edge(edge).iter().map(|&(f, _)| f).collect();
    assert_eq!(faces, vec![0, 1, 2]);
}

#[test]
fn high_valence_fan_vertex() {
    // A closed fan of 200 triangles around vertex 0 (valence 200, ≥ 64 required).
    let n = 200u32;
    let triangles: Vec<[u32; 3]> = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
    let topology = assert_matches_brute_force(n + 1, &triangles);
    assert_eq!(topology.vertex_valence[0], n);
    assert_eq!(topology.boundary_edge_count(), n);
    assert_eq!(topology.edge_count(), 2 * n);
}

#[test]
fn random_soups_match_brute_force() {
    let mut state = 7u64;
    let mut next = move |bound: u32| {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
        ((state >> 33) % u64::from(bound)) as u32
    };
    for round in 0..50 {
        let vertex_count = 3 + round;
        let mut triangles = Vec::new();
        while triangles.len() < (round as usize * 3 + 1) {
            let t = [next(vertex_count), next(vertex_count), next(vertex_count)];
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                triangles.push(t);
            }
        }
        assert_matches_brute_force(vertex_count, &triangles);
    }
}

#[test]
fn empty_mesh_is_valid_and_has_no_samples() {
    let topology = Topology::build(0, &[]).unwrap();
    topology.validate().unwrap();
    let stats = MeshStats::new(&topology, 0, Resolution::new(8).unwrap());
    assert_eq!((stats.triangles, stats.edges, stats.samples, stats.samples_with_mips), (0, 0, 0, 0));
    let welded = weld_scene(&Scene::default());
    assert!(welded.triangles.is_empty() && welded.positions_world.is_empty());
}

#[test]
fn bad_faces_are_refused_not_trusted() {
    assert!(matches!(Topology::build(3, &[[0, 1, 3]]), Err(TopologyError::VertexOutOfRange { vertex: 3, .. })));
    assert!(matches!(Topology::build(3, &[[0, 1, 1]]), Err(TopologyError::DegenerateFace { .. })));
    assert!(WeldedMesh::from_triangles(vec![[0.0; 3]; 2], vec![[0, 1, 2]]).is_err());
    assert_eq!(INVALID, u32::MAX);
}

fn mesh(positions: Vec<[f32; 3]>, uvs: Vec<[f32; 2]>, triangles: Vec<[u32; 3]>) -> SourceMesh {
    let n = positions.len();
    SourceMesh {
        name: "test".into(),
        positions_local: positions,
        normals_local: vec![[0.0, 0.0, 1.0]; n],
        uvs,
        colors: Vec::new(),
        triangle_materials: vec![None; triangles.len()],
        triangles,
    }
}

fn scene_of(meshes: Vec<SourceMesh>, instances: Vec<(u32, Mat4)>) -> Scene {
    Scene {
        meshes,
        instances: instances.into_iter().map(|(mesh, world_from_local)| Instance { mesh, world_from_local }).collect(),
        ..Scene::default()
    }
}

/// A cube with 24 glTF vertices (4 per side, own UVs) like BoxTextured.
fn split_cube() -> SourceMesh {
    let (positions, triangles) = cube();
    let mut split_positions = Vec::new();
    let mut uvs = Vec::new();
    let mut split_triangles = Vec::new();
    for t in triangles {
        let base = split_positions.len() as u32;
        for (k, &c) in t.iter().enumerate() {
            split_positions.push(positions[c as usize]);
            uvs.push([k as f32, 0.5]);
        }
        split_triangles.push([base, base + 1, base + 2]);
    }
    mesh(split_positions, uvs, split_triangles)
}

#[test]
fn welding_merges_uv_seams_and_keeps_each_faces_uvs() {
    let scene = scene_of(vec![split_cube()], vec![(0, Mat4::IDENTITY)]);
    let welded = weld_scene(&scene);
    assert_eq!(welded.positions_world.len(), 8);
    assert_eq!(welded.triangles.len(), 12);
    assert_eq!(welded.corner_uvs[3], [[0.0, 0.5], [1.0, 0.5], [2.0, 0.5]]);
    let topology = assert_matches_brute_force(8, &welded.triangles);
    assert_eq!(topology.edge_count(), 18);
}

#[test]
fn each_instance_is_its_own_copy_in_world_space() {
    let far = Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0));
    let scene = scene_of(vec![split_cube()], vec![(0, Mat4::IDENTITY), (0, far)]);
    let welded = weld_scene(&scene);
    assert_eq!(welded.positions_world.len(), 16);
    assert_eq!(welded.triangles.len(), 24);
    let topology = assert_matches_brute_force(16, &welded.triangles);
    assert_eq!(topology.edge_count(), 36);
    let max_x = welded.positions_world.iter().map(|p| p[0]).fold(f32::MIN, f32::max);
    assert_eq!(max_x, 11.0);
}

#[test]
fn repeated_welded_corners_are_dropped_and_counted_but_zero_area_is_kept() {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0], // same position as vertex 0: welds onto it
        [2.0, 0.0, 0.0], // collinear with 0 and 1: zero area, distinct indices
        [0.0, 1.0, 0.0],
        [-0.0, 1.0, 0.0], // bitwise different from vertex 4: stays apart
    ];
    let triangles = vec![[0, 1, 2], [0, 1, 3], [0, 1, 4], [1, 5, 4], [2, 2, 2]];
    let scene = scene_of(vec![mesh(positions, vec![[0.0; 2]; 6], triangles)], vec![(0, Mat4::IDENTITY)]);
    let welded = weld_scene(&scene);
    assert_eq!(welded.degenerate_triangles_dropped, 2);
    assert_eq!(welded.triangles.len(), 3);
    assert_eq!(welded.positions_world.len(), 5);
    let topology = assert_matches_brute_force(5, &welded.triangles);
    let stats = MeshStats::new(&topology, welded.degenerate_triangles_dropped, Resolution::new(4).unwrap());
    assert_eq!(stats.degenerate_triangles_dropped, 2);
    // Samples: V + E(R−1) + F(R−1)(R−2)/2 with R = 4.
    assert_eq!(stats.samples, 5 + stats.edges * 3 + 3 * 3);
}

#[test]
fn slivers_huge_offsets_and_tiny_scales_weld_exactly() {
    // Positions 1e6 away, scaled by 1e-4, and a sliver one ulp wide: welding is bitwise,
    // so it neither merges close vertices nor splits equal ones.
    let offset = 1.0e6f32;
    let one_ulp = f32::from_bits(offset.to_bits() + 1);
    let positions = vec![
        [offset, offset, offset],
        [offset + 1.0, offset, offset],
        [one_ulp, offset, offset], // sliver corner, distinct from vertex 0
        [offset, offset, offset],  // duplicate of vertex 0
        [offset, offset + 1.0, offset],
    ];
    let triangles = vec![[0, 1, 2], [3, 1, 4]];
    let transform = Mat4::from_scale(Vec3::splat(1e-4));
    let scene = scene_of(vec![mesh(positions, vec![[0.0; 2]; 5], triangles)], vec![(0, transform)]);
    let welded = weld_scene(&scene);
    assert_eq!(welded.positions_world.len(), 4);
    assert_eq!(welded.degenerate_triangles_dropped, 0);
    assert!(welded.positions_world.iter().flatten().all(|x| x.is_finite()));
    let topology = assert_matches_brute_force(4, &welded.triangles);
    assert_eq!(topology.edge_count(), 5);
    let unique: BTreeSet<[u32; 3]> = welded.positions_world.iter().map(|p| p.map(f32::to_bits)).collect();
    assert!(unique.len() >= 3);
}

#[test]
fn stats_at_resolution_extremes() {
    let (positions, triangles) = cube();
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let one = MeshStats::new(&topology, 0, Resolution::ONE);
    assert_eq!((one.samples, one.samples_with_mips), (8, 8));
    let max = MeshStats::new(&topology, 0, Resolution::MAX);
    let r = 4096u64;
    assert_eq!(max.samples, 8 + 18 * (r - 1) + 12 * (r - 1) * (r - 2) / 2);
    // Every level k has R_k = R >> k: sum the closed form per level.
    let with_mips: u64 = (0..=12)
        .map(|k| {
            let rk = r >> k;
            8 + 18 * (rk - 1) + 12 * (rk - 1) * rk.saturating_sub(2) / 2
        })
        .sum();
    assert_eq!(max.samples_with_mips, with_mips);
}

/// Area of a welded mesh, summed in f64.
fn welded_area(mesh: &WeldedMesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| Vec3::from_array(mesh.positions_world[i as usize]).as_dvec3());
            0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
        })
        .sum()
}

#[test]
fn midpoint_subdivision_has_the_closed_form_counts_and_the_same_surface() {
    use meshpaint_core::colors::budget::{Budget, MemorySource};
    use meshpaint_core::convert::subdivide::subdivide_scene;
    let (scene, _) = meshpaint_core::io::document::import_scene(&common::model("Duck/Duck.glb")).unwrap();
    let before = weld_scene(&scene);
    let t0 = Topology::build(before.positions_world.len() as u32, &before.triangles).unwrap();
    let budget = Budget::with_memory(8 << 30, MemorySource::Environment);
    for levels in 1..=2u32 {
        let after = weld_scene(&subdivide_scene(&scene, levels, &budget).unwrap());
        let t1 = Topology::build(after.positions_world.len() as u32, &after.triangles).unwrap();
        t1.validate().unwrap();
        // Closed forms of `levels` 1→4 splits: F' = 4^n F, E' = 2^n E + 3 (4^n − 1)/3 · F … checked
        // one level at a time below, by brute force over the edges.
        let (mut v, mut e, mut f) = (t0.vertex_count as u64, t0.edge_count() as u64, t0.face_count() as u64);
        let mut boundary = t0.boundary_edge_count() as u64;
        for _ in 0..levels {
            (v, e, f) = (v + e, 2 * e + 3 * f, 4 * f);
            boundary *= 2;
        }
        assert_eq!(after.triangles.len() as u64, f);
        assert_eq!(after.positions_world.len() as u64, v, "one new vertex per edge");
        assert_eq!(brute_force_edges(&after.triangles).len() as u64, e);
        assert_eq!(t1.boundary_edge_count() as u64, boundary);
        assert_eq!(t1.nonmanifold_edge_count(), t0.nonmanifold_edge_count());
        let (a0, a1) = (welded_area(&before), welded_area(&after));
        assert!((a1 - a0).abs() <= 1e-5 * a0, "area {a0} → {a1}");
    }
    // The budget is checked on the count before anything is built.
    let tiny = Budget::with_memory(600 * 4 * scene.instanced_triangle_count() as u64, MemorySource::Environment);
    assert!(subdivide_scene(&scene, 1, &tiny).is_ok());
    let refusal = subdivide_scene(&scene, 2, &tiny).unwrap_err().to_string();
    assert!(refusal.contains("subdivided") && refusal.contains("triangles"), "{refusal}");
    assert!(subdivide_scene(&scene, 40, &budget).is_err(), "4^40 triangles overflow to a refusal");
}
