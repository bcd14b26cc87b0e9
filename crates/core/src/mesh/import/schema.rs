//! The JSON: parsed with serde_json, fixed up where gltf 1.4.1 would panic or refuse
//! sound glTF, then deserialized and schema-validated by gltf-json.

use gltf::json;
use gltf::json::mesh::Semantic;
use gltf::json::validation::Checked;

use super::{Fail, invalid};

/// Extensions that change how geometry is stored or placed: a file that requires them
/// cannot be shown correctly without them.
const UNSUPPORTED_GEOMETRY_EXTENSIONS: [&str; 4] =
    ["KHR_draco_mesh_compression", "KHR_mesh_quantization", "EXT_meshopt_compression", "EXT_mesh_gpu_instancing"];

/// The validated glTF JSON, with the warnings found on the way.
pub(super) struct ParsedJson {
    pub(super) root: json::Root,
    pub(super) warnings: Vec<String>,
    /// How many `KHR_lights_punctual` lights the file defines (gltf-json drops them).
    pub(super) lights: usize,
}

/// Parses, fixes up and validates the JSON chunk (or `.gltf` file).
pub(super) fn parse_json(json_bytes: &[u8]) -> Result<ParsedJson, Fail> {
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
    Ok(ParsedJson { root, warnings, lights })
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
