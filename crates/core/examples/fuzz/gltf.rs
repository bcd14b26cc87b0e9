//! The glTF target: seeds, a structure-aware mutator and the oracle.
//!
//! The mutator decodes a seed into its JSON document and binary chunk. It edits the JSON as
//! a tree (any value: numbers to boundary values, other types, removed keys, duplicated or
//! dropped array elements) and with glTF knowledge (accessor counts, offsets, strides,
//! component types and sparse storage; buffer views; node children that form cycles or
//! shared parents, instancing nodes, transforms; primitive modes and attributes; material,
//! texture and image references), edits the binary chunk inside the accessors' byte ranges
//! (indices past the end, NaN and infinite floats) or as raw bytes, and re-assembles a GLB
//! with correct chunk lengths (mostly) or writes the JSON as a `.gltf`. A few mutants get
//! raw byte edits of the whole file.
//!
//! The oracle ([`run`]): the importer must not panic (not even the panics it catches
//! itself as a last resort, which it reports as `ImportError::Panicked`); a scene it
//! accepts must weld, get a topology and colours at a small resolution, pack, and write a
//! packed file that reads back.

use std::path::Path;

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::import::{ImportError, import_gltf_slice};
use meshpaint_core::packing::file as packed_file;
use serde_json::{Value, json};

use super::rng::Rng;

const JSON_CHUNK: u32 = 0x4E4F_534A;
const BIN_CHUNK: u32 = 0x004E_4942;

/// A decoded seed: the JSON document and the binary chunk (if any).
#[derive(Clone)]
pub struct Seed {
    json: Value,
    bin: Option<Vec<u8>>,
}

/// Splits a GLB into JSON and BIN, or parses a `.gltf`.
fn decode(bytes: &[u8]) -> Option<Seed> {
    if !bytes.starts_with(b"glTF") {
        return Some(Seed { json: serde_json::from_slice(bytes).ok()?, bin: None });
    }
    let word = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let json_len = word(12)? as usize;
    let json = serde_json::from_slice(bytes.get(20..20 + json_len)?).ok()?;
    let bin_at = 20 + json_len;
    let bin = match (word(bin_at), word(bin_at + 4)) {
        (Some(len), Some(BIN_CHUNK)) => Some(bytes.get(bin_at + 8..bin_at + 8 + len as usize)?.to_vec()),
        _ => None,
    };
    Some(Seed { json, bin })
}

/// A GLB of `json` and `bin` with correct, 4-byte padded chunk lengths.
fn encode_glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = Vec::with_capacity(json.len() + bin.map_or(0, <[u8]>::len) + 32);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&JSON_CHUNK.to_le_bytes());
    out.extend_from_slice(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&BIN_CHUNK.to_le_bytes());
        out.extend_from_slice(&bin);
    }
    let len = out.len() as u32;
    out[8..12].copy_from_slice(&len.to_le_bytes());
    out
}

/// A small GLB written here: two instances of a mesh with indexed triangles (u8 indices,
/// normalized u8 vertex colours) and a triangle strip whose positions have a sparse patch.
// The seed's JSON text (0.7071068, not FRAC_1_SQRT_2's digits) is part of every campaign's
// inputs: changing it would change what `--replay` regenerates.
#[allow(clippy::approx_constant)]
fn synthetic_seed() -> Vec<u8> {
    let positions: [[f32; 3]; 5] =
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 1.0]];
    let mut bin = Vec::new();
    for p in positions {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    // 60: colours (5 × 4 bytes), 80: indices (9 bytes + 3 padding), 92: sparse index, 96: value.
    for k in 0..5u8 {
        bin.extend_from_slice(&[40 * k, 255 - 40 * k, 128, 255]);
    }
    bin.extend_from_slice(&[0, 1, 4, 1, 2, 4, 2, 3, 4, 0, 0, 0]);
    bin.extend_from_slice(&[2, 0, 0, 0]);
    for c in [1.5f32, 1.5, 0.5] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    let document = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"mesh": 0, "translation": [2.0, 0.0, 0.0]},
            {"mesh": 0, "scale": [1.0, 2.0, 1.0], "children": [2]},
            {"mesh": 1, "rotation": [0.0, 0.0, 0.7071068, 0.7071068]}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2, "mode": 4}]},
            {"primitives": [{"attributes": {"POSITION": 3}, "mode": 5}]}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 5, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 5, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5121, "count": 9, "type": "SCALAR"},
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.5, 1.5, 0.5],
             "sparse": {"count": 1, "indices": {"bufferView": 3, "componentType": 5121},
                        "values": {"bufferView": 4}}}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 60},
            {"buffer": 0, "byteOffset": 60, "byteLength": 20},
            {"buffer": 0, "byteOffset": 80, "byteLength": 9},
            {"buffer": 0, "byteOffset": 92, "byteLength": 1},
            {"buffer": 0, "byteOffset": 96, "byteLength": 12}
        ],
        "buffers": [{"byteLength": bin.len()}]
    });
    encode_glb(document.to_string().as_bytes(), Some(&bin))
}

/// The seed files: small real models (a textured box as GLB and as .gltf with data URIs,
/// cubes, a node hierarchy) and [`synthetic_seed`].
pub fn seeds(models: &Path) -> Vec<Seed> {
    let files = [
        "BoxTextured/BoxTextured.glb",
        "BoxTextured/BoxTextured.embedded.gltf",
        "Cubes/Cubes.glb",
        "MultiNodeScenes/nested.glb",
    ];
    let mut out: Vec<Seed> =
        files.iter().filter_map(|name| std::fs::read(models.join(name)).ok()).filter_map(|b| decode(&b)).collect();
    out.extend(decode(&synthetic_seed()));
    out
}

/// Every JSON pointer in `value` (at most `cap`).
fn pointers(value: &Value, prefix: &mut String, out: &mut Vec<String>, cap: usize) {
    if out.len() >= cap {
        return;
    }
    out.push(prefix.clone());
    let len = prefix.len();
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                prefix.push('/');
                prefix.push_str(&key.replace('~', "~0").replace('/', "~1"));
                pointers(child, prefix, out, cap);
                prefix.truncate(len);
            }
        }
        Value::Array(items) => {
            for (k, child) in items.iter().enumerate() {
                prefix.push_str(&format!("/{k}"));
                pointers(child, prefix, out, cap);
                prefix.truncate(len);
            }
        }
        _ => {}
    }
}

/// A number near the glTF limits or near `old`.
fn interesting_number(rng: &mut Rng, old: Option<f64>) -> Value {
    let old = old.unwrap_or(0.0);
    match rng.below(6) {
        0 => json!(rng.below(8)),
        1 => json!(rng.pick(&[-1i64, 255, 256, 65535, 65536, 1 << 31, (1 << 31) - 1, 1 << 32, -(1 << 31), 1 << 53])),
        2 => json!(rng.pick(&[1e300, -1e300, 0.5, 1e-300, -0.0, 3.4e38, 1e39])),
        3 => json!(old as i64 + rng.below(5) as i64 - 2),
        4 => json!(old * rng.pick(&[2.0, 1000.0, -1.0, 0.5])),
        _ => json!(rng.pick(&[5120, 5121, 5122, 5123, 5125, 5126, 5124, 0, 1, 2, 3, 4, 5, 6, 7, 34962, 34963])),
    }
}

/// Another value for `old`: a neighbouring number, another type, or a glTF word.
fn replacement(rng: &mut Rng, old: &Value) -> Value {
    match (rng.below(4), old) {
        (0 | 1, Value::Number(n)) => interesting_number(rng, n.as_f64()),
        (0, Value::String(_)) => json!(rng.pick(&[
            "",
            "SCALAR",
            "VEC2",
            "VEC3",
            "VEC4",
            "MAT4",
            "BLEND",
            "image/png",
            "image/jpeg",
            "KHR_draco_mesh_compression",
            "data:application/octet-stream;base64,AAAA",
            "data:image/png;base64,iVBORw0KGgo=",
            "missing.bin",
        ])),
        (1, Value::Array(items)) if !items.is_empty() => {
            let mut items = items.clone();
            let copy = items[rng.index(items.len())].clone();
            let times = if rng.chance(1, 4) { 1 + rng.index(60) } else { 1 };
            for _ in 0..times {
                items.push(copy.clone());
            }
            Value::Array(items)
        }
        (2, _) => json!(rng.pick(&[0i64, 1, 2, -1, 4096, 100_000])),
        _ => match rng.below(6) {
            0 => Value::Null,
            1 => json!(true),
            2 => json!([]),
            3 => json!({}),
            4 => json!([0, 1, 2]),
            _ => json!("x"),
        },
    }
}

/// A structural or glTF-aware edit of the JSON document.
fn mutate_json(json: &mut Value, rng: &mut Rng) {
    let mut all = Vec::new();
    pointers(json, &mut String::new(), &mut all, 4096);
    let pointer = all[rng.index(all.len())].clone();
    match rng.below(10) {
        0..=3 => {
            if let Some(slot) = json.pointer_mut(&pointer) {
                *slot = replacement(rng, slot);
            }
        }
        4 => {
            if let Some(Value::Object(map)) = json.pointer_mut(&pointer)
                && !map.is_empty()
            {
                let key = map.keys().nth(rng.index(map.len())).cloned().unwrap_or_default();
                map.remove(&key);
            } else if let Some(Value::Array(items)) = json.pointer_mut(&pointer)
                && !items.is_empty()
            {
                items.remove(rng.index(items.len()));
            }
        }
        _ => mutate_gltf(json, rng),
    }
}

/// An element `index` of top-level array `name`, as a mutable object.
fn element<'a>(json: &'a mut Value, name: &str, rng: &mut Rng) -> Option<&'a mut serde_json::Map<String, Value>> {
    let items = json.get_mut(name)?.as_array_mut()?;
    if items.is_empty() {
        return None;
    }
    let k = rng.index(items.len());
    items[k].as_object_mut()
}

/// Edits that know what glTF fields mean.
fn mutate_gltf(json: &mut Value, rng: &mut Rng) {
    let node_count = json.get("nodes").and_then(Value::as_array).map_or(0, Vec::len) as u64;
    let accessor_count = json.get("accessors").and_then(Value::as_array).map_or(0, Vec::len) as u64;
    match rng.below(9) {
        0 => {
            if let Some(accessor) = element(json, "accessors", rng) {
                let field = rng.pick(&["count", "byteOffset", "componentType", "bufferView", "normalized", "type"]);
                let old = accessor.get(field).cloned().unwrap_or(Value::Null);
                accessor.insert(field.to_owned(), replacement(rng, &old));
            }
        }
        1 => {
            if let Some(accessor) = element(json, "accessors", rng) {
                let sparse = json!({"count": rng.pick(&[1u64, 2, 5, 1 << 20]),
                    "indices": {"bufferView": rng.below(5), "componentType": rng.pick(&[5121, 5123, 5125, 5126])},
                    "values": {"bufferView": rng.below(5), "byteOffset": rng.below(16)}});
                accessor.insert("sparse".to_owned(), sparse);
            }
        }
        2 => {
            if let Some(view) = element(json, "bufferViews", rng) {
                let field = rng.pick(&["byteOffset", "byteLength", "byteStride", "buffer"]);
                let old = view.get(field).cloned().unwrap_or(json!(0));
                view.insert(field.to_owned(), interesting_number(rng, old.as_f64()));
            }
        }
        3 if node_count > 0 => {
            // A child link: may form a cycle or give a node two parents.
            let child = rng.below(node_count + 1);
            if let Some(node) = element(json, "nodes", rng) {
                let children = node.entry("children").or_insert_with(|| json!([]));
                if let Some(list) = children.as_array_mut() {
                    list.push(json!(child));
                }
            }
        }
        4 if node_count > 0 => {
            // Instancing: more nodes pointing at the same mesh, listed in the scene.
            let most = if rng.chance(1, 8) { 300 } else { 8 };
            let copies = 1 + rng.below(most);
            let template = json["nodes"][rng.below(node_count) as usize].clone();
            if let Some(nodes) = json["nodes"].as_array_mut() {
                let first = nodes.len();
                for k in 0..copies {
                    let mut copy = template.clone();
                    if let Some(object) = copy.as_object_mut() {
                        object.remove("children");
                        object.insert("translation".to_owned(), json!([k as f64, 0.0, 0.0]));
                    }
                    nodes.push(copy);
                }
                if let Some(scene) = json.pointer_mut("/scenes/0/nodes").and_then(Value::as_array_mut) {
                    scene.extend((first..first + copies as usize).map(|n| json!(n)));
                }
            }
        }
        5 => {
            if let Some(node) = element(json, "nodes", rng) {
                let big = rng.pick(&[1e30, -1e30, 0.0, 1e-30, 3.4e38, 1e39]);
                let (field, value) = match rng.below(4) {
                    0 => ("matrix", json!([big, 0, 0, 0, 0, big, 0, 0, 0, 0, big, 0, 0, 0, 0, 1])),
                    1 => ("translation", json!([big, 0.0, 1.0])),
                    2 => ("rotation", json!([0.0, 0.0, 0.0, 0.0])),
                    _ => ("scale", json!([big, big, 0.0])),
                };
                node.insert(field.to_owned(), value);
            }
        }
        6 => {
            if let Some(primitive) = json.pointer_mut("/meshes/0/primitives/0").and_then(Value::as_object_mut) {
                match rng.below(4) {
                    0 => {
                        primitive.insert("mode".to_owned(), json!(rng.below(8)));
                    }
                    1 => {
                        primitive.insert("indices".to_owned(), json!(rng.below(accessor_count + 1)));
                    }
                    2 => {
                        let attribute = rng.pick(&["POSITION", "COLOR_0", "TEXCOORD_0", "NORMAL", "TEXCOORD_1"]);
                        if let Some(attributes) = primitive.get_mut("attributes").and_then(Value::as_object_mut) {
                            attributes.insert(attribute.to_owned(), json!(rng.below(accessor_count + 1)));
                        }
                    }
                    _ => {
                        primitive.insert("material".to_owned(), json!(rng.below(3)));
                    }
                }
            }
        }
        7 => {
            let (array, field) = rng.pick(&[
                ("textures", "source"),
                ("textures", "sampler"),
                ("images", "bufferView"),
                ("images", "mimeType"),
                ("materials", "pbrMetallicRoughness"),
                ("samplers", "wrapS"),
                ("buffers", "byteLength"),
                ("scenes", "nodes"),
            ]);
            if let Some(object) = element(json, array, rng) {
                let old = object.get(field).cloned().unwrap_or(Value::Null);
                object.insert(field.to_owned(), replacement(rng, &old));
            }
        }
        _ => {
            if let Some(root) = json.as_object_mut() {
                match rng.below(3) {
                    0 => {
                        let extension = rng.pick(&["KHR_mesh_quantization", "EXT_mesh_gpu_instancing", "X_unknown"]);
                        root.insert("extensionsRequired".to_owned(), json!([extension]));
                        root.insert("extensionsUsed".to_owned(), json!([extension]));
                    }
                    1 => {
                        root.insert("scene".to_owned(), json!(rng.below(3)));
                    }
                    _ => {
                        root.remove(rng.pick(&["scenes", "nodes", "accessors", "bufferViews", "buffers", "meshes"]));
                    }
                }
            }
        }
    }
}

/// An edit of the binary chunk, mostly inside a buffer view so that it hits accessor data.
fn mutate_bin(json: &Value, bin: &mut Vec<u8>, rng: &mut Rng) {
    let views = json.get("bufferViews").and_then(Value::as_array).cloned().unwrap_or_default();
    if views.is_empty() || rng.chance(1, 4) {
        rng.mutate_bytes(bin);
        return;
    }
    let view = &views[rng.index(views.len())];
    let start = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
    let len = view.get("byteLength").and_then(Value::as_u64).unwrap_or(0) as usize;
    if len < 4 || start + len > bin.len() {
        rng.mutate_bytes(bin);
        return;
    }
    let at = start + rng.index(len - 3) / 4 * 4;
    let value = match rng.below(3) {
        0 => rng.interesting_f32().to_bits(),
        1 => rng.interesting_u32(0),
        _ => u32::from(rng.pick(&[0xFFFFu16, 0x7FFF, 24, 25, 255])),
    };
    bin[at..at + 4].copy_from_slice(&value.to_le_bytes());
}

/// A mutant: the bytes and whether they are meant as binary glTF.
pub fn mutate(seeds: &[Seed], rng: &mut Rng) -> (Vec<u8>, bool) {
    let mut seed = seeds[rng.index(seeds.len())].clone();
    for _ in 0..1 + rng.below(3) {
        match (&mut seed.bin, rng.below(4)) {
            (Some(bin), 0) => mutate_bin(&seed.json, bin, rng),
            _ => mutate_json(&mut seed.json, rng),
        }
    }
    let text = seed.json.to_string().into_bytes();
    let glb = seed.bin.is_some() || rng.chance(1, 6);
    let mut bytes = if glb { encode_glb(&text, seed.bin.as_deref()) } else { text };
    if rng.chance(1, 12) {
        for _ in 0..1 + rng.below(3) {
            rng.mutate_bytes(&mut bytes);
        }
    }
    (bytes, glb)
}

/// The error's variant and the first words of its message after the file name.
fn label(error: &ImportError) -> String {
    let text = error.to_string();
    let message = text.split_once(": ").map_or(text.as_str(), |(_, rest)| rest);
    let message = message.strip_prefix("not a valid glTF 2.0 file: ").unwrap_or(message);
    let words: Vec<String> = message
        .split_whitespace()
        .take(4)
        .map(|w| if w.chars().any(|c| c.is_ascii_digit()) { "N".to_owned() } else { w.to_owned() })
        .collect();
    format!("refused: {}", words.join(" "))
}

/// Runs one input through import, welding, colouring at resolution `r` and packing;
/// returns the outcome's label. Panics (the fuzzer catches them) on a broken promise.
pub fn run(bytes: &[u8], glb: bool, r: u32) -> String {
    let name = if glb { "fuzz.glb" } else { "fuzz.gltf" };
    let scene = match import_gltf_slice(bytes, None, name) {
        Ok(scene) => scene,
        Err(ImportError::Panicked { message, .. }) => panic!("the importer caught a panic: {message}"),
        Err(error) => return label(&error),
    };
    let resolution = Resolution::new(u64::from(r)).unwrap_or(Resolution::ONE);
    let document = match Document::from_scene(scene, resolution, Path::new(name)) {
        Ok(document) => document,
        Err(error) => return format!("imported, refused: {}", super::packed::variant(&format!("{error:?}"))),
    };
    if document.store.topology().face_count() == 0 {
        return "imported, no triangles".to_owned();
    }
    let packed = document.pack(ColorFormat::Rgba8Srgb).expect("an imported document does not pack");
    let bytes = packed_file::to_bytes(&packed).expect("the writer refuses an imported document");
    let back = packed_file::from_bytes(&bytes).expect("an imported document does not read back");
    assert!(back == packed, "an imported document does not survive write + read");
    "imported, packed".to_owned()
}
