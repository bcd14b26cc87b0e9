//! Mesh Color Textures on the GPU against the CPU evaluation of the MCT
//! (`MeshColorTexture::sample_level` / `sample_trilinear`, hardware bilinear emulated in
//! `f32`; trilinear at the level of detail of its definition, computed here in `f64`) on
//! every sampled pixel, at most 1 8-bit step. Along edges that evaluation equals mesh colors' linear filter
//! exactly (crates/core/tests/core/mct.rs, every edge, R = 1…64 and mixed), so the GPU does
//! within the same step. Pixels within 1/20 of a lattice cell of an edge are also compared
//! with the reference sampler and printed: there the difference is first order in the
//! distance to the edge times the cell's twist `c₀₀ + c₁₁ − c₁₀ − c₀₁`, plus RGBA8's clamped
//! rings.
//!
//! Every MCT pipeline (fixed level and trilinear, each shading and overlay: the renderer
//! specialises one per set of flags) also draws what mesh colors draw where both are the same
//! signal.
//!
//! These tests fail (never skip) when no GPU adapter is found.

use glam::DVec3;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, encode_srgb8};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::{Document, position_colored};
use meshpaint_core::mct::{self, MeshColorTexture};
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::lod::VertexLod;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_render::{DrawItem, FilterMode, GpuMct, GpuMesh, MeshUploadOptions, Overlays, RenderSettings, Shading};

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
    /// Trilinear: the range of the level of detail over the compared pixels, and how many of
    /// them blend two levels (fraction in 0.05..0.95).
    lod_range: (f32, f32),
    blended: usize,
}

fn steps(gpu: [u8; 4], truth: [f32; 4]) -> u8 {
    (0..3).map(|c| gpu[c].abs_diff(encode_srgb8(truth[c]))).max().unwrap_or(0)
}

/// The trilinear level of detail at barycentrics `bary` of `face` from its definition
/// (crates/core/src/packing/lod.rs module docs) in `f64`, with the per-vertex inputs as the GPU
/// holds them: `log2(Σ bᵢ depthᵢ) + Σ bᵢ μᵢ`, each `μᵢ` with the bias `LOD_BIAS` (unclamped;
/// `sample_trilinear` clamps).
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

/// Renders the MCT of `packed` unlit with `filter` (`Linear`, `MipLevel` or `Trilinear`)
/// and compares sampled pixels.
fn compare(packed: &PackedMesh, camera: OrbitCamera, filter: FilterMode) -> Comparison {
    let gpu = common::gpu::shared();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), packed, &MeshUploadOptions::default()).unwrap();
    let texture: MeshColorTexture = mct::build(packed, 16384, u64::MAX).unwrap();
    let gpu_mct = GpuMct::upload(&gpu.ctx, gpu.renderer.layouts(), &mesh.geometry(), &texture).unwrap();
    let mut settings = RenderSettings::new(camera);
    settings.filter = filter;
    settings.shading = Shading::Unlit;
    let image = gpu.renderer.render_image(&gpu.ctx, DrawItem::Mct(&gpu_mct), &settings, SIZE, SIZE).unwrap();
    let bvh = MeshBvh::build(&packed.positions, &packed.indices, BvhPreset::FastBuild);
    let background: [u8; 3] = settings.background.map(encode_srgb8)[..3].try_into().unwrap();
    let inputs = VertexLod::of(packed);
    let last = (texture.layout.levels - 1) as f32;
    let mut result = Comparison { lod_range: (f32::MAX, f32::MIN), ..Comparison::default() };
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
            let level = match filter {
                FilterMode::MipLevel(level) => level,
                FilterMode::Trilinear => {
                    let lod = continuous_lod(packed, &inputs, &camera, hit.face, hit.barycentric).clamp(0.0, last);
                    let truth = texture.sample_trilinear(hit.face, hit.barycentric, lod).unwrap();
                    let s = steps(pixel, truth);
                    result.max_steps = result.max_steps.max(s);
                    total += u64::from(s);
                    result.compared += 1;
                    result.lod_range = (result.lod_range.0.min(lod), result.lod_range.1.max(lod));
                    result.blended += usize::from((0.05..0.95).contains(&(lod - lod.floor())));
                    continue;
                }
                _ => 0,
            };
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

/// The filter mode of fixed `level`.
fn at_level(level: u32) -> FilterMode {
    if level == 0 { FilterMode::Linear } else { FilterMode::MipLevel(level) }
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
            check(&name, &compare(&packed, camera, at_level(0)), min_edge);
        }
    }
    for format in [ColorFormat::Rgba8Srgb, ColorFormat::Rgba16F] {
        let packed = suzanne_mixed(format);
        let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), -20.0, 10.0);
        for level in [0, 1, 3] {
            check(&format!("Suzanne mixed R {format:?} level {level}"), &compare(&packed, camera, at_level(level)), 0);
        }
    }
}

/// Trilinear: two explicit-level lookups blended at mesh colors' level of detail, every
/// sampled pixel against `sample_trilinear` at the level of detail of its definition; the
/// Duck from two distances and the mixed-resolution Suzanne, so that the views blend levels
/// over a range of more than one level.
#[test]
fn mct_trilinear_matches_its_cpu_evaluation_at_the_continuous_level_of_detail() {
    let duck = Document::open(&model("Duck/Duck.glb"), Resolution::new(32).unwrap()).unwrap();
    for format in [ColorFormat::Rgba8Srgb, ColorFormat::Rgba16F] {
        let packed = duck.pack(format).unwrap();
        let sphere = BoundingSphere::of_points(&packed.positions);
        for (yaw, pitch, zoom) in [(30.0, 20.0, 1.0), (-120.0, 10.0, 1.6)] {
            let mut camera = OrbitCamera::framing(sphere, yaw, pitch);
            camera.distance *= zoom;
            let c = compare(&packed, camera, FilterMode::Trilinear);
            let name = format!("Duck R=32 {format:?} zoom {zoom} trilinear");
            check(&name, &c, 0);
            assert!(c.blended * 2 > c.compared, "{name}: the view must blend levels");
        }
        let packed = suzanne_mixed(format);
        let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), -20.0, 10.0);
        let c = compare(&packed, camera, FilterMode::Trilinear);
        check(&format!("Suzanne mixed R {format:?} trilinear"), &c, 0);
        assert!(c.lod_range.1 - c.lod_range.0 > 1.0, "Suzanne: the lod must span levels");
    }
}

/// Every MCT pipeline draws as mesh colors do where both are the same signal: at R = 1 a
/// face's level-0 tent is one cell made planar by its ring, so hardware bilinear is the
/// linear interpolation of the vertex colours, mesh colors' linear filter (and trilinear has
/// one level). Lighting, smooth shading, the wireframe and the heat map come from the same
/// code (mesh_common.wgsl), specialised per pipeline for MCT: every pixel within 1 step.
#[test]
fn every_mct_pipeline_draws_as_mesh_colors_at_resolution_1() {
    let gpu = common::gpu::shared();
    let document = Document::open(&model("Duck/Duck.glb"), Resolution::new(1).unwrap()).unwrap();
    let packed = document.pack(ColorFormat::Rgba16F).unwrap();
    let mesh = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions::default()).unwrap();
    let texture = mct::build(&packed, 16384, u64::MAX).unwrap();
    let gpu_mct = GpuMct::upload(&gpu.ctx, gpu.renderer.layouts(), &mesh.geometry(), &texture).unwrap();
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&packed.positions), 30.0, 20.0);
    let mut failures = Vec::new();
    // Anisotropic: where the sampler magnifies the pipeline draws trilinear, equal to mesh
    // colors; where the footprint is longer than a texel its taps leave the face's one-texel
    // block (docs/MCT.md): counted, and bounded to the few pixels at grazing angles.
    for filter in [FilterMode::Linear, FilterMode::Trilinear, FilterMode::Anisotropic] {
        for shading in [Shading::Unlit, Shading::Lit, Shading::Smooth] {
            for (wireframe, heatmap) in [(false, false), (true, false), (false, true), (true, true)] {
                let mut settings = RenderSettings::new(camera);
                settings.filter = filter;
                settings.shading = shading;
                settings.overlays = Overlays { wireframe, heatmap };
                let render = |item| gpu.renderer.render_image(&gpu.ctx, item, &settings, SIZE, SIZE).unwrap();
                let (a, b) = (render(DrawItem::MeshColors(&mesh)), render(DrawItem::Mct(&gpu_mct)));
                let background: [u8; 3] = settings.background.map(encode_srgb8)[..3].try_into().unwrap();
                let (mut covered, mut worst, mut off) = (0usize, 0u8, 0usize);
                for (p, q) in a.pixels().zip(b.pixels()) {
                    covered += usize::from(p.0[..3] != background);
                    let d = (0..3).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap_or(0);
                    worst = worst.max(d);
                    off += usize::from(d > 1);
                }
                let name = format!("{filter:?} {shading:?} wireframe {wireframe} heat map {heatmap}");
                println!("{name}: {covered} px covered, worst {worst} steps, {off} px off by more than 1");
                let anisotropic = filter == FilterMode::Anisotropic;
                if (worst > 1 && !anisotropic) || off * 20 > covered || covered < 5000 {
                    failures.push(format!("{name}: {covered} px covered, worst {worst} steps"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
