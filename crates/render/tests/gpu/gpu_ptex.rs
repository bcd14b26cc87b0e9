//! Packed Ptex on the GPU against the CPU evaluation of the packed texture
//! (`PackedPtex::sample_level` / `sample_trilinear`, hardware bilinear emulated in `f32`;
//! trilinear at the level of detail of its definition, computed here in `f64`) on every
//! sampled pixel, at most 1 8-bit step.
//!
//! These tests fail (never skip) when no GPU adapter is found.

use glam::DVec3;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, encode_srgb8};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::{Document, position_colored};
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::lod::VertexLod;
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::ptex::{self, PackedPtex};
use meshpaint_render::{DrawItem, FilterMode, GpuMesh, GpuPtex, MeshUploadOptions, Overlays, RenderSettings, Shading};

use crate::common;
use crate::common::WriteThrough;
use common::model;

const SIZE: u32 = 256;

#[derive(Debug, Default)]
struct Comparison {
    compared: usize,
    max_steps: u8,
    mean_steps: f64,
    coverage_mismatch: usize,
    /// Trilinear: how many compared pixels blend two levels (fraction in 0.05..0.95).
    blended: usize,
}

fn steps(gpu: [u8; 4], truth: [f32; 4]) -> u8 {
    (0..3).map(|c| gpu[c].abs_diff(encode_srgb8(truth[c]))).max().unwrap_or(0)
}

/// The trilinear level of detail at barycentrics `bary` of `face` from its definition
/// (crates/core/src/packing/lod.rs module docs) in `f64`: `log2(Σ bᵢ depthᵢ) + Σ bᵢ μᵢ`, each `μᵢ`
/// with the bias `LOD_BIAS`.
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

fn compare(packed: &PackedMesh, camera: OrbitCamera, filter: FilterMode) -> Comparison {
    let gpu = common::gpu::shared();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), packed, &MeshUploadOptions::default()).unwrap();
    let texture: PackedPtex = ptex::build(packed, 16384, u64::MAX).unwrap();
    let gpu_ptex = GpuPtex::upload(&gpu.ctx, gpu.renderer.layouts(), &mesh.geometry(), &texture).unwrap();
    let mut settings = RenderSettings::new(camera);
    settings.filter = filter;
    settings.shading = Shading::Unlit;
    let image = gpu.renderer.render_image(&gpu.ctx, DrawItem::Ptex(&gpu_ptex), &settings, SIZE, SIZE).unwrap();
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
                    result.blended += usize::from((0.05..0.95).contains(&(lod - lod.floor())));
                    texture.sample_trilinear(hit.face, hit.barycentric, lod).unwrap()
                }
                FilterMode::MipLevel(level) => texture.sample_level(hit.face, hit.barycentric, level).unwrap(),
                _ => texture.sample_level(hit.face, hit.barycentric, 0).unwrap(),
            };
            let s = steps(pixel, truth);
            result.max_steps = result.max_steps.max(s);
            total += u64::from(s);
            result.compared += 1;
        }
    }
    result.mean_steps = total as f64 / result.compared.max(1) as f64;
    result
}

fn check(name: &str, c: &Comparison) {
    println!("{name}: {c:?}");
    assert!(c.compared > 1000, "{name}: too few pixels");
    assert!(c.max_steps <= 1, "{name}: GPU vs CPU Ptex {} steps", c.max_steps);
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
fn ptex_bilinear_matches_its_cpu_evaluation() {
    for resolution in [1u64, 4, 16] {
        let document = Document::open(&model("Duck/Duck.glb"), Resolution::new(resolution).unwrap()).unwrap();
        for format in [ColorFormat::Rgba16F, ColorFormat::Rgba8Srgb] {
            let packed = document.pack(format).unwrap();
            let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), 30.0, 20.0);
            check(&format!("Duck R={resolution} {format:?} level 0"), &compare(&packed, camera, FilterMode::Linear));
        }
    }
    let packed = suzanne_mixed(ColorFormat::Rgba8Srgb);
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), -20.0, 10.0);
    for level in [0, 1, 3] {
        let filter = if level == 0 { FilterMode::Linear } else { FilterMode::MipLevel(level) };
        check(&format!("Suzanne mixed R level {level}"), &compare(&packed, camera, filter));
    }
}

/// Trilinear: two lookups blended at mesh colors' level of detail (the paper's per-pixel
/// level), every sampled pixel against `sample_trilinear`.
#[test]
fn ptex_trilinear_matches_its_cpu_evaluation_at_the_continuous_level_of_detail() {
    let duck = Document::open(&model("Duck/Duck.glb"), Resolution::new(32).unwrap()).unwrap();
    let packed = duck.pack(ColorFormat::Rgba8Srgb).unwrap();
    let sphere = BoundingSphere::of_points(&packed.positions);
    for (yaw, pitch, zoom) in [(30.0, 20.0, 1.0), (-120.0, 10.0, 1.6)] {
        let mut camera = OrbitCamera::framing(sphere, yaw, pitch);
        camera.distance *= zoom;
        let c = compare(&packed, camera, FilterMode::Trilinear);
        let name = format!("Duck R=32 zoom {zoom} trilinear");
        check(&name, &c);
        assert!(c.blended * 2 > c.compared, "{name}: the view must blend levels");
    }
    let packed = suzanne_mixed(ColorFormat::Rgba16F);
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), -20.0, 10.0);
    check("Suzanne mixed R trilinear", &compare(&packed, camera, FilterMode::Trilinear));
}

/// Every Ptex pipeline (lighting, smooth shading, wireframe, heat map: one per set of flags)
/// draws, covering the same pixels as mesh colors.
#[test]
fn every_ptex_pipeline_draws_where_mesh_colors_draw() {
    let gpu = common::gpu::shared();
    let document = Document::open(&model("Duck/Duck.glb"), Resolution::new(4).unwrap()).unwrap();
    let packed = document.pack(ColorFormat::Rgba8Srgb).unwrap();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions::default()).unwrap();
    let texture = ptex::build(&packed, 16384, u64::MAX).unwrap();
    let gpu_ptex = GpuPtex::upload(&gpu.ctx, gpu.renderer.layouts(), &mesh.geometry(), &texture).unwrap();
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), 30.0, 20.0);
    for filter in [FilterMode::Linear, FilterMode::Trilinear] {
        for shading in [Shading::Unlit, Shading::Lit, Shading::Smooth] {
            for (wireframe, heatmap) in [(false, false), (true, true)] {
                let mut settings = RenderSettings::new(camera);
                settings.filter = filter;
                settings.shading = shading;
                settings.overlays = Overlays { wireframe, heatmap };
                let render = |item| gpu.renderer.render_image(&gpu.ctx, item, &settings, SIZE, SIZE).unwrap();
                let (a, b) = (render(DrawItem::MeshColors(&mesh)), render(DrawItem::Ptex(&gpu_ptex)));
                let background: [u8; 3] = settings.background.map(encode_srgb8)[..3].try_into().unwrap();
                let (mut covered, mut differ) = (0usize, 0usize);
                for (p, q) in a.pixels().zip(b.pixels()) {
                    covered += usize::from(p.0[..3] != background);
                    differ += usize::from((p.0[..3] != background) != (q.0[..3] != background));
                }
                let name = format!("{filter:?} {shading:?} wireframe {wireframe} heat map {heatmap}");
                assert!(covered > 5000 && differ * 100 < covered, "{name}: {covered} covered, {differ} differ");
            }
        }
    }
}
