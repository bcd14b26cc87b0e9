//! Temporary files and directories, and where tests write images.

use std::path::{Path, PathBuf};

/// `meshpaint-<test crate>-<process id>-<name>` under the system temp dir: unique per test
/// binary, process and test.
fn temp_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("meshpaint-{}-{}-{name}", env!("CARGO_CRATE_NAME"), std::process::id()))
}

/// A directory under the temp dir, unique per test binary, process and test, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// Creates the directory (emptied first if a previous run left it behind).
    pub fn new(test: &str) -> Self {
        let path = temp_path(test);
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).unwrap();
        TempDir(path)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// A path inside the directory.
    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A file under the temp dir, unique per test binary, process and test, removed on drop.
pub struct TempFile(pub PathBuf);

impl TempFile {
    /// The path (nothing is created; a stale file is removed).
    pub fn new(test: &str, name: &str) -> Self {
        let path = temp_path(&format!("{test}-{name}"));
        let _ = std::fs::remove_file(&path);
        TempFile(path)
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Where tests write images and other output worth looking at: `target/test-output/`
/// (created). Tests never write into the source tree; see [`update_screenshot`].
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/test-output");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The environment variable that lets tests refresh the committed `screenshots/`.
pub const UPDATE_SCREENSHOTS: &str = "MESHPAINT_UPDATE_SCREENSHOTS";

/// Copies `image` (a file a test wrote, normally under [`output_dir`]) to
/// `screenshots/<name>` only when `MESHPAINT_UPDATE_SCREENSHOTS=1`: updating the committed
/// screenshots is an explicit command (`MESHPAINT_UPDATE_SCREENSHOTS=1 cargo test --test
/// app_window`), never a side effect of running the tests.
pub fn update_screenshot(image: &Path, name: &str) {
    if std::env::var_os(UPDATE_SCREENSHOTS).is_none_or(|value| value != "1") {
        return;
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(image, dir.join(name))
        .unwrap_or_else(|error| panic!("copying {} to screenshots/{name}: {error}", image.display()));
    eprintln!("updated screenshots/{name}");
}
