//! One view of the study: the references, every configuration of both representations and
//! the baseline timed interleaved, each configuration rendered and compared — the `baseline`
//! and `config` rows.

use image::RgbaImage;

use super::choices::{Choice, HtexPack, Packed};
use super::metrics::{compare, error_json, median, merge};
use super::{DISTANCES, FILTERS, MCT_FILTERS, TradeOptions};
use crate::bench::BenchRenderError;
use crate::bench::adaptive::{Supersampled, render_supersampled};
use crate::bench::render::FrameTimer;
use meshpaint_core::camera::{BoundingSphere, OrbitCamera, default_camera};
use meshpaint_render::{BaselineMesh, DrawItem, FilterMode, Gpu, RenderSettings, Shading};

/// One camera of the study.
#[derive(Debug, Clone, Copy)]
pub(super) struct View {
    name: &'static str,
    direction: u32,
    distance_factor: f64,
    camera: OrbitCamera,
}

/// Every direction at every distance of [`DISTANCES`].
pub(super) fn views(bounds: BoundingSphere, directions: u32) -> Vec<View> {
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

/// A representation of the study's rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rep {
    MeshColors,
    Mct,
    Ptex,
    Htex,
}

impl Rep {
    fn name(self) -> &'static str {
        match self {
            Rep::MeshColors => "mesh-colors",
            Rep::Mct => "mct",
            Rep::Ptex => "ptex",
            Rep::Htex => "htex",
        }
    }
}

/// One configuration drawn in a view: a choice, one of its packs, the representation and
/// an index into [`FILTERS`] (mesh colors) or [`MCT_FILTERS`] (MCT, packed Ptex and Htex:
/// all hardware bilinear, a fixed level or two levels).
#[derive(Debug, Clone, Copy)]
struct Item {
    choice: usize,
    pack: usize,
    rep: Rep,
    filter: usize,
}

/// What every view of the study draws and compares.
pub(super) struct Study<'a> {
    pub(super) gpu: &'a Gpu,
    pub(super) choices: &'a [Choice],
    /// The UV-texture mesh frame times are divided by.
    pub(super) baseline: &'a BaselineMesh,
    pub(super) textured: bool,
    pub(super) file: &'a str,
    pub(super) options: &'a TradeOptions,
}

impl Study<'_> {
    /// Every (choice, pack, representation, filter) drawn in a view: the mesh-colors filters,
    /// then the MCT filters of each pack whose MCT was uploaded.
    fn items(&self) -> Vec<Item> {
        let mut items = Vec::new();
        for (choice, c) in self.choices.iter().enumerate() {
            for (pack, p) in c.packs.iter().enumerate() {
                items.extend((0..FILTERS.len()).map(|filter| Item { choice, pack, rep: Rep::MeshColors, filter }));
                let built = [(Rep::Mct, p.mct.is_ok()), (Rep::Ptex, p.ptex.is_ok()), (Rep::Htex, p.htex.is_ok())];
                for (rep, ok) in built {
                    if ok {
                        items.extend((0..MCT_FILTERS.len()).map(|filter| Item { choice, pack, rep, filter }));
                    }
                }
            }
        }
        items
    }

    fn packed(&self, item: Item) -> &Packed {
        &self.choices[item.choice].packs[item.pack]
    }

    fn draw_item(&self, item: Item) -> DrawItem<'_> {
        let packed = self.packed(item);
        match (item.rep, &packed.mct, &packed.ptex, &packed.htex) {
            (Rep::Mct, Ok(mct), _, _) => DrawItem::Mct(&mct.gpu),
            (Rep::Ptex, _, Ok(ptex), _) => DrawItem::Ptex(&ptex.gpu),
            (Rep::Htex, _, _, Ok(htex)) => DrawItem::Htex(&htex.gpu),
            _ => DrawItem::MeshColors(&packed.mesh),
        }
    }

    fn filter(item: Item) -> (&'static str, FilterMode) {
        if item.rep == Rep::MeshColors { FILTERS[item.filter] } else { MCT_FILTERS[item.filter] }
    }

    /// Median frame times in ms of the baseline and of every item, interleaved: each round
    /// times the baseline, then every item, the baseline again after every eight.
    fn frame_times(&self, view: &View, items: &[Item]) -> (f64, Vec<f64>) {
        let timer = FrameTimer::new(self.gpu, self.options.size, self.options.size);
        let time_item =
            |timer: &FrameTimer, item: Item| timer.frame(self.draw_item(item), Self::filter(item).1, view.camera);
        let time_baseline =
            |timer: &FrameTimer| timer.frame(DrawItem::Baseline(self.baseline), FilterMode::Linear, view.camera);
        time_baseline(&timer);
        for &item in items {
            time_item(&timer, item);
        }
        let mut baseline_times = Vec::new();
        let mut times: Vec<Vec<f64>> = vec![Vec::new(); items.len()];
        for _ in 0..self.options.frames.max(1) {
            for (k, &item) in items.iter().enumerate() {
                if k % 8 == 0 {
                    baseline_times.push(time_baseline(&timer));
                }
                times[k].push(time_item(&timer, item));
            }
        }
        (median(&mut baseline_times) * 1e3, times.iter_mut().map(|t| median(t) * 1e3).collect())
    }

    /// One supersampled reference per view (textured), or one per resolution choice.
    fn references(&self, settings: &RenderSettings) -> Result<Vec<Supersampled>, BenchRenderError> {
        let (gpu, size) = (self.gpu, self.options.size);
        let mut references = Vec::new();
        if self.textured {
            references.push(render_supersampled(gpu, DrawItem::Baseline(self.baseline), settings, size)?);
        } else {
            for mesh in self.choices.iter().filter_map(|c| c.reference.as_ref()) {
                references.push(render_supersampled(gpu, DrawItem::MeshColors(mesh), settings, size)?);
            }
        }
        Ok(references)
    }

    /// The `baseline` row (textured input) and the `config` rows of one view.
    pub(super) fn view_rows(&self, view: &View, face_count: u32) -> Result<Vec<serde_json::Value>, BenchRenderError> {
        let (gpu, size, file) = (self.gpu, self.options.size, self.file);
        let settings = unlit(view.camera, FilterMode::Linear);
        let references = self.references(&settings)?;
        let Some(first) = references.first() else {
            return Ok(Vec::new());
        };
        let reference_of = |c: usize| if self.textured { first } else { references.get(c).unwrap_or(first) };
        let items = self.items();
        let (baseline_ms, frame_ms) = self.frame_times(view, &items);
        let covered = first.interior.iter().filter(|&&x| x).count() as f64;
        let view_json = serde_json::json!({
            "view": view.name, "direction": view.direction, "distance_factor": view.distance_factor,
            "interior_pixels": covered, "pixels_per_face": covered / f64::from(face_count.max(1)),
        });
        let mut rows = Vec::new();
        if self.textured {
            // The baseline itself at the image size: the error floor of texture filtering.
            let native = gpu.render_image(DrawItem::Baseline(self.baseline), &settings, size, size)?;
            let mut row = error_json(&compare(&first.image, &native, &mask_for(first, &native)));
            merge(&mut row, &view_json);
            merge(
                &mut row,
                &serde_json::json!({
                    "bench": "trade", "kind": "baseline", "file": file, "representation": "uv-texture",
                    "filter": "baseline-uv", "gpu_bytes": self.baseline.gpu_bytes(), "frame_ms": baseline_ms,
                    "frame_ratio": 1.0,
                }),
            );
            rows.push(row);
        }
        for (k, &item) in items.iter().enumerate() {
            let image =
                gpu.render_image(self.draw_item(item), &unlit(view.camera, Self::filter(item).1), size, size)?;
            let reference = reference_of(item.choice);
            let mut row = error_json(&compare(&reference.image, &image, &mask_for(reference, &image)));
            merge(&mut row, &view_json);
            merge(&mut row, &self.config_json(item));
            merge(
                &mut row,
                &serde_json::json!({
                    "frame_ms": frame_ms[k], "baseline_frame_ms": baseline_ms, "frame_ratio": frame_ms[k] / baseline_ms,
                }),
            );
            rows.push(row);
        }
        Ok(rows)
    }

    /// The columns of a `config` row that do not depend on the view: what was drawn and what
    /// it costs besides frame time.
    fn config_json(&self, item: Item) -> serde_json::Value {
        let (choice, packed) = (&self.choices[item.choice], self.packed(item));
        let resolutions = choice.document.store.face_resolutions();
        let mut row = serde_json::json!({
            "bench": "trade", "kind": "config", "file": self.file,
            "representation": item.rep.name(),
            "filter": Self::filter(item).0, "resolution": choice.label, "error_bound": choice.error_bound,
            "resolution_min": resolutions.iter().map(|r| r.get()).min(),
            "resolution_max": resolutions.iter().map(|r| r.get()).max(),
            "format": packed.format.name(),
            "samples": choice.document.store.sample_count(),
            "samples_with_mips": packed.packed.sample_count(),
            "geometry_bytes": packed.geometry_bytes(),
            "mesh_colors_bytes": packed.mesh_colors_bytes(),
            "pack_seconds": packed.pack_seconds,
            "convert_seconds": choice.convert_seconds,
        });
        let more = match (item.rep, &packed.mct, &packed.ptex, &packed.htex) {
            (Rep::Htex, _, _, Ok(htex)) => htex_json(packed, htex),
            (Rep::Ptex, _, Ok(ptex), _) => ptex_json(packed, ptex),
            (Rep::Mct, Ok(mct), _, _) => serde_json::json!({
                "gpu_bytes": packed.geometry_bytes() + mct.gpu.gpu_bytes(),
                "color_gpu_bytes": mct.gpu.gpu_bytes(),
                "mct_bytes": mct.texture.gpu_bytes(),
                "mct_bytes_over_mesh_colors": mct.texture.gpu_bytes() as f64 / packed.mesh_colors_bytes().max(1) as f64,
                "mct_build_seconds": mct.build_seconds,
                "mct_atlas": [mct.texture.layout.width, mct.texture.layout.height],
                "mct_levels": mct.texture.layout.levels,
                "mct_clamped_ring_texels": mct.texture.stats.clamped_ring_texels,
                "mct_max_ring_clamp": mct.texture.stats.max_ring_clamp,
            }),
            _ => serde_json::json!({
                "gpu_bytes": packed.mesh.gpu_bytes(),
                "color_gpu_bytes": packed.mesh.atlas_bytes() + packed.mesh.face_record_bytes(),
                "dab_samples_per_second": choice.dab.get("samples_per_second_median"),
                "dab_samples": choice.dab.get("samples_covered"),
                "dab_seconds": choice.dab.get("dab_seconds_median"),
            }),
        };
        merge(&mut row, &more);
        row
    }
}

/// The Htex columns of a `config` row: bytes (pages + tables; the pages' texels the colours
/// need, without borders and free space), the paper's E/F texture count, build time, the
/// largest colour jump at level 0 across intrinsic edges (corner texels equalised).
fn htex_json(packed: &Packed, htex: &HtexPack) -> serde_json::Value {
    let (e, f) = htex.texture.texture_count();
    let layout = &htex.texture.layout;
    let bpp = htex.texture.format.bytes_per_sample() as u64;
    serde_json::json!({
        "gpu_bytes": packed.geometry_bytes() + htex.gpu.gpu_bytes(),
        "color_gpu_bytes": htex.gpu.gpu_bytes(),
        "htex_bytes": htex.texture.gpu_bytes(),
        "htex_inside_texel_bytes": layout.inside_texels() * bpp,
        "htex_bytes_over_mesh_colors": htex.texture.gpu_bytes() as f64 / packed.mesh_colors_bytes().max(1) as f64,
        "htex_build_seconds": htex.build_seconds,
        "htex_textures": e, "htex_faces": f, "htex_e_over_f": e as f64 / f.max(1) as f64,
        "htex_pages": [layout.page_size, layout.page_height, layout.pages],
        "htex_levels": layout.levels,
    })
}

/// The packed Ptex columns of a `config` row: bytes (GPU, and over the packed mesh colors),
/// where its texels go (the blocks' own, borders, unused: the paper's ~8 % packing and ~10 %
/// border anchors are `ptex_unused_over_interior` and `ptex_border_over_interior`) and the
/// build time.
fn ptex_json(packed: &Packed, ptex: &super::choices::PtexPack) -> serde_json::Value {
    let t = &ptex.texture;
    let interior = t.stats.interior_texels.max(1) as f64;
    serde_json::json!({
        "gpu_bytes": packed.geometry_bytes() + ptex.gpu.gpu_bytes(),
        "color_gpu_bytes": ptex.gpu.gpu_bytes(),
        "ptex_bytes": t.gpu_bytes(),
        "ptex_bytes_over_mesh_colors": t.gpu_bytes() as f64 / packed.mesh_colors_bytes().max(1) as f64,
        "ptex_build_seconds": ptex.build_seconds,
        "ptex_texture": [t.layout.width, t.layout.height],
        "ptex_blocks": t.layout.blocks.len(),
        "ptex_lone_blocks": t.layout.blocks.iter().filter(|b| !b.paired).count(),
        "ptex_levels": t.layout.levels,
        "ptex_interior_texels": t.stats.interior_texels,
        "ptex_border_texels": t.stats.border_texels(),
        "ptex_unused_texels": t.unused_texels(),
        "ptex_border_over_interior": t.stats.border_texels() as f64 / interior,
        "ptex_unused_over_interior": t.unused_texels() as f64 / interior,
        "ptex_resampled_border_texels": t.stats.resampled_border_texels,
        "ptex_unfolded_border_texels": t.stats.unfolded_border_texels,
    })
}

/// The pixels compared: all 16 subsamples of the reference covered, and the test covers the pixel.
fn mask_for(reference: &Supersampled, test: &RgbaImage) -> Vec<bool> {
    reference.interior.iter().zip(test.pixels()).map(|(&inside, p)| inside && p.0[3] > 0).collect()
}
