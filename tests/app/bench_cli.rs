//! Smoke tests of `meshpaint bench pack`, `bench load`, `bench render` and `bench adaptive`
//! on a small input: each runs, prints JSON that parses, and its numbers are positive (speed
//! itself is never asserted; the figures live in the README). `bench paint`, `bench trade`
//! and `bench extremes` have theirs in tests/app/brush.rs, tests/app/trade.rs and tests/app/extremes.rs.

use crate::common;
use common::model;

fn run(args: &[&str]) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint")).args(args).output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn bench_pack_reports_threads_formats_and_the_incremental_repack() {
    let input = model("Duck/Duck.glb");
    let report = run(&[
        "bench",
        "pack",
        input.to_str().unwrap(),
        "--resolution",
        "4",
        "--runs",
        "1",
        "--subdivide",
        "1",
        "--stroke-samples",
        "2000",
    ]);
    assert_eq!(report["bench"], "pack");
    assert_eq!(report["subdivide"], 1);
    // The Duck has 4 212 triangles; one subdivision makes four of each.
    assert_eq!(report["triangles"], 4 * 4212);
    // The binary's main thread works in its own pool, one thread a core with it
    // (`meshpaint_core::threads`); without that it would wait outside the global pool.
    let cores = std::thread::available_parallelism().unwrap().get() as u64;
    assert_eq!(report["threads"].as_u64().unwrap(), cores);
    assert_eq!(report["caller_in_pool"], true);
    let results = report["results"].as_array().unwrap();
    assert_eq!(results.len(), 3);
    for result in results {
        assert!(result["pack"]["best_seconds"].as_f64().unwrap() > 0.0);
        assert!(result["ratio_to_memcpy"].as_f64().unwrap() > 0.0);
        // The repack into reused buffers (checked equal to the fresh pack, else the command
        // fails) and the input-reading floor.
        for key in ["rebuild", "store_read"] {
            assert!(result[key]["best_seconds"].as_f64().unwrap() > 0.0, "{key}");
            assert!(result[format!("{key}_ratio_to_memcpy")].as_f64().unwrap() > 0.0, "{key}");
        }
        let incremental = &result["incremental_after_stroke"];
        assert_eq!(incremental["equal_to_full_pack"], true, "{incremental}");
        assert!(incremental["samples_changed"].as_u64().unwrap() >= 2000);
        assert!(incremental["samples_rewritten"].as_u64().unwrap() > 0);
        assert!(incremental["repack"]["best_seconds"].as_f64().unwrap() > 0.0);
        // Leaving paint mode after a resolution stroke: the relayout, equal to a full pack.
        let relayout = &result["relayout_after_resolution_stroke"];
        assert_eq!(relayout["equal_to_full_pack"], true, "{relayout}");
        assert!(relayout["faces_resized"].as_u64().unwrap() > 0, "{relayout}");
        assert!(relayout["samples_added"].as_u64().unwrap() >= 2000, "{relayout}");
        for key in ["relayout", "rebuild", "memcpy"] {
            assert!(relayout[key]["best_seconds"].as_f64().unwrap() > 0.0, "{key}");
        }
    }
}

#[test]
fn bench_load_reports_every_phase_the_total_and_peak_memory() {
    let input = model("Duck/Duck.glb");
    let report = run(&[
        "bench",
        "load",
        input.to_str().unwrap(),
        "--resolution",
        "4",
        "--subdivide",
        "1",
        "--width",
        "64",
        "--height",
        "48",
    ]);
    assert_eq!(report["bench"], "load");
    assert_eq!(report["triangles"], 4 * 4212);
    let phases = &report["phases"];
    for phase in [
        "import",
        "weld",
        "topology",
        "store",
        "pack",
        "upload",
        "bvh",
        "first_frame",
        "enter_paint",
        "paint_frame",
        "paint_redraw",
    ] {
        let seconds = phases[format!("{phase}_seconds")].as_f64().unwrap();
        assert!(seconds > 0.0, "{phase}: {seconds}");
    }
    let total = report["total_seconds"].as_f64().unwrap();
    let sum_serial = ["import", "weld", "topology", "store", "first_frame"]
        .iter()
        .map(|p| phases[format!("{p}_seconds")].as_f64().unwrap())
        .sum::<f64>();
    assert!(total >= sum_serial, "{total} < {sum_serial}");
    let to_paint = report["total_to_paint_seconds"].as_f64().unwrap();
    let entering = phases["enter_paint_seconds"].as_f64().unwrap() + phases["paint_frame_seconds"].as_f64().unwrap();
    assert!(to_paint + 1e-9 >= total + entering, "{to_paint} < {total} + {entering}");
    let peak = report["peak_resident_bytes"].as_u64().unwrap();
    let on_screen = report["peak_resident_on_screen_bytes"].as_u64().unwrap();
    assert!(on_screen > 1 << 20 && on_screen <= peak, "{on_screen} on screen, {peak} at the end");
}

#[test]
fn bench_render_reports_every_mode_against_the_baseline() {
    let input = model("Duck/Duck.glb");
    let report = run(&[
        "bench",
        "render",
        input.to_str().unwrap(),
        "--resolution",
        "4",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "2",
    ]);
    assert_eq!(report["bench"], "render");
    assert_eq!((report["width"].as_u64(), report["height"].as_u64()), (Some(64), Some(48)));
    let modes = report["modes"].as_array().unwrap();
    assert!(modes.len() >= 2, "{report}");
    for mode in modes {
        assert!(mode["median_ms"].as_f64().unwrap() > 0.0, "{mode}");
        assert!(mode["ratio_to_baseline"].as_f64().unwrap() > 0.0, "{mode}");
        assert!(mode["cpu_ratio_to_baseline"].as_f64().unwrap() > 0.0, "{mode}");
    }
    // The anisotropic MCT row is there whether or not the adapter filters anisotropically.
    assert!(report["anisotropic"].is_boolean(), "{report}");
    assert!(modes.iter().any(|m| m["mode"] == "mct-anisotropic" && m["representation"] == "mct"), "{report}");
    // Htex: three filters, its texture count and the corner jumps per level.
    for mode in ["htex-linear", "htex-mip-1", "htex-trilinear"] {
        assert!(modes.iter().any(|m| m["mode"] == mode && m["representation"] == "htex"), "{report}");
    }
    assert!(report["htex_textures"].as_u64().unwrap() > report["htex_faces"].as_u64().unwrap(), "{report}");
    let jumps = report["htex_jumps"].as_array().unwrap();
    assert!(jumps.iter().any(|j| j["corners_equalized"] == false), "{report}");
    for mode in ["ptex-linear", "ptex-mip-1", "ptex-trilinear"] {
        assert!(modes.iter().any(|m| m["mode"] == mode && m["representation"] == "ptex"), "{mode}: {report}");
    }
    assert!(report["ptex_build_ms"].as_f64().unwrap() > 0.0, "{report}");
}

#[test]
fn bench_adaptive_reports_every_rule_and_the_goals() {
    let input = model("BoxTextured/BoxTextured.glb");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .args(["bench", "adaptive", input.to_str().unwrap(), "--max-resolution", "8", "--size", "32"])
        .args(["--supersample", "1", "--views", "1", "--bake", "point"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<serde_json::Value> =
        String::from_utf8_lossy(&out.stdout).lines().map(|line| serde_json::from_str(line).unwrap()).collect();
    let rows: Vec<&serde_json::Value> = lines.iter().filter(|line| line["bench"] == "adaptive").collect();
    // Uniform R = 1…32, texel density, five error bounds, and a budget row after each uniform R ≥ 4.
    assert_eq!(rows.len(), 6 + 1 + 5 + 4, "{rows:?}");
    for row in &rows {
        assert!(row["samples"].as_u64().unwrap() > 0, "{row}");
        assert!(row["psnr_db"].as_f64().unwrap() > 0.0, "{row}");
        assert_eq!(row["bake"], "point");
    }
    for row in rows.iter().filter(|row| row["rule"] == "budget") {
        assert!(row["samples"].as_u64() <= row["sample_budget"].as_u64(), "{row}");
    }
    let summary = lines.iter().find(|line| line["bench"] == "adaptive-summary").unwrap();
    assert_eq!(summary["uv_face_texels"], 267_974);
    assert!(summary["same_psnr_fewer_samples"].as_array().is_some_and(|rows| rows.len() == 6), "{summary}");
}
