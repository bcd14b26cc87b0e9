//! A fuzz campaign against the packed-file reader, the glTF importer or the MCT-file reader, on
//! stable Rust.
//!
//! ```text
//! cargo run --release -p meshpaint-core --example fuzz -- --iterations 10000000 [--seed 1] [--target packed|gltf|mct|ptex]
//! ```
//!
//! Inputs come from structure-aware mutators (`packed.rs`, `gltf.rs`, `mct_file.rs`); input `I` of seed `S`
//! is a pure function of `(S, I)`, so `--replay I` reruns it alone. Workers are child
//! processes (`supervisor.rs`): a panic is caught per input with `catch_unwind`, an abort
//! or signal kills only the worker, each worker runs under an address-space limit
//! (`--memory-mb`, `RLIMIT_AS`) and an input silent for longer than `--timeout-ms` is killed.
//! The report lists every crash with its input saved under `target/fuzz-crashes/` (and
//! writes itself there); the exit status is 1 when anything crashed.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Duration;

use clap::Parser;

pub mod corpus;
pub mod gltf;
pub mod mct_file;
pub mod packed;
pub mod ptex_file;
pub mod rng;
pub mod supervisor;
pub mod worker;

use corpus::{Corpus, Target};
use supervisor::Campaign;
use worker::WorkerArgs;

/// Command line of the fuzz example.
#[derive(Debug, Parser)]
#[command(about = "Fuzz the packed-file reader, the glTF importer or the MCT-file reader")]
pub struct Args {
    /// Number of inputs.
    #[arg(long, default_value_t = 100_000)]
    pub iterations: u64,
    /// Campaign seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// What to fuzz: packed, gltf, mct or ptex.
    #[arg(long, default_value = "packed", value_parser = parse_target)]
    pub target: Target,
    /// Per-input time limit in milliseconds.
    #[arg(long, default_value_t = 10_000)]
    pub timeout_ms: u64,
    /// Address-space limit of each worker process in MiB.
    #[arg(long, default_value_t = 2048)]
    pub memory_mb: u64,
    /// Where crashing inputs and the report are written.
    #[arg(long)]
    pub crash_dir: Option<PathBuf>,
    /// Run input INDEX alone, in this process, without catching its panic.
    #[arg(long)]
    pub replay: Option<u64>,
    /// Internal: run as a worker process.
    #[arg(long, hide = true)]
    pub worker: Option<String>,
}

fn parse_target(name: &str) -> Result<Target, String> {
    match Target::from_name(name) {
        Some(target) => Ok(target),
        None => Err(format!("unknown target {name:?}: packed, gltf, mct or ptex")),
    }
}

/// The models the seeds are made from.
pub fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/models")
}

fn main() -> ExitCode {
    let args = Args::parse();
    if let Some(encoded) = &args.worker {
        let Some(worker_args) = WorkerArgs::decode(encoded) else {
            eprintln!("fuzz: bad worker arguments {encoded:?}");
            return ExitCode::from(2);
        };
        worker::run(&worker_args, &models());
    }
    if let Some(index) = args.replay {
        let corpus = Corpus::new(args.target, &models());
        let input = corpus.input(args.seed, index);
        println!("input {index}: {} bytes", input.bytes.len());
        println!("outcome: {}", corpus.run(&input));
        return ExitCode::SUCCESS;
    }
    let campaign = Campaign {
        target: args.target,
        seed: args.seed,
        iterations: args.iterations,
        timeout: Duration::from_millis(args.timeout_ms),
        memory_mb: args.memory_mb,
        crash_dir: args.crash_dir.clone().unwrap_or_else(supervisor::default_crash_dir),
        models: models(),
    };
    let exe = match std::env::current_exe() {
        Ok(exe) => exe,
        Err(error) => {
            eprintln!("fuzz: cannot find this program to start workers: {error}");
            return ExitCode::from(2);
        }
    };
    let spawn = |worker: &WorkerArgs| {
        let mut command = Command::new(&exe);
        command.arg("--worker").arg(worker.encode());
        command
    };
    let report = match supervisor::run(&campaign, &spawn) {
        Ok(report) => report,
        Err(error) => {
            eprintln!("fuzz: cannot run the workers: {error}");
            return ExitCode::from(2);
        }
    };
    let text = report.text();
    print!("{text}");
    let _ = std::fs::create_dir_all(&campaign.crash_dir);
    let name = format!("report-{}-seed{}.txt", campaign.target.name(), campaign.seed);
    let _ = std::fs::write(campaign.crash_dir.join(name), &text);
    if report.crashes.is_empty() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}
