//! The large-face detail asset (issue 42): the truck's logo lies on two triangles that span
//! a whole box side, so a face needs R in the thousands where the rest of the truck needs
//! R ≤ 8. Seen up close (one pixel about one texel), the content rules at their defaults —
//! no `--max-resolution` — must show the logo at ≥ 35 dB against the UV-textured render,
//! with at most a tenth of the samples any uniform R showing as much would need: every
//! uniform R with up to ten times the rule's samples shows less. Measured by `bench
//! adaptive`'s supersampled reference, from a close-up camera on the region `synth` names.

use meshpaint::bench::adaptive::{AdaptiveOptions, CloseUp, bench_adaptive};
use meshpaint_core::colors::budget::{Budget, SampleCounts};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::convert::least_squares::BakeFit;
use meshpaint_core::io::document::Document;
use meshpaint_core::synth::production::{AssetClass, Options, generate};

#[test]
fn the_truck_logo_up_close_is_sharp_with_a_tenth_of_the_uniform_samples() {
    let asset = generate(AssetClass::Truck, Options { triangles: Some(800), texture_size: Some(256) }).unwrap();
    let logo = asset.regions.iter().find(|r| r.name == "logo").unwrap();
    assert_eq!(logo.normal, [0.0, 0.0, 1.0], "the camera below looks at the +z side");
    // The region fills the view: 40° vertical field of view.
    let extent = f64::from(logo.size[0].max(logo.size[1]));
    let distance = extent / 2.0 / 20f64.to_radians().tan();
    let options = AdaptiveOptions {
        budget_max: None,
        size: 128,
        views: 1,
        supersample: 4,
        fits: vec![BakeFit::LeastSquares],
        close_up: Some(CloseUp { target: logo.center.map(f64::from), distance, yaw_degrees: 0.0, pitch_degrees: 0.0 }),
    };
    let path = std::path::Path::new("truck.glb");
    let rule = ResolutionRule::ErrorBound { bound: 0.02, max: Resolution::MAX };
    let rows = bench_adaptive(path, &asset.scene, &[rule], &options, &mut |_| {}).unwrap();
    let (samples, db) = (rows[0].samples, rows[0].psnr_db[0]);
    eprintln!("error ≤ 0.02: {samples} samples, {db:.2} dB, R up to {}", rows[0].resolution_range.1);
    assert!(db >= 35.0, "the logo up close: {db:.2} dB");
    assert!(rows[0].resolution_range.1 > 64, "a face past the old cap of 64: {:?}", rows[0].resolution_range);
    // Every uniform R with at most ten times the samples shows less: the finest two of them
    // are rendered (the coarser ones show less still), their counts from the topology.
    let topology = Document::from_scene_within(asset.scene.clone(), Resolution::ONE, path, &Budget::from_environment())
        .unwrap()
        .store
        .topology()
        .clone();
    let within: Vec<Resolution> = (0..=Resolution::MAX.log2())
        .map(|log2| Resolution::from_log2(log2).unwrap())
        .take_while(|&r| SampleCounts::uniform_on(&topology, r).samples <= 10 * samples)
        .collect();
    assert!(within.len() >= 5, "uniform R within ten times the samples: {within:?}");
    let finest: Vec<ResolutionRule> = within.iter().rev().take(2).map(|&r| ResolutionRule::Uniform(r)).collect();
    let rows = bench_adaptive(path, &asset.scene, &finest, &options, &mut |_| {}).unwrap();
    for row in &rows {
        eprintln!("{}: {} samples, {:.2} dB", row.rule.describe(), row.samples, row.psnr_db[0]);
        assert!(row.psnr_db[0] < db, "{} shows {:.2} dB ≥ {db:.2}", row.rule.describe(), row.psnr_db[0]);
    }
}
