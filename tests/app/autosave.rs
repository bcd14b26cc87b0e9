//! Autosave and recovery: recovery files round-trip bit-exactly, are found next to their
//! document, and survive `kill -9` at random moments: a helper process (`meshpaint
//! autosave-soak`) rewrites a recovery file and a saved file in a loop, and after every kill
//! both files read back valid (full packed-file validation and unpacking) and hold at least
//! the last generation the helper reported written.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use meshpaint_core::colors::format::{ColorFormat, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::io::autosave::{self, Autosaver};
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::file as packed_file;

use crate::common;
use crate::common::WriteThrough;
use common::{Rng, TempDir, model};

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn all_samples(store: &ColorStore) -> Vec<(SampleRef, [u32; 4])> {
    let mut out = Vec::new();
    store.for_each_site(|site| out.push((site.sample, store.get(site.sample).unwrap().map(f32::to_bits))));
    out
}

#[test]
fn recovery_files_round_trip_bit_exactly_and_are_found_next_to_the_document() {
    let dir = TempDir::new("roundtrip");
    let document_path = dir.0.join("duck.mpk");
    let mut document = Document::open(&model("Duck/Duck.glb"), Resolution::new(4).unwrap()).unwrap();
    // Mixed resolutions and colours no 8-bit format could hold.
    for face in (0..document.store.topology().face_count()).step_by(5) {
        document.store.write_resolution(face, Resolution::new(16).unwrap()).unwrap();
    }
    let mut rng = Rng(5);
    document.store.write_all(|_| [rng.unit() * 3.0, rng.unit() * 1e-3, -rng.unit(), rng.unit()]);
    packed_file::write_file(&document_path, &document.pack(ColorFormat::Rgba8Srgb).unwrap()).unwrap();

    let recovery = autosave::recovery_path(&document_path).unwrap();
    assert_eq!(recovery, dir.0.join(".duck.mpk.recovery.mpk"));
    assert_eq!(autosave::find_recovery(&document_path), None);
    std::thread::sleep(Duration::from_millis(20));
    let written = autosave::write_recovery(&recovery, &document).unwrap();
    assert!(written.bytes > 0);
    let found = autosave::find_recovery(&document_path).unwrap();
    assert_eq!(found.path, recovery);
    assert!(found.newer_than_document);

    let loaded = autosave::load_recovery(&recovery).unwrap();
    assert_eq!(loaded.positions, document.positions);
    assert_eq!(loaded.store.face_resolutions(), document.store.face_resolutions());
    assert!(all_samples(&loaded.store) == all_samples(&document.store), "recovery is not bit-exact");

    autosave::discard_recovery(&recovery).unwrap();
    autosave::discard_recovery(&recovery).unwrap();
    assert_eq!(autosave::find_recovery(&document_path), None);
    // Documents without a file get a sanitised name in a directory of the caller's choice.
    assert_eq!(autosave::recovery_path_in(&dir.0, "Duck (built-in)"), dir.0.join(".Duck__built-in_.recovery.mpk"));
    // A corrupt recovery file is refused, not half-loaded.
    std::fs::write(&recovery, b"MESHPAK\0 garbage").unwrap();
    assert!(autosave::load_recovery(&recovery).is_err());
}

#[test]
fn the_autosaver_saves_changes_at_most_one_interval_old() {
    let interval = Duration::from_secs(60);
    let mut saver = Autosaver::new(interval, 0);
    let t0 = Instant::now();
    assert!(!saver.is_due(t0, 0), "nothing changed");
    assert!(!saver.is_due(t0, 1), "the first change was just now");
    assert!(!saver.is_due(t0 + Duration::from_secs(59), 3));
    assert!(saver.is_due(t0 + interval, 3));
    saver.mark_saved(t0 + interval, 3);
    assert!(!saver.is_due(t0 + interval * 2, 3), "nothing changed since");
    // A change long after the last save is saved at the next poll: it is then 0 s old, and
    // no change is ever more than one interval old when it is saved.
    assert!(saver.is_due(t0 + interval * 3, 4));
    saver.mark_saved(t0 + interval * 3, 4);
    assert!(!saver.is_due(t0 + interval * 3 + Duration::from_secs(10), 5));
    assert!(saver.is_due(t0 + interval * 4, 5));
    assert_eq!(saver.saved_generation(), 4);
}

/// `due_at` is the first instant `is_due` says yes: what an idle editor wakes up for.
#[test]
fn the_autosaver_says_when_the_next_save_falls_due() {
    let interval = Duration::from_secs(60);
    let mut saver = Autosaver::new(interval, 0);
    let t0 = Instant::now();
    assert_eq!(saver.due_at(0), None, "nothing unsaved");
    assert!(!saver.is_due(t0, 1));
    let due = saver.due_at(1).expect("a change is pending");
    assert_eq!(due, t0 + interval, "one interval after the first unsaved change");
    assert!(!saver.is_due(due - Duration::from_millis(1), 1) && saver.is_due(due, 1));
    saver.mark_saved(due, 1);
    assert_eq!(saver.due_at(1), None);
    assert_eq!(saver.due_at(2), Some(due + interval), "after a save: one interval after it");
}

/// What the soak helper wrote for generation `g`: vertex 0 is `[g, 0, 0, 1]`, and interior
/// sample `offset` of every 7th face is `[s, 0.5, 1 − s, 1]` with `s = ((g + offset) % 17) / 16`.
fn check_generation(store: &ColorStore, what: &str) -> u64 {
    let marker = store.vertex_color(0).unwrap();
    let generation = marker[0] as u64;
    assert_eq!(marker, [generation as f32, 0.0, 0.0, 1.0], "{what}: vertex 0");
    for face in (0..store.topology().face_count()).step_by(7) {
        for (offset, &color) in store.interior_samples(face).iter().enumerate() {
            let shade = ((generation + offset as u64) % 17) as f32 / 16.0;
            let expected: Rgba = [shade, 0.5, 1.0 - shade, 1.0];
            assert_eq!(color, expected, "{what}: generation {generation}, face {face} sample {offset} is torn");
        }
    }
    generation
}

/// The generation a valid file holds (`None` when it does not exist); panics when it is
/// invalid.
fn file_generation(path: &Path, what: &str) -> Option<u64> {
    if !path.exists() {
        return None;
    }
    let document = autosave::load_recovery(path).unwrap_or_else(|error| panic!("{what} is corrupt: {error}"));
    Some(check_generation(&document.store, what))
}

#[test]
fn kill_nine_at_random_moments_never_corrupts_or_loses_a_finished_autosave() {
    let rounds: u64 = std::env::var("MESHPAINT_SOAK_ROUNDS").ok().and_then(|v| v.parse().ok()).unwrap_or(40);
    let dir = TempDir::new("soak");
    // The Duck at R = 8 in RGBA32F: ~3 MB a write, so kills land inside writes too.
    let input = dir.0.join("input.mpk");
    let document = Document::open(&model("Duck/Duck.glb"), Resolution::new(8).unwrap()).unwrap();
    packed_file::write_file(&input, &document.pack(ColorFormat::Rgba32F).unwrap()).unwrap();
    let recovery = autosave::recovery_path(&dir.0.join("doc.mpk")).unwrap();
    let saved = dir.0.join("saved.mpk");

    let mut rng = Rng(0x5eed_1234);
    let (mut file_recovery, mut file_saved) = (None::<u64>, None::<u64>);
    let (mut kills_after_writes, mut total_writes) = (0, 0);
    for round in 0..rounds {
        let start = file_recovery.unwrap_or(0) + 1;
        let mut child = Command::new(BIN)
            .arg("autosave-soak")
            .arg(&input)
            .arg("--recovery")
            .arg(&recovery)
            .arg("--saved")
            .arg(&saved)
            .arg("--start-generation")
            .arg(start.to_string())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("cannot start meshpaint");
        let stdout = child.stdout.take().unwrap();
        let (sender, lines_seen) = std::sync::mpsc::channel();
        let reader = std::thread::spawn(move || {
            let mut lines = Vec::new();
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = sender.send(());
                lines.push(line);
            }
            lines
        });
        // Every fourth round is killed at a random moment from the start (before the first
        // write or in the loop, whatever the machine's load); the others a random moment
        // after the helper reports its first write, so most kills land in the write loop
        // however long a loaded machine takes to start the process.
        if round % 4 != 0 {
            let _ = lines_seen.recv_timeout(Duration::from_secs(120));
        }
        let delay = Duration::from_micros(rng.next() % 500_000);
        std::thread::sleep(delay);
        child.kill().unwrap();
        let status = child.wait().unwrap();
        let lines = reader.join().unwrap();
        let mut stderr = String::new();
        if let Some(mut pipe) = child.stderr.take() {
            use std::io::Read;
            let _ = pipe.read_to_string(&mut stderr);
        }
        assert!(!status.success(), "round {round}: the helper exited by itself: {stderr}");
        let last = |prefix: &str| {
            lines.iter().filter_map(|line| line.strip_prefix(prefix)).filter_map(|n| n.trim().parse::<u64>().ok()).max()
        };
        let (printed_recovery, printed_saved) = (last("recovery "), last("saved "));
        total_writes += lines.len();
        kills_after_writes += usize::from(!lines.is_empty());

        let now_recovery = file_generation(&recovery, &format!("round {round}: recovery file"));
        let now_saved = file_generation(&saved, &format!("round {round}: saved file"));
        // Never lost: at least the last reported write (or the previous round's file).
        let floor = printed_recovery.or(file_recovery);
        if let Some(floor) = floor {
            let now = now_recovery.unwrap_or_else(|| panic!("round {round}: recovery file vanished"));
            // At most one write past the last reported one (killed between rename and print).
            let ceiling = printed_recovery.map_or(start, |g| g + 1);
            assert!(
                (floor..=ceiling).contains(&now),
                "round {round}: recovery holds {now}, expected {floor}..={ceiling}"
            );
        }
        if let Some(floor) = printed_saved.or(file_saved) {
            let now = now_saved.unwrap_or_else(|| panic!("round {round}: saved file vanished"));
            assert!(now >= floor && now.is_multiple_of(3), "round {round}: saved file holds {now}, expected ≥ {floor}");
        }
        file_recovery = now_recovery.or(file_recovery);
        file_saved = now_saved.or(file_saved);
    }
    // The kills must have hit a running loop most of the time, or the test proves little:
    // three rounds in four wait for a write, so fewer means the helper stopped writing.
    assert!(
        kills_after_writes * 4 >= rounds as usize * 3 - 3,
        "only {kills_after_writes} of {rounds} rounds wrote anything"
    );
    assert!(total_writes as u64 > rounds, "{total_writes} writes in {rounds} rounds");
    // Leftover temporary files of killed writers are recognised and removed.
    let temps = |dir: &Path| {
        std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .filter(|entry| entry.file_name().to_string_lossy().ends_with(".tmp"))
            .count()
    };
    let left = temps(&dir.0);
    let removed =
        autosave::remove_stale_temp_files(&recovery).unwrap() + autosave::remove_stale_temp_files(&saved).unwrap();
    assert_eq!(removed, left);
    assert_eq!(temps(&dir.0), 0);
    eprintln!(
        "{rounds} kills, {kills_after_writes} after at least one write, {total_writes} writes reported, \
         {left} temporary files left behind (removed), last recovery generation {file_recovery:?}"
    );
}
