//! Optimize in the editor: the plan runs on a worker thread (`paint::optimize::plan`), the
//! changes are applied as one undo step when it is done, if the colours did not change.

use std::sync::Arc;
use std::time::Duration;

use meshpaint_core::paint::optimize;

use super::editor::{Editor, JobOutput, Optimized};
use super::jobs::JobKind;
use super::state::Severity;
use super::text::{human_bytes, thousands};

impl Editor {
    /// Lowers face resolutions while every shown colour stays within `optimize_bound`
    /// (`paint::optimize`): plans the changes on a worker thread (the status line shows its
    /// progress), then applies them as one undo step and reports the memory before and after.
    pub fn optimize_resolutions(&mut self) {
        if self.paint.is_none() {
            self.set_status(Severity::Info, "Optimize works in paint mode (Tab).");
            return;
        }
        if self.jobs.is_busy() {
            self.set_status(Severity::Warning, "Busy: wait for the running job to finish before optimizing.");
            return;
        }
        self.end_stroke();
        let Some(open) = &self.document else {
            return;
        };
        let document = Arc::clone(&open.document);
        let (bound, generation) = (self.optimize_bound, self.edit_generation);
        let started = self.jobs.start(JobKind::Optimize, "Optimizing", move |job| {
            let plan =
                optimize::plan(&document.store, bound, &|fraction| job.progress(fraction, "trying lower resolutions"))
                    .map_err(|error| error.to_string())?;
            Ok(JobOutput::Optimized(Box::new(Optimized { plan, generation, bound })))
        });
        match started {
            Ok(()) => self.set_status(Severity::Info, format!("Optimizing (E = {bound})…")),
            Err(message) => self.set_status(Severity::Error, message),
        }
    }

    /// Applies a finished Optimize plan if the document is still the one planned on.
    pub(crate) fn finish_optimize(&mut self, optimized: Optimized, elapsed: Duration) {
        let Optimized { plan, generation, bound } = optimized;
        if generation != self.edit_generation || self.paint.is_none() {
            self.set_status(
                Severity::Warning,
                "The colours changed while Optimize ran (or paint mode ended); nothing was changed. Run it again.",
            );
            return;
        }
        let result = self.with_paint(|_, store, _, history| optimize::apply(store, history, &plan));
        match result {
            Some(Ok(report)) => {
                if report.step.is_some() {
                    self.edit_generation += 1;
                }
                if let Some(open) = self.document.as_mut() {
                    open.samples = open.document.store.sample_count();
                }
                // The store keeps RGBA32F samples: 16 bytes each.
                let bytes = |samples: u64| human_bytes(samples.saturating_mul(16));
                self.set_status(
                    Severity::Info,
                    format!(
                        "Optimize (E = {bound}): {} faces lowered, samples {} to {} ({} to {}), largest change {:.2e} ({:.2} s)",
                        thousands(report.faces_lowered.into()),
                        thousands(report.samples_before),
                        thousands(report.samples_after),
                        bytes(report.samples_before),
                        bytes(report.samples_after),
                        report.max_error,
                        elapsed.as_secs_f64()
                    ),
                );
            }
            Some(Err(error)) => self.set_status(Severity::Error, format!("Optimize: {error}")),
            None => self.set_status(Severity::Info, "Optimize works in paint mode (Tab)."),
        }
    }
}
