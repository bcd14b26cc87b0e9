//! glTF 2.0 importer: `.glb` / `.gltf` → [`Scene`].
//!
//! What is read: every triangle primitive (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) of
//! every mesh instance reachable from the default scene (scene 0 when the file names no
//! default), with the node transforms composed from the scene root, the base-colour part
//! of the materials, their decoded base-colour textures and the vertex colours
//! (COLOR_0: float VEC3/VEC4 or normalized unsigned byte/short, as linear RGBA).
//!
//! What is ignored, with one line in [`Scene::warnings`]: point and line primitives,
//! skins, morph targets, animations, cameras and `KHR_lights_punctual` lights.
//!
//! What is refused with an [`ImportError`] naming the file and the problem: unreadable,
//! truncated or mislabelled files, JSON that does not follow the glTF schema, missing
//! buffers or external files, accessors whose data lies outside their buffer, accessors
//! of the wrong type, non-finite positions or node transforms, indices out of range,
//! node cycles and nodes with two parents, and required extensions that change geometry
//! (Draco, meshopt, mesh quantization, GPU instancing).
//!
//! Choices: a file with no scene at all (legal glTF, e.g. a library of meshes) and a
//! scene that holds no triangles both load as an empty [`Scene`] with a warning; the
//! caller decides whether an empty scene is worth showing. A POSITION accessor without
//! the `min`/`max` that glTF requires is accepted with a warning (the bounds are not
//! used), so that its data is still checked. Buffers are loaded when first used, so a
//! missing buffer that nothing reads does not fail the import. A mesh with no triangle
//! primitives gets no [`SourceMesh`] and no instance.
//!
//! Safety against hostile files: the GLB container, buffers and accessors are read by
//! this module with checked arithmetic and bounds checks; gltf-json is used only to
//! deserialize and validate the JSON, with the reference that makes gltf 1.4.1 panic
//! (an unresolved POSITION accessor) checked beforehand and the whole import wrapped in
//! `catch_unwind` as a last resort. Memory is bounded: decoded accessor data may not
//! exceed a budget proportional to the input size, so a small file cannot claim huge
//! counts; image decoding runs under `image` limits. The caller's [`ImportLimits`] bound the
//! node count, the triangles after instancing (counted while walking the scene, before any
//! instance is welded) and the texels of the textures (read from the image headers before
//! decoding).
//!
//! Files: `container` (GLB chunks; buffer and image bytes from the BIN chunk, data URIs
//! or external files), `schema` (the JSON: fix-ups, gltf-json validation), `accessor`
//! (element formats, the memory budget, bounds-checked accessor reads), `nodes` (the node
//! graph and the scene walk), `build` (triangle primitives → meshes), `geometry`
//! (triangle assembly, computed normals) and `materials` (base colour and its image).

use std::borrow::Cow;
use std::cell::OnceCell;
use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use gltf::json;

use crate::mesh::scene::Scene;

mod accessor;
mod build;
mod container;
mod geometry;
mod materials;
mod nodes;
mod schema;

/// Errors of the glTF importer. Every message names the file and the problem.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// A file (the glTF itself, an external buffer or image) could not be read.
    #[error("{path}: cannot read {what}: {source}")]
    Io {
        /// The glTF file the import was about.
        path: String,
        /// What could not be read (e.g. `the file`, `buffer 0 file "a.bin"`).
        what: String,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file is not glTF 2.0: bad GLB container, invalid JSON, or JSON that fails
    /// the glTF schema validation.
    #[error("{path}: not a valid glTF 2.0 file: {message}")]
    Gltf {
        /// The glTF file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The file parses but its content cannot be used (bad data, bad references,
    /// node cycles, non-finite values, out-of-range indices, unsupported extension...).
    #[error("{path}: {message}")]
    Invalid {
        /// The glTF file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A dependency panicked while reading the file; the panic was caught.
    #[error("{path}: internal error while reading the file (caught panic): {message}")]
    Panicked {
        /// The glTF file.
        path: String,
        /// The panic message.
        message: String,
    },
}

/// Limits the importer checks before the work they bound (the caller derives them from its
/// memory budget, see `colors::budget`): every limit past which a file is refused with a
/// message naming the count and the limit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImportLimits {
    /// Triangles over all mesh instances of the scene (after instancing, before welding).
    pub max_triangles: u64,
    /// Nodes in the file.
    pub max_nodes: u64,
    /// Texels of all decoded base-colour textures together (checked from the image
    /// headers, before decoding).
    pub max_texels: u64,
    /// What decides the limits (for messages), e.g. "6.0 GiB of memory".
    pub reason: String,
}

impl Default for ImportLimits {
    /// The format's own limits: 32-bit face ids, 2^24 nodes, 2^28 texels.
    fn default() -> Self {
        ImportLimits {
            max_triangles: u64::from(u32::MAX),
            max_nodes: 1 << 24,
            max_texels: 1 << 28,
            reason: "32-bit face ids".to_owned(),
        }
    }
}

/// Loads a `.glb` or `.gltf` file (external buffers and images are resolved relative
/// to the file's directory) into a [`Scene`] within the default [`ImportLimits`]. See the
/// module documentation for what is read, ignored and refused.
pub fn import_gltf(path: &Path) -> Result<Scene, ImportError> {
    import_gltf_within(path, &ImportLimits::default())
}

/// [`import_gltf`] within `limits`.
pub fn import_gltf_within(path: &Path, limits: &ImportLimits) -> Result<Scene, ImportError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        path: name.clone(),
        what: "the file".to_owned(),
        source,
    })?;
    import_gltf_slice_within(&bytes, path.parent(), &name, limits)
}

/// Loads a glTF from memory. `base_dir` resolves relative URIs of external buffers and
/// images (`None` refuses them); `name_for_messages` names the file in errors and
/// warnings, and a name ending in `.glb` marks content that must be binary glTF.
pub fn import_gltf_slice(bytes: &[u8], base_dir: Option<&Path>, name_for_messages: &str) -> Result<Scene, ImportError> {
    import_gltf_slice_within(bytes, base_dir, name_for_messages, &ImportLimits::default())
}

/// [`import_gltf_slice`] within `limits`.
pub fn import_gltf_slice_within(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name_for_messages: &str,
    limits: &ImportLimits,
) -> Result<Scene, ImportError> {
    let result = catch_unwind(AssertUnwindSafe(|| import_inner(bytes, base_dir, name_for_messages, false, limits)));
    match result {
        Ok(outcome) => outcome.map_err(|err| err.into_error(name_for_messages)),
        Err(payload) => {
            let message = if let Some(text) = payload.downcast_ref::<&str>() {
                (*text).to_owned()
            } else if let Some(text) = payload.downcast_ref::<String>() {
                text.clone()
            } else {
                "unknown panic".to_owned()
            };
            Err(ImportError::Panicked { path: name_for_messages.to_owned(), message })
        }
    }
}

/// An error before the file name is attached.
enum Fail {
    Io { what: String, source: std::io::Error },
    Gltf(String),
    Invalid(String),
}

impl Fail {
    fn into_error(self, path: &str) -> ImportError {
        let path = path.to_owned();
        match self {
            Fail::Io { what, source } => ImportError::Io { path, what, source },
            Fail::Gltf(message) => ImportError::Gltf { path, message },
            Fail::Invalid(message) => ImportError::Invalid { path, message },
        }
    }
}

fn invalid<T>(message: impl Into<String>) -> Result<T, Fail> {
    Err(Fail::Invalid(message.into()))
}

/// Decoded accessor data may use at most this many bytes plus
/// [`BUDGET_PER_INPUT_BYTE`] times the input size.
const BUDGET_BASE: u64 = 64 << 20;
/// See [`BUDGET_BASE`].
const BUDGET_PER_INPUT_BYTE: u64 = 32;

/// The import; `every_mesh` (for tests) also instances, at the identity, every mesh
/// the scene does not use, so that all of a file's data is read.
fn import_inner(
    bytes: &[u8],
    base_dir: Option<&Path>,
    name: &str,
    every_mesh: bool,
    limits: &ImportLimits,
) -> Result<Scene, Fail> {
    let is_glb = bytes.starts_with(b"glTF");
    let (json_bytes, bin) = if is_glb {
        container::split_glb(bytes).map_err(Fail::Gltf)?
    } else {
        let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
        if name.to_ascii_lowercase().ends_with(".glb") && first != Some(&b'{') {
            return Err(Fail::Gltf("named .glb but is not binary glTF (no 'glTF' magic at the start)".to_owned()));
        }
        if first.is_none() {
            return Err(Fail::Gltf("the file is empty".to_owned()));
        }
        (bytes, None)
    };
    let schema::ParsedJson { root, warnings, lights } = schema::parse_json(json_bytes)?;
    container::check_glb_buffer(&root, bin)?;
    if root.nodes.len() as u64 > limits.max_nodes {
        return invalid(format!(
            "the file has {} nodes, more than the {} allowed ({})",
            root.nodes.len(),
            limits.max_nodes,
            limits.reason
        ));
    }

    let budget = BUDGET_BASE.saturating_add((bytes.len() as u64).saturating_mul(BUDGET_PER_INPUT_BYTE));

    let mut importer = Importer {
        root: &root,
        buffers: root.buffers.iter().map(|_| OnceCell::new()).collect(),
        bin,
        base_dir,
        budget: std::cell::Cell::new(budget),
        scene: Scene { warnings, ..Scene::default() },
        mesh_map: HashMap::new(),
        material_map: HashMap::new(),
        image_map: HashMap::new(),
        limits,
        texels: std::cell::Cell::new(0),
    };
    importer.check_node_graph()?;
    importer.traverse_scene()?;
    if every_mesh {
        importer.instance_every_mesh()?;
    }
    importer.note_ignored(lights);
    let scene = importer.scene;
    for warning in &scene.warnings {
        if warning.starts_with("ignored:") {
            log::info!("{name}: {warning}");
        } else {
            log::warn!("{name}: {warning}");
        }
    }
    Ok(scene)
}

/// The state of one import: the validated JSON, the buffers loaded so far, the memory
/// budget left and the scene being built. Its methods live in the files of this module
/// (`accessor`, `nodes`, `build`, `materials`).
struct Importer<'a, 'b> {
    root: &'a json::Root,
    /// Buffers, loaded on first use.
    buffers: Vec<OnceCell<Cow<'b, [u8]>>>,
    /// The GLB BIN chunk, if any.
    bin: Option<&'b [u8]>,
    base_dir: Option<&'a Path>,
    budget: std::cell::Cell<u64>,
    scene: Scene,
    /// glTF mesh index → index into `scene.meshes` (`None`: the mesh has no triangles).
    mesh_map: HashMap<usize, Option<u32>>,
    /// glTF material index → index into `scene.materials`.
    material_map: HashMap<usize, u32>,
    /// glTF image index → index into `scene.textures` (`None`: not decodable).
    image_map: HashMap<usize, Option<u32>>,
    /// The limits checked before the work they bound.
    limits: &'a ImportLimits,
    /// Texels of the textures decoded so far.
    texels: std::cell::Cell<u64>,
}

impl Importer<'_, '_> {
    /// Adds the one info line about ignored features.
    fn note_ignored(&mut self, lights: usize) {
        let root = self.root;
        let morph_meshes = root
            .meshes
            .iter()
            .filter(|mesh| mesh.primitives.iter().any(|p| p.targets.as_ref().is_some_and(|t| !t.is_empty())))
            .count();
        let parts: Vec<String> = [
            (root.skins.len(), "skin", "skins"),
            (morph_meshes, "mesh with morph targets", "meshes with morph targets"),
            (root.animations.len(), "animation", "animations"),
            (root.cameras.len(), "camera", "cameras"),
            (lights, "light", "lights"),
        ]
        .iter()
        .filter(|(count, _, _)| *count > 0)
        .map(|&(count, one, many)| format!("{count} {}", if count == 1 { one } else { many }))
        .collect();
        if !parts.is_empty() {
            self.scene.warnings.push(format!("ignored: {}", parts.join(", ")));
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;

    /// Every fixture, with every mesh read (most validator fixtures have no scene):
    /// no panic, and whatever loads is consistent.
    #[test]
    fn every_mesh_of_every_invalid_fixture_reads_safely() {
        fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
            let Ok(entries) = std::fs::read_dir(dir) else {
                return;
            };
            for entry in entries.flatten() {
                let path = entry.path();
                if path.is_dir() {
                    walk(&path, out);
                } else if matches!(path.extension().and_then(|e| e.to_str()), Some("gltf" | "glb")) {
                    out.push(path);
                }
            }
        }
        let mut files = Vec::new();
        walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/invalid"), &mut files);
        assert!(files.len() > 80);
        let (mut loaded, mut refused) = (0, 0);
        for file in files {
            let bytes = std::fs::read(&file).unwrap();
            let name = file.display().to_string();
            let limits = ImportLimits::default();
            let outcome = catch_unwind(AssertUnwindSafe(|| import_inner(&bytes, file.parent(), &name, true, &limits)));
            match outcome {
                Ok(Ok(scene)) => {
                    loaded += 1;
                    for mesh in &scene.meshes {
                        let n = mesh.positions_local.len();
                        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
                        assert_eq!(mesh.normals_local.len(), n);
                        assert_eq!(mesh.uvs.len(), n);
                        assert!(mesh.colors.is_empty() || mesh.colors.len() == n);
                    }
                }
                Ok(Err(_)) => refused += 1,
                Err(_) => panic!("{name}: panicked"),
            }
        }
        assert!(loaded > 0 && refused > 0);
    }
}
