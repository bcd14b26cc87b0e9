//! The Khronos glTF-Validator (npm package `gltf-validator`, pinned in tools/validate-gltf),
//! the independent truth every glTF export is checked against. `.ci/run` installs Node.js
//! and runs `npm ci` once; a test that finds it missing installs it, once per run (the
//! test modules of this binary share the lock).

use std::path::Path;
use std::process::Command;
use std::sync::Mutex;

use serde_json::Value;

use crate::common::workspace_path;

/// Installs tools/validate-gltf/node_modules with `npm ci` when missing (once per run).
fn ensure_validator_installed() {
    static INSTALLED: Mutex<bool> = Mutex::new(false);
    let mut installed = INSTALLED.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if *installed {
        return;
    }
    let dir = workspace_path("tools/validate-gltf");
    if !dir.join("node_modules/gltf-validator/package.json").is_file() {
        let status = Command::new("npm").arg("ci").arg("--prefix").arg(&dir).current_dir(workspace_path(".")).status();
        match status {
            Ok(status) => assert!(status.success(), "`npm ci --prefix tools/validate-gltf` failed ({status})"),
            Err(error) => panic!(
                "the Khronos glTF-Validator is not installed and `npm ci --prefix tools/validate-gltf` could not \
                 run ({error}): this test needs Node.js and npm on PATH"
            ),
        }
    }
    *installed = true;
}

/// Runs the Khronos glTF-Validator on `path` and returns its summary (numErrors, ...).
pub fn validate(path: &Path) -> Value {
    ensure_validator_installed();
    let output = Command::new("node")
        .arg(workspace_path("tools/validate-gltf/validate.mjs"))
        .arg(path)
        .current_dir(workspace_path("."))
        .output();
    let output = match output {
        Ok(output) => output,
        Err(error) => panic!(
            "cannot run `node` ({error}): the glTF-Validator test needs Node.js (>= 18) on PATH; it is not skipped"
        ),
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let report: Value = serde_json::from_str(stdout.trim()).unwrap_or_else(|error| {
        panic!("{}: validator printed no JSON ({error}); stdout: {stdout}; stderr: {stderr}", path.display())
    });
    assert_eq!(
        output.status.code(),
        Some(if report["numErrors"] == 0 { 0 } else { 1 }),
        "{}: exit status {} disagrees with the report {report}; stderr: {stderr}",
        path.display(),
        output.status
    );
    report
}
