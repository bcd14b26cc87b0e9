//! Autosave state of the editor, on top of [`meshpaint_core::io::autosave`]: the settings, the timer,
//! the recovery file of the open document and the recovery offer, and when the next
//! recovery write is due ([`AutosaveState::tick`]). The settings and the recovery dialog are
//! the autosave panel (`panels::autosave`); the editor runs the write as a job.
//!
//! Recovery files of project files sit next to them ([`autosave::recovery_path`]); those of
//! imported glTF files and the built-in scene go to `$XDG_STATE_HOME/meshpaint` (else
//! `~/.local/state/meshpaint`, else the temporary directory).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::io::autosave::{self, Autosaver, RecoveryInfo, RecoveryWrite};

use super::document::OpenDocument;
use super::text::human_bytes;

/// What an autosave job wrote.
#[derive(Debug, Clone)]
pub struct Autosaved {
    /// The recovery file.
    pub path: PathBuf,
    /// Size and time.
    pub write: RecoveryWrite,
    /// The edit generation it holds.
    pub generation: u64,
}

/// The document a restore replaces: what the restored document keeps of it.
#[derive(Debug, Clone)]
pub(crate) struct Restoring {
    pub(crate) path: Option<PathBuf>,
    pub(crate) project_path: Option<PathBuf>,
    pub(crate) title: String,
    pub(crate) format: ColorFormat,
}

/// Autosave settings and state.
#[derive(Debug, Clone)]
pub struct AutosaveState {
    /// Autosave on or off.
    pub enabled: bool,
    /// Seconds between autosaves (while there are unsaved edits).
    pub interval_seconds: u32,
    pub(crate) autosaver: Autosaver,
    /// The open document's recovery file.
    pub recovery_path: Option<PathBuf>,
    /// A recovery file found when the document opened, offered for restoring.
    pub offer: Option<RecoveryInfo>,
    /// When the last autosave finished.
    pub last_saved: Option<Instant>,
    pub(crate) restoring: Option<Restoring>,
    /// Where the recovery offer's Restore button was last logged (physical px).
    pub(crate) logged_restore_button: Option<[i32; 2]>,
}

/// The environment variable that sets the autosave interval in whole seconds (at least 1),
/// e.g. `MESHPAINT_AUTOSAVE_SECONDS=1` in the window tests; otherwise 60 s.
pub const INTERVAL_ENV: &str = "MESHPAINT_AUTOSAVE_SECONDS";

/// The interval [`INTERVAL_ENV`] asks for, else the default (a bad value is logged).
fn interval_from_env() -> u32 {
    let default = autosave::DEFAULT_INTERVAL.as_secs() as u32;
    let Some(value) = std::env::var_os(INTERVAL_ENV) else {
        return default;
    };
    match value.to_str().and_then(|v| v.trim().parse::<u32>().ok()).filter(|&s| s >= 1) {
        Some(seconds) => seconds,
        None => {
            log::warn!("{INTERVAL_ENV}={value:?} is not a number of seconds >= 1; autosaving every {default} s");
            default
        }
    }
}

impl Default for AutosaveState {
    fn default() -> Self {
        let interval_seconds = interval_from_env();
        AutosaveState {
            enabled: true,
            interval_seconds,
            autosaver: Autosaver::new(Duration::from_secs(u64::from(interval_seconds)), 0),
            recovery_path: None,
            offer: None,
            last_saved: None,
            restoring: None,
            logged_restore_button: None,
        }
    }
}

/// Where recovery files of documents without a project file go.
pub fn state_directory() -> PathBuf {
    if let Some(dir) = std::env::var_os("XDG_STATE_HOME").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir).join("meshpaint");
    }
    if let Some(home) = std::env::var_os("HOME").filter(|d| !d.is_empty()) {
        return PathBuf::from(home).join(".local/state/meshpaint");
    }
    std::env::temp_dir().join("meshpaint")
}

/// The recovery file of `open`.
pub fn recovery_path_of(open: &OpenDocument) -> Option<PathBuf> {
    match &open.project_path {
        Some(path) => autosave::recovery_path(path),
        None => Some(autosave::recovery_path_in(&state_directory(), &open.title)),
    }
}

/// What autosave wants this frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AutosaveTick {
    /// Nothing now; the next write falls due after this long, if one is pending (the editor
    /// draws no frame at rest, so the UI asks to be woken then).
    Wait(Option<Duration>),
    /// Write the recovery file here now.
    Write(PathBuf),
}

impl AutosaveState {
    /// Whether a recovery write of the open document is due at edit `generation`; `blocked`
    /// (a job running, a stroke in progress) waits without a wake-up, as do autosave being
    /// off and an open recovery offer.
    pub fn tick(&mut self, generation: u64, blocked: bool) -> AutosaveTick {
        if !self.enabled || blocked || self.offer.is_some() {
            return AutosaveTick::Wait(None);
        }
        let Some(path) = self.recovery_path.clone() else {
            return AutosaveTick::Wait(None);
        };
        self.autosaver.interval = Duration::from_secs(u64::from(self.interval_seconds.max(1)));
        let now = Instant::now();
        if !self.autosaver.is_due(now, generation) {
            return AutosaveTick::Wait(self.autosaver.due_at(generation).map(|at| at.saturating_duration_since(now)));
        }
        AutosaveTick::Write(path)
    }

    /// A document opened: patches a restored one, finds its recovery file, resets the timer.
    pub(crate) fn document_opened(&mut self, open: &mut OpenDocument, generation: u64) {
        if let Some(restoring) = self.restoring.take() {
            open.path = restoring.path;
            open.project_path = restoring.project_path;
            open.title = restoring.title;
            open.format = restoring.format;
            self.offer = None;
        } else {
            self.recovery_path = recovery_path_of(open);
            let document_path = open.project_path.as_deref().or(open.path.as_deref());
            self.offer = self
                .recovery_path
                .as_deref()
                .and_then(|path| autosave::find_recovery_at(path, document_path))
                .filter(|info| info.newer_than_document);
        }
        self.recovery_path = recovery_path_of(open);
        self.autosaver = Autosaver::new(Duration::from_secs(u64::from(self.interval_seconds)), generation);
    }

    /// An autosave failed: try again after another interval.
    pub(crate) fn failed(&mut self) {
        let generation = self.autosaver.saved_generation();
        self.autosaver.mark_saved(Instant::now(), generation);
    }

    /// Applies a finished autosave.
    pub(crate) fn finished(&mut self, autosaved: &Autosaved) {
        self.autosaver.mark_saved(Instant::now(), autosaved.generation);
        self.last_saved = Some(Instant::now());
        log::info!(
            "Autosaved {} ({}, {:.2} s)",
            autosaved.path.display(),
            human_bytes(autosaved.write.bytes),
            autosaved.write.seconds
        );
    }

    /// After a normal save of `open` at edit `generation`: the recovery file is obsolete;
    /// later autosaves go next to the saved project.
    pub(crate) fn saved(&mut self, open: Option<&OpenDocument>, generation: u64) {
        if let Some(path) = self.recovery_path.take()
            && let Err(error) = autosave::discard_recovery(&path)
        {
            log::warn!("{error}");
        }
        if let Some(open) = open {
            self.recovery_path = recovery_path_of(open);
        }
        self.autosaver.mark_saved(Instant::now(), generation);
    }
}
