//! The worker process: runs a range of inputs, each under `catch_unwind`, inside an
//! address-space limit (`RLIMIT_AS`), and reports on stdout in lines starting `@fuzz`:
//!
//! - `ready` once the seeds are built;
//! - `begin I` before input `I` (verbose mode only: the supervisor uses it to name the input
//!   that killed or hung a worker);
//! - `panic I MESSAGE` for a caught panic (the worker goes on with the next input);
//! - `stat N LABEL` (outcome counts since the last report) and `progress I` (all inputs
//!   below `I` are done) at most every 50 ms (after every input in verbose mode), and
//!   `done I` at the end.

use std::collections::BTreeMap;
use std::io::Write;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use super::corpus::{Corpus, Target};

/// What a worker runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WorkerArgs {
    /// The target.
    pub target: Target,
    /// The campaign seed.
    pub seed: u64,
    /// First input index.
    pub start: u64,
    /// Number of inputs.
    pub count: u64,
    /// Report `begin I` before every input.
    pub verbose: bool,
    /// Address-space limit in MiB (0: none).
    pub memory_mb: u64,
}

impl WorkerArgs {
    /// One command-line word: `target,seed,start,count,verbose,memory_mb`.
    pub fn encode(&self) -> String {
        let target = self.target.name();
        format!("{target},{},{},{},{},{}", self.seed, self.start, self.count, u8::from(self.verbose), self.memory_mb)
    }

    /// The inverse of [`WorkerArgs::encode`].
    pub fn decode(text: &str) -> Option<Self> {
        let parts: Vec<&str> = text.split(',').collect();
        let [target, seed, start, count, verbose, memory_mb] = parts.as_slice() else { return None };
        Some(WorkerArgs {
            target: Target::from_name(target)?,
            seed: seed.parse().ok()?,
            start: start.parse().ok()?,
            count: count.parse().ok()?,
            verbose: *verbose == "1",
            memory_mb: memory_mb.parse().ok()?,
        })
    }
}

/// Limits this process's address space to `mb` MiB and disables core files.
pub fn limit_memory(mb: u64) -> std::io::Result<()> {
    let set = |resource, value: u64| {
        let limit = libc::rlimit { rlim_cur: value as libc::rlim_t, rlim_max: value as libc::rlim_t };
        // SAFETY: setrlimit reads the struct we pass and changes only this process's limits.
        if unsafe { libc::setrlimit(resource, &limit) } != 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok(())
    };
    set(libc::RLIMIT_CORE, 0)?;
    if mb > 0 {
        set(libc::RLIMIT_AS, mb << 20)?;
    }
    Ok(())
}

/// The last panic's message and location, recorded by the hook instead of printed.
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

fn install_quiet_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let payload = info.payload();
        let text = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "non-string panic".to_owned());
        let location = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = Some(format!("{text}{location}"));
        }
    }));
}

/// Runs the inputs of `args` and exits the process (status 0 when all ran).
pub fn run(args: &WorkerArgs, models: &Path) -> ! {
    if let Err(error) = limit_memory(args.memory_mb) {
        eprintln!("fuzz worker: cannot set the memory limit: {error}");
        std::process::exit(2);
    }
    let corpus = Corpus::new(args.target, models);
    install_quiet_panic_hook();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let _ = writeln!(out, "@fuzz ready");
    let _ = out.flush();
    let mut stats: BTreeMap<String, u64> = BTreeMap::new();
    let mut last_report = Instant::now();
    let end = args.start.saturating_add(args.count);
    for index in args.start..end {
        if args.verbose {
            let _ = writeln!(out, "@fuzz begin {index}");
            let _ = out.flush();
        }
        let input = corpus.input(args.seed, index);
        match catch_unwind(AssertUnwindSafe(|| corpus.run(&input))) {
            Ok(label) => *stats.entry(label).or_default() += 1,
            Err(_) => {
                let message = LAST_PANIC.lock().ok().and_then(|mut m| m.take()).unwrap_or_default();
                let _ = writeln!(out, "@fuzz panic {index} {}", message.replace(['\n', '\r'], " | "));
                let _ = out.flush();
                *stats.entry("panic".to_owned()).or_default() += 1;
            }
        }
        if args.verbose || last_report.elapsed() >= Duration::from_millis(50) || index + 1 == end {
            for (label, count) in std::mem::take(&mut stats) {
                let _ = writeln!(out, "@fuzz stat {count} {label}");
            }
            let _ = writeln!(out, "@fuzz progress {}", index + 1);
            let _ = out.flush();
            last_report = Instant::now();
        }
    }
    let _ = writeln!(out, "@fuzz done {end}");
    let _ = out.flush();
    drop(out);
    std::process::exit(0)
}
