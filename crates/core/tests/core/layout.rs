//! Mesh-colors layout math against independent truths: brute-force enumeration of
//! lattices, geometric sample positions, summed level sizes, and the thesis' formulas
//! evaluated literally.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use std::collections::HashMap;

use meshpaint_core::colors::layout::*;
use meshpaint_core::mesh::topology::Topology;

fn all_resolutions() -> impl Iterator<Item = Resolution> {
    (0..=MAX_LOG2_RESOLUTION).map(|k| Resolution::from_log2(k).unwrap())
}

#[test]
fn resolution_accepts_powers_of_two_up_to_the_limit_and_refuses_the_rest() {
    for k in 0..=MAX_LOG2_RESOLUTION {
        let r = Resolution::new(1 << k).unwrap();
        assert_eq!((r.get(), r.log2(), r.level_count()), (1 << k, k, k + 1));
    }
    assert_eq!(Resolution::new(0), Err(LayoutError::NotPowerOfTwo(0)));
    assert_eq!(Resolution::new(3), Err(LayoutError::NotPowerOfTwo(3)));
    assert_eq!(Resolution::new(u64::MAX), Err(LayoutError::NotPowerOfTwo(u64::MAX)));
    assert_eq!(Resolution::new(8192), Err(LayoutError::TooLarge(8192)));
    assert_eq!(Resolution::new(1 << 63), Err(LayoutError::TooLarge(1 << 63)));
    assert!(Resolution::from_log2(MAX_LOG2_RESOLUTION + 1).is_err());
    assert_eq!(Resolution::MAX.get(), MAX_RESOLUTION);
    assert_eq!(Resolution::MAX.doubled(), None);
    assert_eq!(Resolution::ONE.halved(), None);
}

#[test]
fn per_element_counts_match_a_brute_force_lattice_walk() {
    for r in all_resolutions().take(11) {
        let res = r.get();
        let (mut corners, mut on_edges, mut interior) = (0u64, 0u64, 0u64);
        for i in 0..=res {
            for j in 0..=res - i {
                let on_boundary = [i == 0, j == 0, i + j == res].iter().filter(|&&b| b).count();
                match on_boundary {
                    0 => interior += 1,
                    1 => on_edges += 1,
                    _ => corners += 1,
                }
            }
        }
        assert_eq!(corners, 3 * u64::from(vertex_sample_count()), "R = {res}");
        assert_eq!(on_edges, 3 * u64::from(edge_sample_count(r)), "R = {res}");
        assert_eq!(interior, u64::from(interior_sample_count(r)), "R = {res}");
        assert_eq!(corners + on_edges + interior, u64::from(face_lattice_sample_count(r)));
    }
}

/// Marks every storage slot of one face reached by classifying its whole lattice and
/// checks that each slot is reached exactly once.
fn assert_face_lattice_reaches_every_slot_once(r: Resolution, reversed: [bool; 3]) {
    let res = r.get();
    let edge_len = edge_sample_count(r) as usize;
    let mut vertex_hits = [0u8; 3];
    let mut edge_hits = vec![vec![0u8; edge_len]; 3];
    let mut interior_hits = vec![0u8; interior_sample_count(r) as usize];
    for i in 0..=res {
        for j in 0..=res - i {
            match classify_sample(r, i, j, reversed).unwrap() {
                SampleLocation::Vertex { corner } => vertex_hits[usize::from(corner)] += 1,
                SampleLocation::Edge { face_edge, offset } => edge_hits[usize::from(face_edge)][offset as usize] += 1,
                SampleLocation::Interior { offset } => {
                    assert_eq!(interior_sample_at(r, offset), Some((i, j)));
                    interior_hits[offset as usize] += 1
                }
            }
        }
    }
    assert_eq!(vertex_hits, [1, 1, 1], "R = {res}");
    for hits in edge_hits.iter().chain(std::iter::once(&interior_hits)) {
        assert!(hits.iter().all(|&h| h == 1), "R = {res} reversed {reversed:?}");
    }
    assert_eq!(classify_sample(r, res + 1, 0, reversed), None);
    assert_eq!(classify_sample(r, res, 1, reversed), None);
}

#[test]
fn every_sample_of_a_face_is_reached_exactly_once_for_every_resolution() {
    for r in all_resolutions() {
        let orientations: &[[bool; 3]] = if r.get() <= 256 {
            &[
                [false, false, false],
                [true, false, false],
                [false, true, false],
                [false, false, true],
                [true, true, false],
                [true, false, true],
                [false, true, true],
                [true, true, true],
            ]
        } else {
            &[[false, true, false]]
        };
        for &reversed in orientations {
            assert_face_lattice_reaches_every_slot_once(r, reversed);
        }
    }
}

#[test]
fn interior_offset_is_the_thesis_equation_3_2() {
    for r in all_resolutions().take(9) {
        let res = i64::from(r.get());
        for i in 1..res - 1 {
            for j in 1..res - i {
                // Eq. 3.2 summed literally: Σ_{k=1}^{i-1} (R - (k + 1)) + (j - 1).
                let summed: i64 = (1..i).map(|k| res - (k + 1)).sum::<i64>() + (j - 1);
                let closed = (2 * res - 2 - i) * (i - 1) / 2 + (j - 1);
                assert_eq!(summed, closed);
                assert_eq!(i64::from(interior_offset(r, i as u32, j as u32)), summed);
            }
        }
    }
}

/// A closed octahedron with faces in both orientations relative to edge directions, and
/// a vertex numbering that makes some face edges run against the canonical direction.
fn octahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let positions =
        vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let triangles = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    (positions, triangles)
}

/// Global id of a face-local sample in a uniform-resolution layout:
/// vertices, then edges (R-1 each), then interiors.
fn global_id(topology: &Topology, r: Resolution, face: u32, i: u32, j: u32) -> u64 {
    let (v, e) = (u64::from(topology.vertex_count), u64::from(topology.edge_count()));
    let edge_len = u64::from(edge_sample_count(r));
    match classify_sample(r, i, j, topology.reversed(face)).unwrap() {
        SampleLocation::Vertex { corner } => u64::from(topology.face_vertices[face as usize][usize::from(corner)]),
        SampleLocation::Edge { face_edge, offset } => {
            let edge = topology.face_edges[face as usize][usize::from(face_edge)];
            v + u64::from(edge) * edge_len + u64::from(offset)
        }
        SampleLocation::Interior { offset } => {
            v + e * edge_len + u64::from(face) * u64::from(interior_sample_count(r)) + u64::from(offset)
        }
    }
}

#[test]
fn shared_samples_get_one_id_and_one_position_from_every_face() {
    let (positions, triangles) = octahedron();
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    topology.validate().unwrap();
    for r in all_resolutions().take(8) {
        let res = r.get();
        let mut position_of_id: HashMap<u64, [f64; 3]> = HashMap::new();
        for face in 0..topology.face_count() {
            let corners = triangles[face as usize].map(|c| positions[c as usize]);
            let mut ids_of_face = std::collections::HashSet::new();
            for i in 0..=res {
                for j in 0..=res - i {
                    let id = global_id(&topology, r, face, i, j);
                    assert!(ids_of_face.insert(id), "face {face} reaches id {id} twice");
                    let w = sample_barycentric(r, i, j);
                    let p: [f64; 3] =
                        std::array::from_fn(|a| w[0] * corners[0][a] + w[1] * corners[1][a] + w[2] * corners[2][a]);
                    if let Some(previous) = position_of_id.insert(id, p) {
                        for a in 0..3 {
                            assert!((previous[a] - p[a]).abs() < 1e-12, "id {id} moves between faces at R = {res}");
                        }
                    }
                }
            }
        }
        // The union of all faces' samples is exactly 0..samples (closed form).
        let counts = uniform_counts(
            r,
            u64::from(topology.vertex_count),
            u64::from(topology.edge_count()),
            u64::from(topology.face_count()),
        );
        let ids: std::collections::BTreeSet<u64> = position_of_id.keys().copied().collect();
        assert_eq!(ids.len() as u64, counts.samples, "R = {res}");
        assert_eq!(ids.first().copied(), Some(0));
        assert_eq!(ids.last().copied(), Some(counts.samples - 1));
        // V + E(R−1) + F(R−1)(R−2)/2, with R as a plain integer.
        let n = u64::from(res);
        assert_eq!(counts.samples, 6 + 12 * (n - 1) + 8 * (n - 1) * n.saturating_sub(2) / 2);
    }
}

#[test]
fn a_shared_edge_at_the_largest_resolution_yields_the_same_ids_from_both_faces() {
    // Two faces sharing edge (0, 1), walking it in opposite directions.
    let triangles = [[0, 1, 2], [1, 0, 3]];
    let topology = Topology::build(4, &triangles).unwrap();
    let r = Resolution::MAX;
    let res = r.get();
    for position in 1..res {
        let (i0, j0) = edge_sample_coords(r, 0, position); // face 0: 0 → 1
        let (i1, j1) = edge_sample_coords(r, 0, res - position); // face 1: 1 → 0
        assert_eq!(global_id(&topology, r, 0, i0, j0), global_id(&topology, r, 1, i1, j1), "position {position}");
    }
}

#[test]
fn mip_offsets_equal_summed_level_sizes_and_the_thesis_closed_forms() {
    for r in all_resolutions() {
        let m = r.log2();
        let (mut edge_sum, mut interior_sum) = (0u64, 0u64);
        for level in 0..=m {
            let at = r.at_level(level).unwrap();
            assert_eq!(at.get(), r.get() >> level);
            assert_eq!(u64::from(edge_level_offset(r, level).unwrap()), edge_sum);
            assert_eq!(u64::from(interior_level_offset(r, level).unwrap()), interior_sum);
            // Thesis eq. 3.4a: 2^(m+1) − 2^(m−mip+1) − mip.
            let thesis_edge = (1i64 << (m + 1)) - (1i64 << (m - level + 1)) - i64::from(level);
            assert_eq!(i64::from(edge_level_offset(r, level).unwrap()), thesis_edge);
            // Thesis eq. 3.4b: (2^(2m+1) − 2^(2(m−mip)+1))/3 − 3(2^m − 2^(m−mip)) + mip.
            let thesis_interior = ((1i64 << (2 * m + 1)) - (1i64 << (2 * (m - level) + 1))) / 3
                - 3 * ((1i64 << m) - (1i64 << (m - level)))
                + i64::from(level);
            assert_eq!(i64::from(interior_level_offset(r, level).unwrap()), thesis_interior);
            edge_sum += u64::from(edge_sample_count(at));
            interior_sum += u64::from(interior_sample_count(at));
        }
        assert_eq!(u64::from(edge_chain_len(r)), edge_sum);
        assert_eq!(u64::from(interior_chain_len(r)), interior_sum);
        assert_eq!(vertex_chain_len(r), m + 1);
        assert!(edge_level_offset(r, m + 1).is_err());
        assert!(interior_level_offset(r, m + 1).is_err());
    }
}

fn assert_valid_lookup(r: Resolution, bary: [f32; 3]) -> [WeightedSample; 3] {
    let samples = linear_samples(r, bary);
    let sum: f32 = samples.iter().map(|s| s.weight).sum();
    assert!((sum - 1.0).abs() < 1e-5, "weights sum to {sum} for {bary:?}");
    for s in samples {
        assert!(s.i + s.j <= r.get(), "sample ({}, {}) outside R = {} for {bary:?}", s.i, s.j, r.get());
        assert!((0.0..=1.0).contains(&s.weight));
        assert!(classify_sample(r, s.i, s.j, [false; 3]).is_some());
    }
    samples
}

#[test]
fn exact_vertices_map_to_their_vertex_sample_at_every_resolution() {
    for r in all_resolutions() {
        let res = r.get();
        for (bary, expected) in [([1.0, 0.0, 0.0], (0, 0)), ([0.0, 1.0, 0.0], (res, 0)), ([0.0, 0.0, 1.0], (0, res))] {
            assert_valid_lookup(r, bary);
            assert_eq!(nearest_sample(r, bary), expected, "R = {res}");
            let linear = linear_samples(r, bary);
            let hit = linear.iter().find(|s| (s.i, s.j) == expected).unwrap();
            assert!((hit.weight - 1.0).abs() < 1e-6);
        }
    }
}

#[test]
fn every_lattice_sample_maps_to_itself_with_weight_one() {
    for r in all_resolutions().take(8) {
        let res = r.get();
        for i in 0..=res {
            for j in 0..=res - i {
                let w = sample_barycentric(r, i, j).map(|x| x as f32);
                assert_valid_lookup(r, w);
                assert_eq!(nearest_sample(r, w), (i, j), "R = {res}");
            }
        }
    }
}

#[test]
fn points_on_edges_and_sub_triangle_boundaries_stay_inside_the_lattice() {
    for r in all_resolutions() {
        let res = r.get() as f32;
        let steps = 97u32;
        for step in 0..=steps {
            let t = step as f32 / steps as f32;
            // On each of the three face edges (w = 1 along edge 1 is the classic floor bug).
            for bary in [[1.0 - t, t, 0.0], [0.0, 1.0 - t, t], [t, 0.0, 1.0 - t]] {
                let samples = assert_valid_lookup(r, bary);
                // A point on an edge interpolates only samples of that edge.
                // Weights below f32 rounding of R·b (a few R·ε) are noise, not a leak.
                let noise = 8.0 * res * f32::EPSILON;
                for s in samples.iter().filter(|s| s.weight > noise) {
                    let on_edge = if bary[2] == 0.0 {
                        s.j == 0
                    } else if bary[0] == 0.0 {
                        s.i + s.j == r.get()
                    } else {
                        s.i == 0
                    };
                    assert!(on_edge, "R = {res}, {bary:?} leaves the edge via ({}, {})", s.i, s.j);
                }
            }
            // On sub-triangle diagonals u + v = integer and on lattice lines.
            let u = t * res;
            let k = (u.floor() + 1.0).min(res);
            let v = k - u;
            assert_valid_lookup(r, [1.0 - (u + v) / res, u / res, v / res]);
        }
    }
}

#[test]
fn linear_weights_reproduce_the_point_they_filter() {
    // Linear precision: Σ w_s · P(s) = P for any point inside the face.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for r in all_resolutions() {
        for _ in 0..2000 {
            let (a, b) = (random(), random());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let bary = [1.0 - a - b, a, b];
            let samples = assert_valid_lookup(r, bary);
            let mut p = [0.0f64; 3];
            for s in samples {
                let w = sample_barycentric(r, s.i, s.j);
                for axis in 0..3 {
                    p[axis] += f64::from(s.weight) * w[axis];
                }
            }
            // Tolerance: f32 rounding of R·b, in units of one sample spacing.
            let tolerance = 4.0 * f64::from(f32::EPSILON) * f64::from(r.get()).max(1.0) / f64::from(r.get());
            for axis in 0..3 {
                assert!((p[axis] - f64::from(bary[axis])).abs() < tolerance + 1e-6, "R = {} {bary:?}", r.get());
            }
        }
    }
}

#[test]
fn nearest_is_the_closest_sample_on_an_equilateral_face() {
    // On an equilateral triangle the highest-weight sample is the Euclidean nearest one.
    let embed = |u: f64, v: f64| (u + 0.5 * v, v * 3f64.sqrt() / 2.0);
    let mut state = 12345u64;
    let mut random = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for r in all_resolutions().take(7) {
        let res = r.get();
        for _ in 0..3000 {
            let (a, b) = (random(), random());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let (u, v) = (a * f64::from(res), b * f64::from(res));
            let (x, y) = embed(u, v);
            let mut distances: Vec<(f64, (u32, u32))> = Vec::new();
            for i in 0..=res {
                for j in 0..=res - i {
                    let (sx, sy) = embed(f64::from(i), f64::from(j));
                    distances.push(((sx - x).hypot(sy - y), (i, j)));
                }
            }
            distances.sort_by(|p, q| p.0.total_cmp(&q.0));
            if distances[1].0 - distances[0].0 < 1e-4 {
                continue; // a tie: either answer is right
            }
            let bary = [(1.0 - a - b) as f32, a as f32, b as f32];
            assert_eq!(nearest_sample(r, bary), distances[0].1, "R = {res}, {bary:?}");
        }
    }
}

#[test]
fn hostile_barycentrics_are_sanitised() {
    for r in [Resolution::ONE, Resolution::MAX] {
        for bary in [
            [f32::NAN, 0.5, 0.5],
            [f32::INFINITY, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [-1.0, 2.0, -0.5],
            [-1e-7, 1.0 + 1e-7, 0.0],
            [0.0, 0.5 + 1e-7, 0.5],
            [1e-30, 1e-30, 1e-30],
        ] {
            assert_valid_lookup(r, bary);
        }
    }
}

#[test]
fn resolution_one_has_only_vertex_samples() {
    let r = Resolution::ONE;
    assert_eq!((edge_sample_count(r), interior_sample_count(r), face_lattice_sample_count(r)), (0, 0, 3));
    assert_eq!((edge_chain_len(r), interior_chain_len(r), vertex_chain_len(r)), (0, 0, 1));
    let samples = linear_samples(r, [0.2, 0.3, 0.5]);
    let mut corners: Vec<(u32, u32)> = samples.iter().map(|s| (s.i, s.j)).collect();
    corners.sort();
    assert_eq!(corners, vec![(0, 0), (0, 1), (1, 0)]);
    assert_eq!(nearest_sample(r, [0.2, 0.3, 0.5]), (0, 1));
}
