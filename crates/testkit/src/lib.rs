//! What the test binaries of the workspace share: paths in the workspace ([`workspace_path`],
//! [`model`]), temporary files and directories ([`TempDir`], [`TempFile`]), where tests write
//! images ([`output_dir`]) and the small meshes of [`meshpaint_core::synth`] in the shapes the
//! tests use ([`Mesh`], [`octahedron`], [`join`]). The random sources are
//! [`meshpaint_core::synth`]'s, re-exported under the names the tests use.
//!
//! A dev-dependency only, and GPU-free: the core's tests link it without wgpu. The headless
//! GPU helper of the GPU tests is `crates/render/tests/common/gpu.rs`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use meshpaint_core::colors::format::Rgba;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef, SampleSite};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::paint::undo::{StoreWriter, UndoError, UndoHistory};
pub use meshpaint_core::synth::rng::{SplitMix64, XorShift64 as Rng};
pub use meshpaint_core::synth::shapes::{OCTAHEDRON_TRIANGLES, icosphere, octahedron_positions};

/// The workspace root (the folder of `Cargo.lock`), wherever the test binary's crate is.
pub fn workspace_root() -> PathBuf {
    let mut dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    while !dir.join("Cargo.lock").exists() {
        assert!(dir.pop(), "no Cargo.lock above {}", env!("CARGO_MANIFEST_DIR"));
    }
    dir
}

/// A path relative to the workspace root.
pub fn workspace_path(relative: &str) -> PathBuf {
    workspace_root().join(relative)
}

/// A model under `assets/models/`.
pub fn model(relative: &str) -> PathBuf {
    workspace_path("assets/models").join(relative)
}

/// A unique path under the system temp dir: `meshpaint-<process id>-<n>-<name>`, where `n`
/// counts the calls of this process, so tests of one binary never share one.
fn temp_path(name: &str) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("meshpaint-{}-{n}-{name}", std::process::id()))
}

/// A directory under the temp dir, unique per process and call, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// Creates the directory.
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

/// A file under the temp dir, unique per process and call, removed on drop.
pub struct TempFile(pub PathBuf);

impl TempFile {
    /// The path (nothing is created).
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

/// Where tests write images and other output worth looking at: `target/test-output/` at
/// the workspace root (created). Tests never write into the source tree; see
/// [`update_screenshot`].
pub fn output_dir() -> PathBuf {
    let dir = workspace_path("target/test-output");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The environment variable that lets tests refresh the committed `screenshots/`.
pub const UPDATE_SCREENSHOTS: &str = "MESHPAINT_UPDATE_SCREENSHOTS";

/// Copies `image` (a file a test wrote, normally under [`output_dir`]) to
/// `screenshots/<name>` only when `MESHPAINT_UPDATE_SCREENSHOTS=1`: updating the committed
/// screenshots is an explicit command (`MESHPAINT_UPDATE_SCREENSHOTS=1 cargo test --test
/// editor app_window`), never a side effect of running the tests.
pub fn update_screenshot(image: &Path, name: &str) {
    if std::env::var_os(UPDATE_SCREENSHOTS).is_none_or(|value| value != "1") {
        return;
    }
    let dir = workspace_path("screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(image, dir.join(name))
        .unwrap_or_else(|error| panic!("copying {} to screenshots/{name}: {error}", image.display()));
    eprintln!("updated screenshots/{name}");
}

/// Positions and triangles.
pub type Mesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// The unit octahedron with its topology: 6 vertices, 12 edges, 8 faces.
pub fn octahedron() -> (Vec<[f32; 3]>, Topology) {
    let topology = Topology::build(6, &OCTAHEDRON_TRIANGLES).expect("the octahedron is a valid mesh");
    (octahedron_positions(), topology)
}

/// The unit octahedron as positions and triangles.
pub fn octahedron_mesh() -> Mesh {
    (octahedron_positions(), OCTAHEDRON_TRIANGLES.to_vec())
}

/// Two meshes in one (indices of the second shifted).
pub fn join((mut positions, mut triangles): Mesh, (p2, t2): Mesh) -> Mesh {
    let offset = positions.len() as u32;
    positions.extend(p2);
    triangles.extend(t2.into_iter().map(|t| t.map(|v| v + offset)));
    (positions, triangles)
}

/// Test set-up through the store's one write path ([`StoreWriter`], with no undo step open,
/// so nothing is recorded): the store's own setters are private to the core.
pub trait WriteThrough {
    /// Writes `color` to `sample`; whether the sample exists ([`UndoHistory::set_sample`]).
    fn write_sample(&mut self, sample: SampleRef, color: Rgba) -> bool;
    /// Writes `color_at(site)` to every sample ([`StoreWriter::fill_with`]).
    fn write_all(&mut self, color_at: impl FnMut(SampleSite) -> Rgba) -> u64;
    /// Changes the resolution of `face` ([`StoreWriter::set_face_resolution`]).
    fn write_resolution(&mut self, face: u32, resolution: Resolution) -> Result<bool, UndoError>;
}

impl WriteThrough for ColorStore {
    fn write_sample(&mut self, sample: SampleRef, color: Rgba) -> bool {
        UndoHistory::new(0).set_sample(self, sample, color)
    }

    fn write_all(&mut self, color_at: impl FnMut(SampleSite) -> Rgba) -> u64 {
        StoreWriter::new(self, &mut UndoHistory::new(0)).fill_with(color_at)
    }

    fn write_resolution(&mut self, face: u32, resolution: Resolution) -> Result<bool, UndoError> {
        StoreWriter::new(self, &mut UndoHistory::new(0)).set_face_resolution(face, resolution)
    }
}

/// PSNR in dB of `a` against `b` over the RGB channels of the pixels where either differs
/// from the background (`a`'s top-left pixel), written here from the definition.
pub fn psnr_over_foreground(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let background = *a.get_pixel(0, 0);
    let (mut sum, mut count) = (0.0f64, 0u64);
    for (p, q) in a.pixels().zip(b.pixels()) {
        if *p == background && *q == background {
            continue;
        }
        sum += (0..3).map(|k| (f64::from(p[k]) - f64::from(q[k])).powi(2)).sum::<f64>();
        count += 1;
    }
    10.0 * (255.0f64 * 255.0 / (sum / (3.0 * count.max(1) as f64)).max(1e-12)).log10()
}
