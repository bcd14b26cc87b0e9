//! `meshpaint bench adaptive`: samples and error of uniform resolutions next to the
//! content-driven ones (texel density, error bounds), on a textured glTF.
//!
//! Error is measured against the UV-textured render of the same file (the baseline
//! pipeline: the glTF UVs and base-colour texture with hardware trilinear filtering):
//! both are rendered unlit at `s`× the image size in each direction and box-filtered `s`×`s`
//! to the image size (so the figure measures the colour signal, not edge aliasing), from
//! `views` cameras around the model (yaw 30° + k·360°/views, pitch 20°, framing
//! distance), or one close-up camera (`--look-at`). PSNR is over the RGB channels of the 8-bit sRGB images, on the pixels that
//! either render covers; the row reports the mean over the views and the worst view.
//! Mesh colors are packed in RGBA8 (the display and save format) and drawn with the
//! linear filter at level 0, the reconstruction the conversion fits.
//!
//! The supersampling `s` is [`ADAPTIVE_SUPERSAMPLE`] = 16 by default, not the trade study's
//! [`SUPERSAMPLE`] = 4: at 4 the reference itself is only 55.9 dB (Duck, interior pixels,
//! mean of the three views) from the same render at 16 — hardware trilinear picks its level
//! from the supersample's footprint, so the box-filtered pixel is blurred once more — and the
//! rows above ~55 dB measured that blur, not the conversion (docs/ADAPTIVE.md, "Why the
//! figures saturated"). At 8 the reference is 65.2 dB from 16.

use std::path::Path;
use std::time::Instant;

use image::RgbaImage;

use meshpaint_core::camera::default_camera;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::psnr::psnr;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::convert::least_squares::BakeFit;
use meshpaint_core::io::document::{Document, OpenPhases};
use meshpaint_core::mesh::scene::Scene;
use meshpaint_render::{DrawItem, FilterMode, Gpu, RenderSettings, Shading};

use super::BenchRenderError;

/// Supersampling factor per axis of both renders in `bench trade`.
pub const SUPERSAMPLE: u32 = 4;

/// Supersampling factor per axis of both renders in `bench adaptive` (module docs).
pub const ADAPTIVE_SUPERSAMPLE: u32 = 16;

/// What `bench adaptive` renders and which bakes it compares.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveOptions {
    /// With `Some(max)`, each uniform `R ≥ 4` is followed by the budget allocation (capped at
    /// `max`) given a third of its samples.
    pub budget_max: Option<Resolution>,
    /// Image size (square).
    pub size: u32,
    /// Camera views around the model.
    pub views: u32,
    /// Supersampling per axis of both renders.
    pub supersample: u32,
    /// Each rule is converted with each of these bakes.
    pub fits: Vec<BakeFit>,
    /// With `Some`, one close-up camera instead of `views` cameras around the model.
    pub close_up: Option<CloseUp>,
}

/// A camera looking at a point of the model (a logo, a detail) instead of framing all of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloseUp {
    /// The point looked at, world space.
    pub target: [f64; 3],
    /// Eye distance from `target`.
    pub distance: f64,
    /// Camera yaw, degrees (0 looks along −Z, from +Z).
    pub yaw_degrees: f64,
    /// Camera pitch, degrees.
    pub pitch_degrees: f64,
}

/// `bake` in the JSON rows: `least-squares` or `point`.
pub fn fit_name(fit: BakeFit) -> &'static str {
    match fit {
        BakeFit::Point => "point",
        BakeFit::LeastSquares => "least-squares",
    }
}

/// One measured conversion.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveRow {
    /// The rule, as [`ResolutionRule::describe`] writes it.
    pub rule: ResolutionRule,
    /// How the texture was baked.
    pub fit: BakeFit,
    /// Level-0 samples.
    pub samples: u64,
    /// Samples with MIP chains (the packed colour buffer).
    pub samples_with_mips: u64,
    /// Bytes of the packed face records and colours (RGBA8).
    pub packed_bytes: u64,
    /// Seconds to convert (fit + bake) the scene.
    pub convert_seconds: f64,
    /// Where the conversion's time went.
    pub phases: OpenPhases,
    /// PSNR per view against the UV-textured render, dB.
    pub psnr_db: Vec<f64>,
    /// Face resolutions: smallest and largest.
    pub resolution_range: (u32, u32),
    /// Supersampling per axis of both renders.
    pub supersample: u32,
}

impl AdaptiveRow {
    /// As JSON (`resolution` is the integer R for uniform rows, `null` otherwise).
    pub fn to_json(&self) -> serde_json::Value {
        let (resolution, bound, rule) = match self.rule {
            ResolutionRule::Uniform(r) => (Some(r.get()), None, "uniform"),
            ResolutionRule::WhereTextured(r) => (Some(r.get()), None, "where-textured"),
            ResolutionRule::TexelDensity { .. } => (None, None, "texel-density"),
            ResolutionRule::ErrorBound { bound, .. } => (None, Some(bound), "error"),
            ResolutionRule::Budget { .. } => (None, None, "budget"),
        };
        let budget = match self.rule {
            ResolutionRule::Budget { samples, .. } => Some(samples),
            _ => None,
        };
        let mean = self.psnr_db.iter().sum::<f64>() / self.psnr_db.len().max(1) as f64;
        let worst = self.psnr_db.iter().copied().fold(f64::INFINITY, f64::min);
        serde_json::json!({
            "rule": rule,
            "bake": fit_name(self.fit),
            "describe": self.rule.describe(),
            "resolution": resolution,
            "error_bound": bound,
            "sample_budget": budget,
            "samples": self.samples,
            "samples_with_mips": self.samples_with_mips,
            "packed_bytes": self.packed_bytes,
            "convert_seconds": self.convert_seconds,
            "texture_psnr_db": self.phases.texture_psnr_db.filter(|db| db.is_finite()),
            "faces_held_by_budget": self.phases.rule.faces_held_by_budget,
            "phase_seconds": {
                "weld": self.phases.weld.as_secs_f64(),
                "topology": self.phases.topology.as_secs_f64(),
                "calibrate": self.phases.rule.calibrate.as_secs_f64(),
                "predict": self.phases.rule.predict.as_secs_f64(),
                "allocate": self.phases.rule.allocate.as_secs_f64(),
                "bake": self.phases.bake.as_secs_f64(),
                "store": self.phases.store.as_secs_f64(),
                "measure": self.phases.measure.as_secs_f64(),
            },
            "psnr_db": mean,
            "psnr_db_worst_view": worst,
            "psnr_db_per_view": self.psnr_db,
            "resolution_min": self.resolution_range.0,
            "resolution_max": self.resolution_range.1,
            "supersample": self.supersample,
        })
    }
}

/// Measures every rule in `rules` with every bake of `options` on `scene` (read from
/// `path`), `size`² images supersampled `supersample`² (module docs), `views` cameras, the
/// budget rows of [`AdaptiveOptions::budget_max`]. Fails when the scene has no base-colour
/// texture (no reference).
/// Long: references, then one conversion, pack, upload and render per row; `on_row` sees
/// each row as soon as it is measured (the CLI prints it then).
pub fn bench_adaptive(
    path: &Path,
    scene: &Scene,
    rules: &[ResolutionRule],
    options: &AdaptiveOptions,
    on_row: &mut dyn FnMut(&AdaptiveRow),
) -> Result<Vec<AdaptiveRow>, BenchRenderError> {
    let AdaptiveOptions { budget_max, size, views, supersample, ref fits, close_up } = *options;
    let gpu = Gpu::new_headless()?;
    let baseline = gpu
        .upload_baseline(scene)?
        .ok_or_else(|| BenchRenderError::NoReference(format!("{}: no base-colour texture", path.display())))?;
    let cameras: Vec<_> = match close_up {
        Some(c) => {
            let mut camera = default_camera(baseline.bounds, c.yaw_degrees, c.pitch_degrees, Some(c.distance));
            camera.target = c.target;
            vec![camera]
        }
        None => (0..views.max(1))
            .map(|k| default_camera(baseline.bounds, 30.0 + 360.0 * f64::from(k) / f64::from(views.max(1)), 20.0, None))
            .collect(),
    };
    let settings = |camera| {
        let mut settings = RenderSettings::new(camera);
        settings.shading = Shading::Unlit;
        settings.filter = FilterMode::Linear;
        settings.background = [0.0; 4];
        settings
    };
    let references: Vec<RgbaImage> = cameras
        .iter()
        .map(|&camera| {
            render_supersampled_by(&gpu, DrawItem::Baseline(&baseline), &settings(camera), size, supersample)
                .map(|s| s.image)
        })
        .collect::<Result<_, _>>()?;
    let mut rows: Vec<AdaptiveRow> = Vec::new();
    let mut queue: std::collections::VecDeque<(ResolutionRule, BakeFit)> =
        rules.iter().flat_map(|&rule| fits.iter().map(move |&fit| (rule, fit))).collect();
    while let Some((rule, fit)) = queue.pop_front() {
        let started = Instant::now();
        let mut phases = OpenPhases::default();
        let document = Document::from_scene_phased(
            scene.clone(),
            rule,
            fit,
            path,
            &meshpaint_core::colors::budget::Budget::from_environment(),
            &mut phases,
            meshpaint_core::progress::Reporter::silent().progress(),
        )?;
        let convert_seconds = started.elapsed().as_secs_f64();
        let packed = document.pack(ColorFormat::Rgba8Srgb)?;
        let mesh = gpu.upload(&packed)?;
        let mut psnr_db = Vec::new();
        for (camera, reference) in cameras.iter().zip(&references) {
            let image =
                render_supersampled_by(&gpu, DrawItem::MeshColors(&mesh), &settings(*camera), size, supersample)?.image;
            psnr_db.push(psnr(reference, &image));
        }
        let resolutions = document.store.face_resolutions();
        let range = (
            resolutions.iter().map(|r| r.get()).min().unwrap_or(1),
            resolutions.iter().map(|r| r.get()).max().unwrap_or(1),
        );
        // Next to each uniform R ≥ 4: the budget allocation with a third of its samples.
        if let (ResolutionRule::Uniform(r), Some(max)) = (rule, budget_max)
            && r.get() >= 4
        {
            queue.push_front((ResolutionRule::Budget { samples: document.store.sample_count() / 3, max }, fit));
        }
        rows.push(AdaptiveRow {
            rule,
            fit,
            samples: document.store.sample_count(),
            samples_with_mips: packed.sample_count(),
            packed_bytes: packed.face_record_bytes() + packed.color_bytes(),
            convert_seconds,
            phases,
            psnr_db,
            resolution_range: range,
            supersample: supersample.max(1),
        });
        if let Some(row) = rows.last() {
            on_row(row);
        }
    }
    Ok(rows)
}

/// The rules `bench adaptive` measures by default: uniform R = 1…32, texel density and
/// error bounds 0.05…0.0025, all capped at `max`.
pub fn default_rules(max: Resolution) -> Vec<ResolutionRule> {
    let mut rules: Vec<ResolutionRule> =
        (0..=5).filter_map(|l| Resolution::from_log2(l).ok()).map(ResolutionRule::Uniform).collect();
    rules.push(ResolutionRule::TexelDensity { max });
    rules.extend([0.05f32, 0.02, 0.01, 0.005, 0.0025].map(|bound| ResolutionRule::ErrorBound { bound, max }));
    rules
}

/// Parses one rule of `bench adaptive --rules`: `uniform:R`, `texel-density`, `error:E` or
/// `samples:N` (a budget), the adaptive ones capped at `max`.
pub fn parse_rule(text: &str, max: Resolution) -> Result<ResolutionRule, String> {
    let (name, value) = text.split_once(':').unwrap_or((text, ""));
    let number =
        |what: &str| value.parse::<f64>().map_err(|_| format!("{text:?}: {what} needs a number, e.g. {what}:8"));
    match name {
        "uniform" => Resolution::new(number("uniform")? as u64)
            .map(ResolutionRule::Uniform)
            .map_err(|err| format!("{text:?}: {err}")),
        "texel-density" if value.is_empty() => Ok(ResolutionRule::TexelDensity { max }),
        "error" => match number("error")? {
            bound if bound.is_finite() && bound >= 0.0 => Ok(ResolutionRule::ErrorBound { bound: bound as f32, max }),
            bound => Err(format!("{text:?}: an error bound is a number ≥ 0, got {bound}")),
        },
        "samples" => match value.parse::<u64>() {
            Ok(samples) if samples > 0 => Ok(ResolutionRule::Budget { samples, max }),
            _ => Err(format!("{text:?}: a budget is a whole number of samples > 0, e.g. samples:20000")),
        },
        _ => Err(format!("{text:?}: a rule is uniform:R, texel-density, error:E or samples:N")),
    }
}

/// A render supersampled [`SUPERSAMPLE`]² and box-filtered to its size, with the pixels all of
/// whose subsamples the mesh covers (alpha > 0): the interior, free of silhouette aliasing.
#[derive(Debug, Clone, PartialEq)]
pub struct Supersampled {
    /// The box-filtered image (8-bit sRGB values averaged, alpha too).
    pub image: RgbaImage,
    /// Per pixel (row-major): every subsample covered.
    pub interior: Vec<bool>,
}

/// Renders `item` at `size · SUPERSAMPLE` per side and box-filters it to `size × size` — the
/// reference of `bench adaptive` and `bench trade`.
pub fn render_supersampled(
    gpu: &Gpu,
    item: DrawItem<'_>,
    settings: &RenderSettings,
    size: u32,
) -> Result<Supersampled, meshpaint_render::RenderError> {
    render_supersampled_by(gpu, item, settings, size, SUPERSAMPLE)
}

/// Renders `item` at `size · supersample` per side (`supersample` at least 1) and
/// box-filters it to `size × size`.
pub fn render_supersampled_by(
    gpu: &Gpu,
    item: DrawItem<'_>,
    settings: &RenderSettings,
    size: u32,
    supersample: u32,
) -> Result<Supersampled, meshpaint_render::RenderError> {
    let supersample = supersample.max(1);
    let big = size * supersample;
    Ok(box_down(&gpu.render_image(item, settings, big, big)?, supersample))
}

/// Box filter `factor × factor` (in 8-bit sRGB values, alpha averaged too).
fn box_down(image: &RgbaImage, factor: u32) -> Supersampled {
    let (w, h) = (image.width() / factor, image.height() / factor);
    let mut interior = vec![false; w as usize * h as usize];
    let image = RgbaImage::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 4];
        let mut covered = 0;
        for dy in 0..factor {
            for dx in 0..factor {
                let p = image.get_pixel(x * factor + dx, y * factor + dy).0;
                for c in 0..4 {
                    sum[c] += u32::from(p[c]);
                }
                covered += u32::from(p[3] > 0);
            }
        }
        let n = factor * factor;
        interior[y as usize * w as usize + x as usize] = covered == n;
        image::Rgba(sum.map(|s| ((s + n / 2) / n) as u8))
    });
    Supersampled { image, interior }
}

/// Texels the UV islands of `scene` cover in their base-colour textures (per texture, UVs
/// wrapped; texels several faces cover count once), summed over the textures.
pub fn uv_island_texels(scene: &Scene) -> u64 {
    uv_texels(scene, |faces, size| meshpaint_core::convert::bake_uv::uv_island_texels(faces, size))
}

/// Texels the faces of `scene` show: as [`uv_island_texels`], but a texel counts once per
/// face that maps it ([`meshpaint_core::convert::bake_uv::uv_face_texels`]); larger where UV islands
/// overlap (BoxTextured: each of the 6 sides maps the whole texture).
pub fn uv_face_texels(scene: &Scene) -> u64 {
    uv_texels(scene, |faces, size| meshpaint_core::convert::bake_uv::uv_face_texels(faces, size))
}

/// `count(faces of each base-colour texture, its size)` summed over the textures.
fn uv_texels(scene: &Scene, count: impl Fn(Vec<&[[f32; 2]; 3]>, [u32; 2]) -> u64) -> u64 {
    let welded = meshpaint_core::mesh::weld::weld_scene(scene);
    let texture_of = |material: &Option<u32>| {
        material.and_then(|m| scene.materials.get(m as usize)).and_then(|m| m.base_color_texture)
    };
    scene
        .textures
        .iter()
        .enumerate()
        .map(|(index, texture)| {
            let faces = welded
                .corner_uvs
                .iter()
                .zip(&welded.triangle_materials)
                .filter(|(_, material)| texture_of(material) == Some(index as u32))
                .map(|(uvs, _)| uvs)
                .collect::<Vec<_>>();
            count(faces, [texture.width, texture.height])
        })
        .sum()
}

/// The goals of the adaptive-resolution issue, checked on the rows of `rows` baked with
/// `fit`: the fewest samples of any
/// rule at ≥ 38 dB (mean over the views) against `uv_island_texels`, and for each uniform
/// R the fewest samples of a content-driven rule reaching its PSNR (`ratio` = uniform
/// samples / those; the goal is ≥ 3).
pub fn summary(rows: &[AdaptiveRow], fit: BakeFit, uv_island_texels: u64) -> serde_json::Value {
    let rows: Vec<&AdaptiveRow> = rows.iter().filter(|row| row.fit == fit).collect();
    let mean = |row: &AdaptiveRow| row.psnr_db.iter().sum::<f64>() / row.psnr_db.len().max(1) as f64;
    let fewest_at = |db: f64, adaptive_only: bool| {
        rows.iter()
            .filter(|row| mean(row) >= db && !(adaptive_only && matches!(row.rule, ResolutionRule::Uniform(_))))
            .min_by_key(|row| row.samples)
    };
    let at_38 = fewest_at(38.0, false);
    let uniform: Vec<serde_json::Value> = rows
        .iter()
        .filter(|row| matches!(row.rule, ResolutionRule::Uniform(_)))
        .map(|row| {
            let best = fewest_at(mean(row), true);
            serde_json::json!({
                "uniform": row.rule.describe(),
                "uniform_samples": row.samples,
                "psnr_db": mean(row),
                "adaptive": best.map(|b| b.rule.describe()),
                "adaptive_samples": best.map(|b| b.samples),
                "ratio": best.map(|b| row.samples as f64 / b.samples.max(1) as f64),
            })
        })
        .collect();
    serde_json::json!({
        "bake": fit_name(fit),
        "uv_island_texels": uv_island_texels,
        "fewest_samples_at_38_db": at_38.map(|row| row.samples),
        "rule_at_38_db": at_38.map(|row| row.rule.describe()),
        "goal_38_db_within_texels": at_38.is_some_and(|row| row.samples <= uv_island_texels),
        "same_psnr_fewer_samples": uniform,
    })
}
