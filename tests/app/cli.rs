//! Integration tests of the `meshpaint` command line: `info` against the counts in
//! assets/SOURCES.md and the mesh-colors sample formulas, robustness on the invalid glTF
//! fixtures and bad arguments, and `pack` round trips through packed files.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::common;
use common::{TempFile, model, workspace_path};

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");
const FORMATS: [(&str, u64); 3] = [("rgba8", 4), ("rgba16f", 8), ("rgba32f", 16)];

fn meshpaint<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    Command::new(BIN).args(args).output().expect("cannot start the meshpaint binary")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Describes a finished run for assertion messages.
fn describe(args: &str, output: &Output) -> String {
    format!(
        "meshpaint {args}\nstatus: {:?}\nstdout: {}\nstderr: {}",
        output.status,
        text(&output.stdout),
        text(&output.stderr)
    )
}

/// Runs a command that must succeed and returns its stdout.
fn run_ok(args: &[&str]) -> Output {
    let output = meshpaint(args);
    assert!(output.status.success(), "expected success:\n{}", describe(&args.join(" "), &output));
    output
}

/// Runs a command that must fail cleanly (exit 1, a non-empty message, no panic) and
/// returns its stderr.
fn run_fail(args: &[&str]) -> String {
    let output = meshpaint(args);
    let what = describe(&args.join(" "), &output);
    assert_eq!(output.status.code(), Some(1), "expected exit code 1:\n{what}");
    let stderr = text(&output.stderr);
    assert!(!stderr.trim().is_empty(), "empty error message:\n{what}");
    assert!(!stderr.contains("panicked"), "panic:\n{what}");
    stderr
}

/// `meshpaint info --json` of `file` (with `extra` arguments) as a JSON object.
fn info_json(file: &Path, extra: &[&str]) -> serde_json::Map<String, Value> {
    let file = file.to_str().expect("UTF-8 path");
    let mut args = vec!["info", file, "--json"];
    args.extend_from_slice(extra);
    let output = run_ok(&args);
    let stdout = text(&output.stdout);
    match serde_json::from_str::<Value>(stdout.trim()) {
        Ok(Value::Object(object)) => object,
        other => panic!("`meshpaint {}` did not print one JSON object ({other:?}):\n{stdout}", args.join(" ")),
    }
}

fn get_u64(object: &serde_json::Map<String, Value>, key: &str) -> u64 {
    object.get(key).and_then(Value::as_u64).unwrap_or_else(|| panic!("no unsigned integer '{key}' in {object:?}"))
}

/// Samples of one uniform level: `V + E(R−1) + F(R−1)(R−2)/2`, overflow-checked.
fn level_samples(v: u64, e: u64, f: u64, r: u64) -> u64 {
    assert!(r >= 1);
    let interior = f
        .checked_mul(r - 1)
        .and_then(|x| x.checked_mul(r.saturating_sub(2)))
        .map(|x| x / 2)
        .expect("interior sample count overflows u64");
    let edge = e.checked_mul(r - 1).expect("edge sample count overflows u64");
    v.checked_add(edge).and_then(|x| x.checked_add(interior)).expect("sample count overflows u64")
}

/// Samples over the MIP chain R, R/2, …, 1.
fn samples_with_mips(v: u64, e: u64, f: u64, r: u64) -> u64 {
    assert!(r.is_power_of_two());
    (0..=r.trailing_zeros())
        .map(|k| level_samples(v, e, f, r >> k))
        .fold(0u64, |sum, n| sum.checked_add(n).expect("MIP sample count overflows u64"))
}

/// Checks `samples` and `samples_with_mips` against the formulas from the printed V/E/F.
fn check_sample_budget(name: &str, object: &serde_json::Map<String, Value>, r: u64) {
    let (v, e, f) = (get_u64(object, "vertices"), get_u64(object, "edges"), get_u64(object, "triangles"));
    assert_eq!(get_u64(object, "resolution"), r, "{name}: resolution");
    assert_eq!(get_u64(object, "samples"), level_samples(v, e, f, r), "{name}: samples at R = {r}");
    assert_eq!(
        get_u64(object, "samples_with_mips"),
        samples_with_mips(v, e, f, r),
        "{name}: samples_with_mips at R = {r}"
    );
}

/// Counting identity: every face has three edges and an edge has 1 (boundary), 2 or ≥ 3
/// (non-manifold) faces, so `3F ≥ 2E − b + n`, with equality when no edge has 4+ faces.
fn check_edge_face_incidence(name: &str, object: &serde_json::Map<String, Value>) {
    let (e, f) = (get_u64(object, "edges"), get_u64(object, "triangles"));
    let (b, n) = (get_u64(object, "boundary_edges"), get_u64(object, "nonmanifold_edges"));
    assert!(e <= 3 * f, "{name}: {e} edges > 3 × {f} triangles");
    assert!(get_u64(object, "vertices") <= 3 * f, "{name}: more vertices than triangle corners");
    assert!(b + n <= e, "{name}: {b} boundary + {n} non-manifold edges > {e} edges");
    assert!(2 * e + n - b <= 3 * f, "{name}: 2E − b + n = {} > 3F = {}", 2 * e + n - b, 3 * f);
    if n == 0 {
        assert_eq!(2 * e - b, 3 * f, "{name}: manifold mesh must have 2E − b = 3F");
    }
}

/// glTF files under `dir`, recursively, sorted.
fn gltf_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_owned()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if matches!(path.extension().and_then(|x| x.to_str()), Some("gltf" | "glb")) {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// One row of assets/SOURCES.md: exact welded counts.
struct Expected {
    file: &'static str,
    triangles: u64,
    vertices: u64,
    edges: u64,
    boundary_edges: u64,
    nonmanifold_edges: u64,
}

const TABLE: &[Expected] = &[
    Expected {
        file: "BoxTextured/BoxTextured.glb",
        triangles: 12,
        vertices: 8,
        edges: 18,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "BoxTextured/BoxTextured.embedded.gltf",
        triangles: 12,
        vertices: 8,
        edges: 18,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "Duck/Duck.glb",
        triangles: 4212,
        vertices: 2108,
        edges: 6318,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "Fox/Fox.glb",
        triangles: 576,
        vertices: 290,
        edges: 864,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "Suzanne/monkey.glb",
        triangles: 968,
        vertices: 505,
        edges: 1473,
        boundary_edges: 42,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "Alien/alien.glb",
        triangles: 292,
        vertices: 158,
        edges: 438,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "CakeBirthday/cakeBirthday.glb",
        triangles: 1332,
        vertices: 636,
        edges: 1932,
        boundary_edges: 0,
        nonmanifold_edges: 132,
    },
    Expected {
        file: "NonManifold/no_indices_3storybuilding.glb",
        triangles: 72,
        vertices: 36,
        edges: 96,
        boundary_edges: 0,
        nonmanifold_edges: 12,
    },
    Expected {
        file: "Cubes/Cubes.glb",
        triangles: 36,
        vertices: 24,
        edges: 54,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
    Expected {
        file: "Bunny144k/bunny.glb",
        triangles: 144_046,
        vertices: 72_027,
        edges: 216_069,
        boundary_edges: 0,
        nonmanifold_edges: 0,
    },
];

/// MultiNodeScenes: the table gives only a triangle range (36–3,408) and pins' 3,408.
const MULTI_NODE: &[(&str, Option<u64>)] = &[
    ("MultiNodeScenes/TestScene.gltf", None),
    ("MultiNodeScenes/nested.glb", None),
    ("MultiNodeScenes/pins.glb", Some(3408)),
    ("MultiNodeScenes/simple_pole.glb", None),
];

#[test]
fn info_matches_sources_table_at_default_resolution() {
    // Every model file is covered by the table (a new asset needs a row here).
    let root = model("");
    let found: Vec<String> =
        gltf_files(&root).iter().map(|p| p.strip_prefix(&root).unwrap().to_str().unwrap().replace('\\', "/")).collect();
    let mut known: Vec<String> =
        TABLE.iter().map(|row| row.file.to_owned()).chain(MULTI_NODE.iter().map(|(f, _)| (*f).to_owned())).collect();
    known.sort();
    assert_eq!(found, known, "assets/models and the SOURCES.md table disagree");

    let mut mismatches = Vec::new();
    for row in TABLE {
        let object = info_json(&model(row.file), &[]);
        let actual = [
            ("triangles", row.triangles),
            ("vertices", row.vertices),
            ("edges", row.edges),
            ("boundary_edges", row.boundary_edges),
            ("nonmanifold_edges", row.nonmanifold_edges),
        ];
        for (key, expected) in actual {
            let got = get_u64(&object, key);
            if got != expected {
                mismatches.push(format!("{}: {key} = {got}, SOURCES.md says {expected}", row.file));
            }
        }
        check_edge_face_incidence(row.file, &object);
        check_sample_budget(row.file, &object, 8);
    }
    assert!(mismatches.is_empty(), "count mismatches:\n{}", mismatches.join("\n"));

    for &(file, triangles) in MULTI_NODE {
        let object = info_json(&model(file), &[]);
        let f = get_u64(&object, "triangles");
        assert!((36..=3408).contains(&f), "{file}: {f} triangles outside the table's range 36–3,408");
        if let Some(expected) = triangles {
            assert_eq!(f, expected, "{file}: triangles");
        }
        check_edge_face_incidence(file, &object);
        check_sample_budget(file, &object, 8);
    }
}

#[test]
fn info_sample_budget_box_textured_small_resolutions() {
    for r in [1u64, 8] {
        let object = info_json(&model("BoxTextured/BoxTextured.glb"), &["--resolution", &r.to_string()]);
        check_sample_budget("BoxTextured.glb", &object, r);
    }
    // R = 1: only the vertices are samples, and there is a single MIP level.
    let object = info_json(&model("BoxTextured/BoxTextured.glb"), &["--resolution", "1"]);
    assert_eq!(get_u64(&object, "samples"), 8);
    assert_eq!(get_u64(&object, "samples_with_mips"), 8);
}

#[test]
fn info_sample_budget_box_textured_max_resolution() {
    // R = 4096: 12 faces × ~8.4 M interior samples; the budget must be computed in u64.
    let object = info_json(&model("BoxTextured/BoxTextured.glb"), &["--resolution", "4096"]);
    check_sample_budget("BoxTextured.glb", &object, 4096);
    assert_eq!(get_u64(&object, "samples"), 8 + 18 * 4095 + 12 * 4095 * 4094 / 2);
}

/// Outcome of a guarded run: the exit status (None when killed after the time limit).
struct Guarded {
    status: Option<ExitStatus>,
    stderr: String,
}

/// Runs `meshpaint args`, killing it if it has not exited after `limit` (a hang guard).
fn run_guarded(args: &[&std::ffi::OsStr], limit: Duration) -> Guarded {
    let mut child = Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start the meshpaint binary");
    // Drain stderr on a thread so a chatty child can never block on a full pipe.
    let mut pipe = child.stderr.take().expect("piped stderr");
    let reader = std::thread::spawn(move || {
        let mut buffer = Vec::new();
        let _ = pipe.read_to_end(&mut buffer);
        buffer
    });
    let start = Instant::now();
    let status = loop {
        match child.try_wait().expect("try_wait") {
            Some(status) => break Some(status),
            None if start.elapsed() > limit => {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            None => std::thread::sleep(Duration::from_millis(10)),
        }
    };
    let stderr = text(&reader.join().expect("stderr reader"));
    Guarded { status, stderr }
}

/// How long `info` may run on one invalid file before it counts as hung.
const HANG_LIMIT: Duration = Duration::from_secs(60);

#[test]
fn info_on_invalid_fixtures_never_panics_or_hangs() {
    let files = gltf_files(&workspace_path("tests/fixtures/invalid"));
    assert!(files.len() > 50, "expected the invalid fixtures, found {} files", files.len());
    // A hang guard, not a speed test: the limit holds on a loaded 2-core machine (an invalid
    // file is refused in milliseconds; a hang never ends).
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let chunks: Vec<Vec<PathBuf>> =
        (0..threads).map(|t| files.iter().skip(t).step_by(threads).cloned().collect()).collect();
    let failures: Vec<String> = std::thread::scope(|scope| {
        let handles: Vec<_> = chunks
            .iter()
            .map(|chunk| {
                scope.spawn(move || {
                    let mut failures = Vec::new();
                    for file in chunk {
                        let args = ["info".as_ref(), file.as_os_str(), "--json".as_ref()];
                        let run = run_guarded(&args, HANG_LIMIT);
                        let name = file.file_name().unwrap().to_string_lossy();
                        let shown = file.display();
                        match run.status.map(|s| (s, s.code())) {
                            None => failures.push(format!("{shown}: still running after {HANG_LIMIT:?} (killed)")),
                            Some((_, Some(0))) => {}
                            Some((_, Some(1))) => {
                                if run.stderr.trim().is_empty() {
                                    failures.push(format!("{shown}: exit 1 with empty stderr"));
                                } else if !run.stderr.contains(name.as_ref()) {
                                    failures.push(format!("{shown}: message does not name the file: {}", run.stderr));
                                }
                            }
                            Some((status, _)) => {
                                failures.push(format!("{shown}: {status:?}, stderr: {}", run.stderr.trim()))
                            }
                        }
                    }
                    failures
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker thread")).collect()
    });
    assert!(failures.is_empty(), "{} of {} fixtures failed:\n{}", failures.len(), files.len(), failures.join("\n"));
}

#[test]
fn bad_arguments_fail_with_a_message() {
    let box_glb = model("BoxTextured/BoxTextured.glb");
    let box_glb = box_glb.to_str().unwrap();

    for (r, keyword) in [("3", "power of two"), ("0", "power of two"), ("8192", "exceeds")] {
        let stderr = run_fail(&["info", box_glb, "--resolution", r]);
        assert!(stderr.contains(keyword) && stderr.contains(r), "--resolution {r}: {stderr}");
        let out = TempFile::new("bad_arguments", &format!("r{r}.mpk"));
        let stderr = run_fail(&["pack", box_glb, "--resolution", r, "-o", out.path().to_str().unwrap()]);
        assert!(stderr.contains(keyword), "pack --resolution {r}: {stderr}");
        assert!(!out.path().exists(), "pack --resolution {r} wrote an output file");
    }

    let missing = std::env::temp_dir().join(format!("meshpaint-cli-{}-missing.glb", std::process::id()));
    let stderr = run_fail(&["info", missing.to_str().unwrap()]);
    assert!(stderr.contains("No such file") && stderr.contains("missing.glb"), "missing file: {stderr}");

    let dir = model("BoxTextured");
    let stderr = run_fail(&["info", dir.to_str().unwrap()]);
    assert!(stderr.contains("BoxTextured"), "directory: {stderr}");

    let empty = TempFile::new("bad_arguments", "empty.glb");
    std::fs::write(empty.path(), b"").unwrap();
    let stderr = run_fail(&["info", empty.path().to_str().unwrap()]);
    assert!(stderr.contains("empty.glb"), "empty file: {stderr}");

    let textual = TempFile::new("bad_arguments", "x.glb");
    std::fs::write(textual.path(), b"this is not a binary glTF file\n").unwrap();
    let stderr = run_fail(&["info", textual.path().to_str().unwrap()]);
    assert!(stderr.contains("x.glb") && stderr.contains("glTF"), "text file named .glb: {stderr}");
}

fn pack(input: &Path, extra: &[&str], output: &Path) {
    let mut args = vec!["pack", input.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["-o", output.to_str().unwrap()]);
    run_ok(&args);
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

const PACK_CASES: [(&str, u64); 3] =
    [("Duck/Duck.glb", 16), ("BoxTextured/BoxTextured.glb", 1), ("BoxTextured/BoxTextured.glb", 64)];

#[test]
fn pack_round_trip_and_packed_info() {
    for (file, r) in PACK_CASES {
        let gltf = model(file);
        let r_text = r.to_string();
        let gltf_info = info_json(&gltf, &["--resolution", &r_text]);
        for (format, bytes_per_sample) in FORMATS {
            let case = format!("{file} R={r} {format}");
            let stem = format!("{}-{r}-{format}", file.replace('/', "_"));
            let out = TempFile::new("pack_round_trip", &format!("{stem}.mpk"));
            let out2 = TempFile::new("pack_round_trip", &format!("{stem}-2.mpk"));
            pack(&gltf, &["--resolution", &r_text, "--format", format], out.path());
            pack(out.path(), &[], out2.path());
            assert!(read(out.path()) == read(out2.path()), "{case}: repacking the packed file changed its bytes");

            let packed = info_json(out.path(), &[]);
            for key in ["triangles", "vertices", "edges", "samples", "samples_with_mips"] {
                assert_eq!(get_u64(&packed, key), get_u64(&gltf_info, key), "{case}: {key}");
            }
            assert_eq!(packed.get("format").and_then(Value::as_str), Some(format), "{case}: format");
            assert_eq!(get_u64(&packed, "resolution"), r, "{case}: resolution");
            assert_eq!(get_u64(&packed, "resolution_min"), r, "{case}: resolution_min");
            let triangles = get_u64(&packed, "triangles");
            assert_eq!(get_u64(&packed, "face_record_bytes"), 16 * triangles, "{case}: face_record_bytes");
            assert_eq!(
                get_u64(&packed, "color_bytes"),
                get_u64(&packed, "samples_with_mips") * bytes_per_sample,
                "{case}: color_bytes"
            );
        }
    }
}

#[test]
fn repacking_rgba32f_in_another_format_equals_packing_the_gltf() {
    // rgba32f stores the f32 level 0 exactly, so unpacking it gives the glTF's colours and
    // converting to any format must give what packing the glTF directly gives.
    for (file, r) in PACK_CASES {
        let gltf = model(file);
        let r_text = r.to_string();
        let stem = format!("{}-{r}", file.replace('/', "_"));
        let wide = TempFile::new("repack_format", &format!("{stem}-rgba32f.mpk"));
        pack(&gltf, &["--resolution", &r_text, "--format", "rgba32f"], wide.path());
        for format in ["rgba8", "rgba16f"] {
            let converted = TempFile::new("repack_format", &format!("{stem}-{format}-converted.mpk"));
            let direct = TempFile::new("repack_format", &format!("{stem}-{format}-direct.mpk"));
            pack(wide.path(), &["--format", format], converted.path());
            pack(&gltf, &["--resolution", &r_text, "--format", format], direct.path());
            assert!(
                read(converted.path()) == read(direct.path()),
                "{file} R={r}: rgba32f → {format} differs from packing the glTF as {format}"
            );
        }
    }
}

#[test]
fn truncated_packed_file_is_refused() {
    let gltf = model("BoxTextured/BoxTextured.glb");
    for (format, _) in FORMATS {
        let out = TempFile::new("truncated", &format!("{format}.mpk"));
        pack(&gltf, &["--resolution", "8", "--format", format], out.path());
        let bytes = read(out.path());
        let half = TempFile::new("truncated", &format!("{format}-half.mpk"));
        std::fs::write(half.path(), &bytes[..bytes.len() / 2]).unwrap();
        let stderr = run_fail(&["info", half.path().to_str().unwrap()]);
        assert!(stderr.contains("truncated") && stderr.contains("half.mpk"), "{format}, first half: {stderr}");

        // Other cut points: magic only, magic and a partial header, one byte short.
        for cut in [8, 20, bytes.len() - 1] {
            let short = TempFile::new("truncated", &format!("{format}-{cut}.mpk"));
            std::fs::write(short.path(), &bytes[..cut]).unwrap();
            let stderr = run_fail(&["info", short.path().to_str().unwrap()]);
            assert!(stderr.contains(&format!("{format}-{cut}.mpk")), "{format}, first {cut} bytes: {stderr}");
        }
    }
}

/// `meshpaint info FILE | head` must end quietly when the reader goes away: the read end
/// of the pipe is closed before `info` prints, so every write meets a closed pipe.
#[test]
fn a_closed_stdout_pipe_ends_the_command_without_a_panic() {
    let mut child = Command::new(BIN)
        .args(["info", model("Duck/Duck.glb").to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = text(&output.stderr);
    assert!(!stderr.contains("panicked") && !stderr.contains("Broken pipe"), "{:?}: {stderr}", output.status);
}
