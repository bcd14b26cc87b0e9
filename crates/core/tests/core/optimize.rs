//! Optimize (lower R while the shown colours stay within E): measured at random points of
//! every face with the CPU reference sampler, independently of the optimizer's own test
//! points; undo and redo restore the exact states.

use crate::common;
use crate::common::WriteThrough;

use common::{Rng, icosphere};
use meshpaint_core::colors::format::Rgba;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::paint::UndoHistory;
use meshpaint_core::paint::optimize::optimize;

/// Which kind of content a face holds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Region {
    /// One grey everywhere.
    Flat,
    /// A colour linear in world position (exact at R = 1).
    Linear,
    /// Random samples (needs its full R).
    Painted,
}

fn region_of(centroid: [f64; 3]) -> Region {
    if centroid[0] > 0.45 {
        Region::Painted
    } else if centroid[1] > 0.5 {
        Region::Linear
    } else {
        Region::Flat
    }
}

/// An icosphere at R = 8: a flat grey region, a linear gradient region and a painted one.
fn document() -> (ColorStore, Vec<[f32; 3]>, Vec<Region>) {
    let (positions, triangles) = icosphere(2);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::new(8).unwrap(), [0.0; 4]);
    let regions: Vec<Region> = triangles
        .iter()
        .map(|t| {
            let c = |k: usize| t.iter().map(|&v| f64::from(positions[v as usize][k])).sum::<f64>() / 3.0;
            region_of([c(0), c(1), c(2)])
        })
        .collect();
    let mut rng = Rng(0x0971);
    store.write_all(|site| {
        let t = triangles[site.face as usize];
        let p: [f32; 3] =
            std::array::from_fn(|k| (0..3).map(|c| site.barycentric[c] * positions[t[c] as usize][k]).sum());
        match regions[site.face as usize] {
            Region::Flat => [0.5, 0.5, 0.5, 1.0],
            Region::Linear => [0.5 + 0.25 * p[0], 0.5 + 0.25 * p[2], 0.3, 1.0],
            Region::Painted => [rng.unit(), rng.unit(), rng.unit(), 1.0],
        }
    });
    (store, positions, regions)
}

/// The largest channel difference between what `a` and `b` show (linear, level 0) at
/// `per_face` random points of every face.
fn largest_shown_difference(a: &ColorStore, b: &ColorStore, per_face: usize, seed: u64) -> f32 {
    let mut rng = Rng(seed);
    let mut worst = 0.0f32;
    for face in 0..a.topology().face_count() {
        for _ in 0..per_face {
            let (mut u, mut v) = (rng.unit(), rng.unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let bary = [1.0 - u - v, u, v];
            let (ca, cb): (Rgba, Rgba) =
                (sample(a, face, bary, Filter::Linear, 0).unwrap(), sample(b, face, bary, Filter::Linear, 0).unwrap());
            for c in 0..4 {
                worst = worst.max((ca[c] - cb[c]).abs());
            }
        }
    }
    worst
}

/// Every sample of every element, for exact comparisons.
fn all_samples(store: &ColorStore) -> (Vec<Resolution>, Vec<Rgba>) {
    let mut samples = Vec::new();
    store.for_each_site(|site| samples.push(store.get(site.sample).unwrap()));
    (store.face_resolutions().to_vec(), samples)
}

fn faces_touching(store: &ColorStore, regions: &[Region], triangles: &[[u32; 3]], region: Region) -> Vec<bool> {
    let mut vertex_touches = vec![false; store.topology().vertex_count as usize];
    for (face, t) in triangles.iter().enumerate() {
        if regions[face] == region {
            for &v in t {
                vertex_touches[v as usize] = true;
            }
        }
    }
    triangles.iter().map(|t| t.iter().any(|&v| vertex_touches[v as usize])).collect()
}

#[test]
fn lossless_optimize_keeps_every_shown_colour_and_collapses_flat_regions() {
    let (original, _, regions) = document();
    let (_, triangles) = icosphere(2);
    let mut store = original.clone();
    let mut history = UndoHistory::default();
    let report = optimize(&mut store, &mut history, 0.0).unwrap();
    eprintln!("{report:?}");
    assert_eq!(report.samples_before, original.sample_count());
    assert_eq!(report.samples_after, store.sample_count());
    assert!(report.samples_after * 2 < report.samples_before, "{report:?}");

    let worst = largest_shown_difference(&original, &store, 300, 11);
    eprintln!("lossless: largest difference at random points {worst:.2e}");
    assert!(worst <= 2e-6, "E = 0 changed a shown colour by {worst}");

    // Faces whose neighbourhood holds one flat or one linear colour: R = 1 (next to another
    // region a face shows the step along its shared edge, which needs its R). Painted faces
    // keep theirs.
    let near_painted = faces_touching(&store, &regions, &triangles, Region::Painted);
    let near_linear = faces_touching(&store, &regions, &triangles, Region::Linear);
    let near_flat = faces_touching(&store, &regions, &triangles, Region::Flat);
    for (face, region) in regions.iter().enumerate() {
        let r = store.face_resolution(face as u32).unwrap().get();
        match region {
            Region::Flat if !near_painted[face] && !near_linear[face] => assert_eq!(r, 1, "flat face {face}"),
            Region::Linear if !near_painted[face] && !near_flat[face] => assert_eq!(r, 1, "linear face {face}"),
            Region::Painted => assert_eq!(r, 8, "painted face {face}"),
            _ => {}
        }
    }

    // One undo step restores the document exactly; redo gives the optimized one back.
    let optimized = all_samples(&store);
    assert!(history.undo(&mut store).unwrap());
    assert_eq!(all_samples(&store), all_samples(&original));
    assert!(history.redo(&mut store).unwrap());
    assert_eq!(all_samples(&store), optimized);
}

#[test]
fn a_positive_bound_is_never_crossed_and_saves_more() {
    let (original, _, _) = document();
    let mut lossless = original.clone();
    optimize(&mut lossless, &mut UndoHistory::default(), 0.0).unwrap();
    for bound in [0.02f32, 0.1, 0.3] {
        let mut store = original.clone();
        let report = optimize(&mut store, &mut UndoHistory::default(), bound).unwrap();
        let worst = largest_shown_difference(&original, &store, 300, 12);
        eprintln!(
            "E = {bound}: {} → {} samples, {} faces lowered, largest difference at random points {worst:.4}",
            report.samples_before, report.samples_after, report.faces_lowered
        );
        assert!(worst <= bound + 1e-5, "E = {bound} crossed: {worst}");
        assert!(report.max_error <= bound);
        assert!(store.sample_count() <= lossless.sample_count());
    }
    // The largest bound lowers painted faces too.
    let mut store = original.clone();
    optimize(&mut store, &mut UndoHistory::default(), 1.0).unwrap();
    assert!(store.sample_count() < lossless.sample_count());
}

#[test]
fn optimize_refuses_a_bound_that_is_not_a_number_and_leaves_the_store_alone() {
    let (original, _, _) = document();
    for bound in [-0.1f32, f32::NAN, f32::INFINITY] {
        let mut store = original.clone();
        let mut history = UndoHistory::default();
        assert!(optimize(&mut store, &mut history, bound).is_err());
        assert_eq!(all_samples(&store), all_samples(&original));
        assert_eq!(history.undo_len(), 0);
    }
    // A single-colour mesh: every face collapses to R = 1; its one sample per vertex stays.
    let mut store = original.clone();
    store.write_all(|_| [0.2, 0.4, 0.6, 1.0]);
    optimize(&mut store, &mut UndoHistory::default(), 0.0).unwrap();
    assert!(store.face_resolutions().iter().all(|r| r.get() == 1));
    assert_eq!(store.sample_count(), u64::from(store.topology().vertex_count));
}
