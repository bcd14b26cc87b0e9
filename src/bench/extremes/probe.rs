//! The truths the extreme cases are measured against: a per-pixel `f64` ray cast over
//! every triangle (no BVH), the CPU reference sampler at the hit, and the comparison of a
//! GPU render with it in 8-bit steps (the same procedure as `tests/app/gpu_render.rs`).

use glam::DVec3;

use meshpaint_core::camera::OrbitCamera;
use meshpaint_core::colors::format::{Rgba, encode_rgba8_srgb};
use meshpaint_core::colors::layout::{self, Resolution};
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::sampler::{Filter, sample};
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};
use meshpaint_render::{DrawItem, FilterMode, Gpu, GpuMesh, RenderSettings, Shading};

use super::ExtremesError;

/// Image side of every render, pixels.
pub const SIZE: u32 = 256;
/// Pixels whose centre has a barycentric coordinate below this are edge pixels (skipped).
pub const EDGE_MARGIN: f64 = 1e-4;

/// The deterministic source of the cases (SplitMix64, shared with the tests and the fuzzer);
/// `unit_f64() as f32` where an `f32` is drawn.
pub use meshpaint_core::synth::SplitMix64 as Rng;

/// Triangles, a camera and their colours.
#[derive(Debug, Clone)]
pub struct Probe {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The camera of every render and ray.
    pub camera: OrbitCamera,
    /// The colours.
    pub store: ColorStore,
}

/// What the reference says about one pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Truth {
    /// No triangle: background.
    Background,
    /// Too close to an edge (or to another surface) to call.
    Ambiguous,
    /// Face and barycentrics of the closest hit, and the ray parameter.
    Hit(u32, [f64; 3], f64),
}

/// A store over `triangles` at `resolutions` with random colours, alpha in `[0.5, 1]` (the
/// background is transparent black, so coverage shows in alpha).
pub fn random_store(
    vertex_count: usize,
    triangles: &[[u32; 3]],
    resolutions: Vec<Resolution>,
    seed: u64,
) -> Result<ColorStore, ExtremesError> {
    let topology = Topology::build(vertex_count as u32, triangles).map_err(ExtremesError::setup)?;
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).map_err(ExtremesError::setup)?;
    let mut rng = Rng(seed);
    let mut unit = || rng.unit_f64() as f32;
    StoreWriter::new(&mut store, &mut UndoHistory::new(0)).fill_with(|_| [unit(), unit(), unit(), 0.5 + 0.5 * unit()]);
    Ok(store)
}

/// Two-sided Möller–Trumbore in `f64`: `(t, barycentrics)` of the plane hit (also outside
/// the triangle), `None` for a ray parallel to the plane.
pub fn intersect(origin: DVec3, direction: DVec3, [a, b, c]: [DVec3; 3]) -> Option<(f64, [f64; 3])> {
    let (e1, e2) = (b - a, c - a);
    let pv = direction.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-300 {
        return None;
    }
    let tv = origin - a;
    let u = tv.dot(pv) / det;
    let qv = tv.cross(e1);
    let v = direction.dot(qv) / det;
    Some((e2.dot(qv) / det, [1.0 - u - v, u, v]))
}

/// `p` in `f64`.
pub fn dvec(p: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

impl Probe {
    /// The nearest hit of the pixel-centre ray over every triangle (module docs).
    pub fn truth(&self, x: u32, y: u32) -> Truth {
        let (origin, direction) = self.camera.ray_through_pixel(f64::from(x) + 0.5, f64::from(y) + 0.5, SIZE, SIZE);
        self.cast(origin, direction)
    }

    /// The nearest hit of a ray over every triangle ([`cast_all`]).
    pub fn cast(&self, origin: DVec3, direction: DVec3) -> Truth {
        cast_all(&self.positions, &self.triangles, origin, direction)
    }
}

/// The nearest hit of a ray over every triangle, brute force in `f64`: ambiguous when it is
/// within [`EDGE_MARGIN`] of an edge or another surface is as close.
pub fn cast_all(positions: &[[f32; 3]], triangles: &[[u32; 3]], origin: DVec3, direction: DVec3) -> Truth {
    let mut hits = Vec::new();
    for (face, tri) in triangles.iter().enumerate() {
        let corners = tri.map(|v| dvec(positions[v as usize]));
        let Some((t, bary)) = intersect(origin, direction, corners) else { continue };
        let min = bary.iter().copied().fold(f64::INFINITY, f64::min);
        if t <= 0.0 || min < -EDGE_MARGIN {
            continue;
        }
        hits.push((t, face as u32, bary, min >= EDGE_MARGIN));
    }
    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
    let Some(&(t, face, bary, inside)) = hits.first() else { return Truth::Background };
    let close_second = hits.get(1).is_some_and(|second| (second.0 - t).abs() < 1e-6 * t);
    if !inside || close_second { Truth::Ambiguous } else { Truth::Hit(face, bary, t) }
}

/// Statistics of one GPU-vs-truth comparison, errors in 8-bit steps.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Comparison {
    /// Pixels compared.
    pub compared: u64,
    /// Pixels skipped (edges, ill-conditioned).
    pub skipped: u64,
    /// Largest per-channel difference.
    pub max_steps: u32,
    /// Sum of per-channel differences.
    pub sum_steps: f64,
    /// Background where a face is, or the reverse.
    pub coverage_errors: u64,
    /// Every compared pixel over 2 steps (reading another sample, not rounding): face,
    /// `f64` barycentrics, steps.
    pub over: Vec<(u32, [f64; 3], u32)>,
}

impl Comparison {
    /// Mean per-channel difference.
    pub fn mean_steps(&self) -> f64 {
        if self.compared == 0 { 0.0 } else { self.sum_steps / (self.compared as f64 * 4.0) }
    }

    /// The statistics as JSON (without the pixel list).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "compared_px": self.compared,
            "skipped_px": self.skipped,
            "max_steps": self.max_steps,
            "mean_steps": self.mean_steps(),
            "coverage_errors": self.coverage_errors,
        })
    }
}

/// Renders `mesh` unlit on a transparent background with `filter`.
pub fn render(
    gpu: &Gpu,
    mesh: &GpuMesh,
    camera: OrbitCamera,
    filter: FilterMode,
) -> Result<image::RgbaImage, ExtremesError> {
    let mut settings = RenderSettings::new(camera);
    settings.filter = filter;
    settings.shading = Shading::Unlit;
    settings.background = [0.0; 4];
    Ok(gpu.render_image(DrawItem::MeshColors(mesh), &settings, SIZE, SIZE)?)
}

/// Renders `probe` (uploaded as `mesh`) with `filter` and compares every pixel with
/// `reference(face, bary)` encoded to sRGB8, skipping pixels where `skip` says so.
pub fn compare(
    gpu: &Gpu,
    probe: &Probe,
    mesh: &GpuMesh,
    filter: FilterMode,
    reference: impl Fn(u32, [f32; 3]) -> Option<Rgba>,
    skip: impl Fn(u32, [f32; 3]) -> bool,
) -> Result<Comparison, ExtremesError> {
    let image = render(gpu, mesh, probe.camera, filter)?;
    let mut stats = Comparison::default();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let actual = image.get_pixel(x, y).0;
            match probe.truth(x, y) {
                Truth::Background => stats.coverage_errors += u64::from(actual != [0; 4]),
                Truth::Ambiguous => stats.skipped += 1,
                Truth::Hit(face, bary64, _) => {
                    let bary = bary64.map(|w| w as f32);
                    if skip(face, bary) {
                        stats.skipped += 1;
                        continue;
                    }
                    if actual[3] == 0 {
                        stats.coverage_errors += 1;
                        continue;
                    }
                    let want = encode_rgba8_srgb(
                        reference(face, bary).ok_or_else(|| ExtremesError::setup("the CPU sampler failed"))?,
                    );
                    let steps = (0..4).map(|c| u32::from(want[c].abs_diff(actual[c]))).max().unwrap_or(0);
                    stats.sum_steps += (0..4).map(|c| f64::from(want[c].abs_diff(actual[c]))).sum::<f64>();
                    stats.max_steps = stats.max_steps.max(steps);
                    if steps > 2 {
                        stats.over.push((face, bary64, steps));
                    }
                    stats.compared += 1;
                }
            }
        }
    }
    Ok(stats)
}

/// Compares `probe` with the CPU reference for a fixed filter (`Filter`, level), skipping
/// pixels that cannot be called: nearest within [`super::CELL_MARGIN`] lattice units of a
/// cell boundary, linear where barycentric noise of a rasteriser moves the colour by more
/// than ⅓ step ([`ill_conditioned`]).
pub fn compare_fixed(
    gpu: &Gpu,
    probe: &Probe,
    packed: &PackedMesh,
    mesh: &GpuMesh,
    (mode, filter, level): (FilterMode, Filter, u32),
) -> Result<Comparison, ExtremesError> {
    compare(
        gpu,
        probe,
        mesh,
        mode,
        |face, bary| sample(packed, face, bary, filter, level),
        |face, bary| match filter {
            Filter::Nearest => near_cell_boundary(packed, face, bary, level),
            Filter::Linear => ill_conditioned(packed, face, bary, level),
        },
    )
}

/// The resolution nearest filtering reads `face` at, at `level`.
fn level_resolution(packed: &PackedMesh, face: u32, level: u32) -> Option<Resolution> {
    let r = packed.face_records.get(face as usize)?.resolution()?;
    r.at_level(level.min(r.log2())).ok()
}

/// Whether nearest filtering could pick another sample within [`super::CELL_MARGIN`]
/// lattice units of `bary` (as `tests/app/gpu_render.rs` decides).
pub fn near_cell_boundary(packed: &PackedMesh, face: u32, bary: [f32; 3], level: u32) -> bool {
    let Some(res) = level_resolution(packed, face, level) else { return true };
    let chosen = layout::nearest_sample(res, bary);
    let d = super::CELL_MARGIN as f32 / res.get() as f32;
    let moves: [[f32; 3]; 6] = [[-d, d, 0.0], [d, -d, 0.0], [-d, 0.0, d], [d, 0.0, -d], [0.0, d, -d], [0.0, -d, d]];
    moves.iter().any(|m| layout::nearest_sample(res, std::array::from_fn(|k| bary[k] + m[k])) != chosen)
}

/// Whether the linear reference moves by more than ⅓ of an 8-bit step when the
/// barycentrics move by 5·10⁻⁷ (a rasteriser's interpolation noise on faces thousands of
/// pixels wide), as `tests/app/gpu_render.rs` decides.
pub fn ill_conditioned(packed: &PackedMesh, face: u32, bary: [f32; 3], level: u32) -> bool {
    const BARY_NOISE: f32 = 5e-7;
    let Some(center) = sample(packed, face, bary, Filter::Linear, level) else { return true };
    let d = BARY_NOISE;
    let moves: [[f32; 3]; 6] = [[-d, d, 0.0], [d, -d, 0.0], [-d, 0.0, d], [d, 0.0, -d], [0.0, d, -d], [0.0, -d, d]];
    moves.iter().any(|m| {
        let moved = sample(packed, face, std::array::from_fn(|k| (bary[k] + m[k]).max(0.0)), Filter::Linear, level);
        moved.is_none_or(|c| (0..4).any(|ch| (c[ch] - center[ch]).abs() > 1.0 / (3.0 * 255.0)))
    })
}

/// How far (lattice units) the point `bary` (exact, `f64`) is from the nearest boundary
/// between nearest-filter cells at resolution `r`: half the gap between its two largest
/// linear weights (a weight changes by 1 per lattice unit along the lattice axes, the gap
/// by up to 2).
pub fn nearest_boundary_distance(r: Resolution, bary: [f64; 3]) -> f64 {
    let res = f64::from(r.get());
    let (u, v) = (bary[1] * res, bary[2] * res);
    let (fu, fv) = (u - u.floor(), v - v.floor());
    let mut weights = if fu + fv > 1.0 { [fu + fv - 1.0, 1.0 - fv, 1.0 - fu] } else { [1.0 - fu - fv, fu, fv] };
    weights.sort_by(|a, b| b.total_cmp(a));
    0.5 * (weights[0] - weights[1])
}
