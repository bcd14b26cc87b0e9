//! The geometric extremes: R = 4096 in perspective and the shader's index precision,
//! meshes far from the origin and tiny, slivers, a valence-200 vertex, brushes at grazing
//! angles.

use glam::DVec3;
use serde_json::json;

use meshpaint_core::camera::{BoundingSphere, OrbitCamera};
use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::paint::brush::{BlendMode, BrushRadius, BrushSettings, Falloff, PaintView, Painter, Tool};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;
use meshpaint_core::synth::{OCTAHEDRON_POSITIONS, OCTAHEDRON_TRIANGLES};
use meshpaint_render::{FilterMode, Gpu, GpuMesh};

use super::probe::{
    Comparison, Probe, Rng, SIZE, Truth, cast_all, compare, compare_fixed, dvec, nearest_boundary_distance,
    random_store,
};
use super::{CELL_MARGIN, ExtremeCase, ExtremesError, MAX_STEPS};

const GPU_TEST: &str = "tests/app/extremes.rs (every case); tests/app/gpu_render.rs (same procedure)";

fn r(log2: u32) -> Resolution {
    Resolution::from_log2(log2).unwrap_or(Resolution::ONE)
}

fn packed_and_uploaded(gpu: &Gpu, probe: &Probe) -> Result<(PackedMesh, GpuMesh), ExtremesError> {
    let packed = pack(&probe.store, &probe.positions, ColorFormat::Rgba8Srgb).map_err(ExtremesError::setup)?;
    let mesh = gpu.upload(&packed)?;
    Ok((packed, mesh))
}

/// A render row: the largest difference over `stats`, sound when every comparison covered
/// at least `min_compared` pixels without a coverage error.
fn render_row(case: &str, stats: &[(String, Comparison)], min_compared: u64) -> ExtremeCase {
    let measured = stats.iter().map(|(_, s)| f64::from(s.max_steps)).fold(0.0, f64::max);
    let sound = stats.iter().all(|(_, s)| s.compared >= min_compared && s.coverage_errors == 0);
    let detail: serde_json::Map<String, serde_json::Value> =
        stats.iter().map(|(name, s)| (name.clone(), s.to_json())).collect();
    ExtremeCase {
        case: case.into(),
        measured,
        unit: "8-bit steps (largest per-channel GPU − CPU reference at the f64 ray-cast hit)",
        tolerance: MAX_STEPS,
        test: GPU_TEST,
        outcome: "measured".into(),
        sound,
        detail: serde_json::Value::Object(detail),
    }
}

/// One R = 4096 face in perspective (filling the view, seen at an angle): linear and
/// nearest against the `f64` ray-cast truth, and the precision of the shader's sample index.
pub fn r4096_perspective(gpu: &Gpu) -> Result<Vec<ExtremeCase>, ExtremesError> {
    let positions = vec![[-1.2, -1.0, 0.0], [1.3, -0.8, 0.0], [0.1, 1.4, 0.0]];
    let triangles = vec![[0, 1, 2]];
    let store = random_store(3, &triangles, vec![r(12)], 4096)?;
    let mut camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 30.0, 35.0);
    camera.distance *= 0.35;
    let probe = Probe { positions, triangles, camera, store };
    let (packed, mesh) = packed_and_uploaded(gpu, &probe)?;
    let linear = compare_fixed(gpu, &probe, &packed, &mesh, (FilterMode::Linear, Filter::Linear, 0))?;
    let nearest = compare_fixed(gpu, &probe, &packed, &mesh, (FilterMode::Nearest, Filter::Nearest, 0))?;
    // At one lattice unit per pixel, random colours make ~2/3 of the linear pixels
    // ill-conditioned (skipped); 10 000 compared pixels remain.
    let min = 10_000;
    let mut rows = vec![
        render_row("r4096_perspective_linear", &[("linear".into(), linear)], min),
        render_row("r4096_perspective_nearest", &[("nearest".into(), nearest)], min),
    ];
    rows.push(index_precision(gpu, &probe, &packed, &mesh)?);
    Ok(rows)
}

/// The shader's index computation at R = 4096: nearest, nothing skipped; every pixel that
/// reads another sample than the `f64` hit says must lie within the distance of a cell
/// boundary that the barycentric precision explains. Also the `f32` lattice error of the
/// index computation alone (exact barycentrics rounded to `f32`, as the CPU mirror does).
fn index_precision(
    gpu: &Gpu,
    probe: &Probe,
    packed: &PackedMesh,
    mesh: &GpuMesh,
) -> Result<ExtremeCase, ExtremesError> {
    let res = r(12);
    let all = compare(
        gpu,
        probe,
        mesh,
        FilterMode::Nearest,
        |face, bary| sample(packed, face, bary, Filter::Nearest, 0),
        |_, _| false,
    )?;
    let worst = all.over.iter().map(|&(_, bary, _)| nearest_boundary_distance(res, bary)).fold(0.0, f64::max);
    // The f32 lattice coordinates of exact points, as `linear_samples` computes them.
    let mut rng = Rng(12);
    let (mut lattice_error, mut cells_differ) = (0.0f64, 0u32);
    let points = 200_000;
    for _ in 0..points {
        let (mut u, mut v) = (rng.unit_f64(), rng.unit_f64());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let exact = [1.0 - u - v, u, v];
        let rounded = layout::sanitize_barycentric(exact.map(|w| w as f32));
        let scale = f64::from(res.get());
        let (u_f32, v_f32) = (rounded[1] * res.get() as f32, rounded[2] * res.get() as f32);
        lattice_error =
            lattice_error.max((f64::from(u_f32) - u * scale).abs()).max((f64::from(v_f32) - v * scale).abs());
        let chosen = layout::nearest_sample(res, rounded);
        let exact_choice = nearest_exact(res, exact);
        cells_differ += u32::from(chosen != exact_choice && nearest_boundary_distance(res, exact) > 1e-3);
    }
    Ok(ExtremeCase {
        case: "shader_index_precision_r4096".into(),
        measured: worst,
        unit: "lattice units (largest distance from a nearest-cell boundary of a pixel whose GPU sample differs from the f64 truth)",
        tolerance: CELL_MARGIN,
        test: GPU_TEST,
        outcome: "measured".into(),
        sound: all.compared > u64::from(SIZE * SIZE) / 4 && all.coverage_errors == 0 && cells_differ == 0,
        detail: json!({
            "compared_px": all.compared,
            "px_reading_another_sample": all.over.len(),
            "f32_lattice_error_cpu": lattice_error,
            "f32_lattice_error_bound": 2.0 * f64::from(res.get()) * f64::from(f32::EPSILON),
            "cpu_points": points,
            "cpu_cells_differing_beyond_1e-3": cells_differ,
        }),
    })
}

/// The nearest sample of exact barycentrics (`f64`): the largest linear weight.
fn nearest_exact(res: Resolution, bary: [f64; 3]) -> (u32, u32) {
    let n = f64::from(res.get());
    let (u, v) = (bary[1] * n, bary[2] * n);
    let i = u.floor().clamp(0.0, n - 1.0) as u32;
    let j = v.floor().clamp(0.0, n - 1.0 - f64::from(i)) as u32;
    let (fu, fv) = (u - f64::from(i), v - f64::from(j));
    let candidates = if fu + fv > 1.0 && i + j + 2 <= res.get() {
        [((i + 1, j + 1), fu + fv - 1.0), ((i + 1, j), 1.0 - fv), ((i, j + 1), 1.0 - fu)]
    } else {
        [((i, j), 1.0 - fu - fv), ((i + 1, j), fu), ((i, j + 1), fv)]
    };
    candidates.iter().fold(candidates[0], |best, c| if c.1 > best.1 { *c } else { best }).0
}

/// The octahedron of radius `size`, rotated so that no coordinate is a round number (its
/// vertices are not representable in `f32`: moving it rounds every one of them).
fn octahedron(size: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let rotation = glam::DMat3::from_euler(glam::EulerRot::YXZ, 0.3, 0.7, 0.1);
    let positions = OCTAHEDRON_POSITIONS.map(|p| (rotation * DVec3::from_array(p) * size).to_array()).to_vec();
    (positions, OCTAHEDRON_TRIANGLES.to_vec())
}

/// The spacing of `f32` values at magnitude `m` (one ulp).
fn f32_spacing(m: f64) -> f64 {
    if m <= 0.0 { f64::from(f32::MIN_POSITIVE) } else { 2f64.powi(m.log2().floor() as i32 - 23) }
}

/// One transform of the offset cases: `p · scale + offset` on every axis.
#[derive(Debug, Clone, Copy)]
struct Transform {
    name: &'static str,
    offset: f64,
    scale: f64,
    /// Radius of the untransformed octahedron.
    size: f64,
}

impl Transform {
    fn apply(&self, p: DVec3) -> DVec3 {
        p * self.scale + DVec3::splat(self.offset)
    }

    fn camera(&self, base: &OrbitCamera) -> OrbitCamera {
        OrbitCamera {
            target: self.apply(DVec3::from_array(base.target)).to_array(),
            distance: base.distance * self.scale,
            scene_radius: base.scene_radius * self.scale,
            ..*base
        }
    }
}

/// Meshes offset by 1e5 and 1e6 and scaled by 1e-4: render against the ray-cast truth on
/// the moved mesh; pick and paint against the unmoved mesh moved in `f64`.
pub fn offsets(gpu: &Gpu) -> Result<Vec<ExtremeCase>, ExtremesError> {
    let transforms = [
        Transform { name: "offset_1e5", offset: 1e5, scale: 1.0, size: 100.0 },
        Transform { name: "offset_1e6", offset: 1e6, scale: 1.0, size: 100.0 },
        Transform { name: "scale_1e-4", offset: 0.0, scale: 1e-4, size: 1.0 },
    ];
    let mut rows = Vec::new();
    for transform in transforms {
        let (exact, triangles) = octahedron(transform.size);
        let base: Vec<[f32; 3]> = exact.iter().map(|p| p.map(|x| x as f32)).collect();
        let moved: Vec<[f32; 3]> =
            exact.iter().map(|&p| transform.apply(DVec3::from_array(p)).to_array().map(|x| x as f32)).collect();
        let magnitude = moved.iter().flatten().map(|x| f64::from(x.abs())).fold(0.0, f64::max);
        let ulp = f32_spacing(magnitude);
        let mut base_camera = OrbitCamera::framing(BoundingSphere::of_points(&base), 35.0, 25.0);
        base_camera.distance *= 0.8;
        let camera = transform.camera(&base_camera);
        let resolutions = [0, 1, 2, 3, 4, 2, 0, 5].map(r).to_vec();
        let store = random_store(moved.len(), &triangles, resolutions, 99)?;
        let probe = Probe { positions: moved.clone(), triangles: triangles.clone(), camera, store };
        let (packed, mesh) = packed_and_uploaded(gpu, &probe)?;
        let linear = compare_fixed(gpu, &probe, &packed, &mesh, (FilterMode::Linear, Filter::Linear, 0))?;
        let nearest = compare_fixed(gpu, &probe, &packed, &mesh, (FilterMode::Nearest, Filter::Nearest, 0))?;
        rows.push(render_row(
            &format!("{}_render", transform.name),
            &[("linear".into(), linear), ("nearest".into(), nearest)],
            5_000,
        ));
        let meshes = Meshes { base: &base, moved: &moved, triangles: &triangles, base_camera, camera };
        rows.push(offset_pick(transform, &meshes, ulp));
        rows.push(offset_paint(transform, &meshes, ulp)?);
    }
    Ok(rows)
}

/// The unmoved and the moved mesh with their cameras.
struct Meshes<'a> {
    base: &'a [[f32; 3]],
    moved: &'a [[f32; 3]],
    triangles: &'a [[u32; 3]],
    base_camera: OrbitCamera,
    camera: OrbitCamera,
}

/// Picks through a pixel grid on both meshes: the same face, and the moved hit where the
/// unmoved one lands after the transform, within what rounding the vertices to `f32`
/// explains: each vertex moves by at most ½ ulp per coordinate, so the surface moves by at
/// most `√3/2` ulp along its normal. Measured: `|Δp · n|`, in ulps of the moved coordinates.
fn offset_pick(transform: Transform, meshes: &Meshes, ulp: f64) -> ExtremeCase {
    let base_bvh = MeshBvh::build(meshes.base, meshes.triangles, BvhPreset::default());
    let moved_bvh = MeshBvh::build(meshes.moved, meshes.triangles, BvhPreset::default());
    let (mut compared, mut faces_differ, mut worst, mut worst_along_ray) = (0u32, 0u32, 0.0f64, 0.0f64);
    for y in (2..SIZE).step_by(4) {
        for x in (2..SIZE).step_by(4) {
            let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            let (o, d) = meshes.base_camera.ray_through_pixel(px, py, SIZE, SIZE);
            let (o2, d2) = meshes.camera.ray_through_pixel(px, py, SIZE, SIZE);
            let (Some(a), Some(b)) = (base_bvh.cast(o, d, f64::INFINITY), moved_bvh.cast(o2, d2, f64::INFINITY)) else {
                continue;
            };
            if a.barycentric.iter().any(|&w| w < 1e-3) {
                continue;
            }
            compared += 1;
            if a.face != b.face {
                faces_differ += 1;
                continue;
            }
            let [p0, p1, p2] = meshes.triangles[b.face as usize].map(|v| dvec(meshes.moved[v as usize]));
            let normal = (p1 - p0).cross(p2 - p0).normalize();
            let delta = DVec3::from_array(b.position_world) - transform.apply(DVec3::from_array(a.position_world));
            worst = worst.max(delta.dot(normal).abs() / ulp);
            worst_along_ray = worst_along_ray.max(delta.length() / ulp);
        }
    }
    ExtremeCase {
        case: format!("{}_pick", transform.name),
        measured: worst,
        unit: "ulps of f32 at the mesh's coordinates, along the face normal (moved hit − transformed unmoved hit)",
        tolerance: 3f64.sqrt() / 2.0 + 0.05,
        test: "tests/app/extremes.rs; crates/core/tests/core/picking.rs extremes_match_brute_force",
        outcome: "measured".into(),
        sound: compared > 500 && faces_differ == 0,
        detail: json!({
            "picks_compared": compared,
            "faces_differ": faces_differ,
            "ulp": ulp,
            "largest_distance_ulps": worst_along_ray,
        }),
    }
}

/// Grey stores over both meshes at R = 32, one red dab (constant falloff) at the centre
/// pixel's hit with radius 0.3 of the mesh size: the same samples painted on both, except
/// within 4 ulps of the brush's rim (vertex and pick rounding).
fn offset_paint(transform: Transform, meshes: &Meshes, ulp: f64) -> Result<ExtremeCase, ExtremesError> {
    let settings = BrushSettings {
        color: RED,
        falloff: Falloff::Constant,
        occlusion: false,
        backface_culling: false,
        ..BrushSettings::default()
    };
    let center = [f64::from(SIZE) * 0.5 + 0.25; 2];
    let radius = 0.3 * transform.size;
    let base = dab_on(meshes.base, meshes.triangles, &meshes.base_camera, settings, center, (r(5), Some(radius)))?;
    let moved = dab_on(
        meshes.moved,
        meshes.triangles,
        &meshes.camera,
        settings,
        center,
        (r(5), Some(radius * transform.scale)),
    )?;
    let band = 4.0 * ulp / transform.scale;
    let (mut painted, mut in_band, mut differ) = (0u32, 0u32, 0u32);
    let mut sites = Vec::new();
    base.store.for_each_site(|site| sites.push(site));
    for site in sites {
        let corners = meshes.triangles[site.face as usize].map(|v| dvec(meshes.base[v as usize]));
        let p: DVec3 = (0..3).map(|k| corners[k] * f64::from(site.barycentric[k])).sum();
        let near_rim = ((p - base.center).length() - radius).abs() <= band;
        let (a, b) = (base.store.get(site.sample) == Some(RED), moved.store.get(site.sample) == Some(RED));
        painted += u32::from(a);
        in_band += u32::from(near_rim);
        differ += u32::from(a != b && !near_rim);
    }
    Ok(ExtremeCase {
        case: format!("{}_paint", transform.name),
        measured: f64::from(differ),
        unit: "samples painted on one mesh and not the other, outside a band of 4 ulps at the brush rim",
        tolerance: 0.0,
        test: "tests/app/extremes.rs",
        outcome: "measured".into(),
        sound: painted > 50,
        detail: json!({ "painted_samples": painted, "samples_in_rim_band": in_band, "band_world": band * transform.scale }),
    })
}

const RED: Rgba = [1.0, 0.0, 0.0, 1.0];
const GREY: Rgba = [0.5, 0.5, 0.5, 1.0];

/// What one dab did: the store after it, the dab's centre and world radius.
struct Dabbed {
    store: ColorStore,
    center: DVec3,
    radius_world: f64,
}

/// A grey store at `resolution` over the mesh and one dab with `settings` at pixel `cursor`: at
/// the given world radius (`dab_at`), or as a stroke of one dab with the settings' radius.
fn dab_on(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    camera: &OrbitCamera,
    settings: BrushSettings,
    cursor: [f64; 2],
    (resolution, radius_world): (Resolution, Option<f64>),
) -> Result<Dabbed, ExtremesError> {
    let topology = Topology::build(positions.len() as u32, triangles).map_err(ExtremesError::setup)?;
    let mut store = ColorStore::uniform(topology, resolution, GREY);
    let bvh = MeshBvh::build(positions, triangles, BvhPreset::default());
    let view = PaintView { positions, bvh: &bvh, camera, viewport_px: [SIZE, SIZE], base: None };
    let mut painter = Painter::new(positions);
    painter.set_settings(settings);
    let mut history = UndoHistory::new(1 << 26);
    let hit = view.pick(cursor).ok_or_else(|| ExtremesError::setup("the centre pixel misses the mesh"))?;
    let center = DVec3::from_array(hit.position_world);
    let radius = if let Some(radius) = radius_world {
        painter.dab_at(&view, &mut store, &mut history, center, radius).map_err(ExtremesError::setup)?;
        radius
    } else {
        let update = painter.begin_stroke(&view, &mut store, &mut history, cursor).map_err(ExtremesError::setup)?;
        painter.end_stroke(&mut history);
        update.dabs.first().map_or(0.0, |dab| dab.radius_world)
    };
    Ok(Dabbed { store, center, radius_world: radius })
}

/// A sliver next to a zero-area face (as `tests/app/gpu_render.rs` `sliver_and_degenerate_faces`),
/// a thin prism picked by rays, and a vertex of valence 200, rendered and picked.
pub fn slivers_and_valence(gpu: &Gpu) -> Result<Vec<ExtremeCase>, ExtremesError> {
    let camera = OrbitCamera::framing(BoundingSphere { center: [0.0; 3], radius: 1.0 }, 0.0, 0.0);
    let on_plane = |x: f64, y: f64| {
        let (origin, direction) = camera.ray_through_pixel(x, y, SIZE, SIZE);
        let p = origin + direction * ((camera.target[2] - origin.z) / direction.z);
        [p.x as f32, p.y as f32, p.z as f32]
    };
    let pixels = [[10.0, 100.0], [246.0, 103.0], [128.0, 103.0], [20.0, 200.0], [120.0, 200.0], [220.0, 200.0]];
    let positions: Vec<[f32; 3]> = pixels.iter().map(|&[x, y]| on_plane(x, y)).collect();
    let triangles = vec![[0, 1, 2], [3, 4, 5]];
    let store = random_store(positions.len(), &triangles, vec![r(4), r(2)], 11)?;
    let probe = Probe { positions, triangles, camera, store };
    let (packed, mesh) = packed_and_uploaded(gpu, &probe)?;
    let mut stats = Vec::new();
    for (name, mode, filter, level) in [
        ("nearest", FilterMode::Nearest, Filter::Nearest, 0),
        ("linear", FilterMode::Linear, Filter::Linear, 0),
        ("linear L2", FilterMode::MipLevel(2), Filter::Linear, 2),
    ] {
        stats.push((name.to_string(), compare_fixed(gpu, &probe, &packed, &mesh, (mode, filter, level))?));
    }
    let mut rows = vec![render_row("sliver_render", &stats, 30)];
    rows.push(sliver_pick());
    let (positions, triangles) = valence_fan(200);
    let resolutions = (0..triangles.len() as u32).map(|f| r(f % 5)).collect();
    let store = random_store(positions.len(), &triangles, resolutions, 200)?;
    let camera = OrbitCamera::framing(BoundingSphere::of_points(&positions), 20.0, 40.0);
    let probe = Probe { positions, triangles, camera, store };
    let (packed, mesh) = packed_and_uploaded(gpu, &probe)?;
    let linear = compare_fixed(gpu, &probe, &packed, &mesh, (FilterMode::Linear, Filter::Linear, 0))?;
    rows.push(render_row("valence_200_render", &[("linear".into(), linear)], 10_000));
    let rays: Vec<(DVec3, DVec3)> = (0..SIZE * SIZE)
        .map(|k| probe.camera.ray_through_pixel(f64::from(k % SIZE) + 0.5, f64::from(k / SIZE) + 0.5, SIZE, SIZE))
        .collect();
    rows.push(pick_row("valence_200_pick", &probe.positions, &probe.triangles, &rays));
    Ok(rows)
}

/// A cone: apex at height 0.3 over a ring of `n` vertices on the unit circle, `n` faces.
fn valence_fan(n: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions: Vec<[f32; 3]> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
            [a.cos() as f32, a.sin() as f32, 0.0]
        })
        .collect();
    positions.push([0.0, 0.0, 0.3]);
    let triangles = (0..n).map(|k| [k, (k + 1) % n, n]).collect();
    (positions, triangles)
}

/// A closed prism 1000 long with sides of 1e-3, picked by 2000 rays across it.
fn sliver_pick() -> ExtremeCase {
    let (length, width) = (1000.0f32, 1e-3f32);
    let h = width * 3f32.sqrt() / 2.0;
    let mut positions = Vec::new();
    for z in [0.0, length] {
        for [x, y] in [[0.0, 0.0], [width, 0.0], [width / 2.0, h]] {
            positions.push([x, y, z]);
        }
    }
    let mut triangles = vec![[0, 2, 1], [3, 4, 5]];
    for i in 0..3u32 {
        let j = (i + 1) % 3;
        triangles.push([i, j, j + 3]);
        triangles.push([i, j + 3, i + 3]);
    }
    let mut rng = Rng(99);
    let rays: Vec<(DVec3, DVec3)> = (0..2000)
        .map(|k| {
            let target = DVec3::new(0.5e-3, 0.25e-3, 1000.0 * (f64::from(k) + 0.5) / 2000.0);
            let direction = loop {
                let d = DVec3::new(rng.unit_f64(), rng.unit_f64(), rng.unit_f64()) * 2.0 - 1.0;
                if (0.01..=1.0).contains(&d.length_squared()) {
                    break d.normalize();
                }
            };
            (target + direction * 0.01, -direction)
        })
        .collect();
    pick_row("sliver_pick", &positions, &triangles, &rays)
}

/// BVH picks against the brute-force `f64` ray cast: rays whose truth is a clear hit must
/// hit the same face, rays that miss must miss.
fn pick_row(case: &str, positions: &[[f32; 3]], triangles: &[[u32; 3]], rays: &[(DVec3, DVec3)]) -> ExtremeCase {
    let bvh = MeshBvh::build(positions, triangles, BvhPreset::default());
    let (mut compared, mut differ) = (0u32, 0u32);
    for &(origin, direction) in rays {
        let got = bvh.cast(origin, direction, f64::INFINITY);
        match cast_all(positions, triangles, origin, direction) {
            Truth::Ambiguous => continue,
            Truth::Background => differ += u32::from(got.is_some()),
            Truth::Hit(face, _, _) => differ += u32::from(got.is_none_or(|hit| hit.face != face)),
        }
        compared += 1;
    }
    ExtremeCase {
        case: case.into(),
        measured: f64::from(differ),
        unit: "rays whose BVH hit differs from the brute-force f64 ray cast",
        tolerance: 0.0,
        test: "tests/app/extremes.rs; crates/core/tests/core/picking.rs high_valence_apex_and_slivers",
        outcome: "measured".into(),
        sound: compared * 2 > rays.len() as u32,
        detail: json!({ "rays": rays.len(), "compared": compared }),
    }
}

/// A 2 × 2 plane at R = 64 seen at 60°…88° from its normal: the centre pick against the
/// ray–plane hit in `f64`, and one dab of 12 px (constant falloff, the editor's occlusion
/// and culling on) against the closed-form disc `|p − c| ≤ r` on the plane.
pub fn grazing_brush() -> Result<Vec<ExtremeCase>, ExtremesError> {
    let positions = vec![[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]];
    let triangles = vec![[0, 2, 1], [0, 3, 2]];
    let mut rows = Vec::new();
    for angle in [60.0f64, 80.0, 85.0, 88.0] {
        let mut camera = OrbitCamera::framing(BoundingSphere { center: [0.0; 3], radius: 1.0 }, 0.0, 90.0 - angle);
        camera.distance = 2.0;
        let settings = BrushSettings {
            tool: Tool::Paint,
            color: RED,
            blend: BlendMode::Mix,
            radius: BrushRadius::Pixels { radius_px: 12.0 },
            falloff: Falloff::Constant,
            ..BrushSettings::default()
        };
        let cursor = [f64::from(SIZE) * 0.5 + 0.25; 2];
        let dabbed = dab_on(&positions, &triangles, &camera, settings, cursor, (r(6), None))?;
        let (origin, direction) = camera.ray_through_pixel(cursor[0], cursor[1], SIZE, SIZE);
        let truth = origin + direction * (-origin.y / direction.y);
        let world_per_px =
            2.0 * (truth - camera.eye()).dot(-camera.eye_direction()) * (camera.fov_y_degrees.to_radians() * 0.5).tan()
                / f64::from(SIZE);
        let pick_error_px = (dabbed.center - truth).length() / world_per_px;
        let radius = dabbed.radius_world;
        let (mut painted, mut inside, mut differ) = (0u32, 0u32, 0u32);
        let mut sites = Vec::new();
        dabbed.store.for_each_site(|site| sites.push(site));
        for site in sites {
            let corners = triangles[site.face as usize].map(|v| dvec(positions[v as usize]));
            let p: DVec3 = (0..3).map(|k| corners[k] * f64::from(site.barycentric[k])).sum();
            let distance = (p - dabbed.center).length();
            let is_painted = dabbed.store.get(site.sample) == Some(RED);
            painted += u32::from(is_painted);
            inside += u32::from(distance <= radius);
            differ += u32::from(is_painted != (distance <= radius) && (distance - radius).abs() > 1e-9 * radius);
        }
        rows.push(ExtremeCase {
            case: format!("grazing_brush_{angle}deg"),
            measured: f64::from(differ),
            unit: "samples whose painted state differs from the closed-form disc |p − c| ≤ r",
            tolerance: 0.0,
            test: "tests/app/extremes.rs",
            outcome: "measured".into(),
            sound: inside >= 3 && pick_error_px < 1e-3,
            detail: json!({
                "angle_from_normal_deg": angle,
                "pick_error_px": pick_error_px,
                "radius_world": radius,
                "samples_inside": inside,
                "samples_painted": painted,
                "screen_extent_across_px": 24.0,
                "screen_extent_along_view_px": 24.0 * angle.to_radians().cos(),
            }),
        });
    }
    Ok(rows)
}
