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
//! counts; image decoding runs under `image` limits.

use std::borrow::Cow;
use std::cell::OnceCell;
use std::collections::HashMap;
use std::io::Read;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;

use crate::mesh::scene::{Instance, Material, Scene, SourceMesh, Texture};

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

/// Loads a `.glb` or `.gltf` file (external buffers and images are resolved relative
/// to the file's directory) into a [`Scene`]. See the module documentation for what is
/// read, ignored and refused.
pub fn import_gltf(path: &Path) -> Result<Scene, ImportError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        path: name.clone(),
        what: "the file".to_owned(),
        source,
    })?;
    import_gltf_slice(&bytes, path.parent(), &name)
}

/// Loads a glTF from memory. `base_dir` resolves relative URIs of external buffers and
/// images (`None` refuses them); `name_for_messages` names the file in errors and
/// warnings, and a name ending in `.glb` marks content that must be binary glTF.
pub fn import_gltf_slice(bytes: &[u8], base_dir: Option<&Path>, name_for_messages: &str) -> Result<Scene, ImportError> {
    let result = catch_unwind(AssertUnwindSafe(|| import_inner(bytes, base_dir, name_for_messages, false)));
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

/// Extensions that change how geometry is stored or placed: a file that requires them
/// cannot be shown correctly without them.
const UNSUPPORTED_GEOMETRY_EXTENSIONS: [&str; 4] =
    ["KHR_draco_mesh_compression", "KHR_mesh_quantization", "EXT_meshopt_compression", "EXT_mesh_gpu_instancing"];

/// Decoded accessor data may use at most this many bytes plus
/// [`BUDGET_PER_INPUT_BYTE`] times the input size.
const BUDGET_BASE: u64 = 64 << 20;
/// See [`BUDGET_BASE`].
const BUDGET_PER_INPUT_BYTE: u64 = 32;
/// Largest external image file read.
const MAX_IMAGE_FILE: u64 = 256 << 20;
/// glTF's neutral vertex colour, used where a primitive has no COLOR_0.
const WHITE: [f32; 4] = [1.0; 4];
/// Largest decoded texture side.
const MAX_TEXTURE_SIDE: u32 = 16384;

/// The import; `every_mesh` (for tests) also instances, at the identity, every mesh
/// the scene does not use, so that all of a file's data is read.
fn import_inner(bytes: &[u8], base_dir: Option<&Path>, name: &str, every_mesh: bool) -> Result<Scene, Fail> {
    let is_glb = bytes.starts_with(b"glTF");
    let (json_bytes, bin) = if is_glb {
        split_glb(bytes).map_err(Fail::Gltf)?
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

    let mut value: serde_json::Value =
        serde_json::from_slice(json_bytes).map_err(|err| Fail::Gltf(format!("invalid JSON: {err}")))?;
    integerise(&mut value);
    add_missing_scene_nodes(&mut value);
    let lights = value
        .pointer("/extensions/KHR_lights_punctual/lights")
        .and_then(|lights| lights.as_array())
        .map_or(0, Vec::len);
    let mut root: json::Root = serde_json::from_value(value)
        .map_err(|err| Fail::Gltf(format!("JSON does not follow the glTF schema: {err}")))?;
    let mut warnings = Vec::new();
    prepare_for_validation(&mut root, &mut warnings)?;
    validate(&root)?;
    check_glb_buffer(&root, bin)?;

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

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let header = bytes.get(0..12).ok_or_else(|| "truncated GLB header (shorter than 12 bytes)".to_owned())?;
    let version = read_u32(header, 4).unwrap_or(0);
    let length = read_u32(header, 8).unwrap_or(0) as usize;
    if version != 2 {
        return Err(format!("unsupported GLB version {version} (only 2 is supported)"));
    }
    if length < 12 {
        return Err(format!("GLB header declares a length of {length} bytes, less than the header"));
    }
    let data = bytes
        .get(12..length)
        .ok_or_else(|| format!("truncated GLB: the header declares {length} bytes but the file has {}", bytes.len()))?;
    let mut json: Option<&[u8]> = None;
    let mut bin: Option<&[u8]> = None;
    let mut pos = 0usize;
    while pos < data.len() {
        let chunk_header = data
            .get(pos..pos.saturating_add(8))
            .ok_or_else(|| format!("truncated GLB chunk header at byte {}", pos + 12))?;
        let chunk_len = read_u32(chunk_header, 0).unwrap_or(0) as usize;
        let chunk_type = chunk_header.get(4..8).unwrap_or(&[]);
        let start = pos + 8;
        let end = start.checked_add(chunk_len).filter(|&end| end <= data.len());
        let Some(end) = end else {
            return Err(format!(
                "truncated GLB: chunk at byte {} declares {chunk_len} bytes but only {} remain",
                pos + 12,
                data.len() - start
            ));
        };
        let chunk = data.get(start..end).unwrap_or(&[]);
        match chunk_type {
            b"JSON" => {
                if json.is_some() {
                    return Err("GLB has more than one JSON chunk".to_owned());
                }
                if chunk.is_empty() {
                    return Err("GLB JSON chunk is empty".to_owned());
                }
                json = Some(chunk);
            }
            b"BIN\0" => {
                if json.is_none() {
                    return Err("GLB's first chunk is BIN, not JSON".to_owned());
                }
                if bin.is_some() {
                    return Err("GLB has more than one BIN chunk".to_owned());
                }
                bin = Some(chunk);
            }
            other => {
                if json.is_none() {
                    return Err(format!("GLB's first chunk has type {:?}, not JSON", String::from_utf8_lossy(other)));
                }
                // Unknown chunks after the JSON chunk are ignored, as the spec requires.
            }
        }
        pos = end;
    }
    let json = json.ok_or_else(|| "GLB has no JSON chunk".to_owned())?;
    Ok((json, bin))
}

fn read_u32(bytes: &[u8], offset: usize) -> Option<u32> {
    let raw: [u8; 4] = bytes.get(offset..offset.checked_add(4)?)?.try_into().ok()?;
    Some(u32::from_le_bytes(raw))
}

/// Fixes what would make gltf 1.4.1's validation panic or refuse a sound file.
fn prepare_for_validation(root: &mut json::Root, warnings: &mut Vec<String>) -> Result<(), Fail> {
    // gltf-json indexes `accessors` with the POSITION index without checking it.
    let accessor_count = root.accessors.len();
    for (m, mesh) in root.meshes.iter_mut().enumerate() {
        for (p, primitive) in mesh.primitives.iter_mut().enumerate() {
            if let Some(index) = primitive.attributes.get(&Checked::Valid(Semantic::Positions)) {
                let Some(accessor) = root.accessors.get_mut(index.value()) else {
                    return invalid(format!(
                        "mesh {m} primitive {p}: POSITION refers to accessor {} but the file has {accessor_count} accessors",
                        index.value()
                    ));
                };
                // gltf-json refuses a POSITION accessor without min/max; they are not
                // used here, so fill them in and keep checking the data itself.
                let valid_bound = |bound: &Option<json::Value>| {
                    bound.as_ref().is_some_and(|b| serde_json::from_value::<[f32; 3]>(b.clone()).is_ok())
                };
                if !valid_bound(&accessor.min) || !valid_bound(&accessor.max) {
                    accessor.min = Some(serde_json::json!([0.0, 0.0, 0.0]));
                    accessor.max = Some(serde_json::json!([0.0, 0.0, 0.0]));
                    warnings.push(format!(
                        "accessor {} (POSITION of mesh {m} primitive {p}) lacks valid min/max; ignored",
                        index.value()
                    ));
                }
            }
            // Application-specific attributes ("_NAME") are legal glTF but gltf-json
            // (without its `extras` feature) marks them invalid; they are not used here.
            let before = primitive.attributes.len();
            primitive.attributes.retain(|semantic, _| matches!(semantic, Checked::Valid(_)));
            let dropped = before - primitive.attributes.len();
            if dropped > 0 {
                warnings.push(format!("mesh {m} primitive {p}: ignored {dropped} unrecognised vertex attribute(s)"));
            }
        }
    }
    // gltf-json refuses required extensions it does not implement; those that only add
    // appearance or scene content can be ignored here.
    let mut kept = Vec::new();
    for extension in root.extensions_required.drain(..) {
        if UNSUPPORTED_GEOMETRY_EXTENSIONS.contains(&extension.as_str()) {
            return invalid(format!("the file requires extension {extension}, which is not supported"));
        }
        kept.push(extension);
    }
    for extension in kept {
        if extension != "KHR_lights_punctual" {
            warnings.push(format!("required extension {extension} is not supported; ignored"));
        }
    }
    Ok(())
}

/// gltf-json's schema validation (what `gltf::Document::from_json` runs), minus the
/// one finding that is legal glTF: an accessor with neither `bufferView` nor `sparse`
/// (its elements are zeros).
fn validate(root: &json::Root) -> Result<(), Fail> {
    use json::validation::{Error, Validate};
    let mut errors: Vec<(json::Path, Error)> = Vec::new();
    root.validate(root, json::Path::new, &mut |path, error| {
        errors.push((path(), error));
    });
    errors.retain(|(path, error)| {
        let path = path.as_str();
        !(*error == Error::Missing && path.starts_with("accessors[") && path.ends_with(".bufferView"))
    });
    if errors.is_empty() {
        return Ok(());
    }
    let shown: Vec<String> = errors.iter().take(5).map(|(path, error)| format!("{path}: {error}")).collect();
    let more = if errors.len() > 5 { format!(" (and {} more)", errors.len() - 5) } else { String::new() };
    Err(Fail::Gltf(format!("schema validation failed: {}{more}", shown.join("; "))))
}

/// The GLB BIN chunk must hold at least what buffer 0 declares (checked even when no
/// accessor reads it: a mismatch means a corrupt container).
fn check_glb_buffer(root: &json::Root, bin: Option<&[u8]>) -> Result<(), Fail> {
    if let (Some(bin), Some(buffer)) = (bin, root.buffers.first())
        && buffer.uri.is_none()
        && buffer.byte_length.0 > bin.len() as u64
    {
        return invalid(format!(
            "buffer 0 declares {} bytes but the GLB BIN chunk holds only {}",
            buffer.byte_length.0,
            bin.len()
        ));
    }
    Ok(())
}

/// `scene.nodes` is optional in glTF 2.0 but required by gltf-json: add an empty list.
fn add_missing_scene_nodes(value: &mut serde_json::Value) {
    if let Some(scenes) = value.get_mut("scenes").and_then(|s| s.as_array_mut()) {
        for scene in scenes {
            if let Some(scene) = scene.as_object_mut() {
                scene.entry("nodes").or_insert_with(|| serde_json::Value::Array(Vec::new()));
            }
        }
    }
}

/// Rewrites integral floating-point numbers (`1.0`) as integers: JSON does not tell
/// them apart and glTF accepts both, but gltf-json's integer fields refuse `1.0`.
fn integerise(value: &mut serde_json::Value) {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    match value {
        serde_json::Value::Number(number) if !number.is_i64() && !number.is_u64() => {
            if let Some(f) = number.as_f64()
                && f.fract() == 0.0
                && f.abs() < EXACT
            {
                *number =
                    if f >= 0.0 { serde_json::Number::from(f as u64) } else { serde_json::Number::from(f as i64) };
            }
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(integerise),
        serde_json::Value::Object(map) => map.values_mut().for_each(integerise),
        _ => {}
    }
}

/// Loads buffer `i`: the GLB BIN chunk, a data URI or an external file.
fn load_buffer<'a>(
    root: &json::Root,
    i: usize,
    bin: Option<&'a [u8]>,
    base_dir: Option<&Path>,
) -> Result<Cow<'a, [u8]>, Fail> {
    let Some(buffer) = root.buffers.get(i) else {
        return invalid(format!("buffer {i} does not exist"));
    };
    {
        let declared = buffer.byte_length.0;
        let data: Cow<'a, [u8]> = match buffer.uri.as_deref() {
            None => {
                let Some(bin) = bin.filter(|_| i == 0) else {
                    return invalid(format!("buffer {i} has no uri and there is no GLB BIN chunk for it"));
                };
                Cow::Borrowed(bin)
            }
            Some(uri) => load_uri(uri, base_dir, &format!("buffer {i}"), Some(declared))?,
        };
        let Some(data) = usize::try_from(declared).ok().and_then(|len| slice_cow(data, len)) else {
            return invalid(format!(
                "buffer {i} declares {declared} bytes but its data is shorter (missing or truncated data)"
            ));
        };
        Ok(data)
    }
}

fn slice_cow(data: Cow<'_, [u8]>, len: usize) -> Option<Cow<'_, [u8]>> {
    if data.len() < len {
        return None;
    }
    Some(match data {
        Cow::Borrowed(slice) => Cow::Borrowed(slice.get(..len)?),
        Cow::Owned(mut vec) => {
            vec.truncate(len);
            Cow::Owned(vec)
        }
    })
}

/// Reads a URI's bytes: a base64 data URI or a relative path. `limit` caps how much of
/// an external file is read.
fn load_uri(uri: &str, base_dir: Option<&Path>, what: &str, limit: Option<u64>) -> Result<Cow<'static, [u8]>, Fail> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, payload)) = rest.split_once(',') else {
            return invalid(format!("{what}: malformed data URI (no comma)"));
        };
        let Some(mime) = header.strip_suffix(";base64") else {
            return invalid(format!("{what}: data URI is not base64-encoded"));
        };
        if what.starts_with("buffer") && !matches!(mime, "application/octet-stream" | "application/gltf-buffer") {
            return invalid(format!(
                "{what}: data URI has media type {mime:?}, not application/octet-stream or application/gltf-buffer"
            ));
        }
        let Some(decoded) = decode_base64(payload) else {
            return invalid(format!("{what}: data URI holds invalid base64"));
        };
        return Ok(Cow::Owned(decoded));
    }
    let scheme_end = uri.find(':');
    let path_sep = uri.find(['/', '\\']);
    if let Some(colon) = scheme_end
        && path_sep.is_none_or(|sep| colon < sep)
    {
        return invalid(format!(
            "{what}: URI {uri:?} uses a scheme that is not supported (only data URIs and relative paths are)"
        ));
    }
    let Some(relative) = percent_decode(uri) else {
        return invalid(format!("{what}: URI {uri:?} has invalid percent-encoding"));
    };
    let Some(base_dir) = base_dir else {
        return invalid(format!("{what}: refers to external file {relative:?} but no base directory was given"));
    };
    if relative.starts_with(['/', '\\']) || Path::new(&relative).is_absolute() {
        return invalid(format!("{what}: URI {uri:?} is an absolute path; only relative paths are supported"));
    }
    let full: PathBuf = base_dir.join(&relative);
    let label = format!("{what} file {relative:?} ({})", full.display());
    let metadata = std::fs::metadata(&full).map_err(|source| Fail::Io { what: label.clone(), source })?;
    if !metadata.is_file() {
        return invalid(format!("{label} is not a regular file"));
    }
    // Never read more than the file holds (a buffer's declared length is only a claim)
    // nor, for images, more than MAX_IMAGE_FILE.
    let cap = match limit {
        Some(limit) => limit.min(metadata.len()),
        None if metadata.len() > MAX_IMAGE_FILE => {
            return invalid(format!(
                "{label} is {} bytes, larger than the {MAX_IMAGE_FILE} accepted for an image",
                metadata.len()
            ));
        }
        None => metadata.len(),
    };
    let mut data = Vec::new();
    std::fs::File::open(&full)
        .and_then(|file| file.take(cap).read_to_end(&mut data))
        .map_err(|source| Fail::Io { what: label.clone(), source })?;
    Ok(Cow::Owned(data))
}

fn decode_base64(text: &str) -> Option<Vec<u8>> {
    fn value(c: u8) -> Option<u32> {
        match c {
            b'A'..=b'Z' => Some(u32::from(c - b'A')),
            b'a'..=b'z' => Some(u32::from(c - b'a') + 26),
            b'0'..=b'9' => Some(u32::from(c - b'0') + 52),
            b'+' | b'-' => Some(62),
            b'/' | b'_' => Some(63),
            _ => None,
        }
    }
    let trimmed = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(trimmed.len() / 4 * 3 + 3);
    let mut acc = 0u32;
    let mut bits = 0u32;
    for &c in trimmed {
        acc = (acc << 6) | value(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push(((acc >> bits) & 0xff) as u8);
        }
    }
    if bits >= 6 {
        return None;
    }
    Some(out)
}

fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The layout of one accessor element in a buffer.
#[derive(Clone, Copy)]
struct ElementFormat {
    component: ComponentType,
    components: usize,
    normalized: bool,
}

impl ElementFormat {
    fn size(self) -> usize {
        component_size(self.component) * self.components
    }
}

fn component_size(component: ComponentType) -> usize {
    match component {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn type_components(ty: Type) -> usize {
    match ty {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

fn type_name(ty: Type) -> &'static str {
    match ty {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

fn component_name(component: ComponentType) -> &'static str {
    match component {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

/// Component `i` of an element, as f32 (normalized integers mapped to [0, 1] / [-1, 1]).
fn component_f32(bytes: &[u8], format: ElementFormat, i: usize) -> Option<f32> {
    let size = component_size(format.component);
    let at = i.checked_mul(size)?;
    let raw = bytes.get(at..at.checked_add(size)?)?;
    let norm = format.normalized;
    Some(match format.component {
        ComponentType::F32 => f32::from_le_bytes(raw.try_into().ok()?),
        ComponentType::U8 => {
            let v = f32::from(*raw.first()?);
            if norm { v / 255.0 } else { v }
        }
        ComponentType::I8 => {
            let v = f32::from(i8::from_le_bytes(raw.try_into().ok()?));
            if norm { (v / 127.0).max(-1.0) } else { v }
        }
        ComponentType::U16 => {
            let v = f32::from(u16::from_le_bytes(raw.try_into().ok()?));
            if norm { v / 65535.0 } else { v }
        }
        ComponentType::I16 => {
            let v = f32::from(i16::from_le_bytes(raw.try_into().ok()?));
            if norm { (v / 32767.0).max(-1.0) } else { v }
        }
        ComponentType::U32 => {
            let v = u32::from_le_bytes(raw.try_into().ok()?) as f32;
            if norm { v / u32::MAX as f32 } else { v }
        }
    })
}

fn index_value(bytes: &[u8], component: ComponentType) -> Option<u32> {
    match component {
        ComponentType::U8 => bytes.first().map(|&b| u32::from(b)),
        ComponentType::U16 => Some(u32::from(u16::from_le_bytes(bytes.get(0..2)?.try_into().ok()?))),
        ComponentType::U32 => Some(u32::from_le_bytes(bytes.get(0..4)?.try_into().ok()?)),
        _ => None,
    }
}

fn decode_vec3(bytes: &[u8], format: ElementFormat) -> Option<[f32; 3]> {
    Some([component_f32(bytes, format, 0)?, component_f32(bytes, format, 1)?, component_f32(bytes, format, 2)?])
}

fn decode_vec2(bytes: &[u8], format: ElementFormat) -> Option<[f32; 2]> {
    Some([component_f32(bytes, format, 0)?, component_f32(bytes, format, 1)?])
}

/// A COLOR_0 element as RGBA; a three-component element gets alpha 1.
fn decode_color(bytes: &[u8], format: ElementFormat) -> Option<[f32; 4]> {
    let [r, g, b] = decode_vec3(bytes, format)?;
    let a = if format.components >= 4 { component_f32(bytes, format, 3)? } else { 1.0 };
    Some([r, g, b, a])
}

fn decode_index(bytes: &[u8], format: ElementFormat) -> Option<u32> {
    index_value(bytes, format.component)
}

/// What an accessor must look like for one use.
struct Expect {
    purpose: String,
    ty: Type,
    components: &'static [(ComponentType, bool)],
}

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
}

impl Importer<'_, '_> {
    fn charge(&self, bytes: u64, what: &str) -> Result<(), Fail> {
        let left = self.budget.get();
        if bytes > left {
            return invalid(format!("{what} needs {bytes} bytes of memory, more than the file's size justifies"));
        }
        self.budget.set(left - bytes);
        Ok(())
    }

    /// The bytes of buffer `index`, loaded on first use (which raises the memory budget
    /// by what the buffer's size justifies).
    fn buffer(&self, index: usize, what: &str) -> Result<&[u8], Fail> {
        let Some(cell) = self.buffers.get(index) else {
            return invalid(format!("{what}: buffer {index} does not exist"));
        };
        if cell.get().is_none() {
            let data = load_buffer(self.root, index, self.bin, self.base_dir)?;
            let extra = (data.len() as u64).saturating_mul(BUDGET_PER_INPUT_BYTE);
            self.budget.set(self.budget.get().saturating_add(extra));
            let _ = cell.set(data);
        }
        match cell.get() {
            Some(data) => Ok(data.as_ref()),
            None => invalid(format!("{what}: buffer {index} could not be loaded")),
        }
    }

    /// The bytes of buffer view `index`, bounds-checked against its buffer.
    fn view_bytes(&self, index: usize, what: &str) -> Result<(&[u8], Option<usize>), Fail> {
        let Some(view) = self.root.buffer_views.get(index) else {
            return invalid(format!("{what}: bufferView {index} does not exist"));
        };
        let buffer_index = view.buffer.value();
        let buffer = self.buffer(buffer_index, what)?;
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let length = view.byte_length.0;
        let range =
            offset.checked_add(length).and_then(|end| Some(usize::try_from(offset).ok()?..usize::try_from(end).ok()?));
        let Some(bytes) = range.and_then(|range| buffer.get(range)) else {
            return invalid(format!(
                "{what}: bufferView {index} (offset {offset}, length {length}) lies outside buffer {buffer_index} ({} bytes)",
                buffer.len()
            ));
        };
        Ok((bytes, view.byte_stride.map(|s| s.0)))
    }

    /// Reads accessor `index` element by element with `decode`, applying sparse data.
    fn read_accessor<T: Copy + Default>(
        &mut self,
        index: usize,
        expect: &Expect,
        decode: fn(&[u8], ElementFormat) -> Option<T>,
    ) -> Result<Vec<T>, Fail> {
        let root = self.root;
        let what = format!("{} (accessor {index})", expect.purpose);
        let Some(accessor) = root.accessors.get(index) else {
            return invalid(format!("{what}: accessor does not exist"));
        };
        let (Checked::Valid(ty), Checked::Valid(component)) = (accessor.type_, accessor.component_type) else {
            return invalid(format!("{what}: invalid type or componentType"));
        };
        let component = component.0;
        let allowed =
            expect.components.iter().any(|&(c, normalized)| c == component && normalized == accessor.normalized);
        if ty != expect.ty || !allowed {
            let allowed_names: Vec<String> = expect
                .components
                .iter()
                .map(|&(c, n)| format!("{}{}", component_name(c), if n { " normalized" } else { "" }))
                .collect();
            return invalid(format!(
                "{what}: wrong accessor type {} {}{} (expected {} of {})",
                type_name(ty),
                component_name(component),
                if accessor.normalized { " normalized" } else { "" },
                type_name(expect.ty),
                allowed_names.join(" or ")
            ));
        }
        let format = ElementFormat { component, components: type_components(ty), normalized: accessor.normalized };
        let element_size = format.size();
        let count_u64 = accessor.count.0;
        let Ok(count) = usize::try_from(count_u64) else {
            return invalid(format!("{what}: count {count_u64} is too large"));
        };
        let out_bytes = count_u64.saturating_mul(std::mem::size_of::<T>() as u64);

        let mut out: Vec<T> = if let Some(view_index) = accessor.buffer_view {
            let (bytes, stride) = self.view_bytes(view_index.value(), &what)?;
            let stride = stride.unwrap_or(element_size);
            if stride < element_size {
                return invalid(format!("{what}: byteStride {stride} is smaller than the element size {element_size}"));
            }
            let offset = accessor.byte_offset.map_or(0, |o| o.0);
            let needed = if count == 0 {
                Some(0)
            } else {
                (count as u64 - 1)
                    .checked_mul(stride as u64)
                    .and_then(|v| v.checked_add(element_size as u64))
                    .and_then(|v| v.checked_add(offset))
            };
            let Some(needed) = needed.filter(|&n| n <= bytes.len() as u64) else {
                return invalid(format!(
                    "{what}: {count} elements at offset {offset} with stride {stride} lie outside bufferView {} ({} bytes): data out of bounds",
                    view_index.value(),
                    bytes.len()
                ));
            };
            let _ = needed;
            self.charge(out_bytes, &what)?;
            let offset = usize::try_from(offset).unwrap_or(usize::MAX);
            let mut out = Vec::with_capacity(count);
            for k in 0..count {
                let element = k
                    .checked_mul(stride)
                    .and_then(|start| start.checked_add(offset))
                    .and_then(|start| bytes.get(start..start.checked_add(element_size)?))
                    .and_then(|element| decode(element, format));
                let Some(value) = element else {
                    return invalid(format!("{what}: element {k} cannot be read"));
                };
                out.push(value);
            }
            out
        } else {
            self.charge(out_bytes, &what)?;
            vec![T::default(); count]
        };

        if let Some(sparse) = &accessor.sparse {
            let sparse_count_u64 = sparse.count.0;
            let Some(sparse_count) = usize::try_from(sparse_count_u64).ok().filter(|&c| c <= count) else {
                return invalid(format!("{what}: sparse count {sparse_count_u64} exceeds the accessor count {count}"));
            };
            let Checked::Valid(index_type) = sparse.indices.component_type else {
                return invalid(format!("{what}: invalid sparse index componentType"));
            };
            let index_size = component_size(index_type.0);
            let (index_bytes, _) = self.view_bytes(sparse.indices.buffer_view.value(), &what)?;
            let (value_bytes, _) = self.view_bytes(sparse.values.buffer_view.value(), &what)?;
            let index_start = usize::try_from(sparse.indices.byte_offset.0).unwrap_or(usize::MAX);
            let value_start = usize::try_from(sparse.values.byte_offset.0).unwrap_or(usize::MAX);
            let index_slice = sparse_count
                .checked_mul(index_size)
                .and_then(|len| index_bytes.get(index_start..index_start.checked_add(len)?));
            let value_slice = sparse_count
                .checked_mul(element_size)
                .and_then(|len| value_bytes.get(value_start..value_start.checked_add(len)?));
            let (Some(index_slice), Some(value_slice)) = (index_slice, value_slice) else {
                return invalid(format!("{what}: sparse data lies outside its bufferView"));
            };
            for (k, (raw_index, raw_value)) in
                index_slice.chunks_exact(index_size).zip(value_slice.chunks_exact(element_size)).enumerate()
            {
                let target = index_value(raw_index, index_type.0).map(|i| i as usize);
                let value = decode(raw_value, format);
                let slot = target.and_then(|t| out.get_mut(t));
                let (Some(slot), Some(value)) = (slot, value) else {
                    return invalid(format!("{what}: sparse element {k} has an index out of range or unreadable data"));
                };
                *slot = value;
            }
        }
        Ok(out)
    }

    /// Refuses node cycles and nodes with more than one parent.
    fn check_node_graph(&self) -> Result<(), Fail> {
        let nodes = &self.root.nodes;
        // Cycle detection: iterative depth-first search with three colours.
        let mut colour = vec![0u8; nodes.len()]; // 0 new, 1 on the current path, 2 done
        for start in 0..nodes.len() {
            if colour.get(start) != Some(&0) {
                continue;
            }
            let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
            if let Some(c) = colour.get_mut(start) {
                *c = 1;
            }
            while let Some(&mut (node, ref mut next_child)) = stack.last_mut() {
                let children = nodes.get(node).and_then(|n| n.children.as_deref()).unwrap_or(&[]);
                if let Some(child) = children.get(*next_child) {
                    *next_child += 1;
                    let child = child.value();
                    match colour.get(child) {
                        None => {
                            return invalid(format!(
                                "node {} has child {child}, which does not exist",
                                node_label(self.root, node)
                            ));
                        }
                        Some(1) => {
                            return invalid(format!(
                                "node hierarchy has a cycle: node {} is its own ancestor (reached again from node {})",
                                node_label(self.root, child),
                                node_label(self.root, node)
                            ));
                        }
                        Some(0) => {
                            if let Some(c) = colour.get_mut(child) {
                                *c = 1;
                            }
                            stack.push((child, 0));
                        }
                        Some(_) => {}
                    }
                } else {
                    if let Some(c) = colour.get_mut(node) {
                        *c = 2;
                    }
                    stack.pop();
                }
            }
        }
        let mut parent: Vec<Option<usize>> = vec![None; nodes.len()];
        for (index, node) in nodes.iter().enumerate() {
            for child in node.children.iter().flatten() {
                let child = child.value();
                let Some(slot) = parent.get_mut(child) else {
                    continue;
                };
                if let Some(previous) = *slot {
                    return invalid(format!(
                        "node {} has two parents (nodes {previous} and {index}); glTF nodes must form trees",
                        node_label(self.root, child)
                    ));
                }
                *slot = Some(index);
            }
        }
        Ok(())
    }

    fn traverse_scene(&mut self) -> Result<(), Fail> {
        let root = self.root;
        let scene_index = match root.scene {
            Some(index) => index.value(),
            None if !root.scenes.is_empty() => 0,
            None => {
                self.scene.warnings.push("the file defines no scene, so there is nothing to show".to_owned());
                return Ok(());
            }
        };
        let Some(gltf_scene) = root.scenes.get(scene_index) else {
            return invalid(format!("default scene {scene_index} does not exist"));
        };
        let mut reached = vec![false; root.nodes.len()];
        let mut stack: Vec<(usize, Mat4)> = Vec::new();
        for node in gltf_scene.nodes.iter().rev() {
            stack.push((node.value(), Mat4::IDENTITY));
        }
        let mut non_triangle = 0usize;
        while let Some((index, parent_world)) = stack.pop() {
            let Some(node) = root.nodes.get(index) else {
                return invalid(format!("scene {scene_index} refers to node {index}, which does not exist"));
            };
            match reached.get_mut(index) {
                Some(seen) if *seen => {
                    return invalid(format!(
                        "node {} is reached twice from scene {scene_index} (listed as a scene root and also a child, or listed twice)",
                        node_label(root, index)
                    ));
                }
                Some(seen) => *seen = true,
                None => {}
            }
            let local = local_transform(node).ok_or_else(|| {
                Fail::Invalid(format!("node {} has a non-finite or invalid transform", node_label(root, index)))
            })?;
            let world = parent_world * local;
            if !world.is_finite() {
                return invalid(format!(
                    "node {}: the composed world transform is non-finite",
                    node_label(root, index)
                ));
            }
            if let Some(mesh) = node.mesh
                && let Some(mesh_index) = self.mesh_for(mesh.value(), &mut non_triangle)?
            {
                self.scene.instances.push(Instance { mesh: mesh_index, world_from_local: world });
            }
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), world));
            }
        }
        if non_triangle > 0 {
            self.scene
                .warnings
                .push(format!("skipped {non_triangle} point/line primitive(s) (only triangles are imported)"));
        }
        if self.scene.instances.is_empty() {
            self.scene.warnings.push(format!("scene {scene_index} contains no triangles"));
        }
        Ok(())
    }

    /// Instances every mesh not instanced yet at the identity (tests only).
    fn instance_every_mesh(&mut self) -> Result<(), Fail> {
        let mut non_triangle = 0;
        for index in 0..self.root.meshes.len() {
            if self.mesh_map.contains_key(&index) {
                continue;
            }
            if let Some(mesh) = self.mesh_for(index, &mut non_triangle)? {
                self.scene.instances.push(Instance { mesh, world_from_local: Mat4::IDENTITY });
            }
        }
        Ok(())
    }

    /// The scene mesh for glTF mesh `index`, built on first use.
    fn mesh_for(&mut self, index: usize, non_triangle: &mut usize) -> Result<Option<u32>, Fail> {
        if let Some(&known) = self.mesh_map.get(&index) {
            return Ok(known);
        }
        let mesh = self.build_mesh(index, non_triangle)?;
        let result = if mesh.triangles.is_empty() {
            None
        } else {
            let Ok(slot) = u32::try_from(self.scene.meshes.len()) else {
                return invalid("too many meshes");
            };
            self.scene.meshes.push(mesh);
            Some(slot)
        };
        self.mesh_map.insert(index, result);
        Ok(result)
    }

    fn build_mesh(&mut self, index: usize, non_triangle: &mut usize) -> Result<SourceMesh, Fail> {
        let root = self.root;
        let Some(gltf_mesh) = root.meshes.get(index) else {
            return invalid(format!("mesh {index} does not exist"));
        };
        let mut mesh = SourceMesh {
            name: gltf_mesh.name.clone().unwrap_or_else(|| format!("mesh {index}")),
            ..SourceMesh::default()
        };
        for (p, primitive) in gltf_mesh.primitives.iter().enumerate() {
            let label = format!("mesh {index} primitive {p}");
            let Checked::Valid(mode) = primitive.mode else {
                return invalid(format!("{label}: invalid mode"));
            };
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                *non_triangle += 1;
                continue;
            }
            let Some(position_accessor) = primitive.attributes.get(&Checked::Valid(Semantic::Positions)) else {
                return invalid(format!("{label}: no POSITION attribute"));
            };
            let positions = self.read_accessor(
                position_accessor.value(),
                &Expect {
                    purpose: format!("{label} POSITION"),
                    ty: Type::Vec3,
                    components: &[(ComponentType::F32, false)],
                },
                decode_vec3,
            )?;
            if let Some(bad) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                return invalid(format!(
                    "{label}: POSITION (accessor {}) of vertex {bad} is non-finite (NaN or infinite)",
                    position_accessor.value()
                ));
            }
            let vertex_count = positions.len();
            let base = mesh.positions_local.len();
            let Some(base_u32) = u32::try_from(base)
                .ok()
                .filter(|b| u32::try_from(vertex_count).is_ok_and(|n| b.checked_add(n).is_some()))
            else {
                return invalid(format!("{label}: the mesh has more than 2^32 vertices"));
            };

            let corners: Vec<u32> = match primitive.indices {
                Some(indices_accessor) => {
                    let indices = self.read_accessor(
                        indices_accessor.value(),
                        &Expect {
                            purpose: format!("{label} indices"),
                            ty: Type::Scalar,
                            components: &[
                                (ComponentType::U8, false),
                                (ComponentType::U16, false),
                                (ComponentType::U32, false),
                            ],
                        },
                        decode_index,
                    )?;
                    if let Some((k, &bad)) = indices.iter().enumerate().find(|&(_, &i)| i as usize >= vertex_count) {
                        return invalid(format!(
                            "{label}: index {bad} at position {k} of accessor {} is out of range (the primitive has {vertex_count} vertices)",
                            indices_accessor.value()
                        ));
                    }
                    indices
                }
                None => (0..u32::try_from(vertex_count).unwrap_or(0)).collect(),
            };
            let (triangles, leftover) = assemble_triangles(&corners, mode);
            if leftover > 0 {
                self.scene.warnings.push(format!(
                    "{label}: {leftover} trailing index(es) do not form a whole triangle and were ignored"
                ));
            }

            let normals = match primitive.attributes.get(&Checked::Valid(Semantic::Normals)) {
                Some(accessor) => {
                    let normals = self.read_accessor(
                        accessor.value(),
                        &Expect {
                            purpose: format!("{label} NORMAL"),
                            ty: Type::Vec3,
                            components: &[(ComponentType::F32, false)],
                        },
                        decode_vec3,
                    )?;
                    if normals.len() != vertex_count {
                        return invalid(format!(
                            "{label}: NORMAL has {} elements but POSITION has {vertex_count}",
                            normals.len()
                        ));
                    }
                    let (normals, replaced) = normalise_or_fill(&normals, &positions, &triangles);
                    if replaced > 0 {
                        self.scene.warnings.push(format!(
                            "{label}: {replaced} zero or non-finite normal(s) replaced by computed ones"
                        ));
                    }
                    normals
                }
                None => computed_normals(&positions, &triangles),
            };

            let uvs = match primitive.attributes.get(&Checked::Valid(Semantic::TexCoords(0))) {
                Some(accessor) => {
                    let mut uvs = self.read_accessor(
                        accessor.value(),
                        &Expect {
                            purpose: format!("{label} TEXCOORD_0"),
                            ty: Type::Vec2,
                            components: &[
                                (ComponentType::F32, false),
                                (ComponentType::U8, true),
                                (ComponentType::U16, true),
                            ],
                        },
                        decode_vec2,
                    )?;
                    if uvs.len() != vertex_count {
                        return invalid(format!(
                            "{label}: TEXCOORD_0 has {} elements but POSITION has {vertex_count}",
                            uvs.len()
                        ));
                    }
                    let mut replaced = 0usize;
                    for uv in &mut uvs {
                        if !uv.iter().all(|c| c.is_finite()) {
                            *uv = [0.0, 0.0];
                            replaced += 1;
                        }
                    }
                    if replaced > 0 {
                        self.scene
                            .warnings
                            .push(format!("{label}: {replaced} non-finite texture coordinate(s) replaced by (0, 0)"));
                    }
                    uvs
                }
                None => vec![[0.0, 0.0]; vertex_count],
            };

            let colors = match primitive.attributes.get(&Checked::Valid(Semantic::Colors(0))) {
                Some(accessor) => Some(self.read_colors(accessor.value(), &label, vertex_count)?),
                None => None,
            };

            let material = match primitive.material {
                Some(material) => Some(self.material_for(material.value())?),
                None => None,
            };

            mesh.positions_local.extend_from_slice(&positions);
            mesh.normals_local.extend_from_slice(&normals);
            mesh.uvs.extend_from_slice(&uvs);
            match colors {
                Some(colors) => {
                    // Earlier primitives without COLOR_0 get glTF's neutral white.
                    mesh.colors.resize(base, WHITE);
                    mesh.colors.extend_from_slice(&colors);
                }
                None if !mesh.colors.is_empty() => mesh.colors.resize(base + vertex_count, WHITE),
                None => {}
            }
            mesh.triangle_materials.extend(std::iter::repeat_n(material, triangles.len()));
            mesh.triangles.extend(triangles.iter().map(|t| t.map(|i| i + base_u32)));
        }
        Ok(mesh)
    }

    /// Reads COLOR_0 (float VEC3/VEC4 or normalized unsigned byte/short) as linear RGBA:
    /// RGB gets alpha 1, non-finite colours become white and values outside `[0, 1]` are
    /// clamped (each with one warning per primitive).
    fn read_colors(&mut self, index: usize, label: &str, vertex_count: usize) -> Result<Vec<[f32; 4]>, Fail> {
        let purpose = format!("{label} COLOR_0");
        let ty = match self.root.accessors.get(index).map(|accessor| accessor.type_) {
            Some(Checked::Valid(Type::Vec3)) => Type::Vec3,
            Some(Checked::Valid(Type::Vec4)) | None | Some(Checked::Invalid) => Type::Vec4,
            Some(Checked::Valid(other)) => {
                return invalid(format!(
                    "{purpose} (accessor {index}): wrong accessor type {} (expected VEC3 or VEC4)",
                    type_name(other)
                ));
            }
        };
        let mut colors = self.read_accessor(
            index,
            &Expect {
                purpose,
                ty,
                components: &[(ComponentType::F32, false), (ComponentType::U8, true), (ComponentType::U16, true)],
            },
            decode_color,
        )?;
        if colors.len() != vertex_count {
            return invalid(format!("{label}: COLOR_0 has {} elements but POSITION has {vertex_count}", colors.len()));
        }
        let (mut replaced, mut clamped) = (0usize, 0usize);
        for color in &mut colors {
            if !color.iter().all(|c| c.is_finite()) {
                *color = WHITE;
                replaced += 1;
            } else if color.iter().any(|c| !(0.0..=1.0).contains(c)) {
                *color = color.map(|c| c.clamp(0.0, 1.0));
                clamped += 1;
            }
        }
        if replaced > 0 {
            self.scene.warnings.push(format!("{label}: {replaced} non-finite vertex colour(s) replaced by white"));
        }
        if clamped > 0 {
            self.scene.warnings.push(format!("{label}: {clamped} vertex colour(s) outside [0, 1] clamped"));
        }
        Ok(colors)
    }

    fn material_for(&mut self, index: usize) -> Result<u32, Fail> {
        if let Some(&known) = self.material_map.get(&index) {
            return Ok(known);
        }
        let root = self.root;
        let Some(gltf_material) = root.materials.get(index) else {
            return invalid(format!("material {index} does not exist"));
        };
        let pbr = &gltf_material.pbr_metallic_roughness;
        let mut factor = pbr.base_color_factor.0;
        if !factor.iter().all(|c| c.is_finite()) {
            self.scene.warnings.push(format!("material {index}: non-finite baseColorFactor replaced by white"));
            factor = [1.0; 4];
        }
        let factor = factor.map(|c| c.clamp(0.0, 1.0));
        let texture = match &pbr.base_color_texture {
            Some(info) => {
                if info.tex_coord != 0 {
                    self.scene.warnings.push(format!(
                        "material {index}: base-colour texture uses TEXCOORD_{}; TEXCOORD_0 is used instead",
                        info.tex_coord
                    ));
                }
                self.texture_for(info.index.value(), index)
            }
            None => None,
        };
        let Ok(slot) = u32::try_from(self.scene.materials.len()) else {
            return invalid("too many materials");
        };
        self.scene.materials.push(Material { base_color_factor: factor, base_color_texture: texture });
        self.material_map.insert(index, slot);
        Ok(slot)
    }

    /// Decodes the image of glTF texture `texture_index`; failures become warnings.
    fn texture_for(&mut self, texture_index: usize, material: usize) -> Option<u32> {
        let root = self.root;
        let Some(texture) = root.textures.get(texture_index) else {
            self.scene.warnings.push(format!(
                "material {material}: texture {texture_index} does not exist; base-colour texture skipped"
            ));
            return None;
        };
        let image_index = texture.source.value();
        if let Some(&known) = self.image_map.get(&image_index) {
            return known;
        }
        let result = match self.decode_image(image_index) {
            Ok(decoded) => match u32::try_from(self.scene.textures.len()) {
                Ok(slot) => {
                    self.scene.textures.push(decoded);
                    Some(slot)
                }
                Err(_) => None,
            },
            Err(message) => {
                self.scene
                    .warnings
                    .push(format!("image {image_index} (base colour of material {material}) skipped: {message}"));
                None
            }
        };
        self.image_map.insert(image_index, result);
        result
    }

    fn decode_image(&self, index: usize) -> Result<Texture, String> {
        let Some(image) = self.root.images.get(index) else {
            return Err("the image does not exist".to_owned());
        };
        let what = format!("image {index}");
        let bytes: Cow<'_, [u8]> = if let Some(view) = image.buffer_view {
            let (bytes, _) = self.view_bytes(view.value(), &what).map_err(fail_message)?;
            Cow::Borrowed(bytes)
        } else if let Some(uri) = image.uri.as_deref() {
            load_uri(uri, self.base_dir, &what, None).map_err(fail_message)?
        } else {
            return Err("it has neither a uri nor a bufferView".to_owned());
        };
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes.as_ref()))
            .with_guessed_format()
            .map_err(|err| err.to_string())?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_TEXTURE_SIDE);
        limits.max_image_height = Some(MAX_TEXTURE_SIDE);
        reader.limits(limits);
        let decoded = reader.decode().map_err(|err| err.to_string())?;
        let rgba = decoded.to_rgba8();
        Ok(Texture { width: rgba.width(), height: rgba.height(), rgba8_srgb: rgba.into_raw() })
    }

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

fn fail_message(fail: Fail) -> String {
    match fail {
        Fail::Io { what, source } => format!("cannot read {what}: {source}"),
        Fail::Gltf(message) | Fail::Invalid(message) => message,
    }
}

fn node_label(root: &json::Root, index: usize) -> String {
    match root.nodes.get(index).and_then(|n| n.name.as_deref()) {
        Some(name) => format!("{index} ({name:?})"),
        None => index.to_string(),
    }
}

/// The node's local transform (matrix, or translation * rotation * scale), or `None`
/// when it is not finite.
fn local_transform(node: &json::Node) -> Option<Mat4> {
    let matrix = if let Some(matrix) = node.matrix {
        Mat4::from_cols_array(&matrix)
    } else {
        let translation = Vec3::from_array(node.translation.unwrap_or([0.0; 3]));
        let rotation = match node.rotation {
            Some(rotation) => {
                let q = Quat::from_array(rotation.0);
                if !q.is_finite() || q.length_squared() == 0.0 {
                    return None;
                }
                q.normalize()
            }
            None => Quat::IDENTITY,
        };
        let scale = Vec3::from_array(node.scale.unwrap_or([1.0; 3]));
        Mat4::from_scale_rotation_translation(scale, rotation, translation)
    };
    matrix.is_finite().then_some(matrix)
}

/// Expands an index list into triangles for the given mode; also returns how many
/// trailing indices of a TRIANGLES list were left over.
fn assemble_triangles(corners: &[u32], mode: Mode) -> (Vec<[u32; 3]>, usize) {
    match mode {
        Mode::TriangleStrip => {
            // glTF: p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}
            let triangles = corners
                .windows(3)
                .enumerate()
                .filter_map(|(i, w)| match *w {
                    [a, b, c] => Some(if i % 2 == 0 { [a, b, c] } else { [a, c, b] }),
                    _ => None,
                })
                .collect();
            (triangles, 0)
        }
        Mode::TriangleFan => {
            // glTF: p_i = {v_{i+1}, v_{i+2}, v_0}
            let Some((&first, rest)) = corners.split_first() else {
                return (Vec::new(), 0);
            };
            let triangles = rest
                .windows(2)
                .filter_map(|w| match *w {
                    [b, c] => Some([b, c, first]),
                    _ => None,
                })
                .collect();
            (triangles, 0)
        }
        _ => {
            let chunks = corners.chunks_exact(3);
            let leftover = chunks.remainder().len();
            let triangles = chunks
                .filter_map(|c| match *c {
                    [a, b, c] => Some([a, b, c]),
                    _ => None,
                })
                .collect();
            (triangles, leftover)
        }
    }
}

/// Area-weighted vertex normals (un-normalised sums) of a triangle list.
fn face_normal_sums(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for triangle in triangles {
        let [a, b, c] =
            triangle.map(|vertex| positions.get(vertex as usize).map_or(Vec3::ZERO, |&p| Vec3::from_array(p)));
        let weighted = (b - a).cross(c - a); // length = twice the area
        if !weighted.is_finite() {
            continue;
        }
        for &vertex in triangle {
            if let Some(sum) = sums.get_mut(vertex as usize) {
                *sum += weighted;
            }
        }
    }
    sums
}

fn unit_or_z(v: Vec3) -> [f32; 3] {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() { [0.0, 0.0, 1.0] } else { n.to_array() }
}

/// Normals computed from the faces: area-weighted, normalised, zero → +Z.
fn computed_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    face_normal_sums(positions, triangles).into_iter().map(unit_or_z).collect()
}

/// Normalises file normals; zero or non-finite ones are replaced by computed normals.
/// Returns the normals and how many were replaced.
fn normalise_or_fill(normals: &[[f32; 3]], positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> (Vec<[f32; 3]>, usize) {
    let mut computed: Option<Vec<Vec3>> = None;
    let mut replaced = 0;
    let out = normals
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            let v = Vec3::from_array(n);
            let unit = v.normalize_or_zero();
            if v.is_finite() && unit != Vec3::ZERO && unit.is_finite() {
                unit.to_array()
            } else {
                replaced += 1;
                let sums = computed.get_or_insert_with(|| face_normal_sums(positions, triangles));
                unit_or_z(sums.get(i).copied().unwrap_or(Vec3::ZERO))
            }
        })
        .collect();
    (out, replaced)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip() {
        assert_eq!(decode_base64("aGVsbG8=").as_deref(), Some(&b"hello"[..]));
        assert_eq!(decode_base64("aGVsbA==").as_deref(), Some(&b"hell"[..]));
        assert_eq!(decode_base64("").as_deref(), Some(&b""[..]));
        assert!(decode_base64("a").is_none());
        assert!(decode_base64("a*bc").is_none());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin").as_deref(), Some("a b.bin"));
        assert!(percent_decode("a%2").is_none());
    }

    #[test]
    fn strips_and_fans() {
        let (strip, _) = assemble_triangles(&[0, 1, 2, 3, 4], Mode::TriangleStrip);
        assert_eq!(strip, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
        let (fan, _) = assemble_triangles(&[0, 1, 2, 3], Mode::TriangleFan);
        assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0]]);
        let (list, leftover) = assemble_triangles(&[0, 1, 2, 3], Mode::Triangles);
        assert_eq!((list, leftover), (vec![[0, 1, 2]], 1));
        assert!(assemble_triangles(&[0, 1], Mode::TriangleStrip).0.is_empty());
        assert!(assemble_triangles(&[], Mode::TriangleFan).0.is_empty());
    }

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
        walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/invalid"), &mut files);
        assert!(files.len() > 80);
        let (mut loaded, mut refused) = (0, 0);
        for file in files {
            let bytes = std::fs::read(&file).unwrap();
            let name = file.display().to_string();
            let outcome = catch_unwind(AssertUnwindSafe(|| import_inner(&bytes, file.parent(), &name, true)));
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

    #[test]
    fn glb_truncations_are_errors() {
        assert!(split_glb(b"glTF").is_err());
        let mut header = b"glTF".to_vec();
        header.extend(2u32.to_le_bytes());
        header.extend(4u32.to_le_bytes());
        assert!(split_glb(&header).is_err());
    }
}
