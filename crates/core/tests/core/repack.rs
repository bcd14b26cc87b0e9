//! The fast packer and the incremental repack against the straightforward serial packer
//! (`packing::reference`), byte for byte: mixed resolutions, boundary and non-manifold
//! edges, every format; random strokes and resolution changes. And the RGBA8 sRGB encoder
//! against the exact (f64) transfer function on every f32 in [0, 1].

use crate::common;
use crate::common::WriteThrough;
use common::{Rng, icosphere, octahedron};
use meshpaint_core::colors::format::{ColorFormat, encode_srgb8};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, DirtyAccumulator, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::packer::{PackCache, pack};
use meshpaint_core::packing::reference::pack_reference;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

fn random_store(topology: Topology, resolutions: Vec<Resolution>, seed: u64) -> ColorStore {
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    // Values past 1 too (HDR channels), so RGBA8 clamps and 16F rounds.
    store.write_all(|_| [rng.unit() * 1.5, rng.unit(), rng.unit() * 0.01, 0.5 + 0.5 * rng.unit()]);
    store.take_dirty();
    store
}

/// Three fins on one edge (non-manifold), one more face, boundary edges elsewhere.
fn fins() -> (Vec<[f32; 3]>, Topology) {
    let positions =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 0.0, 1.0], [1.5, 1.0, 0.0]];
    let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]];
    (positions, Topology::build(6, &triangles).unwrap())
}

/// Meshes of every kind: mixed resolutions (coarse faces next to fine edges), uniform,
/// non-manifold, and a larger sphere with random resolutions (more than one parallel block).
fn cases() -> Vec<(&'static str, Vec<[f32; 3]>, ColorStore)> {
    let mut out = Vec::new();
    let (positions, topology) = octahedron();
    out.push(("octahedron mixed", positions, random_store(topology, [1, 2, 4, 8, 16, 4, 1, 32].map(r).to_vec(), 1)));
    let (positions, topology) = fins();
    out.push(("fins", positions.clone(), random_store(topology.clone(), [8, 2, 4, 16].map(r).to_vec(), 2)));
    // Three fins of one resolution on one edge: the edge filter's path for more than two faces.
    out.push(("fins of one resolution", positions, random_store(topology, [8, 8, 8, 16].map(r).to_vec(), 6)));
    let (positions, triangles) = icosphere(3);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let faces = topology.face_count() as usize;
    out.push(("icosphere uniform 8", positions.clone(), random_store(topology.clone(), vec![r(8); faces], 3)));
    let mut rng = Rng(4);
    let resolutions = (0..faces).map(|_| r(1 << (rng.next() % 5))).collect();
    out.push(("icosphere random", positions, random_store(topology, resolutions, 5)));
    out
}

#[test]
fn fast_pack_is_byte_equal_to_the_reference_packer() {
    for (name, positions, store) in cases() {
        for format in ColorFormat::ALL {
            let fast = pack(&store, &positions, format).unwrap();
            let reference = pack_reference(&store, &positions, format).unwrap();
            assert_eq!(fast.face_records, reference.face_records, "{name} {format:?}");
            assert_eq!(fast.vertex_levels, reference.vertex_levels, "{name} {format:?}");
            assert!(fast.colors == reference.colors, "{name} {format:?}: colour bytes differ");
            assert_eq!(fast, reference, "{name} {format:?}");
        }
    }
}

/// Paints a random "stroke": every sample of a few faces around a random face (their
/// vertices, edges and interiors), as a brush would.
fn stroke(store: &mut ColorStore, rng: &mut Rng) {
    let topology = store.topology().clone();
    let faces = topology.face_count();
    let center = (rng.next() % u64::from(faces)) as u32;
    let count = 1 + rng.next() % 4;
    let color = [rng.unit(), rng.unit(), rng.unit(), rng.unit()];
    for n in 0..count as u32 {
        let face = (center + n * 7) % faces;
        for &v in &topology.face_vertices[face as usize] {
            store.write_sample(SampleRef::Vertex(v), color);
        }
        for &edge in &topology.face_edges[face as usize] {
            for offset in 0..store.edge_samples(edge).len() as u32 {
                store.write_sample(SampleRef::Edge { edge, offset }, [color[0], rng.unit(), color[2], 1.0]);
            }
        }
        for offset in 0..store.interior_samples(face).len() as u32 {
            store.write_sample(SampleRef::Interior { face, offset }, [rng.unit(), color[1], color[2], 1.0]);
        }
    }
    // Sometimes a single sample only (a tiny dab).
    if rng.next().is_multiple_of(3) {
        let v = (rng.next() % u64::from(topology.vertex_count)) as u32;
        store.write_sample(SampleRef::Vertex(v), [0.25, 0.5, 0.75, 1.0]);
    }
}

#[test]
fn incremental_repack_after_random_strokes_equals_a_full_repack() {
    for (name, positions, mut store) in cases() {
        for format in ColorFormat::ALL {
            let mut rng = Rng(11 + format.code() as u64);
            let mut cache = PackCache::build(&store, &positions, format).unwrap();
            let mut accumulated = DirtyAccumulator::new(store.topology());
            for round in 0..6 {
                // Several dabs per session, dirty taken after each (as paint mode does).
                for _ in 0..3 {
                    stroke(&mut store, &mut rng);
                    accumulated.add(&store.take_dirty());
                }
                let dirty = accumulated.take();
                let ranges = cache.update(&store, &dirty).expect("no resolution changed");
                let reference = pack_reference(&store, &positions, format).unwrap();
                assert!(cache.packed().colors == reference.colors, "{name} {format:?} round {round}: bytes differ");
                assert_eq!(*cache.packed(), reference, "{name} {format:?} round {round}");
                // The ranges cover every byte that changed (and stay inside the buffer).
                let samples = reference.sample_count();
                assert!(ranges.iter().all(|&(first, count)| count > 0 && first + count <= samples));
            }
        }
    }
}

#[test]
fn incremental_ranges_cover_every_changed_sample() {
    for (name, positions, mut store) in cases() {
        let format = ColorFormat::Rgba32F;
        let mut rng = Rng(99);
        let mut cache = PackCache::build(&store, &positions, format).unwrap();
        for _ in 0..5 {
            let before = cache.packed().colors.clone();
            stroke(&mut store, &mut rng);
            let ranges = cache.update(&store, &store.clone().take_dirty()).unwrap();
            store.take_dirty();
            let size = format.bytes_per_sample();
            let after = &cache.packed().colors;
            for sample in 0..(after.len() / size) as u64 {
                let at = sample as usize * size;
                if before[at..at + size] != after[at..at + size] {
                    assert!(
                        ranges.iter().any(|&(first, count)| (first..first + count).contains(&sample)),
                        "{name}: sample {sample} changed outside the reported ranges"
                    );
                }
            }
        }
    }
}

#[test]
fn a_resolution_change_asks_for_a_full_repack_and_that_matches_the_reference() {
    for (name, positions, mut store) in cases() {
        let format = ColorFormat::Rgba8Srgb;
        let mut rng = Rng(21);
        let mut cache = PackCache::build(&store, &positions, format).unwrap();
        for _ in 0..4 {
            let face = (rng.next() % u64::from(store.topology().face_count())) as u32;
            let old = store.face_resolution(face).unwrap();
            let new = if old.log2() >= 4 { old.halved().unwrap() } else { old.doubled().unwrap() };
            store.write_resolution(face, new).unwrap();
            stroke(&mut store, &mut rng);
            let dirty = store.take_dirty();
            assert!(cache.update(&store, &dirty).is_none(), "{name}: a resolution change must not be patched");
            // The editor's path: the full repack into the old packing's buffers.
            cache = cache.rebuild(&store, &positions, format).unwrap();
            assert_eq!(*cache.packed(), pack_reference(&store, &positions, format).unwrap(), "{name}");
            // And an R change followed by strokes only: incremental again.
            stroke(&mut store, &mut rng);
            let dirty = store.take_dirty();
            cache.update(&store, &dirty).expect("no resolution changed");
            assert_eq!(*cache.packed(), pack_reference(&store, &positions, format).unwrap(), "{name}");
        }
    }
}

#[test]
fn a_relayout_after_resolution_changes_equals_the_reference_packer() {
    // What leaving paint mode runs after a resolution stroke: several edits accumulated
    // (resolutions up and down, past the largest and below it, strokes between), then the
    // relayout that copies every chain no edit reached. The serial reference packer is the
    // truth; an incremental update after it checks the state it keeps.
    for (name, positions, store) in cases() {
        for format in ColorFormat::ALL {
            let mut store = store.clone();
            let mut rng = Rng(31 + format.code() as u64);
            let mut cache = PackCache::build(&store, &positions, format).unwrap();
            let faces = u64::from(store.topology().face_count());
            for round in 0..5 {
                let mut accumulated = DirtyAccumulator::new(store.topology());
                for _ in 0..2 {
                    let center = (rng.next() % faces) as u32;
                    for n in 0..1 + rng.next() % 3 {
                        let face = ((u64::from(center) + n * 5) % faces) as u32;
                        let old = store.face_resolution(face).unwrap();
                        let new = match rng.next() % 3 {
                            0 if old.log2() > 0 => old.halved().unwrap(),
                            1 => r(64),
                            _ => old.doubled().unwrap_or(old),
                        };
                        store.write_resolution(face, new).unwrap();
                    }
                    accumulated.add(&store.take_dirty());
                    stroke(&mut store, &mut rng);
                    accumulated.add(&store.take_dirty());
                }
                if round % 2 == 1 {
                    // Every face at the largest resolution halved: fewer vertex levels.
                    let largest = store.face_resolutions().iter().copied().max().unwrap();
                    for face in 0..faces as u32 {
                        if store.face_resolution(face) == Some(largest) && largest.log2() > 0 {
                            store.write_resolution(face, largest.halved().unwrap()).unwrap();
                        }
                    }
                    accumulated.add(&store.take_dirty());
                }
                cache = cache.relayout(&store, &positions, &accumulated.take()).unwrap();
                let reference = pack_reference(&store, &positions, format).unwrap();
                assert!(cache.packed().colors == reference.colors, "{name} {format:?} round {round}: bytes differ");
                assert_eq!(*cache.packed(), reference, "{name} {format:?} round {round}");
                // And the `f32` chains it keeps for the next repack are a fresh build's.
                assert!(cache == PackCache::build(&store, &positions, format).unwrap(), "{name} {round}: chains");
                stroke(&mut store, &mut rng);
                cache.update(&store, &store.clone().take_dirty()).expect("no resolution changed");
                store.take_dirty();
                assert!(*cache.packed() == pack_reference(&store, &positions, format).unwrap(), "{name} {round}");
            }
        }
    }
}

#[test]
fn a_relayout_from_one_vertex_level_and_back_to_the_same_layout_equals_a_fresh_build() {
    // Every face at R = 1 (one vertex level, no edge or interior samples), some zero
    // channels; faces raised to 4, then the same faces back to 1 (the layout of before).
    let (positions, triangles) = icosphere(2);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let faces = topology.face_count();
    let mut store = random_store(topology, vec![r(1); faces as usize], 41);
    let mut k = 0;
    store.write_all(|_| {
        k += 1;
        if k % 3 == 0 { [0.0, 0.5, 0.0, 1.0] } else { [0.25, 0.0, 1.0, 0.0] }
    });
    store.take_dirty();
    for format in ColorFormat::ALL {
        let mut store = store.clone();
        let mut cache = PackCache::build(&store, &positions, format).unwrap();
        for target in [r(4), r(1)] {
            for face in (0..faces).step_by(7) {
                store.write_resolution(face, target).unwrap();
            }
            cache = cache.relayout(&store, &positions, &store.clone().take_dirty()).unwrap();
            store.take_dirty();
            assert_eq!(*cache.packed(), pack_reference(&store, &positions, format).unwrap(), "{format:?} {target:?}");
            assert!(cache == PackCache::build(&store, &positions, format).unwrap(), "{format:?} {target:?}: chains");
        }
    }
}

#[test]
fn a_repack_into_reused_buffers_equals_the_reference_packer_whatever_they_held() {
    // Every case into the buffers of every case (smaller and larger, other formats, other
    // random colours): a sample the pack did not rewrite would keep the old colour.
    let cases = cases();
    for (old_name, old_positions, old_store) in &cases {
        for old_format in ColorFormat::ALL {
            for (name, positions, store) in &cases {
                for format in ColorFormat::ALL {
                    let old = PackCache::build(old_store, old_positions, old_format).unwrap();
                    let rebuilt = old.rebuild(store, positions, format).unwrap();
                    let reference = pack_reference(store, positions, format).unwrap();
                    assert!(*rebuilt.packed() == reference, "{name} {format:?} into {old_name} {old_format:?}");
                    // And it still repacks incrementally.
                    let mut store = store.clone();
                    let mut rebuilt = rebuilt;
                    stroke(&mut store, &mut Rng(7));
                    rebuilt.update(&store, &store.clone().take_dirty()).expect("no resolution changed");
                    assert!(*rebuilt.packed() == pack_reference(&store, positions, format).unwrap(), "{name}");
                }
            }
        }
    }
}

#[test]
fn an_empty_edit_changes_nothing() {
    let (_, positions, store) = cases().remove(0);
    let mut cache = PackCache::build(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let before = cache.packed().clone();
    let mut store = store;
    let dirty = store.take_dirty();
    let ranges = cache.update(&store, &dirty).unwrap();
    assert!(ranges.is_empty());
    assert_eq!(*cache.packed(), before);
}

/// The exact code: the f64 transfer function, rounded to nearest. Panics when the value
/// is within f64 noise of a rounding boundary (no f32 lands there: the check would be
/// undecided).
fn exact_srgb8(linear: f32) -> u8 {
    let x = f64::from(linear).clamp(0.0, 1.0);
    let encoded = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
    let scaled = encoded * 255.0;
    assert!((scaled - scaled.floor() - 0.5).abs() > 1e-12, "{linear:e} is too near a boundary to decide");
    (scaled + 0.5).floor() as u8
}

/// The RGBA8 encoder, through the slice encoder the packer runs (AVX2 where the CPU has
/// it) and the scalar one, on every f32 in `[0, 1]` (1,065,353,217 values) in every
/// channel. Alpha against the f32 product `x · 255` rounded half away from zero (the
/// linear 8-bit unorm the encoder has always written). RGB against the f64 transfer function: both it and the
/// encoder are monotonic, so checking that the encoder's code never falls, never rises by
/// more than one between neighbouring f32s, starts at the exact code of 0, and equals the
/// exact code on both sides of every rise, proves it equal to the exact code on every f32
/// (between two rises both are constant). The decoded copy against the f64 decode.
#[test]
fn srgb8_encoder_equals_the_exact_formula_on_every_f32_in_0_1() {
    use rayon::prelude::*;
    let one = 1.0f32.to_bits();
    let decode: Vec<f32> = (0..256)
        .map(|b| {
            let e = f64::from(b) / 255.0;
            (if e <= 0.040_45 { e / 12.92 } else { ((e + 0.055) / 1.055).powf(2.4) }) as f32
        })
        .collect();
    const CHUNK: u32 = 1 << 16;
    let rises: u32 = (0..=one / CHUNK)
        .into_par_iter()
        .map(|chunk| {
            // Each chunk starts one f32 early, so the rise between chunks is inside one.
            let first = (chunk * CHUNK).saturating_sub(1);
            let end = ((chunk + 1) * CHUNK).min(one + 1);
            let values: Vec<f32> = (first..end).map(f32::from_bits).collect();
            let colors: Vec<[f32; 4]> = values.iter().map(|&x| [x; 4]).collect();
            let mut bytes = vec![0u8; 4 * colors.len()];
            let mut decoded = vec![[0.0f32; 4]; colors.len()];
            ColorFormat::Rgba8Srgb.encode_quantized_slice(&colors, &mut bytes, &mut decoded);
            let mut rises = 0;
            for (i, (&x, code)) in values.iter().zip(bytes.chunks_exact(4)).enumerate() {
                let alpha = (x * 255.0).round() as u8;
                assert_eq!(code[3], alpha, "alpha {x:e}");
                assert_eq!(decoded[i][3].to_bits(), ((f64::from(alpha) / 255.0) as f32).to_bits(), "{x:e}");
                assert!(code[0] == code[1] && code[1] == code[2], "{x:e}: {code:?}");
                assert_eq!(encode_srgb8(x), code[0], "scalar {x:e}");
                assert_eq!(decoded[i][0].to_bits(), decode[usize::from(code[0])].to_bits(), "{x:e}");
                if i == 0 {
                    continue;
                }
                let before = bytes[4 * (i - 1)];
                assert!(
                    code[0] == before || code[0] == before + 1,
                    "{x:e} ({:#010x}): {before} → {}",
                    x.to_bits(),
                    code[0]
                );
                if code[0] != before {
                    assert_eq!(exact_srgb8(values[i - 1]), before, "below the rise at {x:e}");
                    assert_eq!(exact_srgb8(x), code[0], "at the rise at {x:e}");
                    rises += 1;
                }
            }
            rises
        })
        .sum();
    assert_eq!(rises, 255, "every code from 0 to 255 reached in steps of one");
    assert_eq!(exact_srgb8(0.0), 0);
    assert_eq!(encode_srgb8(0.0), 0);
    assert_eq!(encode_srgb8(f32::NAN), 0);
    assert_eq!(encode_srgb8(-1.0), 0);
    assert_eq!(encode_srgb8(7.0), 255);
}
