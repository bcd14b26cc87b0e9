//! The PSNR a conversion reports when it ends (`texture_psnr`, issue 42) against closed
//! forms: two separate triangles over a constant texture, each store sample moved by a known
//! step δ in every sRGB-encoded channel, show `−10·log10(Σ δ²·A / Σ A)` (A: world areas); the
//! conversion itself reports a lossless constant as lossless.

use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::{linear_to_srgb, srgb_to_linear};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::convert::adaptive::{ResolutionRule, texture_psnr};
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::weld::weld_scene;
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};
use meshpaint_core::progress::Reporter;

use crate::adaptive_extremes::{scene_of, texture_from};

/// The texel every face shows (sRGB-encoded RGB, alpha), and its value in 0..1.
const TEXEL: [u8; 4] = [60, 140, 200, 128];

/// Two triangles far apart (nothing welds), the second 9× the area of the first.
fn two_triangles() -> meshpaint_core::mesh::scene::Scene {
    let corners = [
        ([0.0, 0.0, 0.0], [0.1, 0.1]),
        ([1.0, 0.0, 0.0], [0.9, 0.1]),
        ([0.0, 1.0, 0.0], [0.1, 0.9]),
        ([10.0, 0.0, 0.0], [0.1, 0.1]),
        ([13.0, 0.0, 0.0], [0.9, 0.1]),
        ([10.0, 3.0, 0.0], [0.1, 0.9]),
    ];
    scene_of(&corners, texture_from(4, 4, |_, _| TEXEL))
}

#[test]
fn a_lossless_conversion_reports_lossless_and_known_steps_give_the_closed_form() {
    let scene = two_triangles();
    let rule = ResolutionRule::Uniform(Resolution::new(4).unwrap());
    let document =
        Document::from_scene_within(scene.clone(), rule, std::path::Path::new("two.glb"), &Budget::from_environment())
            .unwrap();
    let report = document.conversion.clone().expect("a mesh conversion reports");
    // A constant texture is reproduced within float rounding: lossless or above 100 dB.
    let db = report.texture_psnr_db.expect("the faces are textured");
    assert!(db > 100.0, "constant texture: {db} dB");
    assert!(report.summary().contains("against the texture"), "{}", report.summary());

    // Move every sample of face f by δ_f in every sRGB-encoded channel (alpha as is).
    let steps = [0.02f32, 0.005];
    let mut store = document.store.clone();
    let mut history = UndoHistory::new(1 << 30);
    history.begin_step(&store, "offset").unwrap();
    StoreWriter::new(&mut store, &mut history).fill_with(|site| {
        let delta = steps[site.face as usize];
        let mut color = [0.0f32; 4];
        for c in 0..3 {
            color[c] = srgb_to_linear(f32::from(TEXEL[c]) / 255.0 + delta);
        }
        color[3] = f32::from(TEXEL[3]) / 255.0 + delta;
        color
    });
    // Sanity of the construction, independently of the code under test.
    assert!((linear_to_srgb(srgb_to_linear(60.0 / 255.0 + 0.02)) - (60.0 / 255.0 + 0.02)).abs() < 1e-5);
    let mesh = weld_scene(&scene);
    let reporter = Reporter::silent();
    let db = texture_psnr(&store, &mesh, &scene, reporter.progress()).unwrap().unwrap();
    let areas = [0.5f64, 4.5];
    let mse = (areas[0] * f64::from(steps[0]).powi(2) + areas[1] * f64::from(steps[1]).powi(2)) / (areas[0] + areas[1]);
    let expected = -10.0 * mse.log10();
    assert!((db - expected).abs() < 0.01, "{db} dB, closed form {expected} dB");
    // Not the unweighted mean of the faces' errors: the area weighting is what is tested.
    let unweighted = -10.0 * ((f64::from(steps[0]).powi(2) + f64::from(steps[1]).powi(2)) / 2.0).log10();
    assert!((db - unweighted).abs() > 1.0, "{db} vs unweighted {unweighted}");
}
