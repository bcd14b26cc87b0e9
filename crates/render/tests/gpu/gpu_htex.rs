//! Htex on the GPU against its CPU evaluation (`HtexTexture::sample_level` /
//! `sample_trilinear`: Algorithm 3 with hardware bilinear emulated in `f32`; trilinear at
//! the level of detail of its definition, computed here in `f64` as gpu_mct.rs does) on
//! every sampled pixel: at most 1 8-bit step (the hardware's fixed-point filter weights
//! enter colour and normalisation weight alike, so the quotient keeps within rounding).
//!
//! These tests fail (never skip) when no GPU adapter is found.

use glam::DVec3;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, encode_srgb8};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::htex::{self, HtexOptions, HtexTexture};
use meshpaint_core::io::document::{Document, position_colored};
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::lod::VertexLod;
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_render::{DrawItem, FilterMode, GpuHtex, GpuMesh, MeshUploadOptions, RenderSettings, Shading};

use crate::common;
use common::WriteThrough;
use common::model;

const SIZE: u32 = 256;

#[derive(Debug, Default)]
struct Comparison {
    compared: usize,
    max_steps: u8,
    over_one: usize,
    mean_steps: f64,
    coverage_mismatch: usize,
}

fn steps(gpu: [u8; 4], truth: [f32; 4]) -> u8 {
    (0..3).map(|c| gpu[c].abs_diff(encode_srgb8(truth[c]))).max().unwrap_or(0)
}

/// The trilinear level of detail of mesh colors (crates/core/src/packing/lod.rs) in `f64`,
/// each vertex term with the bias `LOD_BIAS`.
fn continuous_lod(packed: &PackedMesh, inputs: &VertexLod, camera: &OrbitCamera, face: u32, bary: [f32; 3]) -> f32 {
    let eye = camera.eye();
    let forward = (DVec3::from_array(camera.target) - eye).normalize();
    let kappa = 2.0 * (camera.fov_y_degrees.to_radians() * 0.5).tan() / f64::from(SIZE);
    let (mut depth, mut mu) = (0.0, 0.0);
    for (k, &v) in packed.indices[face as usize].iter().enumerate() {
        let p = DVec3::from_array(packed.positions[v as usize].map(f64::from));
        let n = DVec3::from_array(inputs.normal(v as usize).unwrap().map(f64::from));
        let to_eye = eye - p;
        let cosine = n.dot(to_eye).abs() / to_eye.length();
        let term = (kappa * f64::from(inputs.density[v as usize]) / cosine.max(1.0 / 16.0)).log2()
            + f64::from(meshpaint_core::packing::lod::LOD_BIAS);
        depth += f64::from(bary[k]) * (p - eye).dot(forward);
        mu += f64::from(bary[k]) * term.clamp(-64.0, 64.0);
    }
    (depth.log2() + mu) as f32
}

fn compare(packed: &PackedMesh, camera: OrbitCamera, filter: FilterMode, equalize_corners: bool) -> Comparison {
    let gpu = common::gpu::shared();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), packed, &MeshUploadOptions::default()).unwrap();
    let texture: HtexTexture =
        htex::build(packed, &HtexOptions { equalize_corners, ..HtexOptions::default() }).unwrap();
    let gpu_htex = GpuHtex::upload(&gpu.ctx, gpu.renderer.layouts(), &mesh.geometry(), &texture).unwrap();
    let mut settings = RenderSettings::new(camera);
    settings.filter = filter;
    settings.shading = Shading::Unlit;
    let image = gpu.renderer.render_image(&gpu.ctx, DrawItem::Htex(&gpu_htex), &settings, SIZE, SIZE).unwrap();
    let bvh = MeshBvh::build(&packed.positions, &packed.indices, BvhPreset::FastBuild);
    let background: [u8; 3] = settings.background.map(encode_srgb8)[..3].try_into().unwrap();
    let inputs = VertexLod::of(packed);
    let last = (texture.layout.levels - 1) as f32;
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
            if hit.barycentric.iter().copied().fold(f32::INFINITY, f32::min) < 2e-3 {
                continue;
            }
            let truth = match filter {
                FilterMode::Trilinear => {
                    let lod = continuous_lod(packed, &inputs, &camera, hit.face, hit.barycentric).clamp(0.0, last);
                    texture.sample_trilinear(hit.face, hit.barycentric, lod)
                }
                FilterMode::MipLevel(level) => texture.sample_level(hit.face, hit.barycentric, level),
                _ => texture.sample_level(hit.face, hit.barycentric, 0),
            }
            .unwrap();
            let s = steps(pixel, truth);
            result.max_steps = result.max_steps.max(s);
            result.over_one += usize::from(s > 1);
            total += u64::from(s);
            result.compared += 1;
        }
    }
    result.mean_steps = total as f64 / result.compared.max(1) as f64;
    result
}

fn check(name: &str, c: &Comparison) {
    println!("{name}: {c:?}");
    assert!(c.compared > 300, "{name}: too few pixels");
    assert!(c.max_steps <= 1 && c.over_one == 0, "{name}: GPU vs CPU Htex {} steps", c.max_steps);
    assert!(c.coverage_mismatch * 100 < c.compared, "{name}: coverage differs");
}

#[test]
fn htex_matches_its_cpu_evaluation_at_fixed_levels_and_trilinear() {
    for resolution in [1u64, 4, 16] {
        let document = Document::open(&model("Duck/Duck.glb"), Resolution::new(resolution).unwrap()).unwrap();
        for format in [ColorFormat::Rgba8Srgb, ColorFormat::Rgba16F] {
            let packed = document.pack(format).unwrap();
            let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), 30.0, 20.0);
            for equalize in [true, false] {
                let name = format!("Duck R={resolution} {format:?} equalised {equalize}");
                check(&format!("{name} level 0"), &compare(&packed, camera, FilterMode::Linear, equalize));
            }
            check(
                &format!("Duck R={resolution} {format:?} level 1"),
                &compare(&packed, camera, FilterMode::MipLevel(1), true),
            );
        }
    }
    // Mixed resolutions (quads of different sizes meet) and trilinear over several levels.
    let mut document = Document::open(&model("Suzanne/monkey.glb"), Resolution::new(8).unwrap()).unwrap();
    document.store = position_colored(&document.store, &document.positions);
    for face in 0..document.store.topology().face_count() {
        document.store.write_resolution(face, Resolution::from_log2(face % 6).unwrap()).unwrap();
    }
    let packed = document.pack(ColorFormat::Rgba8Srgb).unwrap();
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), -20.0, 10.0);
    check("Suzanne mixed level 0", &compare(&packed, camera, FilterMode::Linear, true));
    check("Suzanne mixed trilinear", &compare(&packed, camera, FilterMode::Trilinear, true));
    let mut far = camera;
    far.distance *= 3.0;
    check("Suzanne mixed trilinear far", &compare(&packed, far, FilterMode::Trilinear, true));
}
