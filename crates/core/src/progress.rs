//! Progress and cancellation of long operations (opening and converting a mesh, packing).
//!
//! A [`Reporter`] belongs to whoever waits for the operation (the editor's job, a command's
//! progress bar, a benchmark): it holds the sink that shows progress and the cancel flag.
//! The operation gets a [`Progress`], a part `[start, end]` of the whole, and hands its
//! phases sub-parts of its own ([`Progress::part`]), so every phase reports in its own
//! `[0, 1]` without knowing where it sits in the whole. Parallel loops count items done
//! with [`Progress::counter`] (`stage (k of n faces)`), reporting at most every percent.
//!
//! What the sink sees never goes backwards: a report below the last one is raised to it
//! (`Reporter` keeps the largest fraction reported), so a phase that restarts a count (a
//! refinement round) shows the same fraction until it passes the last one.
//!
//! Cancelling is cooperative: [`Reporter::cancel`] sets a flag that the operation reads at
//! phase boundaries and per item in its loops ([`Progress::check`],
//! [`Progress::is_cancelled`]); it then returns [`Cancelled`] having changed nothing the
//! caller owns (a conversion builds a new document; the open one stays).

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};

use thiserror::Error;

/// The operation was cancelled ([`Reporter::cancel`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("cancelled")]
pub struct Cancelled;

/// What a [`Reporter`] hands each report to: `(fraction of the whole, stage)`.
type Sink<'a> = Box<dyn Fn(f32, &str) + Send + Sync + 'a>;

/// The sink of an operation's progress and its cancel flag (module docs).
pub struct Reporter<'a> {
    sink: Sink<'a>,
    cancelled: AtomicBool,
    /// The caller's own cancel flag, if it keeps one (an editor job's).
    external: Option<&'a AtomicBool>,
    /// The largest fraction reported, as `f32` bits (non-negative floats order as their bits).
    last: AtomicU32,
    /// Held while the sink is called: two threads' reports reach it in the order of their
    /// fractions (a lock-free maximum alone let a smaller one arrive after a larger one).
    order: std::sync::Mutex<()>,
}

impl std::fmt::Debug for Reporter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Reporter")
            .field("cancelled", &self.is_cancelled())
            .field("last", &f32::from_bits(self.last.load(Ordering::Relaxed)))
            .finish()
    }
}

impl<'a> Reporter<'a> {
    /// A reporter that hands `(fraction of the whole in [0, 1], stage)` to `sink`, from any thread.
    pub fn new(sink: impl Fn(f32, &str) + Send + Sync + 'a) -> Self {
        Reporter {
            sink: Box::new(sink),
            cancelled: AtomicBool::new(false),
            external: None,
            last: AtomicU32::new(0),
            order: std::sync::Mutex::new(()),
        }
    }

    /// [`Reporter::new`], also cancelled once `flag` is set.
    pub fn with_cancel_flag(sink: impl Fn(f32, &str) + Send + Sync + 'a, flag: &'a AtomicBool) -> Self {
        Reporter { external: Some(flag), ..Reporter::new(sink) }
    }

    /// A reporter that shows nothing and is never cancelled unless asked.
    pub fn silent() -> Reporter<'static> {
        Reporter::new(|_, _| {})
    }

    /// The whole operation, `[0, 1]`.
    pub fn progress(&self) -> Progress<'_> {
        Progress { reporter: self, start: 0.0, end: 1.0 }
    }

    /// Asks the operation to stop (it returns [`Cancelled`] at its next check).
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Whether [`Reporter::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed) || self.external.is_some_and(|flag| flag.load(Ordering::Relaxed))
    }

    /// The largest fraction reported so far.
    pub fn fraction(&self) -> f32 {
        f32::from_bits(self.last.load(Ordering::Relaxed))
    }

    fn report(&self, fraction: f32, stage: &str) {
        let fraction = if fraction.is_finite() { fraction.clamp(0.0, 1.0) } else { 0.0 };
        // A poisoned lock only means a sink panicked on another thread; the order still holds.
        let _order = self.order.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let previous = self.last.fetch_max(fraction.to_bits(), Ordering::Relaxed);
        (self.sink)(fraction.max(f32::from_bits(previous)), stage);
    }
}

/// A part of an operation's progress (module docs).
#[derive(Debug, Clone, Copy)]
pub struct Progress<'a> {
    reporter: &'a Reporter<'a>,
    start: f32,
    end: f32,
}

impl<'a> Progress<'a> {
    /// Reports `stage` at `fraction` (in `[0, 1]`) of this part.
    pub fn report(&self, fraction: f32, stage: &str) {
        let fraction = if fraction.is_finite() { fraction.clamp(0.0, 1.0) } else { 0.0 };
        self.reporter.report(self.start + (self.end - self.start) * fraction, stage);
    }

    /// The sub-part `[from, to]` (fractions of this part).
    pub fn part(&self, from: f32, to: f32) -> Progress<'a> {
        let at = |f: f32| self.start + (self.end - self.start) * f.clamp(0.0, 1.0);
        Progress { reporter: self.reporter, start: at(from), end: at(to.max(from)) }
    }

    /// Whether the operation was asked to stop.
    pub fn is_cancelled(&self) -> bool {
        self.reporter.is_cancelled()
    }

    /// `Err(Cancelled)` once the operation was asked to stop.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() { Err(Cancelled) } else { Ok(()) }
    }

    /// A counter of `total` items for `stage` over this part, reporting
    /// `stage (k of total items)` at most every percent (from any thread).
    pub fn counter(&self, stage: &'a str, items: &'a str, total: usize) -> Counter<'a> {
        self.report(0.0, &format!("{stage} (0 of {total} {items})"));
        Counter { progress: *self, stage, items, total, done: AtomicUsize::new(0) }
    }
}

/// Items done of a counted stage ([`Progress::counter`]).
#[derive(Debug)]
pub struct Counter<'a> {
    progress: Progress<'a>,
    stage: &'a str,
    items: &'a str,
    total: usize,
    done: AtomicUsize,
}

impl Counter<'_> {
    /// Adds `count` items done; reports when that crosses a percent of the total (nothing
    /// once cancelled).
    pub fn add(&self, count: usize) {
        if self.is_cancelled() {
            // The loop skips what is left; nothing more to show.
            return;
        }
        let before = self.done.fetch_add(count, Ordering::Relaxed);
        let after = (before + count).min(self.total);
        let percent = |n: usize| n.saturating_mul(100) / self.total.max(1);
        if percent(after) != percent(before) || after == self.total {
            let fraction = after as f32 / self.total.max(1) as f32;
            self.progress.report(fraction, &format!("{} ({after} of {} {})", self.stage, self.total, self.items));
        }
    }

    /// Whether the operation was asked to stop (for the loop to skip the rest).
    pub fn is_cancelled(&self) -> bool {
        self.progress.is_cancelled()
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;

    use rayon::prelude::*;

    use super::*;

    #[test]
    fn parts_map_into_the_whole_and_never_go_back() {
        let seen = Mutex::new(Vec::new());
        let reporter = Reporter::new(|f, stage: &str| seen.lock().unwrap().push((f, stage.to_owned())));
        let whole = reporter.progress();
        let second = whole.part(0.5, 1.0);
        whole.part(0.0, 0.5).report(0.5, "a");
        second.report(0.5, "b");
        // A phase that starts again below what was shown does not move the fraction back.
        whole.part(0.0, 0.5).report(0.0, "c");
        second.part(0.5, 1.0).report(1.0, "d");
        let seen = seen.lock().unwrap().clone();
        let fractions: Vec<f32> = seen.iter().map(|(f, _)| *f).collect();
        assert_eq!(fractions, vec![0.25, 0.75, 0.75, 1.0]);
        assert_eq!(seen[2].1, "c");
    }

    #[test]
    fn a_parallel_count_reports_every_item_once_and_ends_at_the_total() {
        let seen = Mutex::new(Vec::new());
        let reporter = Reporter::new(|f, stage: &str| seen.lock().unwrap().push((f, stage.to_owned())));
        let progress = reporter.progress();
        let counter = progress.counter("fitting", "faces", 10_000);
        (0..10_000).into_par_iter().for_each(|_| counter.add(1));
        let seen = seen.lock().unwrap().clone();
        // One report a percent (two threads may both see the same percent crossed).
        assert!(seen.len() <= 1 + 2 * 101, "{} reports", seen.len());
        assert!(seen.contains(&(1.0, "fitting (10000 of 10000 faces)".to_owned())));
        assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0));
        assert_eq!(reporter.fraction(), 1.0);
    }

    #[test]
    fn cancel_is_seen_by_every_part() {
        let reporter = Reporter::silent();
        let part = reporter.progress().part(0.2, 0.4);
        assert_eq!(part.check(), Ok(()));
        reporter.cancel();
        assert_eq!(part.check(), Err(Cancelled));
        assert!(part.part(0.0, 0.1).is_cancelled());
    }
}
