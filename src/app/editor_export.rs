//! The editor's side of File → Export… ([`super::panels::export`]): the export and the UV
//! check it asks for, each started as a job on a snapshot of the document
//! ([`super::export`] does the work).

use std::sync::Arc;

use super::editor::Editor;
use super::export::{self, ExportRequest};
use super::job_output::JobOutput;
use super::jobs::JobKind;
use super::text::error_text;

impl Editor {
    /// Carries out File → Export…'s `request` on a snapshot of the document (a job).
    pub(crate) fn export(&mut self, request: ExportRequest) {
        let Some(open) = &self.document.open else {
            return;
        };
        let (document, source, budget) = (Arc::clone(&open.document), open.source(), self.budget());
        let (kind, label) = (request.write_kind(), request.label());
        let started = self.jobs.start(JobKind::Write(kind), label.clone(), move |job| {
            let written = export::run(&request, &document, &source, &budget, job);
            written.map(|written| JobOutput::Written(written, kind)).map_err(|error| error_text(&error))
        });
        self.report_start(started, &label);
    }

    /// Finds on a job which UVs a `size` bake would use, for File → Export….
    pub(crate) fn check_uvs(&mut self, size: u32) {
        let Some(open) = &self.document.open else {
            return;
        };
        let (document, source, budget) = (Arc::clone(&open.document), open.source(), self.budget());
        let started = self.jobs.start(JobKind::CheckUvs, "Checking the model's UVs", move |_| {
            Ok(JobOutput::UvsChecked(size, export::check_uvs(&source, &document, size, &budget)))
        });
        if started.is_err() {
            self.panels.export.uv_check_requested = None;
        }
    }
}
