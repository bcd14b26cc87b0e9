//! Colour-atlas addressing at large sample indices (beyond 2^24, where `f32` no longer
//! holds every integer) and atlas widths that are not powers of two: the shader turns a
//! colour index into a texel `(index % W, index / W)` without an integer division, so
//! every index it reads must still be exactly the one `sampler::packed_sample_index`
//! names. These tests FAIL when no GPU adapter (lavapipe) exists.
//!
//! The mesh is built by hand: a grid of disjoint triangles whose edge and interior chains
//! sit at scattered indices above 2^24 in a 20 M-sample colour buffer. Every sample a face
//! owns (all levels, found through `packed_sample_index`) holds the face's colour and every
//! other sample a filler colour far from all of them, so any mis-addressed read shows.
//! The grid's vertices and faces come after thousands of unused vertices and degenerate
//! faces, so they straddle row boundaries of the vertex-pulling data textures too.

use glam::DVec3;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::packing::linear::{FaceRecord, PackedMesh, pack_word};
use meshpaint_core::packing::sampler::packed_sample_index;
use meshpaint_render::{DrawItem, FilterMode, GpuMesh, MeshUploadOptions, RenderSettings, Shading};

use crate::common;
use common::Rng;
use common::gpu::Gpu;

const SIZE: u32 = 256;
const GRID: u32 = 8;
/// Unused vertices and zero-area faces before the grid's (the data textures' rows hold 4096).
const PADDING: u32 = 4040;
const LOG2_R: u32 = 2;
const SAMPLES: u64 = 20_000_000;
const FILLER: [u8; 4] = [255, 0, 255, 255];
/// Largest allowed per-channel difference in 8-bit steps (sRGB decode and encode round trip).
const MAX_STEPS: u8 = 2;

/// The grid's faces (the ones that show).
fn visible_faces() -> std::ops::Range<u32> {
    PADDING..PADDING + 2 * GRID * GRID
}

fn face_color(face: u32) -> [u8; 4] {
    [(40 + face * 37 % 180) as u8, (60 + face * 91 % 170) as u8, (30 + face * 53 % 150) as u8, 255]
}

/// `GRID × GRID` cells of two triangles each in the plane z = 0, no shared vertices.
fn grid_mesh() -> PackedMesh {
    let mut positions = vec![[0.5f32, 0.5, 0.0]; PADDING as usize];
    let mut indices = vec![[0u32; 3]; PADDING as usize];
    for cy in 0..GRID {
        for cx in 0..GRID {
            let (x, y) = (cx as f32, cy as f32);
            for corners in [[[x, y], [x + 1.0, y], [x, y + 1.0]], [[x + 1.0, y], [x + 1.0, y + 1.0], [x, y + 1.0]]] {
                let first = positions.len() as u32;
                positions.extend(corners.map(|[px, py]| [px, py, 0.0]));
                indices.push([first, first + 1, first + 2]);
            }
        }
    }
    // Chains of R = 4: edges 2R − 2 − log2 R = 4 samples, interiors 3; scattered above 2^24
    // with gaps, so reading a neighbour (±1 or ±one atlas row) lands on the filler.
    let mut rng = Rng(0x5EED_A71A5);
    let low = 1u64 << 24;
    let mut used: Vec<(u64, u64)> = Vec::new();
    let mut chain = |len: u64| loop {
        let base = low + rng.next() % (SAMPLES - low - len);
        if used.iter().all(|&(start, end)| base + len + 2 <= start || base >= end + 2) {
            used.push((base, base + len));
            return base as u32;
        }
    };
    let face_records = (0..indices.len() as u32)
        .map(|face| {
            if !visible_faces().contains(&face) {
                // R = 1: vertex colours only.
                return FaceRecord { interior: 0, edges: [0; 3] };
            }
            let interior = pack_word(chain(3), LOG2_R);
            let edges = [(); 3].map(|_| pack_word(chain(4), LOG2_R));
            FaceRecord { interior, edges }
        })
        .collect();
    let mut packed = PackedMesh {
        positions,
        indices,
        vertex_levels: LOG2_R + 1,
        face_records,
        format: ColorFormat::Rgba8Srgb,
        colors: FILLER.repeat(SAMPLES as usize),
    };
    for face in visible_faces() {
        for level in 0..=LOG2_R {
            let r = 1u32 << (LOG2_R - level);
            for i in 0..=r {
                for j in 0..=r - i {
                    let index = packed_sample_index(&packed, face, level, i, j).unwrap() as usize;
                    packed.colors[4 * index..4 * index + 4].copy_from_slice(&face_color(face));
                }
            }
        }
    }
    packed
}

fn close(a: [u8; 4], b: [u8; 4]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= MAX_STEPS)
}

fn camera(packed: &PackedMesh) -> OrbitCamera {
    OrbitCamera::framing(BoundingSphere::of_points(&packed.positions[PADDING as usize..]), 0.0, 0.0)
}

/// Renders `mesh` with `filter` and counts covered pixels that show no face's colour
/// (filler or a blend with it) and check points inside face `f` that do not show
/// `expected(f)`.
fn check(gpu: &Gpu, packed: &PackedMesh, mesh: &GpuMesh, filter: FilterMode, expected: impl Fn(u32) -> u32) -> String {
    let camera = camera(packed);
    let mut settings = RenderSettings::new(camera);
    settings.filter = filter;
    settings.shading = Shading::Unlit;
    settings.background = [0.0; 4];
    let image = gpu.renderer.render_image(&gpu.ctx, DrawItem::MeshColors(mesh), &settings, SIZE, SIZE).unwrap();
    let stray =
        image.pixels().filter(|p| p.0 != [0; 4] && !visible_faces().any(|face| close(p.0, face_color(face)))).count();
    let mut wrong = 0;
    for face in visible_faces() {
        let p = packed.indices[face as usize].map(|v| {
            let p = packed.positions[v as usize];
            DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
        });
        for w in [[1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], [0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6]] {
            let world = p[0] * w[0] + p[1] * w[1] + p[2] * w[2];
            let (x, y) = camera.project(world, SIZE, SIZE).unwrap();
            let pixel = image.get_pixel(x.floor() as u32, y.floor() as u32).0;
            if !close(pixel, face_color(expected(face))) {
                wrong += 1;
            }
        }
    }
    if stray > 0 || wrong > 0 {
        format!("{filter:?}: {stray} stray pixels, {wrong} wrong face points")
    } else {
        String::new()
    }
}

#[test]
fn large_indices_and_odd_atlas_widths_address_exactly() {
    let gpu = Gpu::create();
    let packed = grid_mesh();
    let mut failures = Vec::new();
    // 1221 columns need 16380 rows (nearly the 16384 limit); 4093 is prime; 16384 is the default.
    for width in [1221u32, 4093, 16384] {
        let options = MeshUploadOptions { atlas_width: Some(width) };
        let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &options).unwrap();
        assert_eq!(mesh.atlas.width, width);
        for filter in [
            FilterMode::Nearest,
            FilterMode::Linear,
            FilterMode::MipLevel(1),
            FilterMode::NearestMipLevel(2),
            FilterMode::Trilinear,
        ] {
            let failure = check(&gpu, &packed, &mesh, filter, |face| face);
            if !failure.is_empty() {
                failures.push(format!("width {width} {failure}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `GpuMesh::write_face_records` over a range that crosses a data-texture row: faces whose
/// records were swapped show each other's interior colours.
#[test]
fn rewritten_face_records_take_effect() {
    let gpu = Gpu::create();
    let packed = grid_mesh();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions::default()).unwrap();
    let (first, end) = (4090u32, 4110u32);
    assert!(visible_faces().contains(&first) && visible_faces().contains(&(end - 1)));
    let swapped = |face: u32| if (first..end).contains(&face) { first + ((face - first) ^ 1) } else { face };
    let records: Vec<FaceRecord> = (first..end).map(|face| packed.face_records[swapped(face) as usize]).collect();
    mesh.write_face_records(&gpu.ctx, first, &records).unwrap();
    // At level 0 the check points are nearest to interior samples, which the records address.
    let failure = check(&gpu, &packed, &mesh, FilterMode::Nearest, swapped);
    assert!(failure.is_empty(), "{failure}");
    assert!(mesh.write_face_records(&gpu.ctx, end, &records[..1]).is_ok());
    assert!(mesh.write_face_records(&gpu.ctx, packed.indices.len() as u32, &records[..1]).is_err());
}
