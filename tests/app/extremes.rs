//! `meshpaint bench extremes` (src/bench/extremes/): runs the real binary, parses every
//! JSON row, and enforces each case's tolerance from this file's own table — so a bench
//! that loosened its reported tolerance, dropped a case or stopped measuring fails here.
//! The truths behind the numbers (f64 ray casts, the CPU reference sampler, closed-form
//! discs, the unoffset mesh) are documented in the bench module.
//!
//! GPU: fails (never skips) without an adapter.

/// Every case the bench must report, with the largest error this test accepts.
const TOLERANCES: &[(&str, f64)] = &[
    // GPU − CPU reference at the f64 ray-cast hit, 8-bit steps (tests/app/gpu_render.rs MAX_STEPS:
    // the rounding of the sRGB8 encode, 1 step).
    ("r4096_perspective_linear", 1.0),
    ("r4096_perspective_nearest", 1.0),
    // Lattice units: a pixel may read the neighbouring sample only this close to a cell boundary
    // (tests/app/gpu_render.rs CELL_MARGIN).
    ("shader_index_precision_r4096", 1e-3),
    ("offset_1e5_render", 1.0),
    ("offset_1e6_render", 1.0),
    ("scale_1e-4_render", 1.0),
    // Ulps along the normal: vertex rounding to f32 moves a surface by at most √3/2 ulp.
    ("offset_1e5_pick", 0.9160254037844386),
    ("offset_1e6_pick", 0.9160254037844386),
    ("scale_1e-4_pick", 0.9160254037844386),
    // Samples painted differently from the unoffset mesh, outside the rim band.
    ("offset_1e5_paint", 0.0),
    ("offset_1e6_paint", 0.0),
    ("scale_1e-4_paint", 0.0),
    ("sliver_render", 1.0),
    ("sliver_pick", 0.0),
    ("valence_200_render", 1.0),
    ("valence_200_pick", 0.0),
    ("grazing_brush_60deg", 0.0),
    ("grazing_brush_80deg", 0.0),
    ("grazing_brush_85deg", 0.0),
    ("grazing_brush_88deg", 0.0),
    ("rgba16f_max_finite_decode", 0.0),
    ("rgba16f_max_finite_render", 0.0),
    // binary16 keeps 11 significant bits: round to nearest is within 2^-11 relative.
    ("add_blend_hdr_rgba16f", 0.00048828125),
    ("non_finite_colors", 0.0),
];

#[test]
fn bench_extremes_reports_every_case_within_its_tolerance() {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["bench", "extremes", "--json"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let rows: Vec<serde_json::Value> =
        stdout.lines().map(|line| serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"))).collect();
    let mut failures = Vec::new();
    for row in &rows {
        eprintln!("{row}");
        for key in ["case", "measured", "unit", "tolerance", "test", "outcome", "sound", "detail"] {
            assert!(row.get(key).is_some(), "{key} missing: {row}");
        }
    }
    for &(case, tolerance) in TOLERANCES {
        let Some(row) = rows.iter().find(|row| row["case"] == case) else {
            failures.push(format!("{case}: not reported"));
            continue;
        };
        let measured = row["measured"].as_f64().unwrap();
        if measured.is_nan() || measured > tolerance {
            failures.push(format!("{case}: {measured} > {tolerance} ({})", row["unit"]));
        }
        let reported = row["tolerance"].as_f64().unwrap_or(f64::NAN);
        if reported.is_nan() || (reported - tolerance).abs() > 1e-12 * tolerance {
            failures.push(format!("{case}: reports tolerance {} instead of {tolerance}", row["tolerance"]));
        }
        if row["sound"] != true {
            failures.push(format!("{case}: unsound measurement {}", row["detail"]));
        }
    }
    assert_eq!(rows.len(), TOLERANCES.len(), "every reported case has a tolerance here");
    assert!(failures.is_empty(), "{failures:#?}\nstderr: {stderr}");
    assert!(output.status.success(), "{stderr}");
    // What the program does with NaN and ∞ is stated: sanitised where colours are written,
    // refused where they are given (a brush) or read and written (files).
    let outcome = rows.iter().find(|row| row["case"] == "non_finite_colors").unwrap()["outcome"].as_str().unwrap();
    assert!(outcome.contains("sanitised") && outcome.contains("refused") && outcome.contains("finite"), "{outcome}");
}
