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

use glam::DVec3;
use meshpaint::camera::{BoundingSphere, OrbitCamera};
use meshpaint::color::ColorFormat;
use meshpaint::packed::{FaceRecord, PackedMesh, pack_word};
use meshpaint::render::{
    DrawItem, FilterMode, GpuContext, GpuMesh, MeshUploadOptions, OFFSCREEN_FORMAT, RenderSettings, Renderer, Shading,
};
use meshpaint::sampler::packed_sample_index;

const SIZE: u32 = 256;
const GRID: u32 = 8;
const LOG2_R: u32 = 2;
const SAMPLES: u64 = 20_000_000;
const FILLER: [u8; 4] = [255, 0, 255, 255];
/// Largest allowed per-channel difference in 8-bit steps (sRGB decode and encode round trip).
const MAX_STEPS: u8 = 2;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
}

fn face_color(face: u32) -> [u8; 4] {
    [(40 + face * 37 % 180) as u8, (60 + face * 91 % 170) as u8, (30 + face * 53 % 150) as u8, 255]
}

/// `GRID × GRID` cells of two triangles each in the plane z = 0, no shared vertices.
fn grid_mesh() -> PackedMesh {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
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
    let face_records = indices
        .iter()
        .map(|_| {
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
    for face in 0..packed.indices.len() as u32 {
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

#[test]
fn large_indices_and_odd_atlas_widths_address_exactly() {
    let ctx = GpuContext::new_headless()
        .unwrap_or_else(|error| panic!("GPU tests need an adapter (lavapipe: mesa-vulkan-drivers): {error}"));
    let renderer = Renderer::new(&ctx, OFFSCREEN_FORMAT).unwrap();
    let packed = grid_mesh();
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), 0.0, 0.0);
    let faces = packed.indices.len() as u32;
    let mut failures = Vec::new();
    // 1221 columns need 16380 rows (nearly the 16384 limit); 4093 is prime; 16384 is the default.
    for width in [1221u32, 4093, 16384] {
        let mesh = GpuMesh::upload(&ctx, &renderer, &packed, &MeshUploadOptions { atlas_width: Some(width) }).unwrap();
        assert_eq!(mesh.atlas.width, width);
        for filter in [
            FilterMode::Nearest,
            FilterMode::Linear,
            FilterMode::MipLevel(1),
            FilterMode::NearestMipLevel(2),
            FilterMode::Trilinear,
        ] {
            let mut settings = RenderSettings::new(camera);
            settings.filter = filter;
            settings.shading = Shading::Unlit;
            settings.background = [0.0; 4];
            let image = renderer.render_image(&ctx, DrawItem::MeshColors(&mesh), &settings, SIZE, SIZE).unwrap();
            // Every covered pixel shows some face's colour, never the filler or a blend with it.
            let stray = image
                .pixels()
                .filter(|p| p.0 != [0; 4] && !(0..faces).any(|face| close(p.0, face_color(face))))
                .count();
            // Points well inside each face show that face's colour.
            let mut wrong = 0;
            for (face, corners) in packed.indices.iter().enumerate() {
                let p = corners.map(|v| {
                    let p = packed.positions[v as usize];
                    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
                });
                for w in [[1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], [0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6]] {
                    let world = p[0] * w[0] + p[1] * w[1] + p[2] * w[2];
                    let (x, y) = camera.project(world, SIZE, SIZE).unwrap();
                    let pixel = image.get_pixel(x.floor() as u32, y.floor() as u32).0;
                    if !close(pixel, face_color(face as u32)) {
                        wrong += 1;
                    }
                }
            }
            if stray > 0 || wrong > 0 {
                failures.push(format!("width {width} {filter:?}: {stray} stray pixels, {wrong} wrong face points"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
