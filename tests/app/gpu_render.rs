//! The GPU renderer against the CPU reference sampler, per pixel, on a real adapter
//! (lavapipe on machines without a GPU). These tests FAIL when no adapter exists.
//!
//! Truth per pixel: the ray through the pixel centre (`OrbitCamera::ray_through_pixel`) is
//! intersected with every triangle in `f64` (no BVH: a handful of triangles), giving the face
//! and its barycentrics; `meshpaint_core::packing::sampler::sample` on the same `PackedMesh` gives the
//! colour, encoded to sRGB8 as the render target does. Errors are reported in 8-bit steps.
//! Pixels whose centre lies within a margin of a triangle edge are skipped (coverage rules),
//! and for nearest filtering so are pixels within 1e-3 lattice units of a cell boundary.

// Colour channels and image rows are indexed in parallel arrays; indices read clearest.
#![allow(clippy::needless_range_loop)]

use std::path::PathBuf;

use glam::DVec3;
use image::RgbaImage;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, encode_rgba8_srgb};
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::lod::LOD_BIAS;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::packing::sampler::{Filter, sample, sample_trilinear};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_render::{DrawItem, FilterMode, GpuMesh, MeshUploadOptions, RenderSettings, Shading};

use crate::common;
use crate::common::WriteThrough;
use common::gpu::{shared as gpu, textured_baseline};
use common::{Rng, model, output_dir};

const SIZE: u32 = 256;
/// Largest allowed per-channel difference in 8-bit steps (every comparison here reached at
/// most 1 on lavapipe: the rounding of the sRGB8 encode; README "GPU vs CPU reference").
const MAX_STEPS: u32 = 1;
/// Pixels whose centre has a barycentric coordinate below this are edge pixels (skipped).
const EDGE_MARGIN: f64 = 1e-4;
/// Nearest filtering: pixels within this many lattice units of a cell boundary are skipped.
const CELL_MARGIN: f32 = 1e-3;

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

/// A test scene: triangles, a camera, and the store they are coloured with.
struct Scene {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    camera: OrbitCamera,
    store: ColorStore,
    /// For real meshes (thousands of faces): pixel truth from the BVH's watertight `f64`
    /// ray cast instead of brute force over every triangle.
    bvh: Option<MeshBvh>,
}

/// Random colours with alpha in [0.5, 1] (the background is transparent black, so
/// coverage shows in alpha).
fn random_store(vertex_count: u32, triangles: &[[u32; 3]], resolutions: Vec<Resolution>, seed: u64) -> ColorStore {
    let topology = Topology::build(vertex_count, triangles).unwrap();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).unwrap();
    let mut rng = Rng(seed);
    store.write_all(|_| [rng.unit(), rng.unit(), rng.unit(), 0.5 + 0.5 * rng.unit()]);
    store
}

/// A camera looking along −Z at `center` (yaw 0, pitch 0), framing a sphere of `radius`.
fn square_camera(center: [f64; 3], radius: f64) -> OrbitCamera {
    OrbitCamera::framing(BoundingSphere { center, radius }, 0.0, 0.0)
}

/// The world point on the plane `z = center.z` seen through pixel position `(x, y)`.
fn unproject_to_plane(camera: &OrbitCamera, x: f64, y: f64) -> [f32; 3] {
    let (origin, direction) = camera.ray_through_pixel(x, y, SIZE, SIZE);
    let t = (camera.target[2] - origin.z) / direction.z;
    let p = origin + direction * t;
    [p.x as f32, p.y as f32, p.z as f32]
}

/// A scene of triangles facing the camera squarely (constant depth), with vertices at the
/// given pixel positions (integer positions land exactly on the rasteriser's grid).
fn square_scene(
    pixels: &[[f64; 2]],
    triangles: Vec<[u32; 3]>,
    resolutions: Vec<Resolution>,
    center: [f64; 3],
    seed: u64,
) -> Scene {
    let camera = square_camera(center, 1.0);
    let positions: Vec<[f32; 3]> = pixels.iter().map(|&[x, y]| unproject_to_plane(&camera, x, y)).collect();
    let store = random_store(positions.len() as u32, &triangles, resolutions, seed);
    Scene { positions, triangles, camera, store, bvh: None }
}

/// What the reference says about one pixel.
enum Truth {
    /// No triangle: background.
    Background,
    /// Too close to an edge (or to another surface) to call.
    Ambiguous,
    /// Face and barycentrics of the closest hit.
    Hit(u32, [f64; 3]),
}

impl Scene {
    /// Intersects the pixel-centre ray with every triangle (Möller–Trumbore in f64,
    /// barycentrics of the plane hit even outside the triangle).
    fn truth(&self, x: u32, y: u32) -> Truth {
        if let Some(bvh) = &self.bvh {
            return bvh_truth(bvh, &self.camera, x, y);
        }
        let (origin, direction) = self.camera.ray_through_pixel(f64::from(x) + 0.5, f64::from(y) + 0.5, SIZE, SIZE);
        let p = |v: u32| {
            let p = self.positions[v as usize];
            DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
        };
        let mut hits = Vec::new();
        let mut ambiguous = false;
        for (face, tri) in self.triangles.iter().enumerate() {
            let (a, b, c) = (p(tri[0]), p(tri[1]), p(tri[2]));
            let (e1, e2) = (b - a, c - a);
            let pv = direction.cross(e2);
            let det = e1.dot(pv);
            if det.abs() < 1e-300 {
                continue;
            }
            let tv = origin - a;
            let u = tv.dot(pv) / det;
            let qv = tv.cross(e1);
            let v = direction.dot(qv) / det;
            let t = e2.dot(qv) / det;
            let bary = [1.0 - u - v, u, v];
            let min = bary.iter().copied().fold(f64::INFINITY, f64::min);
            if t <= 0.0 || min < -EDGE_MARGIN {
                continue;
            }
            if min < EDGE_MARGIN {
                ambiguous = true;
            }
            hits.push((t, face as u32, bary, min >= EDGE_MARGIN));
        }
        hits.sort_by(|a, b| a.0.total_cmp(&b.0));
        match hits.first() {
            None => Truth::Background,
            Some(&(t, face, bary, inside)) => {
                let close_second = hits.get(1).is_some_and(|second| (second.0 - t).abs() < 1e-6 * t);
                if !inside || close_second || (ambiguous && hits.iter().any(|h| !h.3 && h.0 < t * (1.0 + 1e-6))) {
                    Truth::Ambiguous
                } else {
                    Truth::Hit(face, bary)
                }
            }
        }
    }

    fn packed(&self, format: ColorFormat) -> PackedMesh {
        pack(&self.store, &self.positions, format).unwrap()
    }
}

/// The pixel truth from a BVH: the hit at the pixel centre, ambiguous when it is within
/// 2·10⁻³ (barycentric) of an edge or when rays 0.02 px away see another face or nothing
/// (silhouettes, near-equal depths); background only when those rays miss too.
fn bvh_truth(bvh: &MeshBvh, camera: &OrbitCamera, x: u32, y: u32) -> Truth {
    let cast = |dx: f64, dy: f64| {
        let (origin, direction) =
            camera.ray_through_pixel(f64::from(x) + 0.5 + dx, f64::from(y) + 0.5 + dy, SIZE, SIZE);
        bvh.cast(origin, direction, f64::INFINITY)
    };
    let center = cast(0.0, 0.0);
    let around = [(0.02, 0.0), (-0.02, 0.0), (0.0, 0.02), (0.0, -0.02)].map(|(dx, dy)| cast(dx, dy).map(|h| h.face));
    match center {
        None if around.iter().all(Option::is_none) => Truth::Background,
        None => Truth::Ambiguous,
        Some(hit) if hit.barycentric.iter().any(|&w| w < 2e-3) || around.iter().any(|f| *f != Some(hit.face)) => {
            Truth::Ambiguous
        }
        Some(hit) => Truth::Hit(hit.face, hit.barycentric.map(f64::from)),
    }
}

/// Whether nearest filtering at `level` could pick another sample within `CELL_MARGIN`
/// lattice units of `bary` (the pixel is on a cell boundary).
fn near_cell_boundary(packed: &PackedMesh, face: u32, bary: [f32; 3], level: u32) -> bool {
    let r_face = packed.face_records[face as usize].resolution().unwrap();
    let level = level.min(r_face.log2());
    let res = r_face.at_level(level).unwrap();
    let chosen = layout::nearest_sample(res, bary);
    let d = CELL_MARGIN / res.get() as f32;
    let moves: [[f32; 3]; 6] = [[-d, d, 0.0], [d, -d, 0.0], [-d, 0.0, d], [d, 0.0, -d], [0.0, d, -d], [0.0, -d, d]];
    moves.iter().any(|m| layout::nearest_sample(res, std::array::from_fn(|k| bary[k] + m[k])) != chosen)
}

/// Statistics of one comparison.
#[derive(Debug, Default)]
struct Comparison {
    compared: u64,
    skipped: u64,
    max_steps: u32,
    sum_steps: f64,
    over_limit: u64,
    coverage_errors: u64,
}

impl Comparison {
    fn mean(&self) -> f64 {
        if self.compared == 0 { 0.0 } else { self.sum_steps / (self.compared as f64 * 4.0) }
    }
}

fn render(scene_mesh: &GpuMesh, camera: OrbitCamera, filter: FilterMode) -> RgbaImage {
    let gpu = gpu();
    let mut settings = RenderSettings::new(camera);
    settings.filter = filter;
    settings.shading = Shading::Unlit;
    settings.background = [0.0; 4];
    gpu.renderer.render_image(&gpu.ctx, DrawItem::MeshColors(scene_mesh), &settings, SIZE, SIZE).unwrap()
}

/// Renders `scene` in `format` with `filter` and compares every pixel with the CPU
/// reference `(cpu_filter, level)` (`None` level = trilinear with the analytic `lod`).
/// Returns the statistics; writes PNGs on failure.
fn compare(
    name: &str,
    scene: &Scene,
    mesh: &GpuMesh,
    filter: FilterMode,
    reference: impl Fn(u32, [f32; 3]) -> Option<[f32; 4]>,
    skip: impl Fn(u32, [f32; 3]) -> bool,
) -> Comparison {
    let image = render(mesh, scene.camera, filter);
    let mut expected = RgbaImage::new(SIZE, SIZE);
    let mut stats = Comparison::default();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let actual = image.get_pixel(x, y).0;
            match scene.truth(x, y) {
                Truth::Background => {
                    if actual != [0; 4] {
                        stats.coverage_errors += 1;
                    }
                }
                Truth::Ambiguous => stats.skipped += 1,
                Truth::Hit(face, bary64) => {
                    let bary = bary64.map(|w| w as f32);
                    if skip(face, bary) {
                        stats.skipped += 1;
                        continue;
                    }
                    if actual[3] == 0 {
                        stats.coverage_errors += 1;
                        continue;
                    }
                    let cpu = reference(face, bary).unwrap_or_else(|| panic!("{name}: CPU sample failed"));
                    let want = encode_rgba8_srgb(cpu);
                    expected.put_pixel(x, y, image::Rgba(want));
                    let mut pixel_max = 0;
                    for c in 0..4 {
                        let steps = u32::from(want[c].abs_diff(actual[c]));
                        stats.sum_steps += f64::from(steps);
                        pixel_max = pixel_max.max(steps);
                    }
                    stats.max_steps = stats.max_steps.max(pixel_max);
                    if pixel_max > MAX_STEPS {
                        stats.over_limit += 1;
                    }
                    stats.compared += 1;
                }
            }
        }
    }
    eprintln!(
        "{name}: max {} steps, mean {:.4} steps, {} px compared, {} skipped, {} over {MAX_STEPS}, {} coverage errors",
        stats.max_steps,
        stats.mean(),
        stats.compared,
        stats.skipped,
        stats.over_limit,
        stats.coverage_errors
    );
    if stats.over_limit > 0 || stats.coverage_errors > 0 {
        let dir = output_dir();
        let file = name.replace([' ', '=', '/'], "_");
        image.save(dir.join(format!("{file}.actual.png"))).unwrap();
        expected.save(dir.join(format!("{file}.expected.png"))).unwrap();
        let diff = RgbaImage::from_fn(SIZE, SIZE, |x, y| {
            let (a, e) = (image.get_pixel(x, y).0, expected.get_pixel(x, y).0);
            let d = |c: usize| a[c].abs_diff(e[c]).saturating_mul(16);
            image::Rgba([d(0), d(1), d(2), 255])
        });
        diff.save(dir.join(format!("{file}.diff.png"))).unwrap();
    }
    stats
}

fn upload(packed: &PackedMesh, atlas_width: Option<u32>) -> GpuMesh {
    let gpu = gpu();
    GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), packed, &MeshUploadOptions { atlas_width }).unwrap()
}

/// Nearest at level 0, then linear and nearest at every level of the finest face.
fn fixed_filters(max_log2: u32) -> Vec<(FilterMode, Filter, u32)> {
    let mut filters = vec![(FilterMode::Nearest, Filter::Nearest, 0), (FilterMode::Linear, Filter::Linear, 0)];
    for level in 0..=max_log2 {
        filters.push((FilterMode::MipLevel(level), Filter::Linear, level));
        filters.push((FilterMode::NearestMipLevel(level), Filter::Nearest, level));
    }
    filters
}

fn filter_name(filter: FilterMode) -> String {
    match filter {
        FilterMode::Nearest => "nearest".into(),
        FilterMode::Linear => "linear".into(),
        FilterMode::MipLevel(level) => format!("linear L{level}"),
        FilterMode::NearestMipLevel(level) => format!("nearest L{level}"),
        FilterMode::Trilinear => "trilinear".into(),
        FilterMode::Anisotropic => "anisotropic".into(),
    }
}

/// Compares `scene` for every format and fixed filter; returns the failures.
fn compare_all_fixed(label: &str, scene: &Scene, max_log2: u32) -> Vec<String> {
    let mut failures = Vec::new();
    for format in ColorFormat::ALL {
        let packed = scene.packed(format);
        let mesh = upload(&packed, None);
        for (mode, cpu_filter, level) in fixed_filters(max_log2) {
            let name = format!("{label} {} {}", format.name(), filter_name(mode));
            let stats = compare(
                &name,
                scene,
                &mesh,
                mode,
                |face, bary| sample(&packed, face, bary, cpu_filter, level),
                |face, bary| cpu_filter == Filter::Nearest && near_cell_boundary(&packed, face, bary, level),
            );
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared == 0 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
    }
    failures
}

/// One large triangle facing the camera, vertices on integer pixel positions.
fn big_triangle(resolution: u64, seed: u64) -> Scene {
    square_scene(
        &[[14.0, 236.0], [243.0, 221.0], [97.0, 9.0]],
        vec![[0, 1, 2]],
        vec![r(resolution)],
        [0.0, 0.0, 0.0],
        seed,
    )
}

fn square_on_triangle(resolution: u64) {
    let scene = big_triangle(resolution, 0x9E37_79B9 ^ resolution);
    let failures = compare_all_fixed(&format!("triangle R={resolution}"), &scene, r(resolution).log2());
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn square_on_triangle_r1() {
    square_on_triangle(1);
}

#[test]
fn square_on_triangle_r2() {
    square_on_triangle(2);
}

#[test]
fn square_on_triangle_r8() {
    square_on_triangle(8);
}

#[test]
fn square_on_triangle_r64() {
    square_on_triangle(64);
}

#[test]
fn square_on_triangle_r4096() {
    square_on_triangle(4096);
}

/// The trilinear level of detail at barycentrics `bary` of `face`, computed from its
/// definition (crates/core/src/packing/lod.rs module docs) in `f64` and independently of the renderer:
/// `log2(Σ bᵢ depthᵢ) + Σ bᵢ μᵢ`, `μᵢ = log2(κ ρᵢ / max(|nᵢ · v̂ᵢ|, 1/16))`, the density
/// `ρᵢ` the largest `R_f / sqrt(2 A_f)` around vertex `i`, clamped to `[0, log2 max R]`.
fn continuous_lod(scene: &Scene, face: u32, bary: [f32; 3]) -> f32 {
    continuous_lod_with(scene, &lod_inputs(scene), face, bary)
}

/// Per vertex: the density `ρᵢ` (largest `R_f / sqrt(2 A_f)` around it) and the unit
/// area-weighted normal, in `f64` (one pass over the faces).
fn lod_inputs(scene: &Scene) -> Vec<(f64, DVec3)> {
    let point = |v: u32| {
        let p = scene.positions[v as usize];
        DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
    };
    let resolutions = scene.store.face_resolutions();
    let mut inputs = vec![(0.0f64, DVec3::ZERO); scene.positions.len()];
    for (f, tri) in scene.triangles.iter().enumerate() {
        let cross = (point(tri[1]) - point(tri[0])).cross(point(tri[2]) - point(tri[0]));
        for &v in tri {
            let (density, normal) = &mut inputs[v as usize];
            *density = density.max(resolutions[f].get() as f64 / cross.length().sqrt());
            *normal += cross;
        }
    }
    inputs.into_iter().map(|(density, normal)| (density, normal.normalize_or_zero())).collect()
}

/// [`continuous_lod`] with the per-vertex inputs computed once.
fn continuous_lod_with(scene: &Scene, inputs: &[(f64, DVec3)], face: u32, bary: [f32; 3]) -> f32 {
    let point = |v: u32| {
        let p = scene.positions[v as usize];
        DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
    };
    let resolutions = scene.store.face_resolutions();
    let camera = &scene.camera;
    let eye = camera.eye();
    let forward = (DVec3::from_array(camera.target) - eye).normalize();
    let kappa = 2.0 * (camera.fov_y_degrees.to_radians() * 0.5).tan() / f64::from(SIZE);
    let (mut depth, mut mu) = (0.0, 0.0);
    for (k, &v) in scene.triangles[face as usize].iter().enumerate() {
        let (density, normal) = inputs[v as usize];
        let to_eye = eye - point(v);
        let cosine = normal.dot(to_eye).abs() / to_eye.length();
        depth += f64::from(bary[k]) * (point(v) - eye).dot(forward);
        let term = (kappa * density / cosine.max(1.0 / 16.0)).log2() + f64::from(LOD_BIAS);
        mu += f64::from(bary[k]) * term.clamp(-64.0, 64.0);
    }
    let last = resolutions.iter().map(|r| r.log2()).max().unwrap_or(0);
    (depth.log2() + mu).clamp(0.0, f64::from(last)) as f32
}

/// Trilinear against the CPU reference at the level of detail of its definition
/// ([`continuous_lod`]): the GPU must blend the same two levels by the same weight. Every
/// pixel's `lod` differs slightly (depth is constant, the view angle is not).
#[test]
fn trilinear_matches_the_continuous_level_of_detail() {
    let mut failures = Vec::new();
    // Fine enough that the level of detail, with its bias, blends levels ≥ 1.
    for resolution in [1024u64, 4096] {
        let scene = big_triangle(resolution, 77 + resolution);
        // The blend must matter: most pixels between two levels, not at one.
        let lods: Vec<f32> = (0..SIZE * SIZE)
            .filter_map(|k| match scene.truth(k % SIZE, k / SIZE) {
                Truth::Hit(face, bary) => Some(continuous_lod(&scene, face, bary.map(|w| w as f32))),
                _ => None,
            })
            .collect();
        let blended = lods.iter().filter(|lod| (0.05..0.95).contains(&(*lod - lod.floor()))).count();
        assert!(blended * 2 > lods.len(), "R={resolution}: pick a geometry whose lod is not near an integer");
        for format in ColorFormat::ALL {
            let packed = scene.packed(format);
            let mesh = upload(&packed, None);
            let (lo, hi) = lods.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &l| (lo.min(l), hi.max(l)));
            let name = format!("trilinear R={resolution} {} lod {lo:.3}..{hi:.3}", format.name());
            let stats = compare(
                &name,
                &scene,
                &mesh,
                FilterMode::Trilinear,
                |face, bary| sample_trilinear(&packed, face, bary, continuous_lod(&scene, face, bary)),
                |_, _| false,
            );
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared == 0 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Trilinear (the editor's default filter) on a real mesh in perspective: the Duck baked at
/// R = 32, seen from two distances so that the level of detail spans several levels, every
/// pixel against the CPU reference at the level of detail of its definition (computed here,
/// [`continuous_lod_with`]); pixel truth from the BVH's `f64` ray cast.
#[test]
fn trilinear_on_the_duck_in_perspective_matches_the_continuous_level_of_detail() {
    let document = meshpaint_core::io::document::Document::open(&model("Duck/Duck.glb"), r(32)).unwrap();
    let triangles = document.store.topology().face_vertices.clone();
    let bvh = MeshBvh::build(&document.positions, &triangles, BvhPreset::default());
    let sphere = BoundingSphere::of_points(&document.positions);
    let mut failures = Vec::new();
    for (yaw, pitch, zoom) in [(30.0, 20.0, 1.0), (-120.0, 10.0, 3.0)] {
        let mut camera = OrbitCamera::framing(sphere, yaw, pitch);
        camera.distance *= zoom;
        let scene = Scene {
            positions: document.positions.clone(),
            triangles: triangles.clone(),
            camera,
            store: document.store.clone(),
            bvh: Some(bvh.clone()),
        };
        let inputs = lod_inputs(&scene);
        let lods: Vec<f32> = (0..SIZE * SIZE)
            .filter_map(|k| match scene.truth(k % SIZE, k / SIZE) {
                Truth::Hit(face, bary) => Some(continuous_lod_with(&scene, &inputs, face, bary.map(|w| w as f32))),
                _ => None,
            })
            .collect();
        let (lo, hi) = lods.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &l| (lo.min(l), hi.max(l)));
        let blended = lods.iter().filter(|lod| (0.05..0.95).contains(&(*lod - lod.floor()))).count();
        eprintln!("Duck R=32 zoom {zoom}: lod {lo:.3}..{hi:.3}, {blended} of {} px between two levels", lods.len());
        assert!(blended * 2 > lods.len() && hi - lo > 1.0, "zoom {zoom}: the view must blend levels");
        for format in ColorFormat::ALL {
            let packed = scene.packed(format);
            let mesh = upload(&packed, None);
            let name = format!("Duck trilinear zoom {zoom} {} lod {lo:.2}..{hi:.2}", format.name());
            let stats = compare(
                &name,
                &scene,
                &mesh,
                FilterMode::Trilinear,
                |face, bary| sample_trilinear(&packed, face, bary, continuous_lod_with(&scene, &inputs, face, bary)),
                |_, _| false,
            );
            // The far view covers ~2 000 pixels.
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared < 1_500 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Trilinear across a shared edge of mixed resolution, at distances where the finer face
/// blends MIP levels: the level of detail is a function of the surface point (not of the
/// face), so both faces blend the edge's chain at the same level and agree along it; every
/// pixel on both sides matches the CPU reference at that level of detail.
#[test]
fn trilinear_is_seamless_across_mixed_resolution_edges() {
    let mut failures = Vec::new();
    // Resolutions fine enough that the edge's level of detail, with its bias, is past 1.
    for (ra, rb, seed) in [(4096u64, 256u64, 5u64), (4096, 2, 6), (1, 2048, 7), (2048, 2048, 8)] {
        let scene = square_scene(
            &[[18.0, 31.0], [229.0, 44.0], [37.0, 223.0], [241.0, 238.0]],
            vec![[0, 1, 2], [2, 1, 3]],
            vec![r(ra), r(rb)],
            [0.0, 0.0, 0.0],
            seed,
        );
        // Along the shared edge (vertices 1 and 2) the finer face's level blends two levels.
        let on_edge = continuous_lod(&scene, 0, [0.0, 0.5, 0.5]);
        assert!(on_edge > 1.0 && on_edge.fract() > 0.02, "R={ra}|{rb}: lod {on_edge} on the edge");
        for format in ColorFormat::ALL {
            let packed = scene.packed(format);
            let mesh = upload(&packed, None);
            let name = format!("trilinear seam R={ra}|{rb} {} (edge lod {on_edge:.3})", format.name());
            let stats = compare(
                &name,
                &scene,
                &mesh,
                FilterMode::Trilinear,
                |face, bary| sample_trilinear(&packed, face, bary, continuous_lod(&scene, face, bary)),
                |_, _| false,
            );
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared < 20_000 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// R = 2 next to R = 32 across a shared edge that the two faces walk in opposite
/// directions: both must read the shared edge chain correctly at every level.
#[test]
fn mixed_resolutions_across_a_shared_edge() {
    let scene = square_scene(
        &[[18.0, 31.0], [229.0, 44.0], [37.0, 223.0], [241.0, 238.0]],
        vec![[0, 1, 2], [2, 1, 3]],
        vec![r(2), r(32)],
        [0.0, 0.0, 0.0],
        4242,
    );
    assert!(scene.store.topology().is_reversed(1, 0), "face 1 walks the shared edge 2→1");
    let failures = compare_all_fixed("shared edge R=2|32", &scene, 5);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The octahedron in perspective with eight different resolutions (1..32): vertex pulling
/// with many faces, perspective-correct barycentrics, every edge orientation.
#[test]
fn octahedron_in_perspective_with_mixed_resolutions() {
    let positions =
        vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let triangles = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    let resolutions = [1, 2, 4, 8, 16, 4, 1, 32].map(r).to_vec();
    let store = random_store(6, &triangles, resolutions, 99);
    let mut camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 35.0, 25.0);
    camera.distance *= 0.8;
    let scene = Scene { positions, triangles, camera, store, bvh: None };
    let failures = compare_all_fixed("octahedron", &scene, 5);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A colour atlas forced to tiny widths (61, not a power of two; 1; 7) renders exactly the
/// same image as the default width.
#[test]
fn tiny_atlas_widths_render_the_same_image() {
    let scenes = [
        ("triangle R=64", big_triangle(64, 5)),
        (
            "shared edge",
            square_scene(
                &[[18.0, 31.0], [229.0, 44.0], [37.0, 223.0], [241.0, 238.0]],
                vec![[0, 1, 2], [2, 1, 3]],
                vec![r(8), r(32)],
                [0.0, 0.0, 0.0],
                6,
            ),
        ),
    ];
    for (label, scene) in &scenes {
        for format in ColorFormat::ALL {
            let packed = scene.packed(format);
            let reference = upload(&packed, None);
            assert!(reference.atlas.height == 1, "the default atlas holds these samples in one row");
            for width in [61u32, 7, 1] {
                let narrow = upload(&packed, Some(width));
                assert_eq!(narrow.atlas.width, width);
                assert_eq!(u64::from(narrow.atlas.height), packed.sample_count().div_ceil(u64::from(width)));
                for filter in [FilterMode::Nearest, FilterMode::Linear, FilterMode::MipLevel(2), FilterMode::Trilinear]
                {
                    let want = render(&reference, scene.camera, filter);
                    let got = render(&narrow, scene.camera, filter);
                    if want != got {
                        let dir = output_dir();
                        let file = format!("atlas_{}_{}_{width}", label.replace(' ', "_"), format.name());
                        got.save(dir.join(format!("{file}.actual.png"))).unwrap();
                        want.save(dir.join(format!("{file}.expected.png"))).unwrap();
                        panic!(
                            "{label} {} width {width} {filter:?}: image differs from the default width",
                            format.name()
                        );
                    }
                }
            }
        }
    }
}

/// A sliver (1.5 px tall, 230 px long) next to a zero-area face, lit and unlit: no NaN,
/// no garbage, and the sliver's pixels match the CPU.
#[test]
fn sliver_and_degenerate_faces() {
    let scene = square_scene(
        &[[10.0, 100.0], [246.0, 103.0], [128.0, 103.0], [20.0, 200.0], [120.0, 200.0], [220.0, 200.0]],
        vec![[0, 1, 2], [3, 4, 5]],
        vec![r(16), r(4)],
        [0.0, 0.0, 0.0],
        11,
    );
    let mut failures = Vec::new();
    for format in ColorFormat::ALL {
        let packed = scene.packed(format);
        let mesh = upload(&packed, None);
        for (mode, cpu_filter, level) in [
            (FilterMode::Nearest, Filter::Nearest, 0),
            (FilterMode::Linear, Filter::Linear, 0),
            (FilterMode::MipLevel(2), Filter::Linear, 2),
        ] {
            let name = format!("sliver {} {}", format.name(), filter_name(mode));
            let stats = compare(
                &name,
                &scene,
                &mesh,
                mode,
                |face, bary| sample(&packed, face, bary, cpu_filter, level),
                |face, bary| cpu_filter == Filter::Nearest && near_cell_boundary(&packed, face, bary, level),
            );
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared < 30 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
        // Lit with trilinear and overlays: every covered pixel is finite colour, the rest background.
        let gpu = gpu();
        let mut settings = RenderSettings::new(scene.camera);
        settings.overlays.wireframe = true;
        settings.background = [0.0; 4];
        let image = gpu.renderer.render_image(&gpu.ctx, DrawItem::MeshColors(&mesh), &settings, SIZE, SIZE).unwrap();
        let covered = image.pixels().filter(|p| p.0[3] != 0).count();
        assert!((30..2000).contains(&covered), "{covered} pixels covered");
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The big triangle translated by 1e6 on every axis: positions go to the GPU relative to
/// the render origin, so the image matches the CPU as well as at the origin.
#[test]
fn far_from_the_origin() {
    let center = [1.0e6, -1.0e6, 1.0e6];
    // Size the triangle so that f32 positions (spacing 0.0625 at 1e6) barely move it.
    let camera = square_camera(center, 200.0);
    let pixels = [[14.0, 236.0], [243.0, 221.0], [97.0, 9.0]];
    let positions: Vec<[f32; 3]> = pixels.iter().map(|&[x, y]| unproject_to_plane(&camera, x, y)).collect();
    for p in &positions {
        assert!(p[0] > 9.0e5 && p[2] > 9.0e5, "{p:?}");
    }
    let triangles = vec![[0, 1, 2]];
    let store = random_store(3, &triangles, vec![r(64)], 1234);
    let scene = Scene { positions, triangles, camera, store, bvh: None };
    let failures = compare_all_fixed("offset 1e6 R=64", &scene, 3);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// One R = 4096 face covering the whole 256×256 image (vertices far outside the viewport).
#[test]
fn r4096_face_fills_the_screen() {
    let scene = square_scene(
        &[[-300.0, 420.0], [560.0, 400.0], [120.0, -500.0]],
        vec![[0, 1, 2]],
        vec![r(4096)],
        [0.0, 0.0, 0.0],
        31337,
    );
    let mut failures = Vec::new();
    for format in ColorFormat::ALL {
        let packed = scene.packed(format);
        let mesh = upload(&packed, None);
        for (mode, cpu_filter, level) in [
            (FilterMode::Nearest, Filter::Nearest, 0),
            (FilterMode::Linear, Filter::Linear, 0),
            (FilterMode::MipLevel(3), Filter::Linear, 3),
            (FilterMode::NearestMipLevel(7), Filter::Nearest, 7),
            (FilterMode::MipLevel(12), Filter::Linear, 12),
        ] {
            let name = format!("fill R=4096 {} {}", format.name(), filter_name(mode));
            let stats = compare(
                &name,
                &scene,
                &mesh,
                mode,
                |face, bary| sample(&packed, face, bary, cpu_filter, level),
                |face, bary| cpu_filter == Filter::Nearest && near_cell_boundary(&packed, face, bary, level),
            );
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared < u64::from(SIZE * SIZE) * 9 / 10 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Mean per-channel difference (8-bit steps) over pixels covered in both images, and the
/// number of pixels covered in exactly one.
fn image_difference(a: &RgbaImage, b: &RgbaImage, background: [u8; 4]) -> (f64, u64, u64) {
    let (mut sum, mut both, mut one) = (0u64, 0u64, 0u64);
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        match (pa.0 != background, pb.0 != background) {
            (true, true) => {
                both += 1;
                sum += (0..3).map(|c| u64::from(pa.0[c].abs_diff(pb.0[c]))).sum::<u64>();
            }
            (false, false) => {}
            _ => one += 1,
        }
    }
    (sum as f64 / (both.max(1) * 3) as f64, both, one)
}

/// Mesh colors (texture baked at R = 16, trilinear) and the UV baseline (hardware
/// trilinear) draw the Duck alike: same silhouette, small mean colour difference.
#[test]
fn mesh_colors_and_the_uv_baseline_look_alike() {
    use meshpaint_core::camera::{BoundingSphere, default_camera};
    let gpu = gpu();
    let path = model("Duck/Duck.glb");
    let document = meshpaint_core::io::document::Document::open(&path, r(16)).unwrap();
    let packed = document.pack(ColorFormat::Rgba8Srgb).unwrap();
    let mesh = upload(&packed, None);
    let baseline = textured_baseline(gpu, &path);
    let mut settings =
        RenderSettings::new(default_camera(BoundingSphere::of_points(&document.positions), 30.0, 20.0, None));
    settings.background = [0.0; 4];
    for shading in [Shading::Unlit, Shading::Lit, Shading::Smooth] {
        settings.shading = shading;
        let ours = gpu.renderer.render_image(&gpu.ctx, DrawItem::MeshColors(&mesh), &settings, SIZE, SIZE).unwrap();
        let theirs = gpu.renderer.render_image(&gpu.ctx, DrawItem::Baseline(&baseline), &settings, SIZE, SIZE).unwrap();
        let (mean, both, one) = image_difference(&ours, &theirs, [0; 4]);
        eprintln!(
            "Duck R=16 vs UV baseline ({shading:?}): mean {mean:.3} steps over {both} px, {one} px differ in coverage"
        );
        if mean > 4.0 || both < 10_000 || one > both / 200 {
            let dir = output_dir();
            ours.save(dir.join(format!("duck_equivalence_{shading:?}.actual.png"))).unwrap();
            theirs.save(dir.join(format!("duck_equivalence_{shading:?}.expected.png"))).unwrap();
            panic!("mesh colors and the UV baseline differ: mean {mean} steps, {both} px, {one} coverage");
        }
    }
}

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn run_cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(BIN).args(args).output().unwrap()
}

fn temp_png(name: &str) -> PathBuf {
    output_dir().join(format!("cli-{}-{name}.png", std::process::id()))
}

#[test]
fn cli_render_writes_pngs_of_the_requested_size() {
    let cases: [(&str, Vec<&str>); 5] = [
        ("default", vec![]),
        ("nearest", vec!["--filter", "nearest", "--shading", "unlit", "--resolution", "4", "--wireframe"]),
        ("mip", vec!["--filter", "mip", "--level", "2", "--heatmap", "--yaw", "-45", "--pitch", "-10"]),
        ("linear", vec!["--filter", "linear", "--distance", "5"]),
        ("baseline", vec!["--baseline-uv", "--wireframe"]),
    ];
    let file = model("BoxTextured/BoxTextured.glb");
    for (name, extra) in cases {
        let out = temp_png(name);
        let mut args = vec!["render", file.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", "96"];
        args.extend(["--height", "64"]);
        args.extend(extra);
        let output = run_cli(&args);
        assert!(output.status.success(), "{name}: {}", String::from_utf8_lossy(&output.stderr));
        let image = image::open(&out).unwrap().to_rgba8();
        assert_eq!(image.dimensions(), (96, 64), "{name}");
        let background = *image.get_pixel(0, 0);
        assert!(image.pixels().any(|p| *p != background), "{name}: the box is visible");
        std::fs::remove_file(&out).unwrap();
    }
}

#[test]
fn cli_render_refuses_bad_requests_with_a_message() {
    let textured = model("BoxTextured/BoxTextured.glb");
    let untextured = model("Suzanne/monkey.glb");
    let out = temp_png("refused");
    let out = out.to_str().unwrap();
    let cases: [(Vec<&str>, &str); 5] = [
        (vec![textured.to_str().unwrap(), "--filter", "mip"], "--level"),
        (vec![textured.to_str().unwrap(), "--filter", "trilinear", "--level", "1"], "--level"),
        (vec![textured.to_str().unwrap(), "--resolution", "3"], "resolution"),
        (vec![textured.to_str().unwrap(), "--width", "0"], "render size"),
        (vec![untextured.to_str().unwrap(), "--baseline-uv"], "base-colour texture"),
    ];
    for (args, expected) in cases {
        let mut full = vec!["render", "-o", out];
        full.extend(args.iter().copied());
        let output = run_cli(&full);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} should fail");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

#[test]
fn atlas_layout_wraps_rows_and_refuses_what_does_not_fit() {
    use meshpaint_render::{AtlasLayout, RenderError};
    let atlas = AtlasLayout::new(1000, 61, 16384).unwrap();
    assert_eq!((atlas.width, atlas.height), (61, 17));
    assert_eq!(atlas.texel(0), (0, 0));
    assert_eq!(atlas.texel(60), (60, 0));
    assert_eq!(atlas.texel(61), (0, 1));
    assert_eq!(atlas.texel(999), (999 % 61, 999 / 61));
    assert_eq!(AtlasLayout::new(0, 16384, 16384).unwrap().height, 1, "an empty buffer still gets one row");
    // 2^28 samples (MAX_SAMPLES) fill a 16384² atlas exactly; one more does not fit.
    let full = AtlasLayout::new(meshpaint_core::packing::linear::MAX_SAMPLES, 16384, 16384).unwrap();
    assert_eq!(full.height, 16384);
    assert!(matches!(
        AtlasLayout::new(meshpaint_core::packing::linear::MAX_SAMPLES + 1, 16384, 16384),
        Err(RenderError::AtlasTooLarge { .. })
    ));
    assert!(matches!(AtlasLayout::new(10, 0, 16384), Err(RenderError::InvalidAtlasWidth { .. })));
    assert!(matches!(AtlasLayout::new(10, 20000, 16384), Err(RenderError::InvalidAtlasWidth { .. })));
}

/// A mesh whose atlas would need more rows than the device allows is refused with an
/// error, not a panic or a truncated upload.
#[test]
fn uploads_that_do_not_fit_are_errors() {
    let gpu = gpu();
    let packed = big_triangle(64, 3).packed(ColorFormat::Rgba8Srgb);
    let error = GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &packed, &MeshUploadOptions { atlas_width: Some(0) });
    assert!(error.is_err());
    let mut broken = packed.clone();
    broken.indices[0][1] = 99;
    assert!(GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &broken, &MeshUploadOptions::default()).is_err());
    let mut broken = packed.clone();
    broken.face_records.clear();
    assert!(GpuMesh::upload(&gpu.ctx, gpu.renderer.layouts(), &broken, &MeshUploadOptions::default()).is_err());
}

/// No adapter is an error (the renderer never silently skips): the Metal backend does not
/// exist on this platform.
#[test]
fn no_adapter_is_an_error() {
    let file = model("BoxTextured/BoxTextured.glb");
    let out = temp_png("no-adapter");
    let output = std::process::Command::new(BIN)
        .args(["render", file.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", "8", "--height", "8"])
        .env("WGPU_BACKEND", "metal")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if cfg!(target_os = "macos") {
        return;
    }
    assert!(!output.status.success(), "{stderr}");
    assert!(stderr.contains("no GPU adapter"), "{stderr}");
}

/// Whether the linear reference at `bary` moves by more than ⅓ of an 8-bit step (in linear
/// units) when the barycentrics move by `BARY_NOISE`, the interpolation error of a
/// rasteriser on triangles thousands of pixels wide: at R = 4096 one lattice unit is a
/// pixel and random colours change by up to 1 per unit, so such pixels cannot be called.
fn ill_conditioned(packed: &PackedMesh, face: u32, bary: [f32; 3], level: u32) -> bool {
    const BARY_NOISE: f32 = 5e-7;
    let Some(center) = sample(packed, face, bary, Filter::Linear, level) else {
        return true;
    };
    let d = BARY_NOISE;
    let moves: [[f32; 3]; 6] = [[-d, d, 0.0], [d, -d, 0.0], [-d, 0.0, d], [d, 0.0, -d], [0.0, d, -d], [0.0, -d, d]];
    moves.iter().any(|m| {
        let moved = sample(packed, face, std::array::from_fn(|k| (bary[k] + m[k]).max(0.0)), Filter::Linear, level);
        moved.is_none_or(|c| (0..4).any(|ch| (c[ch] - center[ch]).abs() > 1.0 / (3.0 * 255.0)))
    })
}

/// The seam rule on the GPU: a view zoomed onto an edge shared by faces of different
/// resolution (both sides of the edge fill the image), every fixed level, compared per
/// pixel with the CPU reference — which itself agrees across the edge (crates/core/tests/core/seams.rs).
#[test]
fn zoomed_mixed_resolution_seams_match_the_cpu_reference() {
    // The shared edge 1–2 passes through the image centre (128, 128); the faces extend far
    // beyond the image, so pixels near the edge cover a few of the fine face's samples.
    let pixels = [[-2600.0, -2500.0], [2128.0, -1972.0], [-1772.0, 2123.0], [2700.0, 2600.0]];
    let mut failures = Vec::new();
    for (ra, rb, formats) in [
        (64u64, 4u64, &ColorFormat::ALL[..]),
        (2, 32, &[ColorFormat::Rgba8Srgb][..]),
        (1, 16, &[ColorFormat::Rgba16F][..]),
        (4096, 2, &[ColorFormat::Rgba8Srgb][..]),
    ] {
        let scene = square_scene(&pixels, vec![[0, 1, 2], [2, 1, 3]], vec![r(ra), r(rb)], [0.0, 0.0, 0.0], ra * 7 + rb);
        let max_log2 = r(ra).log2().max(r(rb).log2());
        for &format in formats {
            let packed = scene.packed(format);
            let mesh = upload(&packed, None);
            let mut filters = vec![(FilterMode::Linear, 0)];
            filters.extend((0..=max_log2 + 1).map(|level| (FilterMode::MipLevel(level), level)));
            for (mode, level) in filters {
                let name = format!("seam R={ra}|{rb} {} {}", format.name(), filter_name(mode));
                let stats = compare(
                    &name,
                    &scene,
                    &mesh,
                    mode,
                    |face, bary| sample(&packed, face, bary, Filter::Linear, level),
                    |face, bary| ill_conditioned(&packed, face, bary, level),
                );
                if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared < 30_000 {
                    failures.push(format!("{name}: {stats:?}"));
                }
            }
            // Trilinear: both faces blend at the level of detail of the surface point, one
            // continuous function over the mesh, so they agree along the edge too.
            let name = format!("seam R={ra}|{rb} {} trilinear", format.name());
            let stats = compare(
                &name,
                &scene,
                &mesh,
                FilterMode::Trilinear,
                |face, bary| sample_trilinear(&packed, face, bary, continuous_lod(&scene, face, bary)),
                |face, bary| {
                    let lod = continuous_lod(&scene, face, bary);
                    ill_conditioned(&packed, face, bary, lod.floor() as u32)
                        || ill_conditioned(&packed, face, bary, lod.floor() as u32 + 1)
                },
            );
            if stats.over_limit > 0 || stats.coverage_errors > 0 || stats.compared < 30_000 {
                failures.push(format!("{name}: {stats:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Issue 41: a coloured, mixed-R Duck drawn as a Mesh Color Texture stays within 35 dB PSNR
/// of mesh colors' linear filter (`render --representation mct` against the default).
#[test]
fn cli_render_mct_of_a_painted_mixed_resolution_duck_matches_mesh_colors_linear() {
    let mut document =
        meshpaint_core::io::document::Document::open(&model("Duck/Duck.glb"), Resolution::new(16).unwrap()).unwrap();
    // Colour everywhere (a field of the position over the whole duck), then R from 2 to 32 by face.
    document.store = meshpaint_core::io::document::position_colored(&document.store, &document.positions);
    let faces = document.store.topology().face_count();
    for face in 0..faces {
        document.store.write_resolution(face, Resolution::from_log2(1 + face % 5).unwrap()).unwrap();
    }
    let dir = common::TempDir::new("mct-render");
    let file = dir.join("duck.mpk");
    meshpaint_core::packing::file::write_file(&file, &document.pack(ColorFormat::Rgba8Srgb).unwrap()).unwrap();
    let render = |representation: &str| {
        let out = dir.join(&format!("{representation}.png"));
        let output = run_cli(&[
            "render",
            file.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--filter",
            "linear",
            "--shading",
            "unlit",
            "--representation",
            representation,
        ]);
        assert!(output.status.success(), "{representation}: {}", String::from_utf8_lossy(&output.stderr));
        image::open(&out).unwrap().to_rgba8()
    };
    let (mesh_colors, mct) = (render("mesh-colors"), render("mct"));
    let mut squared = 0.0f64;
    let mut count = 0u64;
    for (a, b) in mesh_colors.pixels().zip(mct.pixels()) {
        for c in 0..3 {
            squared += (f64::from(a[c]) - f64::from(b[c])).powi(2);
        }
        count += 3;
    }
    let psnr = 10.0 * (255.0f64.powi(2) / (squared / count as f64).max(1e-12)).log10();
    println!("MCT vs mesh colors linear, coloured mixed-R Duck: {psnr:.1} dB");
    assert!(psnr >= 35.0, "{psnr} dB");
}

/// A tall box (1 × 1 × 3, Z-up, as scans often are) rendered with `--up z` stands upright:
/// its silhouette is taller than wide, from the front and from the default angles; with the
/// default Y up, seen from the side, it lies on its side (wider than tall).
#[test]
fn cli_render_up_z_shows_a_z_up_object_upright() {
    let dir = common::TempDir::new("up-axis");
    let obj = dir.join("tall.obj");
    let mut text = String::new();
    for z in [0.0, 3.0] {
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            text.push_str(&format!("v {x} {y} {z}\n"));
        }
    }
    // Counter-clockwise from outside.
    for [a, b, c, d] in [[1, 4, 3, 2], [5, 6, 7, 8], [1, 2, 6, 5], [2, 3, 7, 6], [3, 4, 8, 7], [4, 1, 5, 8]] {
        text.push_str(&format!("f {a} {b} {c}\nf {a} {c} {d}\n"));
    }
    std::fs::write(&obj, text).unwrap();
    // (width, height) of the non-background pixels' bounding box.
    let silhouette = |extra: &[&str]| {
        let out = temp_png(&format!("up-{}", extra.join("")));
        let mut args = vec!["render", obj.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", "160"];
        args.extend(["--height", "160", "--shading", "unlit"]);
        args.extend(extra);
        let output = run_cli(&args);
        assert!(output.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&output.stderr));
        let image = image::open(&out).unwrap().to_rgba8();
        std::fs::remove_file(&out).unwrap();
        let background = *image.get_pixel(0, 0);
        let (mut min, mut max) = ((u32::MAX, u32::MAX), (0, 0));
        for (x, y, pixel) in image.enumerate_pixels() {
            if *pixel != background {
                min = (min.0.min(x), min.1.min(y));
                max = (max.0.max(x), max.1.max(y));
            }
        }
        assert!(max.0 > min.0, "{extra:?}: nothing drawn");
        (max.0 - min.0 + 1, max.1 - min.1 + 1)
    };
    for angles in [&["--yaw", "0", "--pitch", "0"][..], &[]] {
        let (w, h) = silhouette(&[&["--up", "z"], angles].concat());
        assert!(h as f64 > 1.5 * w as f64, "--up z {angles:?}: {w} × {h}, not upright");
    }
    // Y up, seen from the side (+X): the box lies along the screen's horizontal.
    let (w, h) = silhouette(&["--yaw", "90", "--pitch", "0"]);
    assert!(w as f64 > 1.5 * h as f64, "Y up: {w} × {h}, not lying on its side");
}
