//! [`bench_trade`]: the study in order — choices, packs and MCTs, the views, seams, BVH.

use std::path::Path;
use std::time::Instant;

use super::bvh::bvh_rows;
use super::choices::{Choice, prepare, resolution_choices};
use super::metrics::merge;
use super::seams::{SeamEdges, SeamJump, htex_seam_jumps, mct_seam_jumps, ptex_seam_jumps, seam_jumps_over};
use super::study::{Study, views};
use super::{DISTANCES, TradeOptions};
use crate::bench::BenchRenderError;
use meshpaint_core::camera::BoundingSphere;
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_render::Gpu;

/// Runs the study on the file at `path` and returns its JSON rows: one `meta` row, one
/// `baseline` row per view (textured input), one `config` row per configuration
/// (representation, resolution, format, filter) and view, one `skipped` row per pack whose
/// MCT could not be made, `seam` rows per resolution choice, representation, filter and
/// level (MCT: per format too), one `bvh` row per preset. The stages: the resolution choices
/// ([`resolution_choices`]), their packs, MCTs and dabs ([`prepare`]), then per view the
/// references, interleaved frame times and errors ([`Study::view_rows`]), then seams and BVH
/// presets.
pub fn bench_trade(path: &Path, options: &TradeOptions) -> Result<Vec<serde_json::Value>, BenchRenderError> {
    bench_trade_streaming(path, options, &mut |_| {})
}

/// [`bench_trade`], giving each group of rows to `on_row` as soon as it is measured (the CLI
/// prints them then: a large asset takes minutes per view).
pub fn bench_trade_streaming(
    path: &Path,
    options: &TradeOptions,
    on_row: &mut dyn FnMut(&serde_json::Value),
) -> Result<Vec<serde_json::Value>, BenchRenderError> {
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
        "the same document at rgba32f, mesh colors linear level 0, 4x4 supersampled"
    };
    // Frame times are ratios to a UV-texture baseline: the file's own, else (a document
    // without texture) `bench render`'s synthetic planar one.
    let timing_baseline = match baseline {
        Some(mesh) => mesh,
        None => crate::bench::render::baseline(&gpu, path, &first.document)?.1,
    };
    let bounds =
        first.packs.first().map_or_else(|| BoundingSphere::of_points(&first.document.positions), |p| p.mesh.bounds);
    let face_count = first.document.store.topology().face_count();
    let representations: Vec<&str> =
        [(true, "mesh-colors"), (options.mct, "mct"), (options.ptex, "ptex"), (options.htex, "htex")]
            .into_iter()
            .filter_map(|(on, name)| on.then_some(name))
            .collect();
    let mut rows = vec![serde_json::json!({
        "bench": "trade", "kind": "meta", "file": file, "adapter": gpu.describe(),
        "size": options.size, "supersample": crate::bench::adaptive::SUPERSAMPLE, "views": options.views,
        "distances": DISTANCES.iter().map(|(n, f)| serde_json::json!({"view": n, "distance_factor": f})).collect::<Vec<_>>(),
        "frames": options.frames, "triangles": face_count, "reference": reference_name,
        "representations": representations,
        "convert_seconds_total": started.elapsed().as_secs_f64(),
    })];
    rows.extend(skipped_rows(&choices, &file, options));
    rows.iter().for_each(&mut *on_row);
    let mut emit = |rows: &mut Vec<serde_json::Value>, new: Vec<serde_json::Value>| {
        new.iter().for_each(&mut *on_row);
        rows.extend(new);
    };
    let study = Study { gpu: &gpu, choices: &choices, baseline: &timing_baseline, textured, file: &file, options };
    for view in views(bounds, options.views) {
        emit(&mut rows, study.view_rows(&view, face_count)?);
    }
    for choice in &choices {
        emit(&mut rows, seam_rows(choice, &file)?);
    }
    let mut bvh = bvh_rows(&first.document, bounds);
    for row in &mut bvh {
        merge(row, &serde_json::json!({"bench": "trade", "kind": "bvh", "file": file}));
    }
    emit(&mut rows, bvh);
    Ok(rows)
}

/// One `skipped` row per pack whose MCT was asked for but could not be built or uploaded.
fn skipped_rows(choices: &[Choice], file: &str, options: &TradeOptions) -> Vec<serde_json::Value> {
    let mut rows = Vec::new();
    for choice in choices {
        for packed in &choice.packs {
            let failures = [
                ("mct", options.mct, packed.mct.as_ref().err()),
                ("ptex", options.ptex, packed.ptex.as_ref().err()),
                ("htex", options.htex, packed.htex.as_ref().err()),
            ];
            for (representation, asked, failure) in failures {
                if let (true, Some(reason)) = (asked, failure) {
                    rows.push(serde_json::json!({
                        "bench": "trade", "kind": "skipped", "file": file, "representation": representation,
                        "resolution": choice.label, "format": packed.format.name(), "reason": reason,
                    }));
                }
            }
        }
    }
    rows
}

/// The seam rows of one choice: mesh colors over every edge with the reference sampler on
/// the RGBA32F pack (packed here when RGBA32F is not measured), then each format's MCT over
/// every edge with its CPU evaluation.
fn seam_rows(choice: &Choice, file: &str) -> Result<Vec<serde_json::Value>, BenchRenderError> {
    let mut rows = Vec::new();
    let mut push = |jumps: Vec<SeamJump>, representation: &str, format: ColorFormat| {
        for seam in jumps {
            let mut row = seam.to_json();
            merge(
                &mut row,
                &serde_json::json!({
                    "bench": "trade", "kind": "seam", "file": file, "resolution": choice.label,
                    "representation": representation, "format": format.name(),
                }),
            );
            rows.push(row);
        }
    };
    let rgba32f = match choice.packs.iter().find(|p| p.format == ColorFormat::Rgba32F) {
        Some(packed) => seam_jumps_over(&packed.packed, SeamEdges::Every),
        None => seam_jumps_over(&choice.document.pack(ColorFormat::Rgba32F)?, SeamEdges::Every),
    };
    push(rgba32f, "mesh-colors", ColorFormat::Rgba32F);
    for packed in &choice.packs {
        if let Ok(mct) = &packed.mct {
            push(mct_seam_jumps(&packed.packed, &mct.texture), "mct", packed.format);
        }
        if let Ok(htex) = &packed.htex {
            push(htex_seam_jumps(&packed.packed, &htex.texture), "htex", packed.format);
        }
        if let Ok(ptex) = &packed.ptex {
            push(ptex_seam_jumps(&packed.packed, &ptex.texture), "ptex", packed.format);
        }
    }
    Ok(rows)
}
