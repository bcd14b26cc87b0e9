//! Long operations (import, conversion, export) on a worker thread, with progress.
//!
//! One job runs at a time. The UI thread starts it with [`Jobs::start`], polls it once per
//! frame with [`Jobs::poll`] and draws its [`Progress`]; the worker reports progress and
//! wakes the UI through a callback (the window's repaint request), so a finished job is
//! noticed at once without redrawing continuously. A panic inside a job becomes an error
//! message, never a crash. A job that reads its cancel flag ([`JobContext::cancel_flag`],
//! handed to the core's [`meshpaint_core::progress::Reporter`]) stops when [`Jobs::cancel`] is
//! called, and its failure is then reported as [`Finished::Cancelled`].

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What a job does: the editor applies a finished job by its kind, never by its label.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JobKind {
    /// Opening a document (`built_in`: the built-in scene, the fallback of a failed start).
    Open {
        /// Whether the built-in scene is being opened.
        built_in: bool,
    },
    /// Writing a file.
    Write(WriteKind),
    /// Repacking the store after paint mode.
    Repack,
    /// Planning Optimize (lower resolutions within a bound) on a snapshot of the store.
    Optimize,
    /// Building an alternate view (source texture, position colours) on the GPU.
    View,
    /// Writing a recovery file.
    Autosave,
    /// Checking which UVs a bake would use (File → Export…).
    CheckUvs,
}

/// Which kind of file a write job produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WriteKind {
    /// The project (packed file) was saved.
    Save,
    /// Packed buffers were exported.
    ExportPacked,
    /// A .glb was exported.
    ExportGltf,
    /// A .glb with the colours baked into a texture was exported.
    ExportBaked,
}

/// A callback that wakes the UI thread (a repaint request); called from the worker.
pub type Waker = Arc<dyn Fn() + Send + Sync>;

/// Progress of a running job: a fraction in `[0, 1]` and the name of the current stage.
#[derive(Debug, Default)]
pub struct Progress {
    fraction_bits: AtomicU32,
    stage: Mutex<String>,
    /// Set by [`Jobs::cancel`]; read by the job.
    cancelled: AtomicBool,
}

impl Progress {
    /// Enters `stage` at `fraction` of the whole job.
    pub fn set(&self, fraction: f32, stage: &str) {
        self.fraction_bits.store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
        if let Ok(mut current) = self.stage.lock() {
            stage.clone_into(&mut current);
        }
    }

    /// The fraction done, `[0, 1]`.
    pub fn fraction(&self) -> f32 {
        f32::from_bits(self.fraction_bits.load(Ordering::Relaxed))
    }

    /// The current stage, e.g. "importing".
    pub fn stage(&self) -> String {
        self.stage.lock().map(|stage| stage.clone()).unwrap_or_default()
    }
}

/// What a job hands to its body: progress reporting that also wakes the UI.
#[derive(Clone)]
pub struct JobContext {
    progress: Arc<Progress>,
    waker: Waker,
}

impl JobContext {
    /// Reports entering `stage` at `fraction` and wakes the UI to show it.
    pub fn progress(&self, fraction: f32, stage: &str) {
        self.progress.set(fraction, stage);
        (self.waker)();
    }

    /// The flag [`Jobs::cancel`] sets, for the job's work to read (the core's
    /// [`meshpaint_core::progress::Reporter::with_cancel_flag`]).
    pub fn cancel_flag(&self) -> &AtomicBool {
        &self.progress.cancelled
    }
}

/// A job that is running.
struct Running<T> {
    kind: JobKind,
    label: String,
    started: Instant,
    progress: Arc<Progress>,
    receiver: Receiver<Result<T, String>>,
}

/// What [`Jobs::poll`] found.
#[derive(Debug)]
pub enum Finished<T> {
    /// The job returned `Ok`.
    Done {
        /// Its result.
        value: T,
        /// How long it ran.
        elapsed: Duration,
    },
    /// The job failed (or panicked) with this message.
    Failed(String),
    /// The job stopped because [`Jobs::cancel`] asked it to.
    Cancelled,
}

/// The job runner: at most one job at a time.
pub struct Jobs<T> {
    running: Option<Running<T>>,
    waker: Waker,
}

impl<T> std::fmt::Debug for Jobs<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Jobs").field("running", &self.running.as_ref().map(|job| &job.label)).finish()
    }
}

impl<T: Send + 'static> Jobs<T> {
    /// A runner whose workers call `waker` on progress and completion.
    pub fn new(waker: Waker) -> Self {
        Jobs { running: None, waker }
    }

    /// Whether a job is running.
    pub fn is_busy(&self) -> bool {
        self.running.is_some()
    }

    /// Asks the running job to stop (it ends as [`Finished::Cancelled`] if it reads its flag).
    pub fn cancel(&self) {
        if let Some(job) = &self.running {
            job.progress.cancelled.store(true, Ordering::Relaxed);
        }
    }

    /// The running job's kind.
    pub fn kind(&self) -> Option<JobKind> {
        self.running.as_ref().map(|job| job.kind)
    }

    /// Whether the running job was asked to stop.
    pub fn is_cancelling(&self) -> bool {
        self.running.as_ref().is_some_and(|job| job.progress.cancelled.load(Ordering::Relaxed))
    }

    /// The running job's label, progress fraction, stage and age.
    pub fn status(&self) -> Option<(&str, f32, String, Duration)> {
        let job = self.running.as_ref()?;
        Some((&job.label, job.progress.fraction(), job.progress.stage(), job.started.elapsed()))
    }

    /// Starts `work` of `kind` on a worker thread under `label` (shown on the status line);
    /// refused (returns the label back as an error message) while another job runs.
    pub fn start(
        &mut self,
        kind: JobKind,
        label: impl Into<String>,
        work: impl FnOnce(&JobContext) -> Result<T, String> + Send + 'static,
    ) -> Result<(), String> {
        let label = label.into();
        if let Some(running) = &self.running {
            return Err(format!("cannot start “{label}”: “{}” is still running", running.label));
        }
        let progress = Arc::new(Progress::default());
        progress.set(0.0, "starting");
        let (sender, receiver) = mpsc::channel();
        let context = JobContext { progress: Arc::clone(&progress), waker: Arc::clone(&self.waker) };
        let spawned = std::thread::Builder::new().name(format!("job: {label}")).spawn(move || {
            let outcome = catch_unwind(AssertUnwindSafe(|| work(&context))).unwrap_or_else(|payload| {
                let message = payload
                    .downcast_ref::<&str>()
                    .map(|text| (*text).to_owned())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown panic".to_owned());
                Err(format!("internal error: {message}"))
            });
            // The receiver is gone only when the app is closing.
            let _ = sender.send(outcome);
            (context.waker)();
        });
        if let Err(error) = spawned {
            return Err(format!("cannot start a worker thread for “{label}”: {error}"));
        }
        self.running = Some(Running { kind, label, started: Instant::now(), progress, receiver });
        Ok(())
    }

    /// The running job's outcome if it has finished (the runner is then free again).
    pub fn poll(&mut self) -> Option<(JobKind, Finished<T>)> {
        let job = self.running.as_ref()?;
        let outcome = match job.receiver.try_recv() {
            Ok(Ok(value)) => Finished::Done { value, elapsed: job.started.elapsed() },
            Ok(Err(_)) if job.progress.cancelled.load(Ordering::Relaxed) => Finished::Cancelled,
            Ok(Err(message)) => Finished::Failed(message),
            Err(TryRecvError::Empty) => return None,
            Err(TryRecvError::Disconnected) => Finished::Failed("the worker thread stopped without an answer".into()),
        };
        let job = self.running.take()?;
        Some((job.kind, outcome))
    }

    /// Blocks until the running job finishes (tests and shutdown), at most `timeout`.
    pub fn wait(&mut self, timeout: Duration) -> Option<(JobKind, Finished<T>)> {
        let deadline = Instant::now() + timeout;
        loop {
            self.running.as_ref()?;
            if let Some(finished) = self.poll() {
                return Some(finished);
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}
