//! `meshpaint bench brush-edge` (issue 43, "hard edges"): a hard stroke on a close-up of the
//! Duck at R = 8 against the ideal stroke, computed independently of the brush code (the dabs'
//! world-space spheres intersected with the surface by ray casts, 4 × 4 subsamples a pixel).
//! Hard brushes' default (raise the faces under them) brings the stroke's rim within 30 dB of
//! the truth; the rim as sampled before (every sample inside the sphere, none outside), which
//! looked ragged in close-up, does not get there. Speed is not asserted.

use crate::common;
use common::model;

#[test]
fn a_hard_stroke_at_the_default_settings_has_a_rim_close_to_the_ideal_one() {
    let input = model("Duck/Duck.glb");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["bench", "brush-edge", input.to_str().unwrap(), "--size", "160", "--supersample", "4"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: Vec<serde_json::Value> =
        String::from_utf8(out.stdout).unwrap().lines().map(|line| serde_json::from_str(line).unwrap()).collect();
    let row = |name: &str| rows.iter().find(|row| row["variant"] == name).unwrap_or_else(|| panic!("no {name} row"));
    let db = |row: &serde_json::Value| row["edge_psnr_db"].as_f64().unwrap();
    // Every variant places the same dabs (the truth's), on the same band of pixels.
    assert!(rows.len() >= 6);
    assert!(rows.iter().all(|row| row["same_dabs"] == true && row["edge_pixels"].as_u64().unwrap() > 500));

    let default: Vec<&serde_json::Value> = rows.iter().filter(|row| row["default"] == true).collect();
    assert_eq!(default.len(), 1, "one row is the painter's default");
    let (default, sampled) = (default[0], row("sampled"));
    assert!(db(default) >= 30.0, "the default hard rim: {:.2} dB", db(default));
    assert!(db(sampled) < 30.0, "the sampled rim: {:.2} dB", db(sampled));
    assert!(default["edge_mean_abs_error"].as_f64().unwrap() < sampled["edge_mean_abs_error"].as_f64().unwrap());
    // It paid for that with samples, within the budget, only where the stroke went.
    assert_eq!(sampled["samples_added"], 0);
    let faces_raised = default["faces_raised"].as_u64().unwrap();
    assert!(faces_raised > 0 && faces_raised < 4212 / 4, "{faces_raised} of the Duck's 4 212 faces raised");
}
