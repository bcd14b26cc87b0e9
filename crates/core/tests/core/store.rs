//! The editable store against closed forms and exact expectations: per-element sample
//! counts, shared-edge agreement, exact refine/reduce inverses, linear precision,
//! dirty tracking, and the resolution extremes.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use crate::common;
use crate::common::WriteThrough;
use common::{Rng, octahedron};
use meshpaint_core::colors::format::Rgba;
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// Fills every sample with a random colour.
fn randomize(store: &mut ColorStore, seed: u64) {
    let mut rng = Rng(seed);
    store.write_all(|_| rng.color());
}

fn snapshot(store: &ColorStore) -> Vec<(SampleRef, Rgba)> {
    let mut all = Vec::new();
    store.for_each_site(|site| all.push((site.sample, store.get(site.sample).unwrap())));
    all
}

/// Compares two snapshots and reports the first few differences only.
fn assert_same(after: &[(SampleRef, Rgba)], before: &[(SampleRef, Rgba)], what: &str) {
    assert_eq!(after.len(), before.len(), "{what}: sample count");
    let differences: Vec<_> = after.iter().zip(before).filter(|(a, b)| a != b).take(3).collect();
    assert!(differences.is_empty(), "{what}: {differences:?}");
}

fn assert_counts_follow_the_closed_form(store: &ColorStore) {
    let topology = store.topology();
    for face in 0..topology.face_count() {
        let rf = u64::from(store.face_resolution(face).unwrap().get());
        assert_eq!(store.interior_samples(face).len() as u64, (rf - 1) * rf.saturating_sub(2) / 2);
    }
    for edge in 0..topology.edge_count() {
        let max_face =
            topology.faces_of_edge(edge).iter().map(|&(f, _)| store.face_resolution(f).unwrap().get()).max().unwrap();
        assert_eq!(store.edge_resolution(edge).unwrap().get(), max_face);
        assert_eq!(store.edge_samples(edge).len() as u32, max_face - 1);
    }
}

/// Every pair of faces sharing an edge reads the same colour at every lattice position
/// they share (the coarser face's positions).
fn assert_shared_edges_agree(store: &ColorStore) {
    let topology = store.topology();
    for edge in 0..topology.edge_count() {
        let faces = topology.faces_of_edge(edge);
        let [lower, _] = topology.edge_vertices[edge as usize];
        let coarsest = faces.iter().map(|&(f, _)| store.face_resolution(f).unwrap()).min().unwrap();
        for step in 0..=coarsest.get() {
            // `step / coarsest` of the way from the lower vertex: read it from every face.
            let colors: Vec<Rgba> = faces
                .iter()
                .map(|&(face, k)| {
                    let rf = store.face_resolution(face).unwrap();
                    let scale = rf.get() / coarsest.get();
                    let from_start = topology.face_vertices[face as usize][usize::from(k)] == lower;
                    let along = if from_start { step } else { coarsest.get() - step } * scale;
                    let (i, j) = layout::edge_sample_coords(rf, k, along);
                    store.face_sample(face, i, j).unwrap()
                })
                .collect();
            assert!(colors.windows(2).all(|w| w[0] == w[1]), "edge {edge} step {step}: {colors:?}");
        }
    }
}

#[test]
fn counts_and_shared_edges_hold_after_random_resolution_changes() {
    let (_, topology) = octahedron();
    let mut store = ColorStore::uniform(topology, r(4), [0.5; 4]);
    randomize(&mut store, 1);
    let mut rng = Rng(99);
    for _ in 0..200 {
        let face = (rng.next() % 8) as u32;
        let resolution = Resolution::from_log2((rng.next() % 7) as u32).unwrap();
        store.write_resolution(face, resolution).unwrap();
        assert_counts_follow_the_closed_form(&store);
        assert_shared_edges_agree(&store);
    }
    let expected: u64 = 6
        + (0..12).map(|e| u64::from(store.edge_resolution(e).unwrap().get() - 1)).sum::<u64>()
        + (0..8).map(|f| u64::from(layout::interior_sample_count(store.face_resolution(f).unwrap()))).sum::<u64>();
    assert_eq!(store.sample_count(), expected);
}

#[test]
fn raising_then_lowering_restores_every_sample_exactly() {
    let (_, topology) = octahedron();
    let mut store = ColorStore::uniform(topology, r(4), [0.0; 4]);
    // Neighbour face 1 is finer than face 0, so one of face 0's edges keeps a higher R.
    store.write_resolution(1, r(16)).unwrap();
    randomize(&mut store, 7);
    let before = snapshot(&store);
    for target in [8, 64, 256] {
        store.write_resolution(0, r(target)).unwrap();
        store.write_resolution(0, r(4)).unwrap();
        assert_same(&snapshot(&store), &before, &format!("up to {target} and back"));
    }
}

#[test]
fn a_thousand_alternating_changes_on_one_face_change_nothing() {
    let (_, topology) = octahedron();
    let mut store = ColorStore::uniform(topology, r(2), [0.0; 4]);
    randomize(&mut store, 3);
    let before = snapshot(&store);
    for step in 0..1000 {
        let target = if step % 2 == 0 { 32 } else { 2 };
        store.write_resolution(5, r(target)).unwrap();
    }
    assert_same(&snapshot(&store), &before, "1000 changes");
}

#[test]
fn raising_keeps_old_samples_and_interpolates_linearly() {
    let (positions, topology) = octahedron();
    let mut store = ColorStore::uniform(topology.clone(), r(4), [0.0; 4]);
    randomize(&mut store, 11);
    let old = store.face_lattice(2).unwrap();
    store.write_resolution(2, r(32)).unwrap();
    for i in 0..=4 {
        for j in 0..=4 - i {
            assert_eq!(store.face_sample(2, i * 8, j * 8), old.get(i, j), "old sample ({i}, {j}) moved");
        }
    }
    // A colour affine in position stays affine: every new sample equals the field.
    let field = |p: [f32; 3]| -> Rgba { [0.3 + 0.2 * p[0], 0.5 - 0.1 * p[1] + 0.2 * p[2], 0.25 * p[2] + 0.5, 1.0] };
    let mut store = ColorStore::uniform(topology, r(2), [0.0; 4]);
    let corners = store.topology().face_vertices.clone();
    let position_of = |face: u32, w: [f32; 3]| -> [f32; 3] {
        let c = corners[face as usize].map(|v| positions[v as usize]);
        std::array::from_fn(|a| w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a])
    };
    store.write_all(|site| field(position_of(site.face, site.barycentric)));
    store.write_resolution(6, r(64)).unwrap();
    let rf = store.face_resolution(6).unwrap();
    for i in 0..=64 {
        for j in 0..=64 - i {
            let w = layout::sample_barycentric(rf, i, j).map(|x| x as f32);
            let expected = field(position_of(6, w));
            let got = store.face_sample(6, i, j).unwrap();
            for c in 0..4 {
                assert!((got[c] - expected[c]).abs() < 1e-5, "({i}, {j}) channel {c}: {got:?} vs {expected:?}");
            }
        }
    }
}

#[test]
fn lowering_preserves_linear_signals_and_removes_the_highest_frequency() {
    let (_, topology) = octahedron();
    // Alternating pattern: 1 on even lattice points, 0 elsewhere, on face 0 at R = 16 (the
    // store holds non-negative colours only, so this is the ±1 pattern shifted up by 1 and
    // halved; the filters are affine, so the pattern must become its mean, ½, inside).
    let mut store = ColorStore::uniform(topology, r(16), [0.0; 4]);
    let rf = r(16);
    for i in 0..=16u32 {
        for j in 0..=16 - i {
            let value = if i % 2 == 0 && j % 2 == 0 { 1.0 } else { 0.0 };
            let sample = store.face_sample_ref(0, i, j).unwrap();
            store.write_sample(sample, [value; 4]);
        }
    }
    let _ = rf;
    store.write_resolution(0, r(8)).unwrap();
    for &c in store.interior_samples(0) {
        for channel in c {
            assert!((channel - 0.5).abs() < 1e-6, "the alternating pattern must vanish inside the face: {c:?}");
        }
    }
}

#[test]
fn largest_resolution_face_next_to_resolution_one() {
    // Two triangles sharing edge (0, 1).
    let topology = Topology::build(4, &[[0, 1, 2], [1, 0, 3]]).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::ONE, [0.0; 4]);
    let colors = [[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0]];
    for (v, &c) in colors.iter().enumerate() {
        store.write_sample(SampleRef::Vertex(v as u32), c);
    }
    store.write_resolution(0, Resolution::MAX).unwrap();
    assert_counts_follow_the_closed_form(&store);
    assert_shared_edges_agree(&store);
    let n = u64::from(Resolution::MAX.get());
    assert_eq!(store.sample_count(), 4 + 3 * (n - 1) + (n - 1) * (n - 2) / 2);
    // Linear interpolation of the vertex colours: the centre-most sample is their average.
    let third = Resolution::MAX.get() / 3;
    let c = store.face_sample(0, third, third).unwrap();
    let w = layout::sample_barycentric(Resolution::MAX, third, third);
    for ch in 0..3 {
        let expected = w[0] as f32 * colors[0][ch] + w[1] as f32 * colors[1][ch] + w[2] as f32 * colors[2][ch];
        assert!((c[ch] - expected).abs() < 1e-5);
    }
    store.write_resolution(0, Resolution::ONE).unwrap();
    assert_eq!(store.sample_count(), 4);
    assert_eq!(store.vertex_color(2), Some(colors[2]));
}

#[test]
fn resolution_one_everywhere_holds_only_vertex_colours() {
    let (_, topology) = octahedron();
    let store = ColorStore::uniform(topology, Resolution::ONE, [0.25; 4]);
    assert_eq!(store.sample_count(), 6);
    let mut sites = 0;
    store.for_each_site(|site| {
        assert!(matches!(site.sample, SampleRef::Vertex(_)));
        sites += 1;
    });
    assert_eq!(sites, 6);
}

#[test]
fn sites_cover_every_sample_once_at_its_position() {
    let (positions, topology) = octahedron();
    let mut store = ColorStore::uniform(topology, r(8), [0.0; 4]);
    store.write_resolution(3, r(32)).unwrap();
    let mut seen = std::collections::HashSet::new();
    let corners = store.topology().face_vertices.clone();
    store.for_each_site(|site| {
        assert!(seen.insert(site.sample), "{:?} twice", site.sample);
        let sum: f32 = site.barycentric.iter().sum();
        assert!((sum - 1.0).abs() < 1e-6);
        // The owner face is the lowest face id containing the sample.
        if let SampleRef::Vertex(v) = site.sample {
            let first = corners.iter().position(|c| c.contains(&v)).unwrap() as u32;
            assert_eq!(site.face, first);
            let corner = corners[site.face as usize].iter().position(|&c| c == v).unwrap();
            assert_eq!(site.barycentric[corner], 1.0);
        }
    });
    assert_eq!(seen.len() as u64, store.sample_count());
    let _ = positions;
}

#[test]
fn dirty_tracking_reports_exactly_what_changed() {
    let (_, topology) = octahedron();
    let mut store = ColorStore::uniform(topology, r(4), [0.0; 4]);
    store.take_dirty();
    assert!(store.take_dirty().is_empty());
    store.write_sample(SampleRef::Vertex(3), [1.0; 4]);
    store.write_sample(SampleRef::Edge { edge: 5, offset: 1 }, [1.0; 4]);
    store.write_sample(SampleRef::Edge { edge: 5, offset: 2 }, [1.0; 4]);
    store.write_sample(SampleRef::Interior { face: 7, offset: 2 }, [1.0; 4]);
    assert!(!store.write_sample(SampleRef::Interior { face: 7, offset: 3 }, [1.0; 4]), "R = 4 has 3 interior samples");
    let dirty = store.take_dirty();
    assert_eq!((dirty.vertices, dirty.edges, dirty.faces), (vec![3], vec![5], vec![7]));
    assert!(dirty.resized_faces.is_empty());
    store.write_resolution(2, r(8)).unwrap();
    let dirty = store.take_dirty();
    assert_eq!(dirty.resized_faces, vec![2]);
    let mut edges_of_face: Vec<u32> = store.topology().face_edges[2].to_vec();
    edges_of_face.sort();
    assert_eq!(dirty.resized_edges, edges_of_face);
    assert_eq!(dirty.faces, vec![2]);
    assert!(store.write_resolution(99, r(2)).is_err());
}
