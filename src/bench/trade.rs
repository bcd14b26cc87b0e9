//! `meshpaint bench trade`: what every choice costs and what it buys, side by side — filter
//! (nearest, linear, fixed MIP level, trilinear) × resolution (uniform R and the content-driven
//! `--error` bounds) × colour format (RGBA8 / RGBA16F / RGBA32F), each seen from several
//! distances, plus BVH presets and the seam error at resolution boundaries.
//!
//! # Error
//!
//! Each configuration is rendered unlit at the image size, as a user sees it (no
//! supersampling: MIP levels and trilinear exist to fight exactly that aliasing), and compared
//! with a reference rendered at 4× per side and box-filtered 4×4
//! ([`super::adaptive::render_supersampled`], the reference of `bench adaptive`):
//!
//! - a glTF with a base-colour texture: its UV-textured render (the baseline pipeline, every
//!   material's factor × texture, hardware trilinear);
//! - anything else (a painted packed file, an untextured mesh): the same document packed in
//!   RGBA32F, linear filter at level 0 — per resolution choice, so the figure isolates what
//!   the filter and the format lose (an untextured glTF is swept over uniform R like a
//!   textured one; a packed file is measured at its own resolutions). Frame ratios are then
//!   to `bench render`'s synthetic planar UV baseline.
//!
//! Pixels are compared where the reference's 16 subsamples are all covered and the test
//! render covers the pixel: the silhouette, whose aliasing no colour setting changes, is left
//! out. Reported: PSNR over RGB of the 8-bit sRGB images, the largest absolute difference in
//! 8-bit steps, and the mean FLIP error (NVIDIA's perceptual metric, `nv-flip`, on the
//! same pixels; 0 = identical, 1 = maximal).
//!
//! # Cost
//!
//! Level-0 samples, samples with MIP chains, GPU bytes of the uploaded mesh, pack time (best of
//! three), frame time as a ratio to the UV-texture baseline (every configuration and the
//! baseline timed interleaved round by round in this one run, at the image size, per view;
//! [`super::render::FrameTimer`], the timer of `bench render`), and the paint-mode dab
//! throughput at that resolution ([`super::paint::dab_throughput`]).
//!
//! # Seams
//!
//! For every edge whose two faces have different resolutions, both faces are sampled with the
//! CPU reference sampler at the same 33 points along the edge (`t = k/32`, exact in `f32`), in
//! RGBA32F, per filter and MIP level; the row reports the largest jump (colour units, 0..1,
//! linear) between the two sides.
//!
//! # BVH
//!
//! Per preset: build time, pick latency on rays through a 64 × 64 pixel grid that hit the mesh,
//! and how many of those picks agree with a brute-force Möller–Trumbore over every triangle
//! (same face, or the same `t` within 1e-9 relative where two faces tie on a shared edge).

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use image::RgbaImage;

use crate::bench::adaptive::{Supersampled, render_supersampled};
use crate::bench::pack::Timing;
pub use crate::bench::plot::pareto_front;
use crate::bench::plot::{PlotError, PlotPoint, plot_tradeoff};
use crate::bench::render::FrameTimer;
use crate::bench::{BenchRenderError, paint};
use meshpaint_core::camera::{BoundingSphere, OrbitCamera, default_camera};
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::psnr::psnr_over;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::sampler::{Filter, sample, sample_trilinear};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_render::{DrawItem, FilterMode, Gpu, GpuMesh, RenderSettings, Shading};

/// What `bench trade` measures.
#[derive(Debug, Clone, PartialEq)]
pub struct TradeOptions {
    /// View directions (yaw 30° + k·360°/views, pitch 20°), each at every distance of [`DISTANCES`].
    pub views: u32,
    /// Image side, pixels (the reference is rendered at 4× this).
    pub size: u32,
    /// Uniform resolutions measured.
    pub uniform: Vec<Resolution>,
    /// `--error` bounds measured (textured glTF only).
    pub error_bounds: Vec<f32>,
    /// The largest R the error bounds give a face.
    pub max_resolution: Resolution,
    /// Colour formats measured.
    pub formats: Vec<ColorFormat>,
    /// Interleaved timing rounds per view (the median frame is reported).
    pub frames: usize,
    /// Dabs per throughput measurement.
    pub dabs: usize,
}

impl Default for TradeOptions {
    fn default() -> Self {
        TradeOptions {
            views: 1,
            size: 256,
            uniform: (0..=5).filter_map(|l| Resolution::from_log2(l).ok()).collect(),
            error_bounds: vec![0.05, 0.02, 0.01, 0.005],
            max_resolution: Resolution::from_log2(6).unwrap_or(Resolution::MAX),
            formats: ColorFormat::ALL.to_vec(),
            frames: 5,
            dabs: 10,
        }
    }
}

/// Camera distances, as multiples of the framing distance (the whole bounding sphere in view):
/// near (the mesh overflows the image: magnification), mid, far and tiny (the mesh a few dozen
/// pixels across: minification, where MIP levels matter).
pub const DISTANCES: [(&str, f64); 4] = [("near", 0.5), ("mid", 1.0), ("far", 4.0), ("tiny", 12.0)];

/// The filters measured, with their names in the report.
pub const FILTERS: [(&str, FilterMode); 5] = [
    ("nearest", FilterMode::Nearest),
    ("linear", FilterMode::Linear),
    ("mip-1", FilterMode::MipLevel(1)),
    ("mip-2", FilterMode::MipLevel(2)),
    ("trilinear", FilterMode::Trilinear),
];

/// Error of a test image against a reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// PSNR over RGB, dB (`inf` when equal).
    pub psnr_db: f64,
    /// Largest absolute difference of an RGB channel, 8-bit steps.
    pub max_error_steps: u8,
    /// Mean FLIP error over the compared pixels (0..1).
    pub flip_mean: f64,
    /// Pixels compared.
    pub pixels: u64,
}

/// Compares `test` with `reference` on the pixels where `mask` (row-major) is true: PSNR,
/// largest error and the mean FLIP error (computed on the whole images, averaged over the mask).
pub fn compare(reference: &RgbaImage, test: &RgbaImage, mask: &[bool]) -> ImageError {
    let psnr_db = psnr_over(reference, test, mask);
    let mut max_error_steps = 0u8;
    let mut pixels = 0u64;
    for ((a, b), &keep) in reference.pixels().zip(test.pixels()).zip(mask) {
        if keep {
            pixels += 1;
            for c in 0..3 {
                max_error_steps = max_error_steps.max(a.0[c].abs_diff(b.0[c]));
            }
        }
    }
    let rgb = |image: &RgbaImage| -> Vec<u8> { image.pixels().flat_map(|p| [p.0[0], p.0[1], p.0[2]]).collect() };
    let (w, h) = reference.dimensions();
    let flip_mean = if pixels == 0 || test.dimensions() != (w, h) {
        f64::NAN
    } else {
        let map = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb(reference)),
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb(test)),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        )
        .to_vec();
        let sum: f64 = map.iter().zip(mask).filter(|(_, keep)| **keep).map(|(e, _)| f64::from(*e)).sum();
        sum / pixels as f64
    };
    ImageError { psnr_db, max_error_steps, flip_mean, pixels }
}

/// One camera of the study.
#[derive(Debug, Clone, Copy)]
struct View {
    name: &'static str,
    direction: u32,
    distance_factor: f64,
    camera: OrbitCamera,
}

fn views(bounds: BoundingSphere, directions: u32) -> Vec<View> {
    let directions = directions.max(1);
    let mut out = Vec::new();
    for direction in 0..directions {
        let yaw = 30.0 + 360.0 * f64::from(direction) / f64::from(directions);
        for (name, factor) in DISTANCES {
            let framing = default_camera(bounds, yaw, 20.0, None);
            let camera = default_camera(bounds, yaw, 20.0, Some(framing.distance * factor));
            out.push(View { name, direction, distance_factor: factor, camera });
        }
    }
    out
}

fn unlit(camera: OrbitCamera, filter: FilterMode) -> RenderSettings {
    let mut settings = RenderSettings::new(camera);
    settings.shading = Shading::Unlit;
    settings.filter = filter;
    settings.background = [0.0; 4];
    settings
}

/// One resolution choice: a document, its JSON label, and the meshes packed from it.
struct Choice {
    label: serde_json::Value,
    error_bound: Option<f32>,
    document: Document,
    convert_seconds: f64,
    packs: Vec<Packed>,
    dab: serde_json::Value,
    /// Without a textured baseline: this document at RGBA32F, the reference of its rows.
    reference: Option<GpuMesh>,
}

struct Packed {
    format: ColorFormat,
    packed: PackedMesh,
    mesh: GpuMesh,
    pack_seconds: f64,
}

/// Runs the study on the file at `path` and returns its JSON rows: one `meta` row, one
/// `baseline` row per view (textured input), one `config` row per configuration and view, one
/// `seam` row per resolution choice with mixed resolutions, filter and level, one `bvh` row
/// per preset. The stages: the resolution choices ([`resolution_choices`]), their packs and
/// dabs ([`prepare`]), then per view the references, interleaved frame times and errors
/// ([`Study::view_rows`]), then seams and BVH presets.
pub fn bench_trade(path: &Path, options: &TradeOptions) -> Result<Vec<serde_json::Value>, BenchRenderError> {
    let gpu = Gpu::new_headless()?;
    let budget = Budget::from_environment().with_gpu(gpu.budget_limits());
    let scene = import_gltf(path).ok();
    let baseline = match &scene {
        Some(scene) => gpu.upload_baseline(scene)?,
        None => None,
    };
    let textured = baseline.is_some();
    let file = path.display().to_string();
    let started = Instant::now();
    let mut choices = resolution_choices(path, scene.as_ref(), textured, options, &budget)?;
    prepare(&gpu, &mut choices, textured, options)?;
    let Some(first) = choices.first() else {
        return Ok(Vec::new());
    };
    let reference_name = if textured {
        "uv-texture render, 4x4 supersampled"
    } else {
        "the same document at rgba32f, linear level 0, 4x4 supersampled"
    };
    // Frame times are ratios to a UV-texture baseline: the file's own, else (a document
    // without texture) `bench render`'s synthetic planar one.
    let timing_baseline = match baseline {
        Some(mesh) => mesh,
        None => super::render::baseline(&gpu, path, &first.document)?.1,
    };
    let bounds =
        first.packs.first().map_or_else(|| BoundingSphere::of_points(&first.document.positions), |p| p.mesh.bounds);
    let face_count = first.document.store.topology().face_count();
    let mut rows = vec![serde_json::json!({
        "bench": "trade", "kind": "meta", "file": file, "adapter": gpu.describe(),
        "size": options.size, "supersample": super::adaptive::SUPERSAMPLE, "views": options.views,
        "distances": DISTANCES.iter().map(|(n, f)| serde_json::json!({"view": n, "distance_factor": f})).collect::<Vec<_>>(),
        "frames": options.frames, "triangles": face_count, "reference": reference_name,
        "convert_seconds_total": started.elapsed().as_secs_f64(),
    })];
    let study = Study { gpu: &gpu, choices: &choices, baseline: &timing_baseline, textured, file: &file, options };
    for view in views(bounds, options.views) {
        rows.extend(study.view_rows(&view, face_count)?);
    }
    for choice in &choices {
        let Some(packed) = choice.packs.iter().find(|p| p.format == ColorFormat::Rgba32F) else {
            continue;
        };
        for seam in seam_jumps(&packed.packed) {
            let mut row = seam.to_json();
            merge(
                &mut row,
                &serde_json::json!({"bench": "trade", "kind": "seam", "file": file, "resolution": choice.label}),
            );
            rows.push(row);
        }
    }
    for mut row in bvh_rows(&first.document, bounds) {
        merge(&mut row, &serde_json::json!({"bench": "trade", "kind": "bvh", "file": file}));
        rows.push(row);
    }
    Ok(rows)
}

/// The resolution choices: a glTF `scene` is swept over uniform R (and, with a texture, the
/// error bounds); any other file is measured as it is.
fn resolution_choices(
    path: &Path,
    scene: Option<&meshpaint_core::mesh::scene::Scene>,
    textured: bool,
    options: &TradeOptions,
    budget: &Budget,
) -> Result<Vec<Choice>, BenchRenderError> {
    let choice = |label, error_bound, document, convert_seconds| Choice {
        label,
        error_bound,
        document,
        convert_seconds,
        packs: Vec::new(),
        dab: 0.into(),
        reference: None,
    };
    let Some(scene) = scene else {
        let started = Instant::now();
        let document = Document::open_within(path, Resolution::from_log2(3).unwrap_or(Resolution::MAX), budget)?;
        return Ok(vec![choice(rule_resolution(&document), None, document, started.elapsed().as_secs_f64())]);
    };
    let mut rules: Vec<ResolutionRule> = options.uniform.iter().copied().map(ResolutionRule::Uniform).collect();
    // Error bounds fit a texture: only with one.
    let bounds: &[f32] = if textured { &options.error_bounds } else { &[] };
    rules.extend(bounds.iter().map(|&bound| ResolutionRule::ErrorBound { bound, max: options.max_resolution }));
    let mut choices = Vec::new();
    for rule in rules {
        let started = Instant::now();
        let document = Document::from_scene_within(scene.clone(), rule, path, budget)?;
        let convert_seconds = started.elapsed().as_secs_f64();
        let (label, error_bound) = match rule {
            ResolutionRule::ErrorBound { bound, .. } => (format!("error<={bound}").into(), Some(bound)),
            _ => (rule_resolution(&document), None),
        };
        choices.push(choice(label, error_bound, document, convert_seconds));
    }
    Ok(choices)
}

/// Packs and uploads every choice in every format (best of three packs), its RGBA32F
/// reference when there is no texture, and times a dab on it.
fn prepare(gpu: &Gpu, choices: &mut [Choice], textured: bool, options: &TradeOptions) -> Result<(), BenchRenderError> {
    for choice in choices {
        for &format in &options.formats {
            let (timing, packed) = Timing::measure(3, || choice.document.pack(format));
            let packed = packed?;
            let mesh = gpu.upload(&packed)?;
            choice.packs.push(Packed { format, packed, mesh, pack_seconds: timing.best_seconds });
        }
        if !textured {
            choice.reference = Some(gpu.upload(&choice.document.pack(ColorFormat::Rgba32F)?)?);
        }
        // A brush of a tenth of the samples (at least 64: a brush at the rim of one sample
        // paints nothing), at most 10k as `bench paint`'s middle size.
        let target = (choice.document.store.sample_count() / 10).clamp(64, 10_000);
        choice.dab = paint::dab_throughput(&choice.document, target, options.dabs)
            .unwrap_or_else(|error| serde_json::json!({ "error": error.to_string() }));
    }
    Ok(())
}

/// What every view of the study draws and compares.
struct Study<'a> {
    gpu: &'a Gpu,
    choices: &'a [Choice],
    /// The UV-texture mesh frame times are divided by.
    baseline: &'a meshpaint_render::BaselineMesh,
    textured: bool,
    file: &'a str,
    options: &'a TradeOptions,
}

impl Study<'_> {
    /// Every (choice, pack, filter) drawn in a view.
    fn items(&self) -> Vec<(usize, usize, usize)> {
        (0..self.choices.len())
            .flat_map(|c| {
                (0..self.choices[c].packs.len()).flat_map(move |p| (0..FILTERS.len()).map(move |f| (c, p, f)))
            })
            .collect()
    }

    /// Median frame times in ms of the baseline and of every item, interleaved: each round
    /// times the baseline, then every item, the baseline again after every eight.
    fn frame_times(&self, view: &View, items: &[(usize, usize, usize)]) -> (f64, Vec<f64>) {
        let timer = FrameTimer::new(self.gpu, self.options.size, self.options.size);
        let item = |&(c, p, _): &(usize, usize, usize)| DrawItem::MeshColors(&self.choices[c].packs[p].mesh);
        let time_baseline =
            |timer: &FrameTimer| timer.frame(DrawItem::Baseline(self.baseline), FilterMode::Linear, view.camera);
        time_baseline(&timer);
        for key in items {
            timer.frame(item(key), FILTERS[key.2].1, view.camera);
        }
        let mut baseline_times = Vec::new();
        let mut times: Vec<Vec<f64>> = vec![Vec::new(); items.len()];
        for _ in 0..self.options.frames.max(1) {
            for (k, key) in items.iter().enumerate() {
                if k % 8 == 0 {
                    baseline_times.push(time_baseline(&timer));
                }
                times[k].push(timer.frame(item(key), FILTERS[key.2].1, view.camera));
            }
        }
        (median(&mut baseline_times) * 1e3, times.iter_mut().map(|t| median(t) * 1e3).collect())
    }

    /// The `baseline` row (textured input) and the `config` rows of one view.
    fn view_rows(&self, view: &View, face_count: u32) -> Result<Vec<serde_json::Value>, BenchRenderError> {
        let (gpu, size, file) = (self.gpu, self.options.size, self.file);
        let settings = unlit(view.camera, FilterMode::Linear);
        // One reference per view (textured), or one per resolution choice.
        let mut references: Vec<Supersampled> = Vec::new();
        if self.textured {
            references.push(render_supersampled(gpu, DrawItem::Baseline(self.baseline), &settings, size)?);
        } else {
            for mesh in self.choices.iter().filter_map(|c| c.reference.as_ref()) {
                references.push(render_supersampled(gpu, DrawItem::MeshColors(mesh), &settings, size)?);
            }
        }
        let reference_of =
            |c: usize| &references[if self.textured { 0 } else { c.min(references.len().saturating_sub(1)) }];
        let items = self.items();
        let (baseline_ms, frame_ms) = self.frame_times(view, &items);
        let mask_for = |reference: &Supersampled, test: &RgbaImage| -> Vec<bool> {
            reference.interior.iter().zip(test.pixels()).map(|(&inside, p)| inside && p.0[3] > 0).collect()
        };
        let covered = reference_of(0).interior.iter().filter(|&&x| x).count() as f64;
        let view_json = serde_json::json!({
            "view": view.name, "direction": view.direction, "distance_factor": view.distance_factor,
            "interior_pixels": covered, "pixels_per_face": covered / f64::from(face_count.max(1)),
        });
        let mut rows = Vec::new();
        if self.textured {
            // The baseline itself at the image size: the error floor of texture filtering.
            let native = gpu.render_image(DrawItem::Baseline(self.baseline), &settings, size, size)?;
            let reference = reference_of(0);
            let mut row = error_json(&compare(&reference.image, &native, &mask_for(reference, &native)));
            merge(&mut row, &view_json);
            merge(
                &mut row,
                &serde_json::json!({
                    "bench": "trade", "kind": "baseline", "file": file, "filter": "baseline-uv",
                    "gpu_bytes": self.baseline.gpu_bytes(), "frame_ms": baseline_ms, "frame_ratio": 1.0,
                }),
            );
            rows.push(row);
        }
        for (k, &(c, p, f)) in items.iter().enumerate() {
            let (choice, packed) = (&self.choices[c], &self.choices[c].packs[p]);
            let (filter_name, filter) = FILTERS[f];
            let image =
                gpu.render_image(DrawItem::MeshColors(&packed.mesh), &unlit(view.camera, filter), size, size)?;
            let reference = reference_of(c);
            let mut row = error_json(&compare(&reference.image, &image, &mask_for(reference, &image)));
            let resolutions = choice.document.store.face_resolutions();
            merge(&mut row, &view_json);
            merge(
                &mut row,
                &serde_json::json!({
                    "bench": "trade", "kind": "config", "file": file,
                    "filter": filter_name, "resolution": choice.label, "error_bound": choice.error_bound,
                    "resolution_min": resolutions.iter().map(|r| r.get()).min(),
                    "resolution_max": resolutions.iter().map(|r| r.get()).max(),
                    "format": packed.format.name(),
                    "samples": choice.document.store.sample_count(),
                    "samples_with_mips": packed.packed.sample_count(),
                    "gpu_bytes": packed.mesh.gpu_bytes(),
                    "pack_seconds": packed.pack_seconds,
                    "convert_seconds": choice.convert_seconds,
                    "frame_ms": frame_ms[k], "baseline_frame_ms": baseline_ms, "frame_ratio": frame_ms[k] / baseline_ms,
                    "dab_samples_per_second": choice.dab.get("samples_per_second_median"),
                    "dab_samples": choice.dab.get("samples_covered"),
                    "dab_seconds": choice.dab.get("dab_seconds_median"),
                }),
            );
            rows.push(row);
        }
        Ok(rows)
    }
}

/// The `resolution` of a document: its R when uniform, else `"R a..b"`.
fn rule_resolution(document: &Document) -> serde_json::Value {
    let resolutions = document.store.face_resolutions();
    let min = resolutions.iter().map(|r| r.get()).min().unwrap_or(1);
    let max = resolutions.iter().map(|r| r.get()).max().unwrap_or(1);
    if min == max { min.into() } else { format!("R {min}..{max}").into() }
}

fn error_json(error: &ImageError) -> serde_json::Value {
    // JSON has no infinity: identical images report PSNR null.
    let psnr = if error.psnr_db.is_finite() { Some(error.psnr_db) } else { None };
    serde_json::json!({
        "psnr_db": psnr, "max_error_steps": error.max_error_steps,
        "flip_mean": if error.flip_mean.is_finite() { Some(error.flip_mean) } else { None },
        "pixels_compared": error.pixels,
    })
}

fn merge(row: &mut serde_json::Value, more: &serde_json::Value) {
    if let (Some(row), Some(more)) = (row.as_object_mut(), more.as_object()) {
        for (k, v) in more {
            row.insert(k.clone(), v.clone());
        }
    }
}

fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// The largest jump across mixed-resolution edges for one filter at one level.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamJump {
    /// `nearest`, `linear` or `trilinear` (at `level + 0.5`).
    pub filter: &'static str,
    /// The requested MIP level.
    pub level: u32,
    /// Edges whose two faces have different R.
    pub mixed_edges: u64,
    /// Points compared (per edge, per face pair).
    pub points: u64,
    /// Largest difference of a channel between the two sides, colour units (linear, 0..1).
    pub max_jump: f32,
    /// Mean over the points of the largest channel difference.
    pub mean_jump: f64,
}

impl SeamJump {
    /// As JSON.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "filter": self.filter, "level": self.level, "mixed_edges": self.mixed_edges,
            "points": self.points, "max_jump": self.max_jump, "mean_jump": self.mean_jump,
            "max_jump_8bit_steps": self.max_jump * 255.0,
        })
    }
}

/// The seam measurement of the module docs on `packed` (all levels up to `log2` of its
/// largest R); empty when no edge has faces of different R.
pub fn seam_jumps(packed: &PackedMesh) -> Vec<SeamJump> {
    // Edges keyed by their sorted vertex pair, with (face, local edge k) on each side.
    let mut edges: std::collections::HashMap<(u32, u32), Vec<(u32, u8)>> = std::collections::HashMap::new();
    for (face, corners) in packed.indices.iter().enumerate() {
        for k in 0..3u8 {
            let (a, b) = (corners[usize::from(k)], corners[(usize::from(k) + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push((face as u32, k));
        }
    }
    let resolution = |face: u32| packed.face_records.get(face as usize).and_then(|r| r.resolution());
    // (sorted vertex pair, one side (face, k), the other side)
    type Side = (u32, u8);
    let mut pairs: Vec<((u32, u32), Side, Side)> = Vec::new();
    for (&key, sides) in &edges {
        for (x, &first) in sides.iter().enumerate() {
            for &second in &sides[x + 1..] {
                if resolution(first.0) != resolution(second.0) {
                    pairs.push((key, first, second));
                }
            }
        }
    }
    if pairs.is_empty() {
        return Vec::new();
    }
    pairs.sort_unstable();
    let mixed_edges = {
        let mut keys: Vec<(u32, u32)> = pairs.iter().map(|p| p.0).collect();
        keys.dedup();
        keys.len() as u64
    };
    let max_level = packed.face_records.iter().filter_map(|r| r.resolution()).map(|r| r.log2()).max().unwrap_or(0);
    // Barycentrics of the point at `t` from vertex `from` to the other end of face edge k.
    let barycentric = |face: u32, k: u8, from: u32, t: f32| -> [f32; 3] {
        let corners = packed.indices[face as usize];
        let (start, end) = (usize::from(k), (usize::from(k) + 1) % 3);
        let mut w = [0.0f32; 3];
        if corners[start] == from {
            w[start] = 1.0 - t;
            w[end] = t;
        } else {
            w[end] = 1.0 - t;
            w[start] = t;
        }
        w
    };
    let mut out = Vec::new();
    for filter in ["nearest", "linear", "trilinear"] {
        for level in 0..=max_level {
            if filter == "trilinear" && level == max_level {
                continue;
            }
            let (mut max_jump, mut sum, mut points) = (0.0f32, 0.0f64, 0u64);
            for &((a, _), (fa, ka), (fb, kb)) in &pairs {
                for step in 0..=32u32 {
                    let t = step as f32 / 32.0;
                    let (wa, wb) = (barycentric(fa, ka, a, t), barycentric(fb, kb, a, t));
                    let read = |face: u32, w: [f32; 3]| match filter {
                        "nearest" => sample(packed, face, w, Filter::Nearest, level),
                        "linear" => sample(packed, face, w, Filter::Linear, level),
                        _ => sample_trilinear(packed, face, w, level as f32 + 0.5),
                    };
                    let (Some(ca), Some(cb)) = (read(fa, wa), read(fb, wb)) else {
                        continue;
                    };
                    let jump = (0..4).map(|c| (ca[c] - cb[c]).abs()).fold(0.0f32, f32::max);
                    max_jump = max_jump.max(jump);
                    sum += f64::from(jump);
                    points += 1;
                }
            }
            out.push(SeamJump {
                filter,
                level,
                mixed_edges,
                points,
                max_jump,
                mean_jump: if points > 0 { sum / points as f64 } else { 0.0 },
            });
        }
    }
    out
}

/// Per BVH preset: build time, pick latency and agreement with brute force (module docs).
fn bvh_rows(document: &Document, bounds: BoundingSphere) -> Vec<serde_json::Value> {
    let positions = &document.positions;
    let triangles = &document.store.topology().face_vertices;
    let camera = default_camera(bounds, 30.0, 20.0, None);
    let reference = MeshBvh::build(positions, triangles, BvhPreset::FastBuild);
    let rays = paint::pick_rays(&camera, [1280, 720], 64, &reference);
    let corners: Vec<[DVec3; 3]> =
        triangles.iter().map(|t| t.map(|v| DVec3::from_array(positions[v as usize].map(f64::from)))).collect();
    let brute: Vec<Option<(u32, f64)>> = rays.iter().map(|&(o, d)| brute_force(&corners, o, d)).collect();
    let mut rows = Vec::new();
    for preset in BvhPreset::ALL {
        let (build, bvh) = Timing::measure(1, || MeshBvh::build(positions, triangles, preset));
        let (pick, hits) = Timing::measure(3, || {
            rays.iter().map(|&(o, d)| bvh.cast(o, d, f64::INFINITY).map(|h| (h.face, h.t))).collect::<Vec<_>>()
        });
        let agree = hits
            .iter()
            .zip(&brute)
            .filter(|(hit, truth)| match (hit, truth) {
                (None, None) => true,
                (Some((fa, ta)), Some((fb, tb))) => fa == fb || (ta - tb).abs() <= 1e-9 * tb.abs().max(1e-300),
                _ => false,
            })
            .count();
        let picks = rays.len().max(1) as f64;
        rows.push(serde_json::json!({
            "preset": preset.name(), "build_seconds": build.best_seconds,
            "pick_seconds_best": pick.best_seconds / picks, "pick_seconds_median": pick.median_seconds / picks,
            "picks": rays.len(), "hits": hits.iter().filter(|h| h.is_some()).count(),
            "agree_with_brute_force": agree, "triangles": triangles.len(),
        }));
    }
    rows
}

/// Nearest hit (face, t) of the ray over every triangle, both sides: Möller–Trumbore in `f64`,
/// ties in `t` to the lowest face.
pub fn brute_force(corners: &[[DVec3; 3]], origin: DVec3, direction: DVec3) -> Option<(u32, f64)> {
    let mut best: Option<(u32, f64)> = None;
    for (face, [p0, p1, p2]) in corners.iter().enumerate() {
        let (e1, e2) = (*p1 - *p0, *p2 - *p0);
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            continue;
        }
        let inv = 1.0 / det;
        let s = origin - *p0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = s.cross(e1);
        let v = direction.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let t = e2.dot(q) * inv;
        if t >= 0.0 && best.is_none_or(|(_, bt)| t < bt) {
            best = Some((face as u32, t));
        }
    }
    best
}

/// Per configuration (resolution, format, filter): the means over the views of PSNR and
/// frame ratio, with GPU bytes — the points of the plots. Returns `(bytes points, frame
/// points, baseline (bytes, mean PSNR))`.
pub fn plot_points(rows: &[serde_json::Value]) -> (Vec<PlotPoint>, Vec<PlotPoint>, Option<(f64, f64)>) {
    type Key = (String, String, String);
    let mut groups: Vec<(Key, f64, Vec<f64>, Vec<f64>)> = Vec::new();
    let (mut baseline_psnr, mut baseline_bytes) = (Vec::new(), f64::NAN);
    for row in rows {
        let text = |k: &str| match &row[k] {
            serde_json::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        let number = |k: &str| row[k].as_f64().unwrap_or(f64::NAN);
        match row["kind"].as_str() {
            Some("config") => {
                let key = (text("resolution"), text("format"), text("filter"));
                let index = match groups.iter().position(|g| g.0 == key) {
                    Some(index) => index,
                    None => {
                        groups.push((key, number("gpu_bytes"), Vec::new(), Vec::new()));
                        groups.len() - 1
                    }
                };
                groups[index].2.push(number("psnr_db"));
                groups[index].3.push(number("frame_ratio"));
            }
            Some("baseline") => {
                baseline_psnr.push(number("psnr_db"));
                baseline_bytes = number("gpu_bytes");
            }
            _ => {}
        }
    }
    // Views where nothing was compared (the mesh smaller than a pixel) have no PSNR.
    let mean = |v: &[f64]| {
        let finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
        if finite.is_empty() { f64::NAN } else { finite.iter().sum::<f64>() / finite.len() as f64 }
    };
    let short = |(resolution, format, filter): &Key| {
        let r = match resolution.strip_prefix("error<=") {
            Some(bound) => format!("e{bound}"),
            None => format!("R{resolution}"),
        };
        let f = match format.as_str() {
            "rgba8" => "8",
            "rgba16f" => "16f",
            _ => "32f",
        };
        let filter = match filter.as_str() {
            "nearest" => "near",
            "linear" => "lin",
            "trilinear" => "tri",
            other => other,
        };
        format!("{r} {f} {filter}")
    };
    let mut bytes = Vec::new();
    let mut frames = Vec::new();
    for (key, gpu_bytes, psnr, ratio) in &groups {
        let point = |cost: f64| PlotPoint {
            cost,
            quality: mean(psnr),
            filter: key.2.clone(),
            format: key.1.clone(),
            label: short(key),
        };
        bytes.push(point(*gpu_bytes));
        frames.push(point(mean(ratio)));
    }
    let baseline = (!baseline_psnr.is_empty()).then(|| (baseline_bytes, mean(&baseline_psnr)));
    (bytes, frames, baseline)
}

/// Writes `trade_<stem>_bytes.png` and `trade_<stem>_frame.png` into `dir` from `rows`;
/// returns their paths.
pub fn write_plots(rows: &[serde_json::Value], dir: &Path, stem: &str) -> Result<Vec<std::path::PathBuf>, PlotError> {
    let (bytes, frames, baseline) = plot_points(rows);
    let name = |what: &str| dir.join(format!("trade_{stem}_{what}.png"));
    let (bytes_path, frame_path) = (name("bytes"), name("frame"));
    plot_tradeoff(
        &bytes_path,
        &format!("{stem}: error vs GPU memory (every filter × resolution × format)"),
        "GPU bytes of the mesh (log scale)",
        true,
        &bytes,
        baseline.map(|(b, p)| (b, p, "UV texture")),
    )?;
    plot_tradeoff(
        &frame_path,
        &format!("{stem}: error vs frame time (ratio to the UV-texture baseline, interleaved)"),
        "frame time / UV-texture frame time (mean over views)",
        false,
        &frames,
        baseline.map(|(_, p)| (1.0, p, "UV texture")),
    )?;
    Ok(vec![bytes_path, frame_path])
}
