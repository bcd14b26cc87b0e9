//! `meshpaint bench brush-edge`: how close a hard stroke's edge comes to the ideal one, per
//! way of painting it (issue 43, "hard edges").
//!
//! One stroke of a hard round brush (constant falloff, strength 1, the editor's occlusion and
//! backface culling) is painted on a close-up of the model at the document's `R`, and the
//! painted document is rendered close up (unlit, linear filter at level 0: what paint mode
//! shows) at `supersample`× the image size per axis and box-filtered down.
//!
//! The truth is independent of the brush code: the same close-up in which every subsample
//! whose ray (cast into the BVH, the nearest hit) lands within a dab's world-space sphere
//! (the dabs the stroke placed: centre and radius) shows the brush colour, and every other
//! subsample shows the unpainted document's render there; box-filtered the same way. The
//! error is measured on the **edge band**, the pixels whose centre's surface point lies within
//! [`BAND_SPACINGS`] sample spacings of the stroke's rim (signed distance to the nearest
//! sphere), and over every covered pixel.
//!
//! Variants ([`HardEdges`], see [`variants`]): `sampled` (every sample inside the sphere at
//! full strength, none outside: hard brushes before issue 43), `antialias_W` (the rim blended
//! by coverage over W sample spacings), `raise_R` (the faces under the brush raised up to `R`
//! within the budget, to a spacing of radius / 16; `_per_K`: radius / K) and `both_…`. The
//! stroke time is the replay's wall time (one run; the machine's load shows in it).

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use image::RgbaImage;
use rayon::prelude::*;

use meshpaint_core::camera::{BoundingSphere, OrbitCamera, default_camera};
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::psnr::psnr_over;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::io::document::Document;
use meshpaint_core::paint::brush::{
    BrushRadius, BrushSettings, Dab, Falloff, HARD_EDGE_SPACINGS_PER_RADIUS, HardEdges, PaintView, Painter,
    replay_stroke,
};
use meshpaint_core::paint::picking::{BvhPreset, MeshBvh};
use meshpaint_core::paint::undo::UndoHistory;
use meshpaint_render::{DrawItem, FilterMode, Gpu, GpuMesh, RenderSettings, Shading};

use super::BenchRenderError;

/// Why `bench brush-edge` failed.
#[derive(Debug, thiserror::Error)]
pub enum BrushEdgeError {
    /// Opening, packing or rendering failed.
    #[error(transparent)]
    Render(#[from] BenchRenderError),
    /// Painting the stroke failed.
    #[error("painting the stroke: {0}")]
    Brush(#[from] meshpaint_core::paint::brush::BrushError),
    /// Writing an image failed.
    #[error("writing {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

impl From<meshpaint_render::RenderError> for BrushEdgeError {
    fn from(error: meshpaint_render::RenderError) -> Self {
        BrushEdgeError::Render(error.into())
    }
}

impl From<meshpaint_core::packing::packer::PackError> for BrushEdgeError {
    fn from(error: meshpaint_core::packing::packer::PackError) -> Self {
        BrushEdgeError::Render(error.into())
    }
}

impl From<meshpaint_core::io::document::DocumentError> for BrushEdgeError {
    fn from(error: meshpaint_core::io::document::DocumentError) -> Self {
        BrushEdgeError::Render(error.into())
    }
}

/// Half-width of the edge band, in sample spacings of the document's `R`.
pub const BAND_SPACINGS: f64 = 1.5;

/// The stroke's colour (sRGB `#d01010`, far from the models' own colours).
const STROKE_SRGB: [u8; 3] = [0xd0, 0x10, 0x10];

/// What `bench brush-edge` paints and renders.
#[derive(Debug, Clone, PartialEq)]
pub struct BrushEdgeOptions {
    /// The document's uniform `R`.
    pub resolution: Resolution,
    /// Image side, pixels (the stroke is painted in this view).
    pub size: u32,
    /// Subsamples per pixel per axis of the renders and of the truth.
    pub supersample: u32,
    /// The close-up: the framing distance divided by this.
    pub zoom: f64,
    /// Camera yaw and pitch, degrees.
    pub yaw_pitch: [f64; 2],
    /// Brush radius, pixels.
    pub radius_px: f64,
    /// The largest `R` of the raising variants.
    pub raise_to: Vec<Resolution>,
    /// Write the box-filtered images (truth and each variant) here as PNG.
    pub out: Option<std::path::PathBuf>,
}

/// `R = 2^log2` (valid for the small powers used here).
fn r(log2: u32) -> Resolution {
    Resolution::from_log2(log2).unwrap_or(Resolution::ONE)
}

impl Default for BrushEdgeOptions {
    fn default() -> Self {
        BrushEdgeOptions {
            resolution: r(3),
            size: 320,
            supersample: 8,
            zoom: 4.0,
            yaw_pitch: [30.0, 20.0],
            radius_px: 20.0,
            raise_to: vec![r(4), r(5), Resolution::SIXTY_FOUR],
            out: None,
        }
    }
}

/// One way of painting the stroke: what the hard brush does at its rim.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    /// The painter's setting.
    pub hard_edges: HardEdges,
}

impl Variant {
    /// `sampled` (as before issue 43), `antialias_W` (over W spacings), `raise_R` (up to R at
    /// 16 spacings per radius), `raise_R_per_K` (K per radius), `both_R`.
    pub fn name(&self) -> String {
        let HardEdges { raise_to, spacings_per_radius, antialias_spacings } = self.hard_edges;
        let per = if spacings_per_radius == HARD_EDGE_SPACINGS_PER_RADIUS {
            String::new()
        } else {
            format!("_per_{spacings_per_radius}")
        };
        match (raise_to, antialias_spacings) {
            (None, None) => "sampled".into(),
            (None, Some(w)) => format!("antialias_{w}"),
            (Some(r), None) => format!("raise_{r}{per}"),
            (Some(r), Some(w)) => format!("both_{r}{per}_antialias_{w}"),
        }
    }
}

/// The variants measured: the sampled rim; anti-aliased over 1 and ½ spacing; raised to each
/// of `raise_to` at the default 16 spacings per radius; raised to the largest of them at 4
/// (resolution-follows-the-brush's rule) and 32 spacings per radius; raised and anti-aliased.
pub fn variants(raise_to: &[Resolution]) -> Vec<Variant> {
    let hard = |raise_to: Option<Resolution>, per: f64, antialias: Option<f64>| Variant {
        hard_edges: HardEdges { raise_to, spacings_per_radius: per, antialias_spacings: antialias },
    };
    let per = HARD_EDGE_SPACINGS_PER_RADIUS;
    let mut list = vec![hard(None, per, None), hard(None, per, Some(1.0)), hard(None, per, Some(0.5))];
    list.extend(raise_to.iter().map(|&r| hard(Some(r), per, None)));
    if let Some(&top) = raise_to.iter().max() {
        list.extend([hard(Some(top), 4.0, None), hard(Some(top), 32.0, None), hard(Some(top), per, Some(1.0))]);
    }
    list
}

/// The hard round brush of the stroke.
pub fn hard_brush(radius_px: f64) -> BrushSettings {
    let color: Rgba = [
        meshpaint_core::colors::format::decode_srgb8(STROKE_SRGB[0]),
        meshpaint_core::colors::format::decode_srgb8(STROKE_SRGB[1]),
        meshpaint_core::colors::format::decode_srgb8(STROKE_SRGB[2]),
        1.0,
    ];
    BrushSettings {
        color,
        radius: BrushRadius::Pixels { radius_px },
        strength: 1.0,
        falloff: Falloff::Constant,
        spacing_percent: 10.0,
        follow_resolution: None,
        ..BrushSettings::default()
    }
}

/// The close-up camera: the framing view at `yaw_pitch`, looking at the surface point under
/// the image centre from `1 / zoom` of the framing distance.
pub fn close_up(positions: &[[f32; 3]], bvh: &MeshBvh, options: &BrushEdgeOptions) -> OrbitCamera {
    let bounds = BoundingSphere::of_points(positions);
    let mut camera = default_camera(bounds, options.yaw_pitch[0], options.yaw_pitch[1], None);
    let half = f64::from(options.size) / 2.0;
    let (origin, direction) = camera.ray_through_pixel(half, half, options.size, options.size);
    if let Some(hit) = bvh.cast(origin, direction, f64::INFINITY) {
        let distance = camera.distance / options.zoom.max(1.0);
        camera.look_at_point(DVec3::from_array(hit.position_world), distance);
        camera.fit_depth_to(bounds);
    }
    camera
}

/// The stroke: a gentle arc across the middle of the image, pixels.
pub fn stroke_points(size: u32) -> Vec<[f64; 2]> {
    let s = f64::from(size);
    (0..=12)
        .map(|k| {
            let t = f64::from(k) / 12.0;
            let x = s * (0.15 + 0.7 * t);
            let y = s * (0.58 - 0.22 * 4.0 * t * (1.0 - t) + 0.06 * t);
            [x, y]
        })
        .collect()
}

/// Per pixel of a `big × big` view: the signed distance from the surface point its ray hits
/// to the rim of the dabs' union (`min_k |p − c_k| − r_k`, negative inside), `None` off the mesh.
pub fn rim_distances(bvh: &MeshBvh, camera: &OrbitCamera, big: u32, dabs: &[Dab]) -> Vec<Option<f64>> {
    (0..big * big)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (f64::from(i % big) + 0.5, f64::from(i / big) + 0.5);
            let (origin, direction) = camera.ray_through_pixel(x, y, big, big);
            let hit = bvh.cast(origin, direction, f64::INFINITY)?;
            let p = DVec3::from_array(hit.position_world);
            let d = dabs
                .iter()
                .map(|dab| (p - DVec3::from_array(dab.center_world)).length() - dab.radius_world)
                .fold(f64::INFINITY, f64::min);
            Some(d)
        })
        .collect()
}

/// The truth at the supersampled size: the brush colour where the subsample is inside a dab's
/// sphere, the unpainted render elsewhere.
fn truth_image(base: &RgbaImage, rim: &[Option<f64>]) -> RgbaImage {
    let mut truth = base.clone();
    for (pixel, d) in truth.pixels_mut().zip(rim) {
        if d.is_some_and(|d| d <= 0.0) {
            pixel.0 = [STROKE_SRGB[0], STROKE_SRGB[1], STROKE_SRGB[2], 255];
        }
    }
    truth
}

/// Box filter `factor × factor` in 8-bit sRGB values (as both images are compared).
fn box_down(image: &RgbaImage, factor: u32) -> RgbaImage {
    let (w, h) = (image.width() / factor, image.height() / factor);
    RgbaImage::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 4];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = image.get_pixel(x * factor + dx, y * factor + dy).0;
                for c in 0..4 {
                    sum[c] += u32::from(p[c]);
                }
            }
        }
        let n = factor * factor;
        image::Rgba(sum.map(|s| ((s + n / 2) / n) as u8))
    })
}

/// Mean absolute error over RGB, 8-bit steps, on the pixels of `mask`.
pub fn mean_abs_error(a: &RgbaImage, b: &RgbaImage, mask: &[bool]) -> f64 {
    let (mut sum, mut count) = (0u64, 0u64);
    for ((pa, pb), &keep) in a.pixels().zip(b.pixels()).zip(mask) {
        if keep {
            sum += (0..3).map(|c| u64::from(pa.0[c].abs_diff(pb.0[c]))).sum::<u64>();
            count += 3;
        }
    }
    if count == 0 { f64::NAN } else { sum as f64 / count as f64 }
}

/// The median sample spacing (longest edge / R) of the faces within the dabs' spheres.
fn median_spacing(document: &Document, bvh: &MeshBvh, dabs: &[Dab]) -> f64 {
    let mut faces: Vec<u32> = dabs
        .iter()
        .flat_map(|dab| bvh.faces_in_sphere(DVec3::from_array(dab.center_world), dab.radius_world))
        .collect();
    faces.sort_unstable();
    faces.dedup();
    let topology = document.store.topology();
    let mut spacings: Vec<f64> = faces
        .iter()
        .filter_map(|&face| {
            let r = document.store.face_resolution(face)?;
            let corners = topology.face_vertices.get(face as usize)?;
            let p = corners.map(|v| DVec3::from_array(document.positions[v as usize].map(f64::from)));
            let longest = (p[1] - p[0]).length().max((p[2] - p[1]).length()).max((p[0] - p[2]).length());
            Some(longest / f64::from(r.get()))
        })
        .collect();
    spacings.sort_by(f64::total_cmp);
    spacings.get(spacings.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The measurement's fixed parts: the document, its BVH, the close-up and its renderer.
struct Scene<'g> {
    gpu: &'g Gpu,
    document: Document,
    bvh: MeshBvh,
    camera: OrbitCamera,
    budget: Budget,
    options: BrushEdgeOptions,
}

impl Scene<'_> {
    /// Renders `document` at the supersampled size.
    fn render(&self, document: &Document) -> Result<RgbaImage, BrushEdgeError> {
        let packed = document.pack(ColorFormat::Rgba8Srgb)?;
        let mesh: GpuMesh = self.gpu.upload(&packed)?;
        let mut settings = RenderSettings::new(self.camera);
        settings.shading = Shading::Unlit;
        settings.filter = FilterMode::Linear;
        settings.background = [0.0; 4];
        let big = self.options.size * self.options.supersample.max(1);
        Ok(self.gpu.render_image(DrawItem::MeshColors(&mesh), &settings, big, big)?)
    }

    /// Paints the stroke with `variant` on a copy of the document: the painted document, the
    /// dabs, the stroke's seconds and the faces it raised.
    fn paint(&self, variant: Variant) -> Result<(Document, Vec<Dab>, f64, u64), BrushEdgeError> {
        let mut document = self.document.clone();
        let base = document.store.clone();
        let view = PaintView {
            positions: &self.document.positions,
            bvh: &self.bvh,
            camera: &self.camera,
            viewport_px: [self.options.size; 2],
            base: Some(&base),
        };
        let mut painter = Painter::new(&self.document.positions);
        painter.set_settings(hard_brush(self.options.radius_px));
        painter.set_budget(Some((self.budget, ColorFormat::Rgba8Srgb)));
        painter.set_hard_edges(variant.hard_edges);
        let mut history = UndoHistory::default();
        let points = stroke_points(self.options.size);
        let started = Instant::now();
        let (update, _) = replay_stroke(&mut painter, &view, &mut document.store, &mut history, &points)?;
        let seconds = started.elapsed().as_secs_f64();
        let raised = (0..document.store.topology().face_count())
            .filter(|&f| document.store.face_resolution(f) != self.document.store.face_resolution(f))
            .count() as u64;
        Ok((document, update.dabs, seconds, raised))
    }
}

/// Measures every variant on `path` (one JSON object per variant, `on_row` sees each as soon as
/// it is measured).
pub fn bench_brush_edge(
    path: &Path,
    options: &BrushEdgeOptions,
    on_row: &mut dyn FnMut(&serde_json::Value),
) -> Result<Vec<serde_json::Value>, BrushEdgeError> {
    let gpu = Gpu::new_headless()?;
    let budget = Budget::from_environment();
    let document = Document::open_within(path, ResolutionRule::Uniform(options.resolution), &budget)?;
    let bvh = MeshBvh::build(&document.positions, &document.store.topology().face_vertices, BvhPreset::default());
    let camera = close_up(&document.positions, &bvh, options);
    let scene = Scene { gpu: &gpu, document, bvh, camera, budget, options: options.clone() };
    let factor = options.supersample.max(1);
    let big = options.size * factor;

    // The truth, from the dabs of today's stroke (every variant places the same dabs).
    let (_, dabs, _, _) = scene.paint(Variant { hard_edges: HardEdges::SAMPLED })?;
    let spacing = median_spacing(&scene.document, &scene.bvh, &dabs);
    let base_big = scene.render(&scene.document)?;
    let rim_big = rim_distances(&scene.bvh, &scene.camera, big, &dabs);
    let truth = box_down(&truth_image(&base_big, &rim_big), factor);
    let rim = rim_distances(&scene.bvh, &scene.camera, options.size, &dabs);
    let band: Vec<bool> = rim.iter().map(|d| d.is_some_and(|d| d.abs() <= BAND_SPACINGS * spacing)).collect();
    let covered: Vec<bool> = rim.iter().map(Option::is_some).collect();
    let world_per_px = camera.world_per_pixel(f64::from(options.size));
    if let Some(dir) = &options.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| BrushEdgeError::Write { path: dir.display().to_string(), message: e.to_string() })?;
        save(&truth, dir, path, "truth")?;
    }

    let mut rows = Vec::new();
    for variant in variants(&options.raise_to) {
        let (painted, variant_dabs, seconds, faces_raised) = scene.paint(variant)?;
        let image = box_down(&scene.render(&painted)?, factor);
        if let Some(dir) = &options.out {
            save(&image, dir, path, &variant.name())?;
        }
        let psnr = |mask: &[bool]| {
            let db = psnr_over(&truth, &image, mask);
            if db.is_finite() { Some(db) } else { None }
        };
        let edge = crate::bench::trade::compare(&truth, &image, &band);
        let row = serde_json::json!({
            "bench": "brush-edge",
            "file": path.display().to_string(),
            "variant": variant.name(),
            "default": variant.hard_edges == HardEdges::default(),
            "raise_to": variant.hard_edges.raise_to.map(|r| r.get()),
            "spacings_per_radius": variant.hard_edges.spacings_per_radius,
            "antialias_spacings": variant.hard_edges.antialias_spacings,
            "resolution": options.resolution.get(),
            "edge_psnr_db": psnr(&band),
            "edge_mean_abs_error": mean_abs_error(&truth, &image, &band),
            "edge_pixels": edge.pixels,
            "edge_flip_mean": if edge.flip_mean.is_finite() { Some(edge.flip_mean) } else { None },
            "edge_max_error": edge.max_error_steps,
            "covered_psnr_db": psnr(&covered),
            "samples": painted.store.sample_count(),
            "samples_added": painted.store.sample_count().saturating_sub(scene.document.store.sample_count()),
            "faces_raised": faces_raised,
            "stroke_seconds": seconds,
            "dabs": variant_dabs.len(),
            "same_dabs": variant_dabs == dabs,
            "radius_px": options.radius_px,
            "spacing_px": spacing / world_per_px,
            "size": options.size,
            "supersample": factor,
            "zoom": options.zoom,
        });
        on_row(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// Writes `image` as `<dir>/edge_<model>_<name>.png`.
fn save(image: &RgbaImage, dir: &Path, model: &Path, name: &str) -> Result<(), BrushEdgeError> {
    let stem = model.file_stem().map_or("mesh".to_owned(), |s| s.to_string_lossy().to_lowercase());
    let file = dir.join(format!("edge_{stem}_{name}.png"));
    image.save(&file).map_err(|e| BrushEdgeError::Write { path: file.display().to_string(), message: e.to_string() })
}
