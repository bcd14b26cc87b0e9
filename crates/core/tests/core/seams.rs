//! Seams between faces of different resolution (CPU reference sampler).
//!
//! Truth: along a mesh edge, the colour both faces must show is the 1D piecewise-linear
//! interpolation of the edge's own samples at the edge's level `min(L, log2 R_e)`, with the
//! end vertices at `min(L, last vertex level)` — read here straight from the packed colour
//! buffer by the layout formulas (docs/FORMAT.md), not through the sampler. Points along the
//! edges are dyadic (20 bits), so barycentrics and lattice coordinates are exact in `f32`
//! and the only error left is the interpolation's own rounding.
//!
//! The same measurement is run with a copy of the sampler as it was before the seam rule
//! (`old_sample`), printed as the "before" figure; only the new sampler is asserted on.

use crate::common;
use crate::common::WriteThrough;

use common::Rng;
use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::{PackLayout, pack};
use meshpaint_core::packing::sampler::{Filter, MeshColorSource, sample, sample_trilinear};

/// Largest allowed difference (colour units) for the linear family: float rounding.
const TOLERANCE: f32 = 2e-6;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// The sampler as it was before the seam rule, kept verbatim as the independent
/// reference for uniform resolutions: level clamped to the face's last level, every
/// lattice sample (vertices included) read at that clamped level, eq. 2.4.
fn old_sample<S: MeshColorSource + ?Sized>(
    source: &S,
    face: u32,
    barycentric: [f32; 3],
    filter: Filter,
    level: u32,
) -> Option<Rgba> {
    let r_face = source.face_resolution(face)?;
    let level = level.min(r_face.log2());
    let r = r_face.at_level(level).ok()?;
    match filter {
        Filter::Nearest => {
            let (i, j) = layout::nearest_sample(r, barycentric);
            source.lattice_color(face, level, i, j)
        }
        Filter::Linear => {
            let mut out = [0.0f32; 4];
            for s in layout::linear_samples(r, barycentric) {
                let color = source.lattice_color(face, level, s.i, s.j)?;
                for c in 0..4 {
                    out[c] += s.weight * color[c];
                }
            }
            Some(out)
        }
    }
}

fn random_store(topology: Topology, resolutions: Vec<Resolution>, seed: u64) -> ColorStore {
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| rng.color());
    store
}

/// Two triangles sharing edge (1, 2), walked 1→2 by face 0 and 2→1 by face 1; the other
/// four edges are boundary edges.
fn two_triangles(ra: u64, rb: u64, seed: u64) -> ColorStore {
    let topology = Topology::build(4, &[[0, 1, 2], [2, 1, 3]]).unwrap();
    random_store(topology, vec![r(ra), r(rb)], seed)
}

/// Three fins on edge (0, 1) (non-manifold), a fourth face sharing (1, 2) with fin 0.
fn fins(resolutions: [u64; 4], seed: u64) -> ColorStore {
    let topology = Topology::build(6, &[[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]]).unwrap();
    random_store(topology, resolutions.map(r).to_vec(), seed)
}

fn packed(store: &ColorStore) -> PackedMesh {
    let positions = vec![[0.0f32; 3]; store.topology().vertex_count as usize];
    pack(store, &positions, ColorFormat::Rgba32F).unwrap()
}

/// Barycentrics of the point at `s` (from the start corner) along face edge `k`.
fn on_face_edge(k: u8, s: f32) -> [f32; 3] {
    match k {
        0 => [1.0 - s, s, 0.0],
        1 => [0.0, 1.0 - s, s],
        _ => [s, 0.0, 1.0 - s],
    }
}

/// The exact colour of `edge` at canonical parameter `s` at requested level `level`, read
/// from the colour buffer with the layout formulas (f64 interpolation).
fn edge_truth(packed: &PackedMesh, layout_: &PackLayout, store: &ColorStore, edge: u32, level: u32, s: f64) -> Rgba {
    let topology = store.topology();
    let r_edge = store.edge_resolution(edge).unwrap();
    let edge_level = level.min(r_edge.log2());
    let r_e = r_edge.get() >> edge_level;
    let last_vertex_level = packed.vertex_levels - 1;
    let [lower, higher] = topology.edge_vertices[edge as usize];
    let value = |p: u32| -> Rgba {
        let index = if p == 0 {
            u64::from(lower) * u64::from(packed.vertex_levels) + u64::from(level.min(last_vertex_level))
        } else if p == r_e {
            u64::from(higher) * u64::from(packed.vertex_levels) + u64::from(level.min(last_vertex_level))
        } else {
            u64::from(layout_.edge_base[edge as usize])
                + u64::from(layout::edge_level_offset(r_edge, edge_level).unwrap())
                + u64::from(p - 1)
        };
        packed.color(index).unwrap()
    };
    let x = s * f64::from(r_e);
    let n = (x.floor() as u32).min(r_e - 1);
    let f = x - f64::from(n);
    let (a, b) = (value(n), value(n + 1));
    std::array::from_fn(|c| ((1.0 - f) * f64::from(a[c]) + f * f64::from(b[c])) as f32)
}

/// Canonical parameters to probe on an edge of resolution `r_e` at its level: every sample
/// position, every midpoint, and `random` random dyadic points.
fn probe_points(r_e: u32, random: usize, rng: &mut Rng) -> Vec<f32> {
    const ONE: u64 = 1 << 20;
    let mut points: Vec<f32> = (0..=2 * r_e).map(|k| k as f32 / (2 * r_e) as f32).collect();
    points.extend((0..random).map(|_| (rng.next() % (ONE + 1)) as f32 / ONE as f32));
    points
}

#[derive(Debug, Default, Clone, Copy)]
struct Jump {
    /// Largest difference between two faces at the same edge point.
    between_faces: f32,
    /// Largest difference between a face and the exact edge colour.
    from_truth: f32,
}

impl Jump {
    fn merge(&mut self, other: Jump) {
        self.between_faces = self.between_faces.max(other.between_faces);
        self.from_truth = self.from_truth.max(other.from_truth);
    }
}

fn max_diff(a: Rgba, b: Rgba) -> f32 {
    (0..4).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max)
}

type Sampler = fn(&PackedMesh, u32, [f32; 3], u32) -> Option<Rgba>;

fn new_linear(p: &PackedMesh, face: u32, bary: [f32; 3], level: u32) -> Option<Rgba> {
    sample(p, face, bary, Filter::Linear, level)
}

fn old_linear(p: &PackedMesh, face: u32, bary: [f32; 3], level: u32) -> Option<Rgba> {
    old_sample(p, face, bary, Filter::Linear, level)
}

/// Jumps on every edge of `store` at every level `0..=last + 1` with `sampler`.
fn measure(store: &ColorStore, sampler: Sampler, random_points: usize, seed: u64) -> Vec<Jump> {
    let packed = packed(store);
    let pack_layout = PackLayout::of(store).unwrap();
    let topology = store.topology();
    let mut rng = Rng(seed);
    let mut per_level = Vec::new();
    for level in 0..=packed.vertex_levels {
        let mut jump = Jump::default();
        for edge in 0..topology.edge_count() {
            let r_edge = store.edge_resolution(edge).unwrap();
            let r_e = r_edge.get() >> level.min(r_edge.log2());
            let [lower, _] = topology.edge_vertices[edge as usize];
            for s in probe_points(r_e, random_points, &mut rng) {
                let truth = edge_truth(&packed, &pack_layout, store, edge, level, f64::from(s));
                let mut seen: Vec<Rgba> = Vec::new();
                for &(face, k) in topology.faces_of_edge(edge) {
                    let from_lower = topology.face_vertices[face as usize][usize::from(k)] == lower;
                    let along = if from_lower { s } else { 1.0 - s };
                    let color = sampler(&packed, face, on_face_edge(k, along), level).unwrap();
                    jump.from_truth = jump.from_truth.max(max_diff(color, truth));
                    for other in &seen {
                        jump.between_faces = jump.between_faces.max(max_diff(color, *other));
                    }
                    seen.push(color);
                }
            }
        }
        per_level.push(jump);
    }
    per_level
}

fn summary(levels: &[Jump]) -> (Jump, Jump) {
    let level0 = levels[0];
    let mut coarser = Jump::default();
    for jump in &levels[1..] {
        coarser.merge(*jump);
    }
    (level0, coarser)
}

#[test]
fn mixed_resolution_edges_agree_at_every_level_for_every_pair_up_to_64() {
    let resolutions = [1u64, 2, 4, 8, 16, 32, 64];
    let mut worst_new = Jump::default();
    let mut failures = Vec::new();
    for (n, &ra) in resolutions.iter().enumerate() {
        for (m, &rb) in resolutions.iter().enumerate() {
            let store = two_triangles(ra, rb, 1000 + (n * 7 + m) as u64);
            let before = measure(&store, old_linear, 48, 5);
            let after = measure(&store, new_linear, 48, 5);
            let ((b0, bl), (a0, al)) = (summary(&before), summary(&after));
            println!(
                "R {ra:>2}|{rb:<2}: before L0 {:.3} (truth {:.3}), L>0 {:.3} (truth {:.3}); \
                 after L0 {:.2e} (truth {:.2e}), L>0 {:.2e} (truth {:.2e})",
                b0.between_faces,
                b0.from_truth,
                bl.between_faces,
                bl.from_truth,
                a0.between_faces,
                a0.from_truth,
                al.between_faces,
                al.from_truth
            );
            for (level, jump) in after.iter().enumerate() {
                worst_new.merge(*jump);
                if jump.between_faces > TOLERANCE || jump.from_truth > TOLERANCE {
                    failures.push(format!("R {ra}|{rb} level {level}: {jump:?}"));
                }
            }
        }
    }
    println!("worst after: {worst_new:?}");
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn largest_resolution_next_to_coarse_faces_agrees_at_every_level() {
    let mut failures = Vec::new();
    for (ra, rb) in [(4096u64, 1u64), (2, 4096), (4096, 64)] {
        let store = two_triangles(ra, rb, ra ^ (rb << 20));
        let before = summary(&measure(&store, old_linear, 8, 9));
        let after = measure(&store, new_linear, 8, 9);
        let (a0, al) = summary(&after);
        println!(
            "R {ra}|{rb}: before L0 {:.3}, L>0 {:.3}; after L0 {:.2e} (truth {:.2e}), L>0 {:.2e} (truth {:.2e})",
            before.0.between_faces,
            before.1.between_faces,
            a0.between_faces,
            a0.from_truth,
            al.between_faces,
            al.from_truth
        );
        for (level, jump) in after.iter().enumerate() {
            if jump.between_faces > TOLERANCE || jump.from_truth > TOLERANCE {
                failures.push(format!("R {ra}|{rb} level {level}: {jump:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn non_manifold_and_boundary_edges_with_mixed_resolutions_agree() {
    let mut failures = Vec::new();
    for (n, resolutions) in [[2u64, 32, 8, 1], [64, 1, 4, 16], [1, 1, 64, 2], [8, 8, 8, 8]].into_iter().enumerate() {
        let store = fins(resolutions, 77 + n as u64);
        let topology = store.topology();
        assert_eq!(topology.nonmanifold_edge_count(), 1);
        assert!(topology.boundary_edge_count() > 0);
        let before = summary(&measure(&store, old_linear, 48, 3));
        let after = measure(&store, new_linear, 48, 3);
        let (a0, al) = summary(&after);
        println!(
            "fins {resolutions:?}: before L0 {:.3}, L>0 {:.3}; after L0 {:.2e} (truth {:.2e}), L>0 {:.2e} (truth {:.2e})",
            before.0.between_faces,
            before.1.between_faces,
            a0.between_faces,
            a0.from_truth,
            al.between_faces,
            al.from_truth
        );
        for (level, jump) in after.iter().enumerate() {
            if jump.between_faces > TOLERANCE || jump.from_truth > TOLERANCE {
                failures.push(format!("fins {resolutions:?} level {level}: {jump:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Trilinear = blend of two fixed levels: at any `lod`, both faces agree along the edge
/// and equal the blend of the two exact edge colours.
#[test]
fn trilinear_agrees_across_mixed_resolution_edges() {
    let mut failures = Vec::new();
    let mut worst = 0.0f32;
    for (ra, rb) in [(2u64, 32u64), (64, 1), (8, 4), (16, 16)] {
        let store = two_triangles(ra, rb, ra * 31 + rb);
        let packed = packed(&store);
        let pack_layout = PackLayout::of(&store).unwrap();
        let topology = store.topology();
        let mut rng = Rng(ra + rb);
        for lod in [0.0f32, 0.25, 0.5, 1.375, 2.75, 3.5, 4.125, 5.5, 6.0, 6.75] {
            let (l0, t) = (lod.floor() as u32, lod - lod.floor());
            for edge in 0..topology.edge_count() {
                let [lower, _] = topology.edge_vertices[edge as usize];
                for s in probe_points(64, 64, &mut rng) {
                    let a = edge_truth(&packed, &pack_layout, &store, edge, l0, f64::from(s));
                    let b = edge_truth(&packed, &pack_layout, &store, edge, l0 + 1, f64::from(s));
                    let truth: Rgba = std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t);
                    for &(face, k) in topology.faces_of_edge(edge) {
                        let from_lower = topology.face_vertices[face as usize][usize::from(k)] == lower;
                        let along = if from_lower { s } else { 1.0 - s };
                        let color = sample_trilinear(&packed, face, on_face_edge(k, along), lod).unwrap();
                        let d = max_diff(color, truth);
                        worst = worst.max(d);
                        if d > 2.0 * TOLERANCE {
                            failures.push(format!("R {ra}|{rb} lod {lod} edge {edge} s {s}: {d}"));
                        }
                    }
                }
            }
        }
    }
    println!("trilinear worst difference from the exact blend: {worst:.2e}");
    assert!(failures.is_empty(), "{:#?}", &failures[..failures.len().min(20)]);
}

/// Uniform resolution: the seam rule never applies, and the sampler is bit-identical to
/// the formula it replaced, for both filters, at every level, in every colour format.
#[test]
fn uniform_resolution_is_bit_identical_to_the_old_formula() {
    let (_, octahedron) = common::octahedron();
    let mut compared = 0u64;
    for resolution in [1u64, 2, 8, 64] {
        let store = random_store(octahedron.clone(), vec![r(resolution); 8], resolution);
        let positions = vec![[0.0f32; 3]; 6];
        for format in ColorFormat::ALL {
            let packed = pack(&store, &positions, format).unwrap();
            let mut rng = Rng(resolution * 7 + 1);
            for level in 0..=r(resolution).log2() + 2 {
                for face in 0..8 {
                    for n in 0..400 {
                        let mut bary = [rng.unit(), rng.unit(), rng.unit()];
                        match n % 4 {
                            0 => bary[n % 3] = 0.0,
                            1 => bary = on_face_edge((n % 3) as u8, rng.unit()),
                            _ => {}
                        }
                        for filter in [Filter::Linear, Filter::Nearest] {
                            let new = sample(&packed, face, bary, filter, level).unwrap();
                            let old = old_sample(&packed, face, bary, filter, level).unwrap();
                            assert_eq!(
                                new.map(f32::to_bits),
                                old.map(f32::to_bits),
                                "R {resolution} {format:?} level {level} face {face} {bary:?} {filter:?}"
                            );
                            compared += 1;
                        }
                    }
                }
            }
        }
    }
    // Level 0 on the store itself too.
    let store = random_store(octahedron, vec![r(16); 8], 3);
    let mut rng = Rng(17);
    for face in 0..8 {
        for _ in 0..2000 {
            let bary = [rng.unit(), rng.unit(), rng.unit()];
            for filter in [Filter::Linear, Filter::Nearest] {
                let new = sample(&store, face, bary, filter, 0).unwrap();
                let old = old_sample(&store, face, bary, filter, 0).unwrap();
                assert_eq!(new.map(f32::to_bits), old.map(f32::to_bits));
                compared += 1;
            }
        }
    }
    println!("{compared} lookups bit-identical");
}

/// Alternative (A), edges stored at the coarser face's resolution: what it would lose. For
/// random colours on an edge of resolution `R_e` next to a face of `R_c`, the fine signal
/// along the edge minus its `R_c` subsampling, as RMS over the edge (closed form per
/// segment: ∫ of a squared linear function), and the edge samples it would not store.
#[test]
fn alternative_min_resolution_edges_lose_the_fine_detail() {
    let mut rng = Rng(2024);
    for (fine, coarse) in [(8u32, 2u32), (16, 1), (64, 4), (64, 32)] {
        let mut squared = 0.0f64;
        let trials = 200;
        for _ in 0..trials {
            let samples: Vec<f64> = (0..=fine).map(|_| f64::from(rng.unit())).collect();
            let stride = fine / coarse;
            for p in 0..fine {
                // Difference at both ends of segment p; the integral of (d0 + (d1 − d0)s)²
                // over s ∈ [0, 1] is (d0² + d0·d1 + d1²)/3.
                let coarse_at = |q: u32| {
                    let (k, f) = (q / stride, f64::from(q % stride) / f64::from(stride));
                    let (a, b) = (samples[(k * stride) as usize], samples[((k + 1) * stride).min(fine) as usize]);
                    a + (b - a) * f
                };
                let d0 = samples[p as usize] - coarse_at(p);
                let d1 =
                    samples[p as usize + 1] - if p + 1 == fine { samples[fine as usize] } else { coarse_at(p + 1) };
                squared += (d0 * d0 + d0 * d1 + d1 * d1) / 3.0 / f64::from(fine);
            }
        }
        let rms = (squared / f64::from(trials)).sqrt();
        println!(
            "min-R edge {fine}→{coarse}: RMS detail lost {rms:.3} (colour units, random samples), \
             {} level-0 edge samples saved per edge",
            fine - coarse
        );
        assert!(rms > 0.05, "random detail cannot be represented at the coarser resolution");
    }
}

/// MIP chains at mixed resolutions (eq. 2.6 on edges with every incident face): edge
/// level `l` = `(C + ½ Σ N)/(1 + n/2)` over the two neighbours along the edge and two per
/// incident face — interior samples of a face at the edge's resolution, and for a coarser
/// face what it shows there at level `l − 1` (the linear filter with the seam rule).
#[test]
fn edge_mip_levels_take_coarser_faces_as_they_are_shown() {
    let mut checked = 0;
    for store in [two_triangles(8, 2, 5), two_triangles(1, 16, 6), fins([2, 32, 8, 1], 7), fins([16, 16, 4, 16], 8)] {
        let packed = packed(&store);
        let pack_layout = PackLayout::of(&store).unwrap();
        let topology = store.topology();
        for edge in 0..topology.edge_count() {
            let r_edge = store.edge_resolution(edge).unwrap();
            let [lower, _] = topology.edge_vertices[edge as usize];
            for level in 1..r_edge.log2() {
                let rl = r_edge.get() >> level;
                let rp = 2 * rl;
                for k in 1..rl {
                    let s = f64::from(2 * k) / f64::from(rp);
                    let along = |d: i32| {
                        edge_truth(&packed, &pack_layout, &store, edge, level - 1, s + f64::from(d) / f64::from(rp))
                    };
                    let center = along(0);
                    let mut neighbours = vec![along(-1), along(1)];
                    for &(face, fk) in topology.faces_of_edge(edge) {
                        let from_lower = topology.face_vertices[face as usize][usize::from(fk)] == lower;
                        let p = if from_lower { 2 * k } else { rp - 2 * k };
                        let inside = match fk {
                            0 => [(p, 1), (p - 1, 1)],
                            1 => [(rp - p - 1, p), (rp - p, p - 1)],
                            _ => [(1, rp - p), (1, rp - p - 1)],
                        };
                        for (i, j) in inside {
                            let w = [(rp - i - j) as f32, i as f32, j as f32].map(|w| w / rp as f32);
                            neighbours.push(sample(&packed, face, w, Filter::Linear, level - 1).unwrap());
                        }
                    }
                    let norm = 1.0 / (1.0 + 0.5 * neighbours.len() as f32);
                    let expected: Rgba = std::array::from_fn(|c| {
                        (center[c] + 0.5 * neighbours.iter().map(|n| n[c]).sum::<f32>()) * norm
                    });
                    let got = edge_truth(&packed, &pack_layout, &store, edge, level, s);
                    assert!(
                        max_diff(got, expected) <= 1e-5,
                        "edge {edge} level {level} k {k}: {got:?} vs {expected:?}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 50, "{checked}");
}
