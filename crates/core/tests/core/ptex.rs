//! Packed Ptex against brute force and the CPU reference sampler.
//!
//! Truths: `packing::sampler::sample` (mesh colors' linear filter) for every interior texel
//! at its centre, placed by the paper's Listing 1 (slips fixed) on tables rebuilt here by
//! counting; an occupancy map of the whole texture; for every border texel, the neighbour's
//! texel found by searching its block for the centre mirrored across the shared edge.
//! Colours are random (the hardest case for filtering).

use crate::common;
use crate::common::WriteThrough;

use common::Rng;
use meshpaint_core::colors::format::{ColorFormat, Rgba, encode_srgb8};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::ptex::{self, PackedPtex, PtexError, SLICES};
use meshpaint_core::synth::shapes::icosphere;
use std::collections::HashMap;

const TOLERANCE: f32 = 1e-5;
const MAX_DIM: u32 = 16384;

fn packed_mesh(levels: u32, resolution: impl Fn(usize) -> u64, format: ColorFormat, seed: u64) -> PackedMesh {
    let (positions, triangles) = icosphere(levels);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let resolutions = (0..triangles.len()).map(|f| Resolution::new(resolution(f)).unwrap()).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| rng.color());
    pack(&store, &positions, format).unwrap()
}

/// An open mesh (boundary edges, lone faces on them): the icosphere without its faces
/// whose first vertex is even-indexed below `cut`.
fn open_mesh(resolution: u64, seed: u64) -> PackedMesh {
    let (positions, triangles) = icosphere(2);
    let kept: Vec<[u32; 3]> = triangles.into_iter().enumerate().filter(|(f, _)| f % 5 != 0).map(|(_, t)| t).collect();
    let topology = Topology::build(positions.len() as u32, &kept).unwrap();
    let resolutions = vec![Resolution::new(resolution).unwrap(); kept.len()];
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| rng.color());
    pack(&store, &positions, ColorFormat::Rgba32F).unwrap()
}

fn mixed(face: usize) -> u64 {
    1 << ((face * 7 + face / 5) % 6)
}

fn max_diff(a: Rgba, b: Rgba) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

/// The paper's tables rebuilt by counting, and Listing 1's placement with its slips fixed:
/// block `b`'s top-left texel in slice `k`.
fn listing_origin(ptex: &PackedPtex, block: u32, k: u32) -> [i64; 2] {
    let logs: Vec<u32> = ptex.layout.blocks.iter().map(|b| b.log2).collect();
    let n_res = logs.iter().filter(|&&m| m < k).count() as i64;
    let size = (1i64 << k) + 2;
    let per_row = i64::from(ptex.layout.width) / size;
    // Slices are stacked from the finest down: rows of every coarser... finer slice above.
    let mut n_row = 0i64;
    for finer in (k + 1)..SLICES as u32 {
        let count = logs.iter().filter(|&&m| m >= finer).count() as i64;
        let s = (1i64 << finer) + 2;
        n_row +=
            (count + (i64::from(ptex.layout.width) / s).max(1) - 1) / (i64::from(ptex.layout.width) / s).max(1) * s;
    }
    let i = i64::from(block) - n_res;
    [(i % per_row) * size, n_row + (i / per_row) * size]
}

/// Barycentrics of `face` at square point `(u, v)` of its block, from the block's corner
/// vertices (`t₁` at (0, 0), `p` (1, 0), `t₂` (1, 1), `q` (0, 1)) by solving the 2×2 system.
fn face_weights(packed: &PackedMesh, ptex: &PackedPtex, face: u32, second: bool, uv: [f64; 2]) -> [f32; 3] {
    let block = ptex.layout.blocks[ptex.layout.records[face as usize].block() as usize];
    let [t1, p, t2, q] = block.corners;
    let place = |v: u32| -> [f64; 2] {
        if v == p {
            [1.0, 0.0]
        } else if v == q {
            [0.0, 1.0]
        } else if second && v == t2 {
            [1.0, 1.0]
        } else {
            assert!(v == t1 || v == t2);
            if second { [1.0, 1.0] } else { [0.0, 0.0] }
        }
    };
    let c = packed.indices[face as usize];
    let [a, b, d] = c.map(place);
    let det = (b[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (b[1] - a[1]);
    let w1 = ((uv[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (uv[1] - a[1])) / det;
    let w2 = ((b[0] - a[0]) * (uv[1] - a[1]) - (uv[0] - a[0]) * (b[1] - a[1])) / det;
    [(1.0 - w1 - w2) as f32, w1 as f32, w2 as f32]
}

#[test]
fn every_interior_texel_is_the_reference_at_its_centre_by_the_papers_tables() {
    for (name, packed) in [
        ("mixed", packed_mesh(2, mixed, ColorFormat::Rgba32F, 1)),
        ("uniform 8", packed_mesh(1, |_| 8, ColorFormat::Rgba32F, 2)),
        ("open 4", open_mesh(4, 3)),
    ] {
        let ptex = ptex::build(&packed, MAX_DIM, u64::MAX).unwrap();
        let mut checked = 0u64;
        for face in 0..packed.indices.len() as u32 {
            let record = ptex.layout.records[face as usize];
            let block = record.block();
            let m = ptex.layout.blocks[block as usize].log2;
            for level in 0..=m {
                let k = m - level;
                let [x0, y0] = listing_origin(&ptex, block, k);
                let n = 1u32 << k;
                for c in 0..n {
                    for a in 0..n {
                        let second = a + c + 1 > n;
                        if second != record.second() {
                            continue;
                        }
                        let uv = [(f64::from(a) + 0.5) / f64::from(n), (f64::from(c) + 0.5) / f64::from(n)];
                        let w = face_weights(&packed, &ptex, face, second, uv);
                        let truth = sample(&packed, face, w, Filter::Linear, level).unwrap();
                        let got = ptex.texel(x0 + 1 + i64::from(a), y0 + 1 + i64::from(c));
                        assert!(max_diff(got, truth) <= TOLERANCE, "{name} face {face} level {level} ({a}, {c})");
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 1000, "{name}: {checked}");
    }
}

#[test]
fn tables_are_the_counts_and_blocks_tile_the_texture_without_overlap() {
    let packed = packed_mesh(2, mixed, ColorFormat::Rgba8Srgb, 4);
    let ptex = ptex::build(&packed, MAX_DIM, u64::MAX).unwrap();
    let layout = &ptex.layout;
    let logs: Vec<u32> = layout.blocks.iter().map(|b| b.log2).collect();
    assert!(logs.windows(2).all(|w| w[0] <= w[1]), "blocks sorted by resolution");
    for k in 0..SLICES as u32 {
        assert_eq!(layout.tables.n_res[k as usize] as usize, logs.iter().filter(|&&m| m < k).count());
        for (b, &m) in logs.iter().enumerate() {
            // Listing 1's clamp: the finest slice at most `wanted` holding the block.
            assert_eq!(layout.tables.slice(b as u32, k), Some(k.min(m)));
        }
    }
    // Every face's two halves: each face is in exactly one block, pairs share one.
    let mut faces_seen = vec![0u32; packed.indices.len()];
    for b in &layout.blocks {
        faces_seen[b.faces[0] as usize] += 1;
        if b.paired {
            faces_seen[b.faces[1] as usize] += 1;
        }
    }
    assert!(faces_seen.iter().all(|&s| s == 1));
    let (w, h) = (layout.width as usize, layout.height as usize);
    let mut owner = vec![u32::MAX; w * h];
    let mut used = 0u64;
    for (b, &m) in logs.iter().enumerate() {
        for k in 0..=m {
            let [x0, y0] = listing_origin(&ptex, b as u32, k);
            assert_eq!(layout.tables.origin(b as u32, k), [x0, y0]);
            let s = (1usize << k) + 2;
            for y in y0 as usize..y0 as usize + s {
                for x in x0 as usize..x0 as usize + s {
                    assert!(x < w && y < h, "block {b} slice {k} leaves the texture");
                    assert_eq!(owner[y * w + x], u32::MAX, "block {b} slice {k} overlaps");
                    owner[y * w + x] = b as u32;
                    used += 1;
                }
            }
        }
    }
    assert_eq!(used, ptex.stats.interior_texels + ptex.stats.border_texels());
    let waste = ptex.unused_texels() as f64 / layout.texel_count() as f64;
    println!("{} blocks, {}×{} texels, unused {:.1} %", logs.len(), w, h, 100.0 * waste);
    assert!(waste < 0.25, "unused {waste}");
}

/// A block side: its start and end vertex, the face owning it and its border texel of index
/// `i` at resolution `n`.
type Side = (u32, u32, u32, fn(i64, i64) -> [i64; 2]);

/// For every border texel, the texel of the neighbour's block (at the same level of detail)
/// whose centre is this one mirrored across the shared edge, found by searching the whole
/// neighbour block: bytes equal where both blocks have the same resolution.
#[test]
fn borders_are_the_neighbours_texels_across_the_edge() {
    for (name, packed) in [
        ("uniform 4", packed_mesh(2, |_| 4, ColorFormat::Rgba8Srgb, 5)),
        ("mixed", packed_mesh(1, mixed, ColorFormat::Rgba8Srgb, 6)),
    ] {
        let ptex = ptex::build(&packed, MAX_DIM, u64::MAX).unwrap();
        let layout = &ptex.layout;
        let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for (face, c) in packed.indices.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                edge_faces.entry((a.min(b), a.max(b))).or_default().push(face as u32);
            }
        }
        let mut compared = 0u64;
        for (bi, block) in layout.blocks.iter().enumerate() {
            let [t1, p, t2, q] = block.corners;
            // (start, end, owner, border texel of index i at resolution n).
            let sides: [Side; 4] = [
                (t1, p, block.faces[0], |i, _| [i, -1]),
                (p, t2, block.faces[1], |i, n| [n, i]),
                (q, t2, block.faces[1], |i, n| [i, n]),
                (t1, q, block.faces[0], |i, _| [-1, i]),
            ];
            for k in 0..=block.log2 {
                let level = block.log2 - k;
                let n = 1i64 << k;
                let [x0, y0] = layout.tables.origin(bi as u32, k);
                for (a, z, owner, at) in sides {
                    let faces = &edge_faces[&(a.min(z), a.max(z))];
                    let Some(&h) = faces.iter().find(|&&f| f != owner) else { continue };
                    let record = layout.records[h as usize];
                    let other = layout.blocks[record.block() as usize];
                    let k2 = other.log2 - level.min(other.log2);
                    if k2 != k {
                        continue;
                    }
                    let [ox, oy] = layout.tables.origin(record.block(), k2);
                    // The edge's ends in h's block square (t₁ (0, 0), p (1, 0), t₂ (1, 1), q (0, 1)).
                    let [u1, up, u2, uq] = other.corners;
                    let place = |v: u32| -> [f64; 2] {
                        if v == up {
                            [1.0, 0.0]
                        } else if v == uq {
                            [0.0, 1.0]
                        } else if record.second() {
                            assert_eq!(v, u2);
                            [1.0, 1.0]
                        } else {
                            assert_eq!(v, u1);
                            [0.0, 0.0]
                        }
                    };
                    let (pa, pz) = (place(a), place(z));
                    let d = [pz[0] - pa[0], pz[1] - pa[1]];
                    for i in 0..n {
                        let t = (i as f64 + 0.5) / n as f64;
                        // h's texel whose centre lies at square distance t from a along the
                        // edge and half a texel inside h's half, searched over the whole block.
                        let mut best = (f64::MAX, [0i64; 2]);
                        for c in 0..n {
                            for x in 0..n {
                                // h's half, its diagonal included (shared by both halves).
                                if (x + c + 1 > n) != record.second() && x + c + 1 != n {
                                    continue;
                                }
                                let centre = [(x as f64 + 0.5) / n as f64, (c as f64 + 0.5) / n as f64];
                                let rel = [centre[0] - pa[0], centre[1] - pa[1]];
                                let along = rel[0] * d[0] + rel[1] * d[1];
                                let across = (rel[0] * d[1] - rel[1] * d[0]).abs();
                                let miss = (along - t).abs() + (across - 0.5 / n as f64).abs();
                                if miss < best.0 {
                                    best = (miss, [x, c]);
                                }
                            }
                        }
                        if best.0 > 1e-9 {
                            // The edge is h's block diagonal (a lone face's): no row there.
                            continue;
                        }
                        let [bx, by] = at(i, n);
                        let mine = ptex.texel(x0 + 1 + bx, y0 + 1 + by);
                        let theirs = ptex.texel(ox + 1 + best.1[0], oy + 1 + best.1[1]);
                        assert_eq!(mine, theirs, "{name}: block {bi} slice {k} border {i} of edge {a}–{z}");
                        compared += 1;
                    }
                }
            }
        }
        println!("{name}: {compared} border texels compared; {:?}", ptex.stats);
        // Every copied border texel found by the search, and nothing else at equal resolution.
        assert_eq!(compared, ptex.stats.copied_border_texels, "{name}: {:?}", ptex.stats);
    }
}

/// Both faces of every edge at every level: a pair's diagonal reads the same texels, a side
/// between blocks of one resolution reads the same two texel rows (exact, away from the
/// half texel at each end, where the border's corner texel is a mean); the rest (lone
/// diagonals, resolution changes, the corners, levels past a block's last) measured and
/// printed.
#[test]
fn bilinear_agrees_across_edges_between_blocks_of_one_resolution() {
    let packed = packed_mesh(2, mixed, ColorFormat::Rgba32F, 7);
    let ptex = ptex::build(&packed, MAX_DIM, u64::MAX).unwrap();
    let layout = &ptex.layout;
    let mut sides: HashMap<(u32, u32), Vec<(u32, usize)>> = HashMap::new();
    for (face, c) in packed.indices.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            sides.entry((a.min(b), a.max(b))).or_default().push((face as u32, k));
        }
    }
    // [exact, measured] per level.
    let mut worst = [[0.0f32; 2]; 6];
    let mut exact_points = 0u64;
    for ((lo, hi), faces) in &sides {
        let [(f, kf), (g, kg)] = [faces[0], faces[1]];
        let (bf, bg) = (layout.records[f as usize].block(), layout.records[g as usize].block());
        let diagonal = |b: u32| {
            let [_, p, _, q] = layout.blocks[b as usize].corners;
            (p.min(q), p.max(q)) == (*lo, *hi)
        };
        for level in 0..6u32 {
            let n_of = |b: u32| {
                let m = layout.blocks[b as usize].log2;
                1u32 << (m - level.min(m))
            };
            let same_block = bf == bg;
            // Past a block's last level its 1×1 slice stands for every coarser level, and its
            // border is the neighbour's at the block's own last level: measured, not exact.
            let real = |b: u32| level <= layout.blocks[b as usize].log2;
            let sides_alike = !diagonal(bf) && !diagonal(bg) && n_of(bf) == n_of(bg) && real(bf) && real(bg);
            let n = n_of(bf) as f32;
            for step in 0..=64 {
                let t = step as f32 / 64.0;
                let at = |face: u32, k: usize| {
                    let c = packed.indices[face as usize];
                    let mut w = [0.0; 3];
                    let from_lo = c[k] == *lo;
                    w[k] = if from_lo { 1.0 - t } else { t };
                    w[(k + 1) % 3] = if from_lo { t } else { 1.0 - t };
                    ptex.sample_level(face, w, level).unwrap()
                };
                let jump = max_diff(at(f, kf), at(g, kg));
                let inner = t * n >= 0.5 && (1.0 - t) * n >= 0.5;
                let exact = same_block || (sides_alike && inner);
                exact_points += u64::from(exact);
                let slot = &mut worst[level as usize][usize::from(!exact)];
                *slot = slot.max(jump);
            }
        }
    }
    println!("largest jump per level [exact cases, measured cases]: {worst:?}");
    assert!(exact_points > 10_000, "{exact_points}");
    assert!(worst.iter().all(|w| w[0] <= TOLERANCE), "{worst:?}");
}

/// The resampling error of level 0 from the store, per R, in 8-bit steps (sRGB), at random
/// points of random-coloured faces: the packed Ptex's bilinear against mesh colors' linear
/// filter (texel centres are exact; between them a bilinear patch on the pair square is not
/// mesh colors' piecewise-linear one). Held to the figures docs/PTEX.md states.
#[test]
fn resampling_error_per_resolution_in_8_bit_steps() {
    // (R, largest, mean) stated.
    let stated = [(1u64, 165u8, 34.0f64), (2, 165, 31.0), (4, 165, 31.0), (8, 165, 31.0), (16, 165, 31.0)];
    for (resolution, max_steps, mean_steps) in stated {
        let packed = packed_mesh(2, |_| resolution, ColorFormat::Rgba8Srgb, 8 + resolution);
        let ptex = ptex::build(&packed, MAX_DIM, u64::MAX).unwrap();
        let mut rng = Rng(99);
        let (mut worst, mut total, mut count) = (0u8, 0u64, 0u64);
        for face in 0..packed.indices.len() as u32 {
            for _ in 0..64 {
                let (a, b) = (rng.unit(), rng.unit());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let w = [1.0 - a - b, a, b];
                let got = ptex.sample_level(face, w, 0).unwrap();
                let truth = sample(&packed, face, w, Filter::Linear, 0).unwrap();
                let steps = (0..3).map(|c| encode_srgb8(got[c]).abs_diff(encode_srgb8(truth[c]))).max().unwrap();
                worst = worst.max(steps);
                total += u64::from(steps);
                count += 1;
            }
        }
        let mean = total as f64 / count as f64;
        println!("R = {resolution}: largest {worst} steps, mean {mean:.2} steps over {count} points");
        assert!(worst <= max_steps && mean <= mean_steps, "R = {resolution}: {worst}, {mean}");
    }
}

#[test]
fn budgets_are_checked_before_allocating() {
    let packed = packed_mesh(1, |_| 64, ColorFormat::Rgba8Srgb, 9);
    assert!(matches!(ptex::build(&packed, MAX_DIM, 1000), Err(PtexError::OverBudget { .. })));
    assert!(matches!(ptex::build(&packed, 32, u64::MAX), Err(PtexError::AtlasTooLarge { .. })));
}
