//! The supervisor: runs a campaign in worker processes and lists every crash.
//!
//! Why child processes: `catch_unwind` catches panics but not aborts (an allocation
//! failure, a stack overflow, `abort`), signals or hangs. Each worker runs many inputs (so
//! ten million inputs need a handful of processes, not ten million) under an address-space
//! limit (`RLIMIT_AS`, see [`super::worker::limit_memory`]), and the supervisor treats
//! silence longer than the per-input time limit as a hang and kills it (SIGKILL). When a
//! worker dies or hangs, the inputs since its last progress report are re-run in a fresh
//! worker in verbose mode, which names each input before running it, so the culprit is
//! known exactly; the campaign then goes on after it.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::corpus::{Corpus, Target};
use super::worker::WorkerArgs;

/// A campaign's settings.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// The target.
    pub target: Target,
    /// The seed: input `I` depends on `(seed, I)` only.
    pub seed: u64,
    /// Number of inputs.
    pub iterations: u64,
    /// Per-input time limit.
    pub timeout: Duration,
    /// Per-worker address-space limit in MiB.
    pub memory_mb: u64,
    /// Where crashing inputs are saved.
    pub crash_dir: PathBuf,
    /// The models the seeds are made from.
    pub models: PathBuf,
}

/// One crashing input.
#[derive(Debug, Clone)]
pub struct Crash {
    /// Its index in the campaign.
    pub index: u64,
    /// `panic`, `signal`, `exit`, `timeout` or `not reproduced`.
    pub kind: &'static str,
    /// The panic message, the signal and the last line the worker wrote to stderr, ...
    pub message: String,
    /// The saved input.
    pub file: PathBuf,
}

/// A campaign's result.
#[derive(Debug, Clone)]
pub struct Report {
    /// The settings.
    pub campaign: Campaign,
    /// Crashes by input index.
    pub crashes: BTreeMap<u64, Crash>,
    /// Outcome labels and how many inputs had each.
    pub outcomes: BTreeMap<String, u64>,
    /// Wall time.
    pub elapsed: Duration,
    /// Worker processes started.
    pub workers: u64,
}

/// How a worker session ended.
enum End {
    Done,
    Died(ExitStatus, String),
    TimedOut,
}

/// A worker session's result.
struct Session {
    end: End,
    /// Every input below this one is done.
    progress: u64,
    /// The last input a verbose worker began.
    last_begin: Option<u64>,
}

/// Time a worker may take to build its seeds.
const STARTUP: Duration = Duration::from_secs(120);

/// The last non-empty line of `text`.
fn last_line(text: &str) -> String {
    text.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("").trim().to_owned()
}

/// A signal's name.
fn signal_name(signal: i32) -> &'static str {
    match signal {
        libc::SIGABRT => "SIGABRT",
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGBUS => "SIGBUS",
        libc::SIGILL => "SIGILL",
        libc::SIGFPE => "SIGFPE",
        libc::SIGKILL => "SIGKILL",
        _ => "signal",
    }
}

fn run_session(
    spawn: &dyn Fn(&WorkerArgs) -> Command,
    args: &WorkerArgs,
    timeout: Duration,
    outcomes: &mut BTreeMap<String, u64>,
    panics: &mut Vec<(u64, String)>,
) -> std::io::Result<Session> {
    let mut child = spawn(args).stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn()?;
    let (lines, receive) = channel();
    let stdout = child.stdout.take().ok_or_else(|| std::io::Error::other("no stdout"))?;
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if lines.send(line).is_err() {
                break;
            }
        }
    });
    let stderr_tail = Arc::new(Mutex::new(Vec::<u8>::new()));
    let mut stderr = child.stderr.take().ok_or_else(|| std::io::Error::other("no stderr"))?;
    let tail = Arc::clone(&stderr_tail);
    let stderr_thread = std::thread::spawn(move || {
        let mut buffer = [0u8; 4096];
        while let Ok(n) = stderr.read(&mut buffer) {
            if n == 0 {
                break;
            }
            if let Ok(mut tail) = tail.lock() {
                tail.extend_from_slice(&buffer[..n]);
                let excess = tail.len().saturating_sub(16 * 1024);
                tail.drain(..excess);
            }
        }
    });
    let mut session = Session { end: End::Done, progress: args.start, last_begin: None };
    let (mut ready, mut done) = (false, false);
    loop {
        match receive.recv_timeout(if ready { timeout } else { STARTUP }) {
            Ok(line) => {
                // Anywhere in the line: a test harness may have written "test name ... " first.
                let Some(rest) = line.find("@fuzz ").map(|at| &line[at + "@fuzz ".len()..]) else { continue };
                let (word, rest) = rest.split_once(' ').unwrap_or((rest, ""));
                let number = || rest.split(' ').next().and_then(|n| n.parse::<u64>().ok());
                match word {
                    "ready" => ready = true,
                    "begin" => session.last_begin = number(),
                    "progress" => session.progress = number().unwrap_or(session.progress),
                    "done" => done = true,
                    "stat" => {
                        if let Some((count, label)) = rest.split_once(' ') {
                            *outcomes.entry(label.to_owned()).or_default() += count.parse::<u64>().unwrap_or(0);
                        }
                    }
                    "panic" => {
                        let (index, message) = rest.split_once(' ').unwrap_or((rest, ""));
                        if let Ok(index) = index.parse() {
                            panics.push((index, message.to_owned()));
                        }
                    }
                    _ => {}
                }
            }
            Err(RecvTimeoutError::Timeout) => {
                let _ = child.kill();
                let _ = child.wait();
                session.end = End::TimedOut;
                return Ok(session);
            }
            Err(RecvTimeoutError::Disconnected) => break,
        }
    }
    let status = child.wait()?;
    let _ = stderr_thread.join();
    if !(done && status.success()) {
        let text = stderr_tail.lock().map(|t| String::from_utf8_lossy(&t).into_owned()).unwrap_or_default();
        session.end = End::Died(status, text);
    }
    Ok(session)
}

/// Describes how a worker died.
fn death(status: ExitStatus, stderr: &str, memory_mb: u64) -> (&'static str, String) {
    use std::os::unix::process::ExitStatusExt;
    let line = match stderr.lines().find(|l| l.contains("memory allocation of") || l.contains("overflowed its stack")) {
        Some(line) => line.trim().to_owned(),
        None => last_line(stderr),
    };
    let oom = if stderr.contains("memory allocation of") {
        format!(" (over the {memory_mb} MiB address-space limit)")
    } else {
        String::new()
    };
    match status.signal() {
        Some(signal) => ("signal", format!("killed by {} ({signal}){oom}: {line}", signal_name(signal))),
        None => ("exit", format!("exited with {status}{oom}: {line}")),
    }
}

impl Report {
    /// A report of `campaign` with nothing run yet.
    fn empty(campaign: &Campaign) -> Report {
        Report {
            campaign: campaign.clone(),
            crashes: BTreeMap::new(),
            outcomes: BTreeMap::new(),
            elapsed: Duration::ZERO,
            workers: 0,
        }
    }

    fn record(&mut self, corpus: &Corpus, index: u64, kind: &'static str, message: String) {
        if self.crashes.contains_key(&index) {
            return;
        }
        let campaign = &self.campaign;
        let input = corpus.input(campaign.seed, index);
        let stem = format!("{}-seed{}-input{index}", campaign.target.name(), campaign.seed);
        let file = campaign.crash_dir.join(format!("{stem}.{}", input.extension));
        let _ = std::fs::create_dir_all(&campaign.crash_dir);
        let _ = std::fs::write(&file, &input.bytes);
        let _ = std::fs::write(campaign.crash_dir.join(format!("{stem}.txt")), format!("{kind}: {message}\n"));
        self.crashes.insert(index, Crash { index, kind, message, file });
    }

    /// Inputs run.
    pub fn inputs(&self) -> u64 {
        self.campaign.iterations
    }

    /// The report as text.
    pub fn text(&self) -> String {
        let c = &self.campaign;
        let seconds = self.elapsed.as_secs_f64();
        let mut out = format!(
            "fuzz report: target {}, seed {}\ninputs: {}\ncrashes: {}\ntime: {seconds:.1} s ({:.0} inputs/s), {} worker processes\n\
             limits per input: {} ms, {} MiB address space (RLIMIT_AS of the worker process)\n",
            c.target.name(),
            c.seed,
            self.inputs(),
            self.crashes.len(),
            self.inputs() as f64 / seconds.max(1e-9),
            self.workers,
            c.timeout.as_millis(),
            c.memory_mb,
        );
        for crash in self.crashes.values() {
            out += &format!(
                "crash: input {} {}: {} (saved as {})\n",
                crash.index,
                crash.kind,
                crash.message,
                crash.file.display()
            );
        }
        out += "outcomes:\n";
        for (label, count) in &self.outcomes {
            out += &format!("  {count:>10}  {label}\n");
        }
        out += &format!(
            "reproduce an input: cargo run --release -p meshpaint-core --example fuzz -- --target {} --seed {} --replay INDEX\n",
            c.target.name(),
            c.seed
        );
        out
    }
}

/// Runs `campaign`, starting workers with `spawn` (the command that runs
/// [`super::worker::run`] with the given arguments): the inputs are split into one
/// contiguous shard per core, each run by its own chain of worker processes, and the shards'
/// reports merged (input `I` depends on `(seed, I)` only, so the split changes nothing but
/// the wall time).
pub fn run(campaign: &Campaign, spawn: &(dyn Fn(&WorkerArgs) -> Command + Sync)) -> std::io::Result<Report> {
    let started = Instant::now();
    let shards =
        std::thread::available_parallelism().map_or(1, |n| n.get() as u64).clamp(1, campaign.iterations.max(1));
    let bounds = |k: u64| campaign.iterations * k / shards;
    let results: Vec<std::io::Result<Report>> = std::thread::scope(|scope| {
        let handles: Vec<_> =
            (0..shards).map(|k| scope.spawn(move || run_shard(campaign, bounds(k), bounds(k + 1), spawn))).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err(std::io::Error::other("a shard panicked"))))
            .collect()
    });
    let mut report = Report::empty(campaign);
    for shard in results {
        let shard = shard?;
        report.crashes.extend(shard.crashes);
        for (label, n) in shard.outcomes {
            *report.outcomes.entry(label).or_default() += n;
        }
        report.workers += shard.workers;
    }
    report.elapsed = started.elapsed();
    Ok(report)
}

/// Runs inputs `start..end` of `campaign` in a chain of worker processes: a worker that dies
/// or hangs is followed by a verbose one that names the culprit, then the chain goes on
/// after it.
fn run_shard(
    campaign: &Campaign,
    start: u64,
    end: u64,
    spawn: &(dyn Fn(&WorkerArgs) -> Command + Sync),
) -> std::io::Result<Report> {
    let corpus = Corpus::new(campaign.target, &campaign.models);
    let mut report = Report::empty(campaign);
    let mut next = start;
    let args = |start: u64, verbose: bool| WorkerArgs {
        target: campaign.target,
        seed: campaign.seed,
        start,
        count: end - start,
        verbose,
        memory_mb: campaign.memory_mb,
    };
    while next < end {
        let mut panics = Vec::new();
        report.workers += 1;
        let session = run_session(spawn, &args(next, false), campaign.timeout, &mut report.outcomes, &mut panics)?;
        for (index, message) in panics.drain(..) {
            report.record(&corpus, index, "panic", message);
        }
        if let End::Done = session.end {
            break;
        }
        // Find the culprit: re-run from the last progress report, naming each input.
        let from = session.progress;
        report.workers += 1;
        let replay = run_session(spawn, &args(from, true), campaign.timeout, &mut report.outcomes, &mut panics)?;
        for (index, message) in panics.drain(..) {
            report.record(&corpus, index, "panic", message);
        }
        let culprit = replay.last_begin.unwrap_or(from);
        match replay.end {
            End::Done => {
                let message = format!("a worker died after input {from}, but the inputs after it ran cleanly again");
                report.record(&corpus, from, "not reproduced", message);
                break;
            }
            End::TimedOut => {
                let message = format!("no answer within {} ms; killed", campaign.timeout.as_millis());
                report.record(&corpus, culprit, "timeout", message);
                *report.outcomes.entry("timeout".to_owned()).or_default() += 1;
            }
            End::Died(status, stderr) => {
                let (kind, message) = death(status, &stderr, campaign.memory_mb);
                report.record(&corpus, culprit, kind, message);
                *report.outcomes.entry(kind.to_owned()).or_default() += 1;
            }
        }
        next = culprit + 1;
    }
    Ok(report)
}

/// The default crash directory: `target/fuzz-crashes` of the workspace.
pub fn default_crash_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-crashes")
}
