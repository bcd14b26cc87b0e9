//! Htex against brute force and the CPU reference sampler.
//!
//! Truth: halfedge twins found by searching every other halfedge for the reversed vertex
//! pair; texel positions from the quad's 3D corners (face centroids and vertices) solved
//! back to face barycentrics in `f64`; `packing::sampler::sample` (mesh colors' linear
//! filter) for colours. Colours are random (the hardest case for filtering).

use crate::common::{Rng, WriteThrough};
use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::htex::halfedge::{NONE, next};
use meshpaint_core::htex::jumps::steps;
use meshpaint_core::htex::layout::decode_record;
use meshpaint_core::htex::{self, HtexError, HtexOptions, HtexTexture};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::synth::shapes::icosphere;
use std::collections::HashMap;

/// An icosphere, or its upper half (boundaries), or with one face wound the other way.
#[derive(Clone, Copy, PartialEq)]
enum Shape {
    Closed,
    Open,
    MisWound,
}

fn mesh(shape: Shape, levels: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let (positions, mut triangles) = icosphere(levels);
    match shape {
        Shape::Closed => {}
        Shape::Open => triangles.retain(|t| t.iter().map(|&v| positions[v as usize][2]).sum::<f32>() > 0.0),
        Shape::MisWound => triangles[0].swap(1, 2),
    }
    (positions, triangles)
}

fn packed_mesh(
    shape: Shape,
    levels: u32,
    resolution: impl Fn(usize) -> u64,
    format: ColorFormat,
    seed: u64,
) -> PackedMesh {
    let (positions, triangles) = mesh(shape, levels);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let resolutions = (0..triangles.len()).map(|f| Resolution::new(resolution(f)).unwrap()).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| rng.color());
    pack(&store, &positions, format).unwrap()
}

fn mixed(face: usize) -> u64 {
    1 << ((face * 7 + face / 5) % 5)
}

fn max_diff(a: Rgba, b: Rgba) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

fn build(packed: &PackedMesh, equalize_corners: bool) -> HtexTexture {
    htex::build(packed, &HtexOptions { equalize_corners, ..HtexOptions::default() }).unwrap()
}

/// Brute force: the halfedge running `to → from`, if exactly one does.
fn brute_twin(triangles: &[[u32; 3]], h: usize) -> u32 {
    let (f, k) = (h / 3, h % 3);
    let (from, to) = (triangles[f][k], triangles[f][(k + 1) % 3]);
    let same_edge: Vec<usize> = (0..triangles.len() * 3)
        .filter(|&g| g != h)
        .filter(|&g| {
            let (a, b) = (triangles[g / 3][g % 3], triangles[g / 3][(g % 3 + 1) % 3]);
            a.min(b) == from.min(to) && a.max(b) == from.max(to)
        })
        .collect();
    match same_edge.as_slice() {
        [g] if triangles[g / 3][g % 3] == to => *g as u32,
        _ => NONE,
    }
}

#[test]
fn halfedges_pair_with_their_twins_and_boundaries_with_themselves() {
    for shape in [Shape::Closed, Shape::Open, Shape::MisWound] {
        let (positions, triangles) = mesh(shape, 2);
        let packed = packed_mesh(shape, 2, |_| 4, ColorFormat::Rgba32F, 1);
        let htex = build(&packed, true);
        let he = &htex.layout.halfedges;
        let mut in_quads = vec![0u32; triangles.len() * 3];
        for (q, &[lower, upper]) in he.quads.iter().enumerate() {
            in_quads[lower as usize] += 1;
            assert_eq!(he.quad[lower as usize], q as u32);
            assert_eq!(brute_twin(&triangles, lower as usize), upper);
            if upper != NONE {
                in_quads[upper as usize] += 1;
                assert!(lower > upper, "Algorithm 2: the larger id is the lower-left");
                assert_eq!(he.quad[upper as usize], q as u32);
            }
        }
        assert!(in_quads.iter().all(|&c| c == 1), "every halfedge in exactly one quad");
        let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
        let boundaries = he.quads.iter().filter(|q| q[1] == NONE).count();
        match shape {
            Shape::Closed => assert_eq!((he.quads.len(), boundaries), (topology.edge_count() as usize, 0)),
            Shape::Open => {
                assert_eq!(he.quads.len(), topology.edge_count() as usize, "E textures (paper §4.3)");
                assert_eq!(boundaries, topology.boundary_edge_count() as usize);
                assert!(boundaries > 0);
            }
            // The flipped face's three edges each become two self-paired quads.
            Shape::MisWound => assert_eq!((he.quads.len(), boundaries), (topology.edge_count() as usize + 3, 6)),
        }
    }
}

/// Barycentrics of 3D point `p` in triangle `t` (least squares on the two edge vectors).
fn solve_barycentric(t: [[f64; 3]; 3], p: [f64; 3]) -> [f32; 3] {
    let e1: [f64; 3] = std::array::from_fn(|i| t[1][i] - t[0][i]);
    let e2: [f64; 3] = std::array::from_fn(|i| t[2][i] - t[0][i]);
    let d: [f64; 3] = std::array::from_fn(|i| p[i] - t[0][i]);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (a, b, c) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
    let (r1, r2) = (dot(e1, d), dot(e2, d));
    let det = a * c - b * b;
    let w1 = (c * r1 - b * r2) / det;
    let w2 = (a * r2 - b * r1) / det;
    [(1.0 - w1 - w2) as f32, w1 as f32, w2 as f32]
}

/// The 3D point of quad point (x, y) and the face it lies in, from the quad's corners:
/// (0, 0) the lower halfedge's face centroid, (1, 0) its start vertex, (0, 1) its end
/// vertex, (1, 1) the twin's face centroid; a self-paired quad's upper half mirrors.
fn quad_point_3d(positions: &[[f32; 3]], triangles: &[[u32; 3]], quad: [u32; 2], x: f64, y: f64) -> (u32, [f64; 3]) {
    let p = |v: u32| positions[v as usize].map(f64::from);
    let centroid = |f: u32| -> [f64; 3] {
        let t = triangles[f as usize];
        std::array::from_fn(|i| (p(t[0])[i] + p(t[1])[i] + p(t[2])[i]) / 3.0)
    };
    let [lower, upper] = quad;
    let (f, k) = (lower / 3, (lower % 3) as usize);
    let (v0, v1) = (p(triangles[f as usize][k]), p(triangles[f as usize][(k + 1) % 3]));
    let (face, x, y, far) = if x + y <= 1.0 {
        (f, x, y, centroid(f))
    } else if upper != NONE {
        (upper / 3, x, y, centroid(upper / 3))
    } else {
        (f, 1.0 - y, 1.0 - x, centroid(f))
    };
    // Bilinear patch of the quad restricted to its triangle: affine in each half.
    let point = if x + y <= 1.0 {
        let c = centroid(face);
        std::array::from_fn(|i| c[i] + (v0[i] - c[i]) * x + (v1[i] - c[i]) * y)
    } else {
        std::array::from_fn(|i| far[i] + (v0[i] - far[i]) * (1.0 - y) + (v1[i] - far[i]) * (1.0 - x))
    };
    (face, point)
}

#[test]
fn every_texel_is_the_reference_at_its_position_at_every_level() {
    for shape in [Shape::Closed, Shape::Open, Shape::MisWound] {
        let (positions, triangles) = mesh(shape, 1);
        let packed = packed_mesh(shape, 1, mixed, ColorFormat::Rgba32F, 2);
        for equalize in [false, true] {
            let htex = build(&packed, equalize);
            let mut checked = 0;
            for (q, &quad) in htex.layout.halfedges.quads.iter().enumerate() {
                for level in 0..htex.layout.levels {
                    let n = htex.layout.size(q as u32, level);
                    let o = htex.layout.origin(q as u32, level);
                    for j in 0..n {
                        for i in 0..n {
                            let corner = (i == 0 || i == n - 1) && (j == 0 || j == n - 1);
                            let (x, y) = if equalize && corner && n >= 2 {
                                (f64::from(i.min(1)), f64::from(j.min(1)))
                            } else {
                                ((f64::from(i) + 0.5) / f64::from(n), (f64::from(j) + 0.5) / f64::from(n))
                            };
                            let (face, point) = quad_point_3d(&positions, &triangles, quad, x, y);
                            let t = triangles[face as usize].map(|v| positions[v as usize].map(f64::from));
                            let w = solve_barycentric(t, point);
                            let want = sample(&packed, face, w, Filter::Linear, level).unwrap();
                            let got = htex.texel(o.page, i64::from(o.x + 1 + i), i64::from(o.y + 1 + j));
                            assert!(
                                max_diff(got, want) < 1e-4,
                                "quad {q} level {level} texel ({i}, {j}): {got:?} vs {want:?}"
                            );
                            checked += 1;
                        }
                    }
                    // The border is zero.
                    for b in 0..n + 2 {
                        for (bx, by) in [(b, 0), (b, n + 1), (0, b), (n + 1, b)] {
                            assert_eq!(htex.texel(o.page, i64::from(o.x + bx), i64::from(o.y + by)), [0.0; 4]);
                        }
                    }
                }
            }
            assert!(checked > 1000);
        }
    }
}

#[test]
fn blocks_never_overlap_and_stay_in_their_page() {
    let packed = packed_mesh(Shape::Open, 2, mixed, ColorFormat::Rgba8Srgb, 3);
    let htex = build(&packed, true);
    let (s, h) = (htex.layout.page_size as usize, htex.layout.page_height as usize);
    let mut owner = vec![u32::MAX; s * h * htex.layout.pages as usize];
    for q in 0..htex.layout.halfedges.quads.len() as u32 {
        for level in 0..htex.layout.levels {
            let (n, o) = (htex.layout.size(q, level) as usize, htex.layout.origin(q, level));
            assert!(o.x as usize + n + 2 <= s && o.y as usize + n + 2 <= h && o.page < htex.layout.pages);
            for y in o.y as usize..o.y as usize + n + 2 {
                for x in o.x as usize..o.x as usize + n + 2 {
                    let at = (o.page as usize * h + y) * s + x;
                    assert_eq!(owner[at], u32::MAX, "quad {q} level {level} overlaps");
                    owner[at] = q;
                }
            }
        }
    }
}

#[test]
fn quad_sizes_are_the_largest_adjacent_resolution() {
    let packed = packed_mesh(Shape::Open, 1, mixed, ColorFormat::Rgba8Srgb, 4);
    let htex = build(&packed, true);
    for (q, &[lower, upper]) in htex.layout.halfedges.quads.iter().enumerate() {
        let r = |h: u32| mixed((h / 3) as usize);
        let want = if upper == NONE { r(lower) } else { r(lower).max(r(upper)) }.max(2);
        assert_eq!(1u64 << htex.layout.quad_log2[q], want);
        for k in 0..3 {
            let (quad, lower_bit, log2) = decode_record(htex.layout.face_records[(lower / 3) as usize][k]);
            if k as u32 == lower % 3 {
                assert_eq!((quad, lower_bit, log2), (q as u32, true, u32::from(htex.layout.quad_log2[q])));
            }
        }
    }
}

#[test]
fn boundary_quads_mirror_their_triangle_across_the_diagonal() {
    let packed = packed_mesh(Shape::Open, 1, |_| 8, ColorFormat::Rgba8Srgb, 5);
    let htex = build(&packed, false);
    let mut mirrored = 0;
    for (q, &[_, upper]) in htex.layout.halfedges.quads.iter().enumerate() {
        if upper != NONE {
            continue;
        }
        let o = htex.layout.origin(q as u32, 0);
        let n = htex.layout.size(q as u32, 0);
        let at = |i: u32, j: u32| htex.texel(o.page, i64::from(o.x + 1 + i), i64::from(o.y + 1 + j));
        for j in 0..n {
            for i in n - j..n {
                assert_eq!(at(i, j), at(n - 1 - j, n - 1 - i));
                mirrored += 1;
            }
        }
    }
    assert!(mirrored > 0);
}

/// Corner texels: every block corner at one mesh vertex (or face centroid) holds one value,
/// found by grouping corners by the 3D point they sit at.
#[test]
fn equalised_corner_texels_agree_at_every_vertex_and_centroid() {
    let (positions, triangles) = mesh(Shape::Open, 1);
    let packed = packed_mesh(Shape::Open, 1, mixed, ColorFormat::Rgba8Srgb, 6);
    let htex = build(&packed, true);
    let mut at_point: HashMap<(u32, [u64; 3]), Vec<Rgba>> = HashMap::new();
    for (q, &quad) in htex.layout.halfedges.quads.iter().enumerate() {
        for level in 0..htex.layout.levels {
            let n = htex.layout.size(q as u32, level);
            if n < 2 {
                continue;
            }
            let o = htex.layout.origin(q as u32, level);
            for (i, j) in [(0, 0), (n - 1, 0), (0, n - 1), (n - 1, n - 1)] {
                let (_, p) = quad_point_3d(&positions, &triangles, quad, f64::from(i.min(1)), f64::from(j.min(1)));
                let key = (level, p.map(|c| (c * 1e6).round() as i64 as u64));
                at_point.entry(key).or_default().push(htex.texel(
                    o.page,
                    i64::from(o.x + 1 + i),
                    i64::from(o.y + 1 + j),
                ));
            }
        }
    }
    let mut shared = 0;
    for values in at_point.values() {
        shared += usize::from(values.len() > 1);
        assert!(values.iter().all(|v| *v == values[0]), "{values:?}");
    }
    assert!(shared > 50);
}

/// The paper: continuous everywhere but at corner texels; equalised corners close those
/// too where the quads meeting at a corner have one resolution (paper §4.4: "continuous
/// filtering whenever textures have the same resolution"), at every level whose blocks are
/// at least 2 texels wide (a 1-texel block has no corner texel of its own). Unequalised,
/// random colours jump at the corners; mixed resolutions jump near vertices (printed).
#[test]
fn equalised_htex_is_continuous_across_every_edge_at_one_resolution() {
    for shape in [Shape::Closed, Shape::Open] {
        let packed = packed_mesh(shape, 1, |_| 8, ColorFormat::Rgba32F, 7);
        let equalized = build(&packed, true);
        for level in 0..3 {
            let j = equalized.jumps(level, 33);
            assert!(j.mesh_edges < 0.02 && j.spokes < 0.02, "level {level}: {j:?}");
        }
        let raw = build(&packed, false).jumps(0, 33);
        println!("unequalised jumps at level 0: {raw:?}");
        assert!(raw.mesh_edges > 1.0 || raw.spokes > 1.0, "{raw:?}");
        let mixed = build(&packed_mesh(shape, 1, mixed, ColorFormat::Rgba32F, 7), true).jumps(0, 33);
        println!("mixed resolutions, equalised, level 0: {mixed:?}");
    }
}

/// The CPU evaluation at every texel point inside its block (away from the block's edge,
/// where one fetch alone has weight 1) returns the texel: the three fetches and the
/// normalisation reduce to the own quad there.
#[test]
fn the_evaluation_reproduces_interior_texels() {
    let packed = packed_mesh(Shape::Closed, 1, |_| 8, ColorFormat::Rgba32F, 8);
    let htex = build(&packed, false);
    for h in 0..packed.indices.len() as u32 * 3 {
        let (q, lower, _) = decode_record(htex.layout.face_records[(h / 3) as usize][(h % 3) as usize]);
        let n = htex.layout.size(q, 0);
        let o = htex.layout.origin(q, 0);
        for j in 1..n - 1 {
            for i in 1..n - 1 {
                let (x, y) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let uv = if lower { [x, y] } else { [1.0 - x, 1.0 - y] };
                if uv[0] + uv[1] > 1.0 {
                    continue;
                }
                let got = htex.sample_halfedge(h, uv, 0);
                let want = htex.texel(o.page, i64::from(o.x + 1 + i), i64::from(o.y + 1 + j));
                assert!(max_diff(got, want) < 1e-5, "{h} ({i}, {j})");
            }
        }
    }
}

/// Resampling error from the store, RGBA8, random colours (the hardest case): Htex level 0
/// against mesh colors' linear filter at random points, in 8-bit steps. Stated figures
/// (docs/HTEX.md): the largest and the RMS error per R.
#[test]
fn resampling_error_per_resolution_is_within_the_stated_figures() {
    // (R, largest, RMS) in 8-bit steps; measured 166.8 / 28.5, 148.2 / 21.1, 120.2 / 18.7.
    for (r, max_bound, rms_bound) in [(4u64, 175.0, 30.0), (8, 155.0, 23.0), (16, 130.0, 20.0)] {
        let packed = packed_mesh(Shape::Closed, 1, |_| r, ColorFormat::Rgba8Srgb, 9);
        let htex = build(&packed, true);
        let mut rng = Rng(10);
        let (mut max, mut sum, mut count) = (0.0f32, 0.0f64, 0u64);
        for face in 0..packed.indices.len() as u32 {
            for _ in 0..200 {
                let (a, b) = (rng.unit(), rng.unit());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let w = [1.0 - a - b, a, b];
                let got = htex.sample_level(face, w, 0).unwrap();
                let want = sample(&packed, face, w, Filter::Linear, 0).unwrap();
                let e = steps(got, want);
                max = max.max(e);
                sum += f64::from(e).powi(2);
                count += 1;
            }
        }
        let rms = (sum / count as f64).sqrt();
        println!("R = {r}: largest {max:.1} steps, RMS {rms:.2} steps");
        assert!(max <= max_bound && rms <= rms_bound, "R = {r}: {max} {rms}");
    }
}

/// An affine colour field (each channel affine in position), which mesh colors' linear
/// filter reproduces exactly: Htex's texels hold it exactly at their points, and bilinear
/// reproduces it inside a half-quad; what is left is where a footprint mixes texels across
/// a fold of the intrinsic quad (its diagonal, or the unfolded neighbour of Algorithm 3),
/// small and stated here (RGBA32F, largest error in 8-bit steps, R = 8).
#[test]
fn an_affine_colour_field_is_reproduced_up_to_the_folds() {
    let (positions, triangles) = mesh(Shape::Closed, 2);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let mut store =
        ColorStore::with_resolutions(topology, vec![Resolution::new(8).unwrap(); triangles.len()], [0.0; 4]).unwrap();
    let affine = |p: [f32; 3]| [0.5 + 0.3 * p[0], 0.5 + 0.3 * p[1], 0.5 + 0.3 * p[2], 1.0];
    store.write_all(|site| {
        let t = triangles[site.face as usize];
        let p = std::array::from_fn(|a| (0..3).map(|k| site.barycentric[k] * positions[t[k] as usize][a]).sum());
        affine(p)
    });
    let packed = pack(&store, &positions, ColorFormat::Rgba32F).unwrap();
    let htex = build(&packed, true);
    let mut rng = Rng(12);
    let mut max = 0.0f32;
    for face in 0..packed.indices.len() as u32 {
        for _ in 0..50 {
            let (a, b) = (rng.unit(), rng.unit());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let w = [1.0 - a - b, a, b];
            let got = htex.sample_level(face, w, 0).unwrap();
            let want = sample(&packed, face, w, Filter::Linear, 0).unwrap();
            max = max.max(steps(got, want));
        }
    }
    println!("affine field, R = 8: largest error {max:.2} steps");
    assert!(max <= 2.0, "{max}");
}

#[test]
fn budgets_are_checked_before_allocating() {
    let packed = packed_mesh(Shape::Closed, 2, |_| 64, ColorFormat::Rgba8Srgb, 11);
    let small = HtexOptions { max_dimension: 32, ..HtexOptions::default() };
    assert!(matches!(htex::build(&packed, &small), Err(HtexError::AtlasTooLarge { .. })));
    let few = HtexOptions { max_dimension: 256, max_pages: 2, ..HtexOptions::default() };
    assert!(matches!(htex::build(&packed, &few), Err(HtexError::TooManyPages { .. })));
    let poor = HtexOptions { max_bytes: 1000, ..HtexOptions::default() };
    assert!(
        matches!(htex::build(&packed, &poor), Err(HtexError::OverBudget { bytes, max_bytes: 1000 }) if bytes > 1000)
    );
    let _ = next;
}
