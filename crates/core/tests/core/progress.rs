//! Progress and cancel of a conversion (crates/core/src/progress.rs, issue 42): what the
//! sink sees advances monotonically from 0 to 1 through the phases in order, and a cancel
//! from the sink stops the conversion with `Cancelled`, for every content rule.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::ResolutionRule;
use meshpaint_core::convert::least_squares::BakeFit;
use meshpaint_core::io::document::{Document, DocumentError, OpenPhases};
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::progress::Reporter;

use crate::common::model;

fn rules() -> Vec<ResolutionRule> {
    let max = Resolution::new(32).unwrap();
    vec![
        ResolutionRule::Uniform(Resolution::new(8).unwrap()),
        ResolutionRule::TexelDensity { max },
        ResolutionRule::ErrorBound { bound: 0.03, max },
        ResolutionRule::Budget { samples: 20_000, max },
    ]
}

fn convert(rule: ResolutionRule, reporter: &Reporter) -> Result<Document, DocumentError> {
    let path = model("Duck/Duck.glb");
    let scene = import_gltf(&path).unwrap();
    let budget = Budget::from_environment();
    let phases = &mut OpenPhases::default();
    Document::from_scene_phased(scene, rule, BakeFit::LeastSquares, &path, &budget, phases, reporter.progress())
}

#[test]
fn a_conversion_reports_its_phases_in_order_and_ends_at_one() {
    for rule in rules() {
        let seen = Mutex::new(Vec::<(f32, String)>::new());
        let reporter = Reporter::new(|fraction, stage: &str| seen.lock().unwrap().push((fraction, stage.to_owned())));
        convert(rule, &reporter).unwrap();
        let seen = seen.lock().unwrap().clone();
        assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0), "{rule:?}: went back");
        assert_eq!(seen.first().map(|s| s.0), Some(0.0), "{rule:?}");
        assert_eq!(seen.last().map(|s| s.0), Some(1.0), "{rule:?}");
        // The fit reports faces done and the solve's iterations, after the rule's own phases.
        let first = |needle: &str| seen.iter().position(|(_, stage)| stage.contains(needle));
        let fit = first("fitting: reading the texture").unwrap_or_else(|| panic!("{rule:?}: no fit in {seen:?}"));
        let solve = first("fitting: solving").unwrap_or_else(|| panic!("{rule:?}: no solve"));
        assert!(fit < solve, "{rule:?}");
        if !matches!(rule, ResolutionRule::Uniform(_)) {
            let chosen = first("face resolutions chosen").unwrap_or_else(|| panic!("{rule:?}: no choice reported"));
            assert!(chosen > 0, "{rule:?}");
            if matches!(rule, ResolutionRule::Budget { .. }) {
                // The budget's allocation fits the whole mesh before the final bake does.
                assert!(fit < chosen, "{rule:?}");
            }
        }
        assert!(seen.len() > 20, "{rule:?}: only {} reports", seen.len());
    }
}

#[test]
fn cancelling_from_the_sink_stops_every_rule_with_cancelled() {
    for rule in rules() {
        for at in [0.0f32, 0.3, 0.6] {
            let flag = AtomicBool::new(false);
            let reports_after = Mutex::new(0usize);
            let reporter = Reporter::with_cancel_flag(
                |fraction, _: &str| {
                    if flag.load(Ordering::Relaxed) {
                        *reports_after.lock().unwrap() += 1;
                    }
                    if fraction >= at {
                        flag.store(true, Ordering::Relaxed);
                    }
                },
                &flag,
            );
            match convert(rule, &reporter) {
                Err(DocumentError::Cancelled { path }) => assert!(path.ends_with("Duck.glb")),
                other => panic!("{rule:?} cancelled at {at}: {:?}", other.map(|d| d.store.sample_count())),
            }
            // It stops at its next check: within a few reports, not at the end.
            let after = *reports_after.lock().unwrap();
            assert!(after < 20, "{rule:?} cancelled at {at}: {after} reports after the cancel");
        }
    }
}
