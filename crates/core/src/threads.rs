//! The thread pool of the thread that starts the program (the editor's UI thread, a
//! command's main thread): a rayon pool with that thread as one of its threads. The
//! program's other threads (the editor's background jobs) use rayon's global pool.
//!
//! Why: a parallel call (`par_iter`, `join`) from a thread outside the pool hands the whole
//! job to the pool and blocks until it is done, so every call waits for a sleeping worker
//! to wake and then for the caller to be woken in turn. Between a stroke's dabs (one a
//! frame) the workers sleep, and on a virtual machine each wake-up takes tens of
//! microseconds, longer than a 10k-sample dab's own work. A caller inside the pool starts on
//! its half of the work at once, the workers join as they wake, and when it waits it looks
//! for work first. Against the default pool, `bench paint`'s 10k-sample dabs at 2.3M
//! triangles ran faster in every row of two interleaved runs (`paint` and `first_dab` by half
//! or more, `occlusion`, the editor's defaults, by less), and `bench pack` and `bench load`
//! did not change beyond their spread. Those runs put the thread in the global pool; the
//! pool of its own below, measured after, was the same within the spread (both A/Bs: the git
//! history of docs/PERFORMANCE.md; the current figures: docs/BENCHMARKS.md).
//!
//! The thread's pool is its own, not rayon's global pool: a thread of a pool that waits in a
//! parallel call may pick up any job queued in that pool, and the editor's background jobs
//! (opening a file, autosave, Optimize) run on threads of their own that hand their parallel
//! work to the global pool. Were the UI thread in the global pool, a dab waiting for its last
//! piece could pick up a whole background pack and hold the UI until it ends. So the calling
//! thread and `cores − 1` workers form one pool (its parallel calls use every core), and the
//! background jobs keep the global pool's `cores` workers.

use std::sync::OnceLock;

/// Why the pool could not be set up as [`init`] asks.
pub type PoolError = rayon::ThreadPoolBuildError;

/// The calling thread's pool (kept for the program's life: rayon leaks a pool that holds the
/// thread that built it).
static POOL: OnceLock<rayon::ThreadPool> = OnceLock::new();

/// Makes the calling thread a thread of a pool of its own, beside `cores − 1` workers: every
/// parallel call it makes from then on runs in that pool. Call it first, from the thread that
/// does the program's parallel work (`main`). On failure (it was called before, or the
/// threads could not start) the thread's parallel calls go to rayon's global pool, as
/// before: correct, only slower for small calls.
pub fn init() -> Result<(), PoolError> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(cores)
        .thread_name(|k| format!("meshpaint worker {k}"))
        .use_current_thread()
        .build()?;
    // A second call fails in `build` (this thread is in a pool already), so this is the first.
    let _ = POOL.set(pool);
    Ok(())
}

/// Whether the calling thread is a thread of a rayon pool (what [`init`] makes of the
/// thread it runs on).
pub fn caller_in_pool() -> bool {
    rayon::current_thread_index().is_some()
}
