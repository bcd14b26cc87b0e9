//! `meshpaint convert` over a library: two generated assets and one invalid file from
//! tests/fixtures/invalid. Each asset gets one JSON line whose counts equal what `pack`
//! writes with the same flags (the reference: convert is pack over many files); the invalid
//! file gets an error line without stopping the others; a second run skips what is up to
//! date; shards cover every asset exactly once; the progress bar stays off stderr unless
//! stderr is a terminal.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common::{TempDir, workspace_path};
use meshpaint_core::packing::file as packed_file;

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn meshpaint(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(BIN);
    command.args(args).env_remove("MESHPAINT_PROGRESS");
    for (key, value) in env {
        command.env(key, value);
    }
    command.output().expect("cannot start the meshpaint binary")
}

fn lines(output: &Output) -> Vec<Value> {
    String::from_utf8_lossy(&output.stdout).lines().map(|line| serde_json::from_str(line).unwrap()).collect()
}

/// `lib/a/truck.glb`, `lib/b/islands.glb`, `lib/c/broken.glb` (a GLB whose chunk is truncated).
fn library(dir: &TempDir) -> PathBuf {
    let lib = dir.join("lib");
    for (class, sub, extra) in [("truck", "a", ["--triangles", "800"]), ("islands", "b", ["--triangles", "2000"])] {
        std::fs::create_dir_all(lib.join(sub)).unwrap();
        let out = lib.join(sub).join(format!("{class}.glb"));
        let mut args = vec!["synth", class, "-o", out.to_str().unwrap(), "--texture-size", "256"];
        args.extend_from_slice(&extra);
        assert!(meshpaint(&args, &[]).status.success(), "synth {class}");
    }
    std::fs::create_dir_all(lib.join("c")).unwrap();
    let invalid = workspace_path("tests/fixtures/invalid/gltf-validator/glb/truncated_chunk_data.glb");
    std::fs::copy(invalid, lib.join("c/broken.glb")).unwrap();
    std::fs::write(lib.join("c/notes.txt"), "not a mesh").unwrap();
    lib
}

/// (faces, samples with MIP chains) of what `pack FILE flags` writes.
fn packed_by_pack(dir: &TempDir, file: &Path, flags: &[&str]) -> (usize, u64) {
    let out = dir.join("reference.mpk");
    let mut args = vec!["pack", file.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend_from_slice(flags);
    assert!(meshpaint(&args, &[]).status.success(), "pack {file:?}");
    let packed = packed_file::read_file(&out).unwrap();
    (packed.face_records.len(), packed.sample_count())
}

#[test]
fn convert_packs_every_asset_reports_the_failure_and_resumes() {
    let dir = TempDir::new("convert-library");
    let lib = library(&dir);
    let out = dir.join("out");
    let flags = ["--samples", "20000"];
    let mut args = vec!["convert", lib.to_str().unwrap(), "--out", out.to_str().unwrap()];
    args.extend_from_slice(&flags);
    let first = meshpaint(&args, &[]);
    assert!(!first.status.success(), "a failed asset makes the exit status non-zero");
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(!stderr.contains('\r') && !stderr.contains("[#"), "no bar when stderr is not a terminal: {stderr}");
    let rows = lines(&first);
    let paths: Vec<&str> = rows.iter().map(|row| row["path"].as_str().unwrap()).collect();
    let expected: Vec<String> =
        ["a/truck.glb", "b/islands.glb", "c/broken.glb"].iter().map(|p| lib.join(p).display().to_string()).collect();
    assert_eq!(paths, expected, "sorted by path, the text file ignored");
    for (row, name) in rows.iter().zip(["a/truck", "b/islands"]) {
        assert_eq!(row["status"], "converted", "{row}");
        let output = out.join(format!("{name}.mpk"));
        assert_eq!(row["output"].as_str(), Some(output.to_str().unwrap()), "mirrored path: {row}");
        let written = packed_file::read_file(&output).unwrap();
        let (faces, samples) = packed_by_pack(&dir, &lib.join(format!("{name}.glb")), &flags);
        assert_eq!(row["faces"].as_u64(), Some(faces as u64), "{row}");
        assert_eq!(row["samples_with_mips"].as_u64(), Some(samples), "{row}");
        assert_eq!(written.sample_count(), samples, "{name}: same samples as pack with the same flags");
        assert!(row["samples"].as_u64().unwrap() > 0 && row["seconds"].as_f64().unwrap() >= 0.0, "{row}");
        // The conversion's PSNR against the texture (its closed forms: core conversion_psnr.rs).
        let db = row["psnr_db"].as_f64().unwrap_or_else(|| panic!("a textured asset reports its PSNR: {row}"));
        assert!((10.0..100.0).contains(&db), "{row}");
    }
    assert_eq!(rows[2]["status"], "failed", "{}", rows[2]);
    assert!(!rows[2]["error"].as_str().unwrap().is_empty());
    assert!(!out.join("c/broken.mpk").exists());

    // Again: the two outputs are up to date; the broken file fails again.
    let second = meshpaint(&args, &[]);
    assert!(!second.status.success());
    let statuses: Vec<Value> = lines(&second).iter().map(|row| row["status"].clone()).collect();
    assert_eq!(statuses, ["up to date", "up to date", "failed"]);

    // An input newer than its output is converted again.
    let truck = lib.join("a/truck.glb");
    let output_time = std::fs::metadata(out.join("a/truck.mpk")).unwrap().modified().unwrap();
    let file = std::fs::File::options().write(true).open(&truck).unwrap();
    file.set_modified(output_time + std::time::Duration::from_secs(10)).unwrap();
    drop(file);
    let statuses: Vec<Value> = lines(&meshpaint(&args, &[])).iter().map(|row| row["status"].clone()).collect();
    assert_eq!(statuses, ["converted", "up to date", "failed"]);
}

#[test]
fn shards_cover_every_asset_exactly_once() {
    let dir = TempDir::new("convert-shards");
    let lib = library(&dir);
    for n in [1usize, 2, 3, 4] {
        let mut seen = Vec::new();
        for i in 0..n {
            let out = dir.join(&format!("out-{n}-{i}"));
            let shard = format!("{i}/{n}");
            let output = meshpaint(
                &["convert", lib.to_str().unwrap(), "--out", out.to_str().unwrap(), "-r", "2", "--shard", &shard],
                &[],
            );
            let rows = lines(&output);
            let has_broken = rows.iter().any(|row| row["status"] == "failed");
            assert_eq!(output.status.success(), !has_broken, "shard {shard}: {rows:?}");
            seen.extend(rows.iter().map(|row| row["path"].as_str().unwrap().to_owned()));
        }
        let unique: BTreeSet<&String> = seen.iter().collect();
        assert_eq!(seen.len(), 3, "{n} shards: {seen:?}");
        assert_eq!(unique.len(), 3, "{n} shards: {seen:?}");
    }
    let refused = meshpaint(&["convert", lib.to_str().unwrap(), "--out", "unused", "--shard", "2/2"], &[]);
    assert!(!refused.status.success());
}

#[test]
fn a_list_file_names_assets_and_the_bar_draws_only_when_asked() {
    let dir = TempDir::new("convert-list");
    let lib = library(&dir);
    let list = dir.join("assets.txt");
    let truck = lib.join("a/truck.glb");
    std::fs::write(&list, format!("# the truck\n\n{}\n", truck.display())).unwrap();
    let out = dir.join("out");
    let args = ["convert", "--list", list.to_str().unwrap(), "--out", out.to_str().unwrap(), "-r", "2"];
    let quiet = meshpaint(&args, &[]);
    assert!(quiet.status.success(), "{}", String::from_utf8_lossy(&quiet.stderr));
    let rows = lines(&quiet);
    assert_eq!(rows.len(), 1);
    // An absolute path in a list: the output takes its file name.
    assert_eq!(rows[0]["output"].as_str(), Some(out.join("truck.mpk").to_str().unwrap()));
    let drawn = meshpaint(&args, &[("MESHPAINT_PROGRESS", "always")]);
    let stderr = String::from_utf8_lossy(&drawn.stderr);
    assert!(stderr.contains("\r[") && stderr.contains('%'), "the bar when asked for: {stderr:?}");
    assert_eq!(lines(&drawn).len(), 1, "the bar never reaches stdout");
}
