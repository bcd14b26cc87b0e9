//! Autosave and recovery: the document is written periodically to a *recovery file* next to
//! it, a packed file in RGBA32F (bit-exact colours, nothing lost to quantisation).
//!
//! Writes go through [`packed_file::write_file`]: the bytes go to a new temporary file in the
//! same directory, which is synced (`fsync`) and then renamed over the recovery file, and the
//! directory is synced. A rename within one directory is atomic, so a crash or `kill -9` at
//! any moment leaves either the previous recovery file or the new one, both complete, and
//! costs at most the edits since the last autosave. (`tests/app/autosave.rs` kills a writer at
//! random moments and reads the files back.) A killed writer can leave its temporary file
//! behind; [`remove_stale_temp_files`] deletes such leftovers of a recovery file.
//!
//! Naming: the recovery file of `dir/name.ext` is `dir/.name.ext.recovery.mpk`
//! ([`recovery_path`]); a document without a file (the built-in scene) uses
//! [`recovery_path_in`] with a directory of the caller's choice.
//!
//! The editor's use: an [`Autosaver`] decides when a save is due (the colours changed since the
//! last autosave and the interval has passed); the editor packs with [`pack_recovery`] and
//! writes with [`write_recovery`] on a worker thread. On open, [`find_recovery`] tells whether a
//! recovery file exists and is newer than the document; [`load_recovery`] opens it. After a
//! normal save, [`discard_recovery`] removes it.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use thiserror::Error;

use crate::colors::format::ColorFormat;
use crate::io::document::Document;
use crate::packing::file::{self as packed_file, PackedFileError, PackedSummary};
use crate::packing::linear::PackedMesh;
use crate::packing::packer::PackError;

/// The colour format of recovery files: bit-exact linear floats.
pub const RECOVERY_FORMAT: ColorFormat = ColorFormat::Rgba32F;
/// The default autosave interval.
pub const DEFAULT_INTERVAL: Duration = Duration::from_secs(60);
/// The suffix appended to a document's file name to name its recovery file.
pub const RECOVERY_SUFFIX: &str = ".recovery.mpk";

/// Errors of autosave and recovery; each names the file.
#[derive(Debug, Error)]
pub enum AutosaveError {
    /// Packing the document failed.
    #[error("{path}: packing for autosave: {source}")]
    Pack {
        /// The recovery file.
        path: PathBuf,
        /// The cause.
        source: PackError,
    },
    /// Writing or reading the packed file failed.
    #[error(transparent)]
    File(#[from] PackedFileError),
    /// The recovery file is valid but does not unpack into a store.
    #[error("{path}: {source}")]
    Unpack {
        /// The recovery file.
        path: PathBuf,
        /// The cause.
        source: PackError,
    },
    /// Removing the recovery file failed.
    #[error("{path}: cannot remove: {source}")]
    Remove {
        /// The recovery file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A path without a file name.
    #[error("{0}: not a file path")]
    NotAFile(PathBuf),
}

/// The recovery file of the document at `document_path`: `.NAME.recovery.mpk` in the same
/// directory. `None` for a path without a file name.
pub fn recovery_path(document_path: &Path) -> Option<PathBuf> {
    let name = document_path.file_name()?;
    let dir = document_path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut file = std::ffi::OsString::from(".");
    file.push(name);
    file.push(RECOVERY_SUFFIX);
    Some(dir.join(file))
}

/// The recovery file for a document named `name` without a file of its own, in `dir`.
pub fn recovery_path_in(dir: &Path, name: &str) -> PathBuf {
    let safe: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    dir.join(format!(".{safe}{RECOVERY_SUFFIX}"))
}

/// Packs `document` for a recovery file (RGBA32F). Cheap enough for the UI thread on small
/// meshes; the write is the slow part.
pub fn pack_recovery(document: &Document) -> Result<PackedMesh, PackError> {
    document.pack(RECOVERY_FORMAT)
}

/// What an autosave wrote.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecoveryWrite {
    /// Bytes of face records and colours.
    pub bytes: u64,
    /// Time to pack and write, seconds.
    pub seconds: f64,
}

/// Writes already-packed buffers to `path` atomically (temp file, fsync, rename, dir sync).
pub fn write_recovery_packed(path: &Path, packed: &PackedMesh) -> Result<(), AutosaveError> {
    packed_file::write_file(path, packed)?;
    Ok(())
}

/// Packs `document` in RGBA32F and writes it to `path` atomically.
pub fn write_recovery(path: &Path, document: &Document) -> Result<RecoveryWrite, AutosaveError> {
    let started = Instant::now();
    let packed = pack_recovery(document).map_err(|source| AutosaveError::Pack { path: path.to_path_buf(), source })?;
    write_recovery_packed(path, &packed)?;
    Ok(RecoveryWrite {
        bytes: packed.face_record_bytes() + packed.color_bytes(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// A recovery file found for a document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecoveryInfo {
    /// The recovery file.
    pub path: PathBuf,
    /// When it was last written.
    pub modified: Option<SystemTime>,
    /// Whether it is newer than the document file (`true` when the document is gone or
    /// either time is unknown: offering recovery is the safe side).
    pub newer_than_document: bool,
    /// What it holds, from its header (`None` when the header cannot be read: restoring
    /// then reports why).
    pub holds: Option<PackedSummary>,
}

/// The recovery file of the document at `document_path`, if one exists (its content is not
/// read here; [`load_recovery`] checks it fully).
pub fn find_recovery(document_path: &Path) -> Option<RecoveryInfo> {
    let path = recovery_path(document_path)?;
    find_recovery_at(&path, Some(document_path))
}

/// Like [`find_recovery`] for an explicit recovery path, compared with `document_path` if given.
pub fn find_recovery_at(path: &Path, document_path: Option<&Path>) -> Option<RecoveryInfo> {
    let metadata = std::fs::metadata(path).ok().filter(std::fs::Metadata::is_file)?;
    let modified = metadata.modified().ok();
    let document_modified = document_path.and_then(|p| std::fs::metadata(p).ok()).and_then(|m| m.modified().ok());
    let newer_than_document = match (modified, document_modified) {
        (Some(recovery), Some(document)) => recovery > document,
        _ => true,
    };
    let holds = packed_file::read_summary(path).ok();
    Some(RecoveryInfo { path: path.to_path_buf(), modified, newer_than_document, holds })
}

/// Opens a recovery file as a document (fully validated by the packed-file reader and the
/// unpacker).
pub fn load_recovery(path: &Path) -> Result<Document, AutosaveError> {
    let packed = packed_file::read_file(path)?;
    Document::from_packed(&packed).map_err(|source| AutosaveError::Unpack { path: path.to_path_buf(), source })
}

/// Removes the recovery file (after a normal save). A missing file is not an error.
pub fn discard_recovery(path: &Path) -> Result<(), AutosaveError> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(source) => Err(AutosaveError::Remove { path: path.to_path_buf(), source }),
    }
}

/// Deletes temporary files a killed writer of `path` left behind (`.NAME.PID-N.tmp` next
/// to it, as [`packed_file::write_file`] names them) whose process id is not this process's.
/// Returns how many were removed. Call it when no other process writes the same file.
pub fn remove_stale_temp_files(path: &Path) -> Result<usize, AutosaveError> {
    let name = path.file_name().ok_or_else(|| AutosaveError::NotAFile(path.to_path_buf()))?;
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    let (Some(prefix), own) = (prefix.to_str(), format!("{}-", std::process::id())) else {
        return Ok(0);
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(0);
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(file_name) = file_name.to_str() else {
            continue;
        };
        let Some(rest) = file_name.strip_prefix(prefix).and_then(|rest| rest.strip_suffix(".tmp")) else {
            continue;
        };
        // `PID-N`: digits, a dash, digits.
        let well_formed = rest.split_once('-').is_some_and(|(pid, n)| {
            !pid.is_empty() && !n.is_empty() && (pid.chars().chain(n.chars())).all(|c| c.is_ascii_digit())
        });
        if well_formed && !rest.starts_with(&own) && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    Ok(removed)
}

/// Decides when to autosave: when the colours changed since the last autosave (a generation
/// counter, e.g. [`crate::paint::undo::UndoHistory::generation`]) and `interval` has passed since
/// the last autosave (or since the first change after it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Autosaver {
    /// Time between autosaves.
    pub interval: Duration,
    saved_generation: u64,
    last_save: Option<Instant>,
    first_unsaved_change: Option<Instant>,
}

impl Autosaver {
    /// An autosaver for a document whose colours are at `generation` (already saved).
    pub fn new(interval: Duration, generation: u64) -> Self {
        Autosaver { interval, saved_generation: generation, last_save: None, first_unsaved_change: None }
    }

    /// Whether an autosave is due at `now` for colours at `generation`.
    pub fn is_due(&mut self, now: Instant, generation: u64) -> bool {
        if generation == self.saved_generation {
            self.first_unsaved_change = None;
            return false;
        }
        let since = *self.first_unsaved_change.get_or_insert(now);
        // Every change is at most `interval` old when it is saved: the oldest unsaved change
        // happened after the last save.
        let reference = self.last_save.unwrap_or(since);
        now.saturating_duration_since(reference) >= self.interval
    }

    /// When an autosave of the colours at `generation` falls due (`None` when nothing is
    /// unsaved, or before [`Autosaver::is_due`] has seen the first unsaved change): the time
    /// an idle editor must wake up at, since nothing else redraws it.
    pub fn due_at(&self, generation: u64) -> Option<Instant> {
        if generation == self.saved_generation {
            return None;
        }
        Some(self.last_save.or(self.first_unsaved_change)? + self.interval)
    }

    /// Records that the colours at `generation` were saved at `now`.
    pub fn mark_saved(&mut self, now: Instant, generation: u64) {
        self.saved_generation = generation;
        self.last_save = Some(now);
        self.first_unsaved_change = None;
    }

    /// The generation last saved.
    pub fn saved_generation(&self) -> u64 {
        self.saved_generation
    }

    /// Writes `document` to `path` if an autosave is due (see [`Autosaver::is_due`]).
    pub fn save_if_due(
        &mut self,
        now: Instant,
        generation: u64,
        path: &Path,
        document: &Document,
    ) -> Result<Option<RecoveryWrite>, AutosaveError> {
        if !self.is_due(now, generation) {
            return Ok(None);
        }
        let write = write_recovery(path, document)?;
        self.mark_saved(now, generation);
        Ok(Some(write))
    }
}
