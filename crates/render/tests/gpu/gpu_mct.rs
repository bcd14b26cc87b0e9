//! Mesh Color Textures on the GPU against the CPU evaluation of the MCT
//! (`MeshColorTexture::sample_level`, hardware bilinear emulated in `f32`) on every sampled
//! pixel, at most 1 8-bit step. Along edges that evaluation equals mesh colors' linear filter
//! exactly (crates/core/tests/core/mct.rs, every edge, R = 1…64 and mixed), so the GPU does
//! within the same step. Pixels within 1/20 of a lattice cell of an edge are also compared
//! with the reference sampler and printed: there the difference is first order in the
//! distance to the edge times the cell's twist `c₀₀ + c₁₁ − c₁₀ − c₀₁`, plus RGBA8's clamped
//! rings.
//!
//! These tests fail (never skip) when no GPU adapter is found.

use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, encode_srgb8};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::{Document, position_colored};
use meshpaint_core::mct::{self, MeshColorTexture};
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_render::{DrawItem, FilterMode, GpuMct, GpuMesh, MeshUploadOptions, RenderSettings, Shading};

use crate::common;
use crate::common::WriteThrough;
use common::model;

const SIZE: u32 = 256;

#[derive(Debug, Default)]
struct Comparison {
    compared: usize,
    max_steps: u8,
    mean_steps: f64,
    edge_compared: usize,
    edge_max_steps: u8,
    coverage_mismatch: usize,
}

fn steps(gpu: [u8; 4], truth: [f32; 4]) -> u8 {
    (0..3).map(|c| gpu[c].abs_diff(encode_srgb8(truth[c]))).max().unwrap_or(0)
}

/// Renders the MCT of `packed` unlit at fixed `level` and compares sampled pixels.
fn compare(packed: &PackedMesh, camera: OrbitCamera, level: u32) -> Comparison {
    let gpu = common::gpu::shared();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), packed, &MeshUploadOptions::default()).unwrap();
    let texture: MeshColorTexture = mct::build(packed, 16384, u64::MAX).unwrap();
    let gpu_mct = GpuMct::upload(&gpu.ctx, gpu.renderer.layouts(), &mesh.geometry(), &texture).unwrap();
    let mut settings = RenderSettings::new(camera);
    settings.filter = if level == 0 { FilterMode::Linear } else { FilterMode::MipLevel(level) };
    settings.shading = Shading::Unlit;
    let image = gpu.renderer.render_image(&gpu.ctx, DrawItem::Mct(&gpu_mct), &settings, SIZE, SIZE).unwrap();
    let bvh = MeshBvh::build(&packed.positions, &packed.indices, BvhPreset::FastBuild);
    let background: [u8; 3] = settings.background.map(encode_srgb8)[..3].try_into().unwrap();
    let mut result = Comparison::default();
    let mut total = 0u64;
    for y in (1..SIZE).step_by(2) {
        for x in (1..SIZE).step_by(2) {
            let pixel = image.get_pixel(x, y).0;
            let (origin, direction) = camera.ray_through_pixel(f64::from(x) + 0.5, f64::from(y) + 0.5, SIZE, SIZE);
            let Some(hit) = bvh.cast(origin, direction, f64::INFINITY) else {
                result.coverage_mismatch += usize::from(pixel[..3] != background);
                continue;
            };
            // Within rasterisation tolerance of an edge the neighbour may cover the pixel.
            let nearest_edge = hit.barycentric.iter().copied().fold(f32::INFINITY, f32::min);
            if nearest_edge < 2e-3 {
                continue;
            }
            let truth = texture.sample_level(hit.face, hit.barycentric, level).unwrap();
            let s = steps(pixel, truth);
            result.max_steps = result.max_steps.max(s);
            total += u64::from(s);
            result.compared += 1;
            // Near an edge (in lattice cells of the block at this level) bilinear must be
            // mesh colors' linear filter.
            let block = 1u32 << texture.layout.records[hit.face as usize].log2_block();
            let r = (block >> level).max(1) as f32;
            if nearest_edge * r < 0.05 {
                let reference = sample(packed, hit.face, hit.barycentric, Filter::Linear, level).unwrap();
                result.edge_max_steps = result.edge_max_steps.max(steps(pixel, reference));
                result.edge_compared += 1;
            }
        }
    }
    result.mean_steps = total as f64 / result.compared.max(1) as f64;
    result
}

fn check(name: &str, c: &Comparison, min_edge_pixels: usize) {
    println!("{name}: {c:?}");
    assert!(c.compared > 1000, "{name}: too few pixels");
    assert!(c.max_steps <= 1, "{name}: GPU vs CPU MCT {} steps", c.max_steps);
    assert!(c.edge_compared >= min_edge_pixels, "{name}: only {} pixels near edges", c.edge_compared);
    assert!(c.coverage_mismatch * 100 < c.compared, "{name}: coverage differs");
}

fn suzanne_mixed(format: ColorFormat) -> PackedMesh {
    let mut document = Document::open(&model("Suzanne/monkey.glb"), Resolution::new(8).unwrap()).unwrap();
    document.store = position_colored(&document.store, &document.positions);
    for face in 0..document.store.topology().face_count() {
        document.store.write_resolution(face, Resolution::from_log2(face % 7).unwrap()).unwrap();
    }
    document.pack(format).unwrap()
}

#[test]
fn mct_bilinear_matches_its_cpu_evaluation_and_the_reference_along_edges() {
    for resolution in [1u64, 2, 4, 16, 64] {
        let document = Document::open(&model("Duck/Duck.glb"), Resolution::new(resolution).unwrap()).unwrap();
        for format in [ColorFormat::Rgba16F, ColorFormat::Rgba8Srgb] {
            let packed = document.pack(format).unwrap();
            let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), 30.0, 20.0);
            // Near-edge pixels exist only where 2e-3 of a face is under 1/20 of a cell.
            let min_edge = if resolution <= 16 { 20 } else { 0 };
            let name = format!("Duck R={resolution} {format:?} level 0");
            check(&name, &compare(&packed, camera, 0), min_edge);
        }
    }
    for format in [ColorFormat::Rgba8Srgb, ColorFormat::Rgba16F] {
        let packed = suzanne_mixed(format);
        let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), -20.0, 10.0);
        for level in [0, 1, 3] {
            check(&format!("Suzanne mixed R {format:?} level {level}"), &compare(&packed, camera, level), 0);
        }
    }
}
