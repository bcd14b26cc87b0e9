//! Per-face resolution from the content (crates/core/src/convert/adaptive.rs), checked independently: the
//! error at random points of each face against the texture read by this test's own bilinear
//! lookup, the budget against the store's own sample count, texel density against its
//! closed form; the budget's goal against the UV-textured render of the source (the GPU's
//! own texture sampling), as `meshpaint bench adaptive` measures it.

use crate::common;

use common::{Rng, model};
use meshpaint::bench::adaptive::{ADAPTIVE_SUPERSAMPLE, AdaptiveOptions, bench_adaptive};
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::{linear_to_srgb, srgb_to_linear};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::convert::least_squares::BakeFit;
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::scene::{Scene, Texture};
use meshpaint_core::mesh::weld::weld_scene;
use meshpaint_core::packing::sampler::{Filter, sample};

fn r(value: u32) -> Resolution {
    Resolution::new(u64::from(value)).unwrap()
}

fn convert(scene: &Scene, rule: ResolutionRule) -> Document {
    Document::from_scene_within(scene.clone(), rule, std::path::Path::new("test.glb"), &Budget::from_environment())
        .unwrap()
}

/// The texture's level 0 at `uv`, bilinear with REPEAT, in linear light (glTF conventions,
/// written here from the spec, not taken from the crate).
fn bilinear(texture: &Texture, uv: [f32; 2]) -> [f32; 4] {
    let (w, h) = (texture.width as i64, texture.height as i64);
    let x = f64::from(uv[0]) * w as f64 - 0.5;
    let y = f64::from(uv[1]) * h as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |xi: i64, yi: i64| {
        let (xi, yi) = (xi.rem_euclid(w) as usize, yi.rem_euclid(h) as usize);
        let p = &texture.rgba8_srgb[(yi * w as usize + xi) * 4..][..4];
        [
            srgb_to_linear(f32::from(p[0]) / 255.0),
            srgb_to_linear(f32::from(p[1]) / 255.0),
            srgb_to_linear(f32::from(p[2]) / 255.0),
            f32::from(p[3]) / 255.0,
        ]
    };
    let mut out = [0.0f32; 4];
    for (dx, dy, weight) in
        [(0, 0, (1.0 - fx) * (1.0 - fy)), (1, 0, fx * (1.0 - fy)), (0, 1, (1.0 - fx) * fy), (1, 1, fx * fy)]
    {
        let t = texel(x0 as i64 + dx, y0 as i64 + dy);
        for c in 0..4 {
            out[c] += weight as f32 * t[c];
        }
    }
    out
}

/// Per-face RMS error (sRGB-encoded RGB and alpha) at `points` random points.
fn face_errors(scene: &Scene, document: &Document, points: usize) -> Vec<f32> {
    let welded = weld_scene(scene);
    let mut rng = Rng(0xada9);
    (0..document.store.topology().face_count())
        .map(|face| {
            let material =
                welded.triangle_materials[face as usize].and_then(|m| scene.materials.get(m as usize)).unwrap();
            let texture = &scene.textures[material.base_color_texture.unwrap() as usize];
            let uvs = welded.corner_uvs[face as usize];
            let mut sum = 0.0f64;
            for _ in 0..points {
                let (mut u, mut v) = (rng.unit(), rng.unit());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let b = [1.0 - u - v, u, v];
                let uv = [0, 1].map(|a| (0..3).map(|k| b[k] * uvs[k][a]).sum::<f32>());
                let t = bilinear(texture, uv);
                let truth: [f32; 4] = std::array::from_fn(|c| material.base_color_factor[c] * t[c]);
                let shown = sample(&document.store, face, b, Filter::Linear, 0).unwrap();
                for c in 0..4 {
                    let (a, e) =
                        if c < 3 { (linear_to_srgb(shown[c]), linear_to_srgb(truth[c])) } else { (shown[c], truth[c]) };
                    sum += f64::from(a - e).powi(2);
                }
            }
            (sum / (4 * points) as f64).sqrt() as f32
        })
        .collect()
}

#[test]
fn error_bound_holds_on_every_face_below_the_cap_and_tighter_bounds_cost_more() {
    let scene = import_gltf(&model("Duck/Duck.glb")).unwrap();
    let mut previous_samples = 0;
    for bound in [0.05f32, 0.02, 0.005] {
        let document = convert(&scene, ResolutionRule::ErrorBound { bound, max: r(64) });
        let errors = face_errors(&scene, &document, 64);
        let resolutions = document.store.face_resolutions();
        // A face's cap: `max`, or two samples a texel along its longest UV edge (at least 8),
        // past which no R removes more than rounding (crates/core/src/convert/adaptive).
        let caps = content_caps(&scene, 64);
        let below_cap: Vec<f32> = (errors.iter().zip(resolutions).zip(&caps))
            .filter(|((_, res), cap)| res.get() < **cap)
            .map(|((e, _), _)| *e)
            .collect();
        let worst = below_cap.iter().copied().fold(0.0f32, f32::max);
        let over = below_cap.iter().filter(|&&e| e > bound * 1.5).count();
        eprintln!(
            "E = {bound}: {} samples, {} of {} faces below the cap, worst random-point RMS {worst:.4}, {over} over 1.5 E",
            document.store.sample_count(),
            below_cap.len(),
            errors.len()
        );
        // The bound holds at the fit's test points; random points are another sample of the
        // same face. When the test points ignored R (a lattice of 8 on faces under a texel),
        // 0.5–1.1 % of the Duck's faces read over 1.5 E here (the strip of foreign colours
        // along a UV seam, 1/R wide, held no test point; docs/ADAPTIVE.md); with test points
        // at least 2R per side, 0–7 faces (≤ 0.17 %) do, seen over several runs (the points
        // are random). This fails at the old share.
        assert!(over * 400 <= below_cap.len(), "E = {bound}: {over} faces over 1.5 E");
        assert!(document.store.sample_count() > previous_samples, "a tighter bound must not cost less");
        previous_samples = document.store.sample_count();
    }
}

/// Each face's longest UV edge in texels of its base-colour texture (0 without one).
fn longest_uv_edges(scene: &Scene) -> Vec<f64> {
    let welded = weld_scene(scene);
    (0..welded.triangles.len())
        .map(|face| {
            let material = welded.triangle_materials[face].and_then(|m| scene.materials.get(m as usize));
            let Some(texture) = material.and_then(|m| m.base_color_texture).map(|t| &scene.textures[t as usize]) else {
                return 0.0;
            };
            let uvs = welded.corner_uvs[face];
            (0..3)
                .map(|k| {
                    let (a, b) = (uvs[k], uvs[(k + 1) % 3]);
                    let du = f64::from(b[0] - a[0]) * f64::from(texture.width);
                    let dv = f64::from(b[1] - a[1]) * f64::from(texture.height);
                    (du * du + dv * dv).sqrt()
                })
                .fold(0.0f64, f64::max)
        })
        .collect()
}

/// Each face's content cap (the module docs' closed form): `2 · T`, `T` the smallest power
/// of two ≥ its longest UV edge in texels, at least 8, at most `max`.
fn content_caps(scene: &Scene, max: u32) -> Vec<u32> {
    let power = |x: f64| (x.ceil().max(1.0) as u32).next_power_of_two();
    longest_uv_edges(scene).iter().map(|&longest| (2 * power(longest)).max(8).min(max)).collect()
}

#[test]
fn a_sample_budget_is_never_crossed_and_spends_where_the_texture_varies() {
    let scene = import_gltf(&model("Duck/Duck.glb")).unwrap();
    let uniform = convert(&scene, ResolutionRule::Uniform(r(8)));
    let uniform_errors = face_errors(&scene, &uniform, 32);
    let uniform_rms =
        (uniform_errors.iter().map(|e| f64::from(*e).powi(2)).sum::<f64>() / uniform_errors.len() as f64).sqrt();
    for samples in [2108u64, 5000, 20_000, 44_928, 150_000] {
        let document = convert(&scene, ResolutionRule::Budget { samples, max: r(64) });
        assert!(document.store.sample_count() <= samples, "{} > {samples}", document.store.sample_count());
        let resolutions = document.store.face_resolutions();
        eprintln!(
            "budget {samples}: {} samples, R {}..{}",
            document.store.sample_count(),
            resolutions.iter().map(|x| x.get()).min().unwrap(),
            resolutions.iter().map(|x| x.get()).max().unwrap()
        );
    }
    // A third of uniform R = 8's samples, allocated by content, is no worse on average (RMS
    // over faces at random points) than uniform R = 8.
    let third = convert(&scene, ResolutionRule::Budget { samples: uniform.store.sample_count() / 3, max: r(64) });
    let errors = face_errors(&scene, &third, 32);
    let rms = (errors.iter().map(|e| f64::from(*e).powi(2)).sum::<f64>() / errors.len() as f64).sqrt();
    eprintln!("uniform R = 8: face RMS {uniform_rms:.5}; a third of its samples by budget: {rms:.5}");
    assert!(rms <= uniform_rms * 1.25, "{rms} vs {uniform_rms}");
}

/// Area-weighted RMS over faces of the per-face random-point errors.
fn area_weighted_rms(scene: &Scene, errors: &[f32]) -> f64 {
    let welded = weld_scene(scene);
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| glam::Vec3::from(welded.positions_world[i as usize]));
        f64::from((b - a).cross(c - a).length())
    };
    let (sum, total) = welded
        .triangles
        .iter()
        .zip(errors)
        .fold((0.0, 0.0), |(s, w), (t, e)| (s + area(t) * f64::from(*e).powi(2), w + area(t)));
    (sum / total).sqrt()
}

/// The least-squares fit shares samples between neighbours, so a budget allocation that
/// predicted each face's error from its own point bake spent a third of Fox's uniform R = 8
/// samples 12 % worse than uniform R = 8 (area-weighted RMS at random points against the
/// texture: 0.0352 vs 0.0314); calibrated on fitted stores it comes within 0.5 % (0.0315).
/// Within 5 % fails the old prediction. (The points are seeded, so the run is repeatable.)
#[test]
fn a_third_of_uniform_r8_samples_by_budget_comes_within_5_percent_of_uniform_r8_on_the_fox() {
    let scene = import_gltf(&model("Fox/Fox.glb")).unwrap();
    let uniform = convert(&scene, ResolutionRule::Uniform(r(8)));
    let samples = uniform.store.sample_count() / 3;
    let budget = convert(&scene, ResolutionRule::Budget { samples, max: r(64) });
    assert!(budget.store.sample_count() <= samples);
    let uniform_rms = area_weighted_rms(&scene, &face_errors(&scene, &uniform, 64));
    let budget_rms = area_weighted_rms(&scene, &face_errors(&scene, &budget, 64));
    eprintln!(
        "Fox: uniform R = 8 area RMS {uniform_rms:.5}; budget {} samples, area RMS {budget_rms:.5}",
        budget.store.sample_count()
    );
    assert!(budget_rms <= uniform_rms * 1.05, "{budget_rms} vs {uniform_rms}");
}

/// The goal's own measure (`bench adaptive`: PSNR of the RGBA8 linear-filter render against
/// the UV-textured render of the source, 3 views, 16×16 supersampled) at a third of uniform
/// R = 4's samples on the Fox (1,536, between R = 2's 1,154 and R = 4's 4,610). Allocated once
/// from predictions measured on uniform stores, the budget showed 27.8 dB against R = 4's
/// 28.1: in the mixed store a coarse face fans towards finer edges and the fit balances
/// shared samples between faces of different R. With the rounds that measure each allocation
/// on its fitted store and correct the predictions (`REFINEMENT_ROUNDS`) it shows 28.6 dB.
/// (Area-weighted over every face at random points against level 0, a measure the views do
/// not weight alike, the budget stays 6 % above R = 4's RMS error: 0.0502 vs 0.0473, 0.0509
/// allocated once.)
#[test]
fn a_third_of_uniform_r4_samples_by_budget_beats_uniform_r4_on_the_fox_in_the_render() {
    let path = model("Fox/Fox.glb");
    let scene = import_gltf(&path).unwrap();
    let options = AdaptiveOptions {
        budget_max: Some(r(64)),
        size: 256,
        views: 3,
        supersample: ADAPTIVE_SUPERSAMPLE,
        fits: vec![BakeFit::LeastSquares],
        close_up: None,
    };
    let mut streamed = Vec::new();
    let rows =
        bench_adaptive(&path, &scene, &[ResolutionRule::Uniform(r(4))], &options, &mut |row| streamed.push(row.rule))
            .unwrap();
    // Each row reaches the caller as it is measured (the CLI prints it then), in order.
    assert_eq!(streamed, rows.iter().map(|row| row.rule).collect::<Vec<_>>());
    // The budget row's phases: the rule's own phases took part of the conversion, never more.
    let phases = rows[1].phases;
    let rule_phases = phases.rule.calibrate + phases.rule.predict + phases.rule.allocate;
    assert!(rule_phases > std::time::Duration::ZERO && rule_phases + phases.bake <= phases.store, "{phases:?}");
    let [budget, uniform] = [ResolutionRule::Budget { samples: 4610 / 3, max: r(64) }, ResolutionRule::Uniform(r(4))]
        .map(|rule| rows.iter().find(|row| row.rule == rule).unwrap());
    let mean = |psnr: &[f64]| psnr.iter().sum::<f64>() / psnr.len() as f64;
    eprintln!(
        "Fox: uniform R = 4, {} samples: {:.2} dB; budget, {} samples: {:.2} dB",
        uniform.samples,
        mean(&uniform.psnr_db),
        budget.samples,
        mean(&budget.psnr_db)
    );
    assert_eq!(uniform.samples, 4610);
    assert!(budget.samples <= 4610 / 3);
    assert!(mean(&budget.psnr_db) > mean(&uniform.psnr_db), "{:?} vs {:?}", budget.psnr_db, uniform.psnr_db);
}

/// A budget that uniform R = 4 leaves unfilled on BoxTextured (98 of 128 samples) is spent
/// on raising faces whose best (larger) raise does not fit: one face to R = 8 adds 30
/// samples. An allocation that gave up on a face whose best raise was too large, or that
/// charged a sample for raises adding none, stopped at 98.
#[test]
fn a_budget_is_filled_by_smaller_raises_when_the_best_one_does_not_fit() {
    let scene = import_gltf(&model("BoxTextured/BoxTextured.glb")).unwrap();
    let uniform = convert(&scene, ResolutionRule::Uniform(r(4))).store.sample_count();
    let budget = convert(&scene, ResolutionRule::Budget { samples: 128, max: r(64) });
    let used = budget.store.sample_count();
    eprintln!("BoxTextured: uniform R = 4 holds {uniform} samples; a budget of 128 uses {used}");
    assert!(used <= 128);
    assert!(used > uniform, "{used} samples, uniform R = 4 holds {uniform}");
}

#[test]
fn texel_density_follows_the_closed_form_and_untextured_faces_stay_at_one() {
    let scene = import_gltf(&model("BoxTextured/BoxTextured.glb")).unwrap();
    let document = convert(&scene, ResolutionRule::TexelDensity { max: r(4096) });
    let welded = weld_scene(&scene);
    for (face, res) in document.store.face_resolutions().iter().enumerate() {
        let material = welded.triangle_materials[face].and_then(|m| scene.materials.get(m as usize)).unwrap();
        let texture = &scene.textures[material.base_color_texture.unwrap() as usize];
        let uvs = welded.corner_uvs[face];
        // One sample per texel covered: R²/2 samples on a face of A texels of UV area; of
        // the powers of two around √(2A), the one whose R²/2 is nearer A.
        let [w, h] = [f64::from(texture.width), f64::from(texture.height)];
        let d = |k: usize| [f64::from(uvs[k][0] - uvs[0][0]) * w, f64::from(uvs[k][1] - uvs[0][1]) * h];
        let area = 0.5 * (d(1)[0] * d(2)[1] - d(2)[0] * d(1)[1]).abs();
        let want = [1u64, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096]
            .into_iter()
            .min_by(|&a, &b| {
                let off = |r: u64| ((r * r) as f64 / 2.0 - area).abs();
                off(a).total_cmp(&off(b)).then(a.cmp(&b))
            })
            .unwrap();
        assert_eq!(u64::from(res.get()), want, "face {face}: {area} texels of UV area");
    }
    // A material without a texture holds one constant: R = 1 under every content rule.
    let mut flat = scene.clone();
    for material in &mut flat.materials {
        material.base_color_texture = None;
        material.base_color_factor = [0.2, 0.5, 0.7, 1.0];
    }
    for rule in [
        ResolutionRule::TexelDensity { max: r(64) },
        ResolutionRule::ErrorBound { bound: 0.0, max: r(64) },
        ResolutionRule::Budget { samples: 1 << 20, max: r(64) },
    ] {
        let document = convert(&flat, rule);
        assert!(document.store.face_resolutions().iter().all(|x| x.get() == 1), "{rule:?}");
    }
}

#[test]
fn bench_adaptive_rules_parse_as_the_cli_documents_them() {
    use meshpaint::bench::adaptive::parse_rule;
    let max = r(256);
    assert_eq!(parse_rule("uniform:16", max), Ok(ResolutionRule::Uniform(r(16))));
    assert_eq!(parse_rule("texel-density", max), Ok(ResolutionRule::TexelDensity { max }));
    assert_eq!(parse_rule("error:0.01", max), Ok(ResolutionRule::ErrorBound { bound: 0.01, max }));
    assert_eq!(parse_rule("samples:20000", max), Ok(ResolutionRule::Budget { samples: 20_000, max }));
    for bad in
        ["uniform:3", "uniform:x", "error:-1", "error:nan", "samples:0", "samples:1.5", "texel-density:2", "blur"]
    {
        let err = parse_rule(bad, max).unwrap_err();
        assert!(err.contains(bad), "{bad}: {err}");
    }
}
