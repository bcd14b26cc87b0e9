//! The fuzz harness (examples/fuzz) in the test suite: its supervisor must report every kind
//! of crash with the input saved, and short campaigns (a fixed seed, a few thousand inputs)
//! against the packed-file reader (layers section included), the glTF importer and the MCT-file reader must find nothing — while their
//! inputs reach far into the reader (the mutators fix the checksum and the layout, so most
//! mutants are refused by content checks, not by the checksum, and some are accepted).
//!
//! The workers are this test binary itself, started with `fuzz_worker_process` and the
//! worker's arguments in `MESHPAINT_FUZZ_WORKER`. The long campaign is
//! `cargo run --release -p meshpaint-core --example fuzz -- --iterations N [--seed S] [--target packed|gltf|mct]`.

use std::collections::BTreeMap;
use std::process::Command;
use std::time::Duration;

#[path = "../../examples/fuzz/main.rs"]
#[allow(dead_code)] // the example's `main` and command line
mod harness;

use crate::common;

use harness::corpus::{self, Target};
use harness::supervisor::{Campaign, Report};
use harness::worker::WorkerArgs;

const WORKER_ENV: &str = "MESHPAINT_FUZZ_WORKER";

#[test]
#[ignore = "the fuzz worker process: started by the tests in this file"]
fn fuzz_worker_process() {
    if let Ok(encoded) = std::env::var(WORKER_ENV) {
        harness::worker::run(&WorkerArgs::decode(&encoded).expect("bad worker arguments"), &harness::models());
    }
}

/// Starts this test binary as a worker.
fn spawn_self(worker: &WorkerArgs) -> Command {
    let mut command = Command::new(std::env::current_exe().unwrap());
    command.args(["fuzz::fuzz_worker_process", "--exact", "--ignored", "--nocapture", "--test-threads=1"]);
    command.env(WORKER_ENV, worker.encode());
    command
}

fn campaign(target: Target, seed: u64, iterations: u64, name: &str) -> Campaign {
    let crash_dir = common::output_dir().join(format!("fuzz-{name}"));
    let _ = std::fs::remove_dir_all(&crash_dir);
    Campaign {
        target,
        seed,
        iterations,
        timeout: Duration::from_secs(20),
        memory_mb: 2048,
        crash_dir,
        models: harness::models(),
    }
}

fn run(campaign: &Campaign) -> Report {
    let report = harness::supervisor::run(campaign, &spawn_self).unwrap();
    eprintln!("{}", report.text());
    report
}

/// Inputs per outcome whose label starts with `prefix`.
fn count(outcomes: &BTreeMap<String, u64>, prefix: &str) -> u64 {
    outcomes.iter().filter(|(label, _)| label.starts_with(prefix)).map(|(_, n)| n).sum()
}

#[test]
fn the_supervisor_reports_panics_aborts_hangs_and_allocations_over_the_limit() {
    let mut campaign = campaign(Target::SelfTest, 3, 40, "selftest");
    campaign.timeout = Duration::from_secs(2);
    // Far below the 4 GiB the allocating input reserves: without the limit, reserving
    // (never touching) 4 GiB succeeds and that input would not crash.
    campaign.memory_mb = 512;
    let report = run(&campaign);
    let expected: Vec<(u64, &str)> = [
        (corpus::SELFTEST_PANIC, "panic"),
        (corpus::SELFTEST_ABORT, "signal"),
        (corpus::SELFTEST_HANG, "timeout"),
        (corpus::SELFTEST_ALLOCATE, "signal"),
    ]
    .into_iter()
    .flat_map(|(k, kind)| [(k, kind), (k + 16, kind), (k + 32, kind)])
    .filter(|&(index, _)| index < 40)
    .collect();
    let mut expected = expected;
    expected.sort();
    let found: Vec<(u64, &str)> = report.crashes.values().map(|c| (c.index, c.kind)).collect();
    assert_eq!(found, expected, "{}", report.text());
    for crash in report.crashes.values() {
        let saved = std::fs::read(&crash.file).unwrap();
        assert_eq!(saved, (crash.index % 16).to_le_bytes(), "input {} saved wrongly", crash.index);
        match crash.index % 16 {
            corpus::SELFTEST_PANIC => assert!(crash.message.contains("self-test panic"), "{}", crash.message),
            corpus::SELFTEST_ABORT => assert!(crash.message.contains("SIGABRT"), "{}", crash.message),
            corpus::SELFTEST_ALLOCATE => {
                assert!(crash.message.contains("memory allocation of 4294967296 bytes failed"), "{}", crash.message);
                assert!(crash.message.contains("512 MiB"), "{}", crash.message);
            }
            _ => {}
        }
    }
    // Every other input ran (and said "ok").
    assert_eq!(report.outcomes.get("ok").copied(), Some(40 - expected.len() as u64), "{}", report.text());
}

#[test]
fn inputs_are_a_function_of_seed_and_index() {
    let corpus = corpus::Corpus::new(Target::Packed, &harness::models());
    let a: Vec<Vec<u8>> = (0..50).map(|i| corpus.input(7, i).bytes).collect();
    let b: Vec<Vec<u8>> =
        (0..50).rev().map(|i| corpus.input(7, i).bytes).collect::<Vec<_>>().into_iter().rev().collect();
    assert_eq!(a, b);
    let other: Vec<Vec<u8>> = (0..50).map(|i| corpus.input(8, i).bytes).collect();
    assert!(a.iter().zip(&other).filter(|(x, y)| x == y).count() < 5, "seeds 7 and 8 draw the same inputs");
    let distinct: std::collections::BTreeSet<&Vec<u8>> = a.iter().collect();
    assert!(distinct.len() > 45, "only {} distinct inputs of 50", distinct.len());
}

#[test]
fn a_short_packed_campaign_finds_no_crash_and_reaches_the_content_checks() {
    let report = run(&campaign(Target::Packed, 20_261_201, 4000, "packed"));
    assert!(report.crashes.is_empty(), "{}", report.text());
    let total: u64 = report.outcomes.values().sum();
    assert_eq!(total, 4000, "{}", report.text());
    let checksum = count(&report.outcomes, "refused: ChecksumMismatch");
    let accepted = count(&report.outcomes, "accepted");
    let kinds = report.outcomes.keys().filter(|label| label.starts_with("refused: ")).count();
    assert!(checksum * 10 < total, "{checksum} of {total} mutants stop at the checksum\n{}", report.text());
    assert!(accepted * 50 > total, "only {accepted} of {total} mutants are accepted\n{}", report.text());
    assert!(kinds >= 15, "only {kinds} kinds of refusal\n{}", report.text());
    // The layered seeds (version 2) reach the layers section: some accepted, some refused.
    let layered = count(&report.outcomes, "accepted with layers");
    let bad_layers = count(&report.outcomes, "refused: BadLayers");
    assert!(layered > 0 && bad_layers > 0, "layers section not reached\n{}", report.text());
}

#[test]
fn a_short_gltf_campaign_finds_no_crash_and_reaches_the_mesh() {
    let report = run(&campaign(Target::Gltf, 20_261_201, 2000, "gltf"));
    assert!(report.crashes.is_empty(), "{}", report.text());
    let total: u64 = report.outcomes.values().sum();
    assert_eq!(total, 2000, "{}", report.text());
    let packed = count(&report.outcomes, "imported, packed");
    let kinds = report.outcomes.keys().filter(|label| label.starts_with("refused: ")).count();
    assert!(packed * 10 > total, "only {packed} of {total} mutants import and pack\n{}", report.text());
    assert!(kinds >= 15, "only {kinds} kinds of refusal\n{}", report.text());
}

#[test]
fn a_short_mct_campaign_finds_no_crash_and_reaches_the_content_checks() {
    let report = run(&campaign(Target::Mct, 20_261_201, 4000, "mct"));
    assert!(report.crashes.is_empty(), "{}", report.text());
    let total: u64 = report.outcomes.values().sum();
    assert_eq!(total, 4000, "{}", report.text());
    let checksum = count(&report.outcomes, "refused: ChecksumMismatch");
    let accepted = count(&report.outcomes, "accepted");
    let kinds = report.outcomes.keys().filter(|label| label.starts_with("refused: ")).count();
    assert!(checksum * 10 < total, "{checksum} of {total} mutants stop at the checksum\n{}", report.text());
    assert!(accepted * 50 > total, "only {accepted} of {total} mutants are accepted\n{}", report.text());
    // The content checks past the section table are reached, each of them.
    for refusal in [
        "NonFinitePosition",
        "IndexOutOfRange",
        "RecordCorner",
        "RecordResolution",
        "RecordLevels",
        "PairIndex",
        "BandReserved",
        "EmptyBand",
        "DuplicateSlot",
        "MissingFirst",
        "PairEdge",
        "OutsideAtlas",
    ] {
        assert!(count(&report.outcomes, &format!("refused: {refusal}")) > 0, "no {refusal}\n{}", report.text());
    }
    assert!(kinds >= 20, "only {kinds} kinds of refusal\n{}", report.text());
}

#[test]
fn a_short_ptex_campaign_finds_no_crash_and_reaches_the_content_checks() {
    let report = run(&campaign(Target::Ptex, 20_261_207, 4000, "ptex"));
    assert!(report.crashes.is_empty(), "{}", report.text());
    let total: u64 = report.outcomes.values().sum();
    assert_eq!(total, 4000, "{}", report.text());
    let checksum = count(&report.outcomes, "refused: ChecksumMismatch");
    let accepted = count(&report.outcomes, "accepted");
    assert!(checksum * 10 < total, "{checksum} of {total} mutants stop at the checksum\n{}", report.text());
    assert!(accepted * 50 > total, "only {accepted} of {total} mutants are accepted\n{}", report.text());
    assert!(count(&report.outcomes, "refused: Content") > 0, "the content checks are reached\n{}", report.text());
}

/// Regression fixtures: inputs the fuzzer once crashed on (tests/fixtures/fuzz/), each
/// run through its target's full oracle, with the outcome it must have now.
#[test]
fn former_fuzz_crashes_are_handled() {
    let expected = [
        (
            // Finite positions and transforms whose product overflows f32: welded world
            // positions were infinite and the packed writer refused the imported document.
            "gltf-world-position-overflows-to-infinity.glb",
            "imported, refused: NonFiniteWorldPosition",
        ),
        (
            // A packed Ptex header of sides near 2^32: the texel byte count overflowed u64
            // before the sides were checked.
            "ptex-texture-size-overflows.ptx",
            "refused: Header",
        ),
    ];
    let dir = common::workspace_path("tests/fixtures/fuzz");
    let mut files: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    files.sort();
    let mut listed: Vec<String> = expected.iter().map(|(name, _)| (*name).to_owned()).collect();
    listed.sort();
    assert_eq!(files, listed, "every fixture in tests/fixtures/fuzz has an expected outcome here");
    for (name, outcome) in expected {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let found = match name.rsplit('.').next() {
            Some("mpk") => harness::packed::run(&bytes),
            Some("mct") => harness::mct_file::run(&bytes),
            Some("ptx") => harness::ptex_file::run(&bytes),
            Some("glb") => harness::gltf::run(&bytes, true, 2),
            _ => harness::gltf::run(&bytes, false, 2),
        };
        assert_eq!(found, outcome, "{name}");
    }
}

#[test]
fn a_world_position_overflow_is_refused_with_a_message_naming_the_file() {
    let path = common::workspace_path("tests/fixtures/fuzz/gltf-world-position-overflows-to-infinity.glb");
    let r2 = meshpaint_core::colors::layout::Resolution::new(2).unwrap();
    let error = meshpaint_core::io::document::Document::open(&path, r2).unwrap_err().to_string();
    assert!(error.starts_with(&path.display().to_string()), "{error}");
    assert!(error.contains("non-finite world position") && error.contains("inf"), "{error}");
}
