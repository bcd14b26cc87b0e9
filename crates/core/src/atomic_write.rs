//! The one way meshpaint writes a file: atomically. The bytes go to a new temporary file in
//! the same directory, which is flushed to disk (`sync_all`) and renamed over the target;
//! then the directory is synced so the rename itself is durable (best effort where
//! directories cannot be opened). A crash leaves either the old file or the new one, never
//! a torn one. Used by the packed-file writer (saves, exports, autosave) and the glTF export.

use std::io::Write;
use std::path::{Path, PathBuf};

/// A failed step of an atomic write, naming the file and the step.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot {action}: {source}", path.display())]
pub struct AtomicWriteError {
    /// The file the step was about (the target or the temporary file).
    pub path: PathBuf,
    /// The step, as "cannot …" completes it.
    pub action: &'static str,
    /// The cause.
    pub source: std::io::Error,
}

/// Writes `bytes` to `path` atomically (see the module docs).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    let Some(file_name) = path.file_name() else {
        return Err(AtomicWriteError {
            path: path.to_path_buf(),
            action: "write a file at a path without a file name",
            source: std::io::ErrorKind::InvalidInput.into(),
        });
    };
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(file_name);
    temp_name.push(format!(".{}-{}.tmp", std::process::id(), temp_counter()));
    let temp = dir.join(temp_name);
    if let Err(error) = write_temp_and_rename(&temp, path, bytes) {
        // Best effort: the temporary file may not exist (any more).
        let _ = std::fs::remove_file(&temp);
        return Err(error);
    }
    if let Ok(dir_handle) = std::fs::File::open(dir) {
        let _ = dir_handle.sync_all();
    }
    Ok(())
}

/// Writes `bytes` to the new file `temp`, syncs it and renames it to `path`.
fn write_temp_and_rename(temp: &Path, path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    let error = |path: &Path, action: &'static str| {
        let path = path.to_path_buf();
        move |source: std::io::Error| AtomicWriteError { path, action, source }
    };
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(temp)
        .map_err(error(temp, "create the temporary file"))?;
    file.write_all(bytes).map_err(error(temp, "write the temporary file"))?;
    file.sync_all().map_err(error(temp, "flush the temporary file to disk"))?;
    drop(file);
    std::fs::rename(temp, path).map_err(error(path, "rename the temporary file onto"))
}

/// A process-wide counter making temporary names unique across threads.
fn temp_counter() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    COUNTER.fetch_add(1, Ordering::Relaxed)
}
