//! The packer and the CPU reference sampler against independent truths: pack/unpack
//! identity, store-vs-packed sampling, MIP values evaluated directly from thesis eq. 2.5
//! and 2.6 on hand-built meshes with boundary and non-manifold edges, and buffer bounds.

// Colour channels are indexed 0..4 in parallel arrays; an index reads clearest.
#![allow(clippy::needless_range_loop)]

use crate::common;
use crate::common::WriteThrough;
use common::{Rng, octahedron};
use meshpaint_core::colors::format::{ColorFormat, Rgba, decode_rgba8_srgb, encode_rgba8_srgb};
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::{PackError, pack};
use meshpaint_core::packing::sampler::{Filter, MeshColorSource, packed_sample_index, sample};
use meshpaint_core::packing::unpack::unpack;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// Three fins on edge (0, 1) (non-manifold), one face sharing edge (1, 2) with fin 0
/// (manifold), every other edge a boundary edge.
fn fins() -> (Vec<[f32; 3]>, Topology) {
    let positions =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 0.0, 1.0], [1.5, 1.0, 0.0]];
    let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]];
    (positions, Topology::build(6, &triangles).unwrap())
}

fn random_store(topology: Topology, resolutions: Vec<Resolution>, seed: u64) -> ColorStore {
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| [rng.unit(), rng.unit(), rng.unit(), 0.5 + 0.5 * rng.unit()]);
    store
}

fn mixed_octahedron_store(seed: u64) -> (Vec<[f32; 3]>, ColorStore) {
    let (positions, topology) = octahedron();
    let resolutions = [1, 2, 4, 8, 16, 4, 1, 32].map(r).to_vec();
    (positions, random_store(topology, resolutions, seed))
}

#[test]
fn rgba8_srgb_round_trips_every_byte() {
    for value in 0..=255u8 {
        let bytes = [value, value, value, value];
        assert_eq!(encode_rgba8_srgb(decode_rgba8_srgb(bytes)), bytes);
    }
}

/// RGBA16F decoding (what the packer's filters and the sampler read) against `half`'s
/// conversion for every one of the 65,536 binary16 bit patterns, in every channel, bit for
/// bit: subnormals, both zeros, infinities and NaNs (quiet, payload kept) included.
#[test]
fn rgba16f_decoding_equals_half_on_every_bit_pattern() {
    use half::f16;
    for h in 0..=u16::MAX {
        let want = f16::from_bits(h).to_f32().to_bits();
        assert_eq!(meshpaint_core::colors::format::f16_bits_to_f32(h).to_bits(), want, "{h:#06x}");
        for channel in 0..4 {
            let mut bytes = [0u8; 8];
            bytes[2 * channel..2 * channel + 2].copy_from_slice(&h.to_le_bytes());
            let decoded = ColorFormat::Rgba16F.decode(&bytes);
            let vector = ColorFormat::Rgba16F.decode_vec4(&bytes).to_array();
            assert_eq!(decoded[channel].to_bits(), want, "{h:#06x} in channel {channel}");
            assert_eq!(vector[channel].to_bits(), want, "{h:#06x} in channel {channel} (vector)");
        }
    }
}

/// RGBA16F encoding (F16C where the CPU has it) against the rounding rule itself, not
/// another converter: every channel's half is a nearest half to the clamped value (checked
/// in `f64` against the halves on either side) and on a tie the even one. Inputs: every
/// 997th f32 bit pattern up to 65,504, every midpoint between neighbouring halves and the
/// f32 on either side of it, in every channel position of an odd-length slice (the vector
/// path's odd last sample runs too); the decoded copy is the half's value.
#[test]
fn rgba16f_encoding_rounds_to_the_nearest_half_ties_to_even() {
    use half::f16;
    let top = 65504.0f32.to_bits();
    let mut values: Vec<f32> = (0..=top).step_by(997).map(f32::from_bits).collect();
    for h in 0..0x7bffu16 {
        let mid = ((f16::from_bits(h).to_f64() + f16::from_bits(h + 1).to_f64()) / 2.0) as f32;
        values.extend([mid.next_down(), mid, mid.next_up()]);
    }
    let colors: Vec<Rgba> =
        (0..values.len() | 1).map(|i| std::array::from_fn(|c| values[(i + c) % values.len()])).collect();
    let mut bytes = vec![0u8; colors.len() * 8];
    let mut decoded = vec![[0.0f32; 4]; colors.len()];
    ColorFormat::Rgba16F.encode_quantized_slice(&colors, &mut bytes, &mut decoded);
    let value = |h: u16| f16::from_bits(h).to_f64();
    for (i, color) in colors.iter().enumerate() {
        for c in 0..4 {
            let x = f64::from(color[c].min(if c == 3 { 1.0 } else { 65504.0 }));
            let h = u16::from_le_bytes([bytes[8 * i + 2 * c], bytes[8 * i + 2 * c + 1]]);
            let error = (x - value(h)).abs();
            for neighbour in [h.checked_sub(1), h.checked_add(1)].into_iter().flatten() {
                let other = (x - value(neighbour)).abs();
                assert!(
                    error < other || (error == other && h.is_multiple_of(2)),
                    "{x} → {h:#06x}, {neighbour:#06x} is nearer or even"
                );
            }
            assert_eq!(decoded[i][c].to_bits(), f16::from_bits(h).to_f32().to_bits(), "decoded {h:#06x}");
        }
    }
}

/// Every format's slice encoders against one channel at a time, on the extremes: NaN,
/// infinities, negatives, subnormals of f32 and of f16, the f16 rounding boundary at the top
/// (65 519.996 rounds down, 65 520 would round to infinity), values past 1 in alpha, and runs
/// that are not a multiple of the encoders' batch sizes.
#[test]
fn slice_encoders_equal_one_channel_at_a_time_on_the_extremes() {
    use half::f16;
    let values = [
        0.0,
        -0.0,
        -1.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::from_bits(1),
        f32::MIN_POSITIVE,
        1e-8,
        5.96e-8,
        6.0e-5,
        6.1e-5,
        1.0 / 3.0,
        0.5,
        1.0,
        1.0000001,
        2.0,
        65504.0,
        65519.996,
        65520.0,
        1e9,
    ];
    // Independent of the crate's clamp: R, G, B to [0, 65504], alpha to [0, 1], NaN and
    // every zero or negative (−0 included) to +0.
    let clamp = |x: f32, max: f32| if x.is_nan() || x <= 0.0 { 0.0 } else { x.min(max) };
    for len in [1usize, 7, 31, 32, 33, 77] {
        let colors: Vec<Rgba> =
            (0..len).map(|i| std::array::from_fn(|c| values[(i * 4 + c * 7 + i / 3) % values.len()])).collect();
        for format in ColorFormat::ALL {
            let size = format.bytes_per_sample();
            let mut bytes = vec![0u8; len * size];
            let mut quantized = vec![[9.0f32; 4]; len];
            format.encode_quantized_slice(&colors, &mut bytes, &mut quantized);
            let mut plain = vec![0u8; len * size];
            format.encode_slice(&colors, &mut plain);
            assert_eq!(plain, bytes, "{format:?} len {len}: encode_slice vs encode_quantized_slice");
            for (i, color) in colors.iter().enumerate() {
                let clamped: Rgba = std::array::from_fn(|c| clamp(color[c], if c == 3 { 1.0 } else { 65504.0 }));
                let (want_bytes, want_value): (Vec<u8>, Rgba) = match format {
                    ColorFormat::Rgba8Srgb => {
                        let b = encode_rgba8_srgb(clamped);
                        (b.to_vec(), decode_rgba8_srgb(b))
                    }
                    ColorFormat::Rgba16F => {
                        let h = clamped.map(f16::from_f32);
                        (h.iter().flat_map(|h| h.to_bits().to_le_bytes()).collect(), h.map(f16::to_f32))
                    }
                    ColorFormat::Rgba32F => (clamped.iter().flat_map(|c| c.to_le_bytes()).collect(), clamped),
                };
                assert_eq!(&bytes[i * size..(i + 1) * size], &want_bytes[..], "{format:?} {color:?}");
                assert_eq!(quantized[i].map(f32::to_bits), want_value.map(f32::to_bits), "{format:?} {color:?}");
                assert_eq!(format.decode(&want_bytes).map(f32::to_bits), want_value.map(f32::to_bits));
                assert_eq!(format.decode_vec4(&want_bytes).to_array().map(f32::to_bits), want_value.map(f32::to_bits));
            }
        }
    }
}

#[test]
fn pack_unpack_pack_is_the_identity_for_every_format() {
    let (positions, store) = mixed_octahedron_store(5);
    for format in ColorFormat::ALL {
        let packed = pack(&store, &positions, format).unwrap();
        assert_eq!(pack(&store, &positions, format).unwrap(), packed, "packing is deterministic");
        let unpacked = unpack(&packed).unwrap();
        let repacked = pack(&unpacked, &positions, format).unwrap();
        assert_eq!(repacked, packed, "{format:?}");
        assert_eq!(packed.face_record_bytes(), 16 * 8);
        // Level 0 round trip: bit-exact for RGBA32F, within quantisation otherwise.
        let mut worst = 0.0f32;
        store.for_each_site(|site| {
            let a = store.get(site.sample).unwrap();
            let b = unpacked.get(site.sample).unwrap();
            for c in 0..4 {
                worst = worst.max((a[c] - b[c]).abs());
            }
        });
        match format {
            ColorFormat::Rgba32F => assert_eq!(worst, 0.0),
            ColorFormat::Rgba16F => assert!(worst <= 1.0 / 2048.0, "{worst}"),
            ColorFormat::Rgba8Srgb => assert!(worst <= 0.5 * 0.0132, "{worst}"), // half the largest sRGB step
        }
    }
}

#[test]
fn sampler_on_packed_buffers_equals_the_sampler_on_the_store() {
    let (positions, store) = mixed_octahedron_store(9);
    let packed = pack(&store, &positions, ColorFormat::Rgba32F).unwrap();
    let packed8 = pack(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let mut rng = Rng(3);
    for face in 0..8 {
        for _ in 0..400 {
            let (a, b) = (rng.unit(), rng.unit());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let bary = [1.0 - a - b, a, b];
            for filter in [Filter::Nearest, Filter::Linear] {
                let truth = sample(&store, face, bary, filter, 0).unwrap();
                assert_eq!(sample(&packed, face, bary, filter, 0).unwrap(), truth, "face {face} {filter:?}");
                let quantised = sample(&packed8, face, bary, filter, 0).unwrap();
                for c in 0..4 {
                    assert!((quantised[c] - truth[c]).abs() <= 0.0066, "RGBA8 face {face}");
                }
            }
        }
    }
}

#[test]
fn every_packed_lookup_stays_inside_the_colour_buffer() {
    let (positions, store) = mixed_octahedron_store(2);
    let packed = pack(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    for face in 0..8 {
        let rf = packed.face_resolution(face).unwrap();
        for level in 0..=rf.log2() + 2 {
            let rl = rf.get() >> level.min(rf.log2());
            for i in 0..=rl {
                for j in 0..=rl - i {
                    let index = packed_sample_index(&packed, face, level, i, j).unwrap();
                    assert!(index < packed.sample_count(), "face {face} level {level} ({i}, {j})");
                }
            }
        }
    }
}

#[test]
fn faces_of_different_resolution_agree_on_shared_edges_at_every_level() {
    let (positions, store) = mixed_octahedron_store(4);
    let packed = pack(&store, &positions, ColorFormat::Rgba32F).unwrap();
    let topology = store.topology();
    for edge in 0..topology.edge_count() {
        let faces = topology.faces_of_edge(edge);
        let [lower, _] = topology.edge_vertices[edge as usize];
        let coarsest = faces.iter().map(|&(f, _)| store.face_resolution(f).unwrap()).min().unwrap();
        for level in 0..=coarsest.log2() {
            let steps = coarsest.get() >> level;
            for step in 0..=steps {
                let colors: Vec<Rgba> = faces
                    .iter()
                    .map(|&(face, k)| {
                        let rf = store.face_resolution(face).unwrap().at_level(level).unwrap();
                        let scale = rf.get() / steps;
                        let from_start = topology.face_vertices[face as usize][usize::from(k)] == lower;
                        let along = if from_start { step } else { steps - step } * scale;
                        let (i, j) = layout::edge_sample_coords(rf, k, along);
                        packed.lattice_color(face, level, i, j).unwrap()
                    })
                    .collect();
                assert!(colors.windows(2).all(|w| w[0] == w[1]), "edge {edge} level {level} step {step}");
            }
        }
    }
}

fn close(a: Rgba, b: Rgba) -> bool {
    (0..4).all(|c| (a[c] - b[c]).abs() <= 1e-6)
}

/// Direct evaluation of eq. 2.5 / 2.6 for level `level` of a uniform-resolution mesh,
/// reading level `level − 1` through the packed sampler (level 0 through the store).
#[test]
fn mip_levels_match_thesis_equations_on_boundary_manifold_and_nonmanifold_edges() {
    let (positions, topology) = fins();
    let resolution = r(8);
    let store = random_store(topology.clone(), vec![resolution; 4], 17);
    let packed = pack(&store, &positions, ColorFormat::Rgba32F).unwrap();
    let previous = |face: u32, level: u32, i: u32, j: u32| packed.lattice_color(face, level - 1, i, j).unwrap();
    let mut checked = (0, 0, 0, 0, 0);
    for level in 1..=resolution.log2() {
        let rl = resolution.get() >> level;
        for face in 0..topology.face_count() {
            // Interior samples, eq. 2.6: ¼(C + ½ Σ six neighbours).
            for i in 1..rl {
                for j in 1..rl.saturating_sub(i) {
                    let (ci, cj) = (2 * i, 2 * j);
                    let n = [
                        previous(face, level, ci, cj - 1),
                        previous(face, level, ci, cj + 1),
                        previous(face, level, ci - 1, cj),
                        previous(face, level, ci - 1, cj + 1),
                        previous(face, level, ci + 1, cj - 1),
                        previous(face, level, ci + 1, cj),
                    ];
                    let c = previous(face, level, ci, cj);
                    let expected: Rgba = std::array::from_fn(|ch| {
                        0.25 * (c[ch] + 0.5 * (n[0][ch] + n[1][ch] + n[2][ch] + n[3][ch] + n[4][ch] + n[5][ch]))
                    });
                    assert!(close(packed.lattice_color(face, level, i, j).unwrap(), expected));
                    checked.0 += 1;
                }
            }
        }
        // Edge samples: centre, two along the edge, two inside each incident face.
        for edge in 0..topology.edge_count() {
            let faces = topology.faces_of_edge(edge);
            let (face0, k0) = faces[0];
            for position in 1..rl {
                // Walk from face0's point of view; other faces map the same physical point.
                let [lower, _] = topology.edge_vertices[edge as usize];
                let canonical = if topology.face_vertices[face0 as usize][usize::from(k0)] == lower {
                    position
                } else {
                    rl - position
                };
                let mut neighbour_sum = [0.0f32; 4];
                let mut count = 0;
                let mut center = [0.0f32; 4];
                for (n, &(face, k)) in faces.iter().enumerate() {
                    let from_start = topology.face_vertices[face as usize][usize::from(k)] == lower;
                    let along = 2 * if from_start { canonical } else { rl - canonical };
                    let fine = Resolution::new(u64::from(2 * rl)).unwrap();
                    let (pi, pj) = layout::edge_sample_coords(fine, k, along);
                    if n == 0 {
                        center = previous(face, level, pi, pj);
                        let (ai, aj) = layout::edge_sample_coords(fine, k, along - 1);
                        let (bi, bj) = layout::edge_sample_coords(fine, k, along + 1);
                        for c in 0..4 {
                            neighbour_sum[c] += previous(face, level, ai, aj)[c] + previous(face, level, bi, bj)[c];
                        }
                        count += 2;
                    }
                    // The two lattice neighbours strictly inside this face.
                    let inside: Vec<(u32, u32)> = [(1i32, 0i32), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)]
                        .iter()
                        .map(|&(di, dj)| (pi as i32 + di, pj as i32 + dj))
                        .filter(|&(a, b)| a >= 1 && b >= 1 && ((a + b) as u32) < 2 * rl)
                        .map(|(a, b)| (a as u32, b as u32))
                        .collect();
                    assert_eq!(inside.len(), 2);
                    for (a, b) in inside {
                        for c in 0..4 {
                            neighbour_sum[c] += previous(face, level, a, b)[c];
                        }
                        count += 1;
                    }
                }
                let expected: Rgba =
                    std::array::from_fn(|c| (center[c] + 0.5 * neighbour_sum[c]) / (1.0 + 0.5 * count as f32));
                let (fi, fj) = layout::edge_sample_coords(Resolution::new(u64::from(rl)).unwrap(), k0, position);
                assert!(close(packed.lattice_color(face0, level, fi, fj).unwrap(), expected), "edge {edge}");
                match faces.len() {
                    1 => checked.1 += 1,
                    2 => checked.2 += 1,
                    _ => checked.3 += 1,
                }
            }
        }
        // Vertices, eq. 2.5: 2/(2+v) (C + ½ Σ adjacent edge samples), v = valence.
        for v in 0..topology.vertex_count {
            let (face, corner) = topology
                .face_vertices
                .iter()
                .enumerate()
                .find_map(|(f, c)| c.iter().position(|&x| x == v).map(|k| (f as u32, k)))
                .unwrap();
            let fine = 2 * rl;
            let corner_ij = [(0, 0), (fine, 0), (0, fine)][corner];
            let c = previous(face, level, corner_ij.0, corner_ij.1);
            let mut sum = [0.0f32; 4];
            let mut valence = 0;
            for edge in 0..topology.edge_count() {
                let [a, b] = topology.edge_vertices[edge as usize];
                if a != v && b != v {
                    continue;
                }
                let (f, k) = topology.faces_of_edge(edge)[0];
                let from_start = topology.face_vertices[f as usize][usize::from(k)] == v;
                let along = if from_start { 1 } else { fine - 1 };
                let (i, j) = layout::edge_sample_coords(Resolution::new(u64::from(fine)).unwrap(), k, along);
                for ch in 0..4 {
                    sum[ch] += previous(f, level, i, j)[ch];
                }
                valence += 1;
            }
            assert_eq!(valence, topology.vertex_valence[v as usize]);
            let expected: Rgba = std::array::from_fn(|ch| 2.0 / (2.0 + valence as f32) * (c[ch] + 0.5 * sum[ch]));
            let rl_res = Resolution::new(u64::from(rl)).unwrap();
            let (ci, cj) = [(0, 0), (rl_res.get(), 0), (0, rl_res.get())][corner];
            assert!(close(packed.lattice_color(face, level, ci, cj).unwrap(), expected), "vertex {v} level {level}");
            checked.4 += 1;
        }
    }
    let (interior, boundary, manifold, nonmanifold, vertices) = checked;
    assert!(interior > 0 && boundary > 0 && manifold > 0 && nonmanifold > 0 && vertices > 0, "{checked:?}");
}

#[test]
fn resolution_one_everywhere_packs_vertex_colours_only() {
    let (positions, topology) = octahedron();
    let store = random_store(topology, vec![Resolution::ONE; 8], 1);
    let packed = pack(&store, &positions, ColorFormat::Rgba32F).unwrap();
    assert_eq!((packed.vertex_levels, packed.sample_count()), (1, 6));
    for v in 0..6 {
        assert_eq!(packed.color(u64::from(v)), store.get(SampleRef::Vertex(v)));
    }
}

#[test]
fn largest_resolution_next_to_resolution_one_packs_and_samples() {
    let topology = Topology::build(4, &[[0, 1, 2], [1, 0, 3]]).unwrap();
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]];
    let mut store = random_store(topology, vec![Resolution::ONE; 2], 8);
    store.write_resolution(0, Resolution::MAX).unwrap();
    let packed = pack(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let n = u64::from(Resolution::MAX.get());
    let expected = 4 * 13
        + 3 * u64::from(layout::edge_chain_len(Resolution::MAX))
        + u64::from(layout::interior_chain_len(Resolution::MAX));
    assert_eq!(packed.sample_count(), expected);
    assert!(expected > (n - 1) * (n - 2) / 2);
    for bary in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.2, 0.3, 0.5], [0.0, 0.5, 0.5]] {
        for level in [0, 5, 12, 13] {
            for face in 0..2 {
                let color = sample(&packed, face, bary, Filter::Linear, level).unwrap();
                assert!(color.iter().all(|c| c.is_finite()));
            }
        }
    }
    let round = unpack(&packed).unwrap();
    assert_eq!(pack(&round, &positions, ColorFormat::Rgba8Srgb).unwrap(), packed);
}

#[test]
fn unpack_refuses_non_canonical_buffers() {
    let (positions, store) = mixed_octahedron_store(1);
    let packed = pack(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let mut moved = packed.clone();
    moved.face_records[3].edges[1] ^= 1;
    assert!(matches!(unpack(&moved), Err(PackError::NotCanonical(_))));
    let mut short = packed.clone();
    short.colors.truncate(short.colors.len() - 4);
    assert!(matches!(unpack(&short), Err(PackError::NotCanonical(_))));
    let mut bad = packed;
    bad.indices[0] = [0, 0, 1];
    assert!(unpack(&bad).is_err());
    let empty = ColorStore::uniform(Topology::build(0, &[]).unwrap(), Resolution::ONE, [0.0; 4]);
    let empty_packed = pack(&empty, &[], ColorFormat::Rgba8Srgb).unwrap();
    assert_eq!(empty_packed.sample_count(), 0);
    assert!(unpack(&empty_packed).is_ok(), "an empty mesh is a valid (empty) document");
    assert!(unpack(&PackedMesh::default()).is_err(), "vertex_levels = 0 is not canonical");
}

#[test]
fn srgb8_encoding_rounds_to_the_nearest_code_in_encoded_space() {
    // Independent truth: the f64 transfer function, rounded.
    let reference = |linear: f64| -> u8 {
        let x = linear.clamp(0.0, 1.0);
        let encoded = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
        (encoded * 255.0).round() as u8
    };
    let mut mismatches = 0;
    for k in 0..=200_000u32 {
        let linear = k as f32 / 200_000.0;
        let got = meshpaint_core::colors::format::encode_srgb8(linear);
        let want = reference(f64::from(linear));
        if got != want {
            // Only values within float noise of a rounding boundary may differ.
            mismatches += 1;
            assert!(got.abs_diff(want) == 1, "{linear}: {got} vs {want}");
        }
    }
    assert!(mismatches < 20, "{mismatches} boundary mismatches");
    assert_eq!(meshpaint_core::colors::format::encode_srgb8(f32::NAN), 0);
    assert_eq!(meshpaint_core::colors::format::encode_srgb8(-1.0), 0);
    assert_eq!(meshpaint_core::colors::format::encode_srgb8(7.0), 255);
}

#[test]
fn store_mip_sampling_matches_packed_sampling_at_every_level_within_quantisation() {
    use meshpaint_core::packing::unpack::StoreMips;
    let (positions, store) = mixed_octahedron_store(21);
    let mips = StoreMips::new(&store).unwrap();
    let packed8 = pack(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let packed16 = pack(&store, &positions, ColorFormat::Rgba16F).unwrap();
    let mut rng = Rng(77);
    for face in 0..8 {
        for level in 0..=6 {
            for _ in 0..100 {
                let (a, b) = (rng.unit(), rng.unit());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let bary = [1.0 - a - b, a, b];
                for filter in [Filter::Nearest, Filter::Linear] {
                    let truth = sample(&mips, face, bary, filter, level).unwrap();
                    if level == 0 {
                        assert_eq!(sample(&store, face, bary, filter, 0).unwrap(), truth);
                    }
                    // RGBA8 quantises level 0 before filtering, then each level again.
                    for (packed, tolerance) in [(&packed8, 0.0135), (&packed16, 0.002)] {
                        let got = sample(packed, face, bary, filter, level).unwrap();
                        for c in 0..4 {
                            assert!((got[c] - truth[c]).abs() <= tolerance, "face {face} level {level}");
                        }
                    }
                }
            }
        }
    }
    assert_eq!(sample(&store, 7, [1.0, 0.0, 0.0], Filter::Linear, 1), None, "the store itself has no MIP chains");
}
