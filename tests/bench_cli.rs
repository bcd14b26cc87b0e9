//! Smoke tests of `meshpaint bench pack` and `meshpaint bench load` on a small input: each
//! runs, prints JSON that parses, and its numbers are positive (speed itself is never
//! asserted; the figures live in the README).

mod common;
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
    assert!(report["threads"].as_u64().unwrap() >= 1);
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
    assert!(report["peak_resident_bytes"].as_u64().unwrap() > 1 << 20);
}
