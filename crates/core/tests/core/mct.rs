//! Mesh Color Textures against the CPU reference sampler.
//!
//! Truth: `packing::sampler::sample` (mesh colors' linear filter with the seam rule, itself
//! tested against the layout formulas in seams.rs), and brute-force texel ownership maps.
//! Colours are random (the hardest case for filtering) in RGBA32F, so the only error left is
//! `f32` rounding; RGBA8's ring clamping is measured separately.

use crate::common;
use crate::common::WriteThrough;

use common::Rng;
use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::io::document::Document;
use meshpaint_core::mct::{self, MctError, MeshColorTexture};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::packing::sampler::{Filter, sample};
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

fn mixed(face: usize) -> u64 {
    1 << ((face * 7 + face / 5) % 6)
}

fn max_diff(a: Rgba, b: Rgba) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

fn weights(corners: [usize; 3], fractions: [f32; 3]) -> [f32; 3] {
    let mut w = [0.0; 3];
    for (corner, f) in corners.into_iter().zip(fractions) {
        w[corner] = f;
    }
    w
}

#[test]
fn every_lattice_texel_is_the_reference_at_every_level() {
    let packed = packed_mesh(2, mixed, ColorFormat::Rgba32F, 1);
    let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    let mut checked = 0u64;
    for face in 0..packed.indices.len() as u32 {
        for level in 0..mct.layout.levels {
            let frame = mct.layout.frame(face, level).unwrap();
            let r = frame.r;
            for beta in 0..=r {
                for alpha in 0..=r - beta {
                    let rf = r as f32;
                    let w =
                        weights(frame.corners, [(r - alpha - beta) as f32 / rf, alpha as f32 / rf, beta as f32 / rf]);
                    let truth = sample(&packed, face, w, Filter::Linear, level).unwrap();
                    let [x, y] = frame.texel(alpha, beta);
                    let got = mct.texel(x, y);
                    assert!(
                        max_diff(got, truth) <= TOLERANCE,
                        "face {face} level {level} ({alpha}, {beta}): {got:?} vs {truth:?}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 10_000, "{checked}");
}

/// Points along every face edge (corner k → k+1), dyadic so they are exact in `f32`.
fn edge_points(face_edge: usize) -> impl Iterator<Item = [f32; 3]> {
    (0..=64).map(move |n| {
        let t = n as f32 / 64.0;
        let mut w = [0.0; 3];
        w[face_edge] = 1.0 - t;
        w[(face_edge + 1) % 3] = t;
        w
    })
}

#[test]
fn level_0_bilinear_is_the_linear_filter_along_every_edge() {
    for (name, resolution) in [
        ("uniform 1", (|_| 1) as fn(usize) -> u64),
        ("uniform 2", |_| 2),
        ("uniform 8", |_| 8),
        ("uniform 64", |_| 64),
        ("mixed", mixed),
        ("mixed 1|64", |f| if f % 3 == 0 { 64 } else { 1 }),
    ] {
        let levels = if name.contains("64") { 1 } else { 2 };
        let packed = packed_mesh(levels, resolution, ColorFormat::Rgba32F, 2);
        let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
        let mut worst = 0.0f32;
        for face in 0..packed.indices.len() as u32 {
            for k in 0..3 {
                for w in edge_points(k) {
                    let truth = sample(&packed, face, w, Filter::Linear, 0).unwrap();
                    worst = worst.max(max_diff(mct.sample_level(face, w, 0).unwrap(), truth));
                }
            }
        }
        assert!(worst <= TOLERANCE, "{name}: worst {worst}");
    }
}

/// Both faces of every edge see the same colours at every level (legs and rings are exact,
/// a pair's shared diagonal is the same texels from both sides).
#[test]
fn every_level_is_continuous_across_every_edge() {
    let packed = packed_mesh(2, mixed, ColorFormat::Rgba32F, 3);
    let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    let mut sides: HashMap<(u32, u32), Vec<(u32, usize)>> = HashMap::new();
    for (face, c) in packed.indices.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            sides.entry((a.min(b), a.max(b))).or_default().push((face as u32, k));
        }
    }
    let mut worst_jump = [0.0f32; 7];
    let mut worst_off_reference = [0.0f32; 7];
    for ((lo, _), faces) in &sides {
        assert_eq!(faces.len(), 2);
        for level in 0..7u32 {
            for n in 0..=64 {
                let t = n as f32 / 64.0;
                // The point at t from the lower vertex id, in each face's corners.
                let colors: Vec<(Rgba, Rgba)> = faces
                    .iter()
                    .map(|&(face, k)| {
                        let c = packed.indices[face as usize];
                        let from_lo = c[k] == *lo;
                        let mut w = [0.0; 3];
                        w[k] = if from_lo { 1.0 - t } else { t };
                        w[(k + 1) % 3] = if from_lo { t } else { 1.0 - t };
                        (
                            mct.sample_level(face, w, level).unwrap(),
                            sample(&packed, face, w, Filter::Linear, level).unwrap(),
                        )
                    })
                    .collect();
                let l = level as usize;
                worst_jump[l] = worst_jump[l].max(max_diff(colors[0].0, colors[1].0));
                worst_off_reference[l] = worst_off_reference[l].max(max_diff(colors[0].0, colors[0].1));
            }
        }
    }
    println!(
        "largest jump per level {worst_jump:?}; largest difference from the reference on edges {worst_off_reference:?}"
    );
    assert!(worst_jump.iter().all(|&j| j <= TOLERANCE), "{worst_jump:?}");
    assert!(worst_off_reference[0] <= TOLERANCE);
}

/// Blocks share texels only where they store the same point of the mesh: a pair's shared
/// leg (level 0) or diagonal (levels ≥ 1), or the side (and its corners) two consecutive
/// squares of a strip share. Ring texels are never shared. The atlas wraps around in x:
/// texels are compared modulo its width.
#[test]
fn blocks_never_overlap_except_where_they_store_the_same_mesh_point() {
    let packed = packed_mesh(3, mixed, ColorFormat::Rgba8Srgb, 4);
    let mct = mct::build(&packed, 2048, u64::MAX).unwrap();
    let width = i64::from(mct.layout.width);
    // Texel → (face, level, the mesh point: (vertex, weight · r) sorted, None for a ring).
    type Point = Option<(u32, Vec<(u32, u32)>)>;
    let mut owner: HashMap<[i64; 2], Vec<(u32, u32, Point)>> = HashMap::new();
    for face in 0..packed.indices.len() as u32 {
        let record = mct.layout.records[face as usize];
        let lone = mct.layout.pairs[record.log2_block() as usize][record.pair() as usize][1] == u32::MAX;
        let corners = packed.indices[face as usize];
        for level in 0..mct.layout.levels {
            let frame = mct.layout.frame(face, level).unwrap();
            let ring = level == 0 || lone;
            for beta in 0..=frame.r + 1 {
                for alpha in 0..=frame.r + 1 - beta {
                    if alpha + beta == frame.r + 1 && (!ring || alpha == 0 || beta == 0) {
                        continue;
                    }
                    let texel = frame.texel(alpha, beta);
                    assert!(
                        texel[0] >= 0
                            && texel[1] >= 0
                            && texel[0] < 2 * width
                            && texel[1] < i64::from(mct.layout.height)
                    );
                    let point = (alpha + beta <= frame.r).then(|| {
                        let weights = [frame.r - alpha - beta, alpha, beta];
                        let mut point: Vec<(u32, u32)> = (0..3)
                            .filter(|&k| weights[k] > 0)
                            .map(|k| (corners[frame.corners[k]], weights[k]))
                            .collect();
                        point.sort_unstable();
                        (frame.r, point)
                    });
                    owner.entry([texel[0] % width, texel[1]]).or_default().push((face, level, point));
                }
            }
        }
    }
    let mut strip_sides = 0u64;
    for (texel, faces) in &owner {
        let first = &faces[0];
        for other in &faces[1..] {
            assert!(first.1 == other.1 && first.2.is_some() && first.2 == other.2, "texel {texel:?}: {faces:?}");
            let (ra, rb) = (mct.layout.records[first.0 as usize], mct.layout.records[other.0 as usize]);
            strip_sides += u64::from(ra.pair() != rb.pair());
        }
    }
    let used = owner.len() as u64;
    println!(
        "atlas {}×{}: {used} texels used of {}, {strip_sides} shared between squares of a strip",
        mct.layout.width,
        mct.layout.height,
        mct.layout.texel_count()
    );
    assert!(strip_sides > 0);
}

fn mesh_colors_gpu_bytes(packed: &PackedMesh) -> u64 {
    packed.face_record_bytes() + packed.color_bytes()
}

/// Issue 41 asks ≤ 1.5 at R = 8 and ≤ 1.25 at R = 32, on the icosphere and on the Duck and
/// the Fox (docs/MCT.md, "GPU bytes": tents at level 0, strips of squares above, the atlas
/// wrapping around in x, and only the band-table entries the GPU reads).
#[test]
fn gpu_bytes_per_resolution() {
    let models = common::workspace_root().join("assets/models");
    for (resolution, levels, bound) in [(8u64, 4, 1.5), (32, 3, 1.25)] {
        let mut meshes = vec![("icosphere".to_owned(), packed_mesh(levels, |_| resolution, ColorFormat::Rgba8Srgb, 5))];
        for model in ["Duck/Duck.glb", "Fox/Fox.glb"] {
            let document = Document::open(&models.join(model), Resolution::new(resolution).unwrap()).unwrap();
            meshes.push((model.to_owned(), document.pack(ColorFormat::Rgba8Srgb).unwrap()));
        }
        for (name, packed) in meshes {
            let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
            let ratio = mct.gpu_bytes() as f64 / mesh_colors_gpu_bytes(&packed) as f64;
            println!(
                "{name}, R = {resolution}: MCT {} bytes, mesh colors {} bytes, ratio {ratio:.3}",
                mct.gpu_bytes(),
                mesh_colors_gpu_bytes(&packed)
            );
            assert!(ratio <= bound, "{name}, R = {resolution}: {ratio}");
        }
    }
}

#[test]
fn rgba8_rings_are_clamped_only_where_the_extrapolation_leaves_the_range() {
    // Constant colours: c₁ + c₂ − c₀ = c, never clamped.
    let (positions, triangles) = icosphere(1);
    let topology = Topology::build(positions.len() as u32, &triangles).unwrap();
    let store = ColorStore::with_resolutions(
        topology,
        vec![Resolution::new(4).unwrap(); triangles.len()],
        [0.3, 0.6, 0.9, 1.0],
    )
    .unwrap();
    let packed = pack(&store, &positions, ColorFormat::Rgba8Srgb).unwrap();
    let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    assert_eq!(mct.stats.clamped_ring_texels, 0);
    assert!(mct.stats.ring_texels > 0);
    // Random colours at R = 1: some ring texels leave [0, 1].
    let packed = packed_mesh(1, |_| 1, ColorFormat::Rgba8Srgb, 6);
    let mct = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    assert!(
        mct.stats.clamped_ring_texels > 0 && mct.stats.max_ring_clamp > 0.0 && mct.stats.max_ring_clamp <= 1.0,
        "{:?}",
        mct.stats
    );
}

#[test]
fn budgets_are_checked_before_allocating() {
    let packed = packed_mesh(2, |_| 64, ColorFormat::Rgba8Srgb, 7);
    assert!(matches!(mct::build(&packed, 128, u64::MAX), Err(MctError::AtlasTooLarge { .. })));
    assert!(
        matches!(mct::build(&packed, MAX_DIM, 1000), Err(MctError::OverBudget { bytes, max_bytes: 1000 }) if bytes > 1000)
    );
    let fine: MeshColorTexture = mct::build(&packed, MAX_DIM, u64::MAX).unwrap();
    assert!(fine.layout.width <= MAX_DIM && fine.layout.height <= MAX_DIM);
}
