//! The thread pool the program runs its parallel work on: rayon's global pool, with the
//! thread that starts the program (the editor's UI thread, a command's main thread) as one
//! of its threads.
//!
//! Why: a parallel call (`par_iter`, `join`) from a thread outside the pool hands the whole
//! job to the pool and blocks until it is done, so every call waits for a sleeping worker
//! to wake and then for the caller to be woken in turn. Between a stroke's dabs (one a
//! frame) the workers sleep, and on a virtual machine each wake-up takes tens of
//! microseconds, longer than a 10k-sample dab's own work. A caller inside the pool starts on
//! its half of the work at once, the workers join as they wake, and when it waits it looks
//! for work first. `bench paint`, 2.3M tris, 10k-sample dabs, median M samples/s, two
//! interleaved runs each against the default pool: `paint` 41.0 / 52.8 → 82.6 / 88.7,
//! `occlusion` (the editor's defaults) 40.2 / 56.8 → 65.6 / 67.4, `first_dab` 21.1 / 34.8 →
//! 55.5 / 55.0; `bench pack` and `bench load` unchanged within their spread
//! (docs/PERFORMANCE.md, Session 20).
//!
//! The pool keeps one worker per core besides the calling thread: the editor's background
//! jobs (opening a file, baking) run on their own threads and hand their parallel work to
//! the workers, so they keep every core while the UI thread waits for events.

/// Why the pool could not be set up as [`init`] asks.
pub type PoolError = rayon::ThreadPoolBuildError;

/// Makes the calling thread a thread of rayon's global pool, beside one worker per core.
/// Call it first, from the thread that does the program's parallel work (`main`); fails if
/// the global pool already exists (it is then used as it is, which is correct, only slower
/// for small parallel calls).
pub fn init() -> Result<(), PoolError> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    rayon::ThreadPoolBuilder::new().num_threads(cores + 1).use_current_thread().build_global()
}

/// Whether the calling thread is one of the global pool's threads (what [`init`] makes of
/// the thread it runs on).
pub fn caller_in_pool() -> bool {
    rayon::current_thread_index().is_some()
}
