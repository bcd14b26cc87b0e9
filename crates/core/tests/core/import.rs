//! Tests of the glTF importer against independent truths: the triangle counts of
//! assets/SOURCES.md, counts read with the gltf crate's own loader, the Khronos
//! validator's verdicts on the invalid files, and small hand-built files.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use glam::{Mat4, Vec3};
use meshpaint_core::mesh::import::{ImportError, import_gltf, import_gltf_slice};
use meshpaint_core::mesh::scene::Scene;

fn manifest() -> PathBuf {
    crate::common::workspace_root()
}

fn model(relative: &str) -> PathBuf {
    manifest().join("assets/models").join(relative)
}

fn invalid_file(relative: &str) -> PathBuf {
    manifest().join("tests/fixtures/invalid").join(relative)
}

fn load(path: &Path) -> Scene {
    match import_gltf(path) {
        Ok(scene) => scene,
        Err(err) => panic!("{} failed to load: {err}", path.display()),
    }
}

/// Triangles of the default scene counted with the gltf crate's own loader and scene
/// traversal: for each mesh instance, each triangle primitive contributes
/// (index count or vertex count) / 3 (strips and fans: count - 2).
fn reference_triangle_count(path: &Path) -> usize {
    // JSON only (accessor counts), without the gltf crate's validation, which refuses
    // required extensions it does not implement (Cubes.glb requires KHR_lights_punctual).
    let bytes = std::fs::read(path).unwrap();
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).expect("gltf crate parses");
    let document = gltf.document;
    let scene = document.default_scene().or_else(|| document.scenes().next()).expect("model has a scene");
    fn visit(node: gltf::Node<'_>) -> usize {
        let own = node.mesh().map_or(0, |mesh| {
            mesh.primitives()
                .map(|p| {
                    let count = match p.indices() {
                        Some(indices) => indices.count(),
                        None => p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count()),
                    };
                    match p.mode() {
                        gltf::mesh::Mode::Triangles => count / 3,
                        gltf::mesh::Mode::TriangleStrip | gltf::mesh::Mode::TriangleFan => count.saturating_sub(2),
                        _ => 0,
                    }
                })
                .sum()
        });
        own + node.children().map(visit).sum::<usize>()
    }
    scene.nodes().map(visit).sum()
}

#[test]
fn real_models_load_with_the_documented_triangle_counts() {
    // (file, triangles from SOURCES.md, or None when only the independent count is known)
    let cases: [(&str, Option<usize>); 14] = [
        ("BoxTextured/BoxTextured.glb", Some(12)),
        ("BoxTextured/BoxTextured.embedded.gltf", Some(12)),
        ("Duck/Duck.glb", Some(4_212)),
        ("Fox/Fox.glb", Some(576)),
        ("Suzanne/monkey.glb", Some(968)),
        ("Alien/alien.glb", None),
        ("CakeBirthday/cakeBirthday.glb", Some(1_332)),
        ("NonManifold/no_indices_3storybuilding.glb", Some(72)),
        ("MultiNodeScenes/TestScene.gltf", None),
        ("MultiNodeScenes/nested.glb", None),
        ("MultiNodeScenes/pins.glb", Some(3_408)),
        ("MultiNodeScenes/simple_pole.glb", None),
        ("Cubes/Cubes.glb", Some(36)),
        ("Bunny144k/bunny.glb", Some(144_046)),
    ];
    for (file, documented) in cases {
        let path = model(file);
        let scene = load(&path);
        let count = scene.instanced_triangle_count();
        assert_eq!(count, reference_triangle_count(&path), "{file}: triangle count differs from the gltf crate's");
        if let Some(documented) = documented {
            assert_eq!(count, documented, "{file}: triangle count differs from SOURCES.md");
        }
        assert!(!scene.instances.is_empty(), "{file}: no instances");
        for mesh in &scene.meshes {
            let n = mesh.positions_local.len();
            assert_eq!(mesh.normals_local.len(), n, "{file}");
            assert_eq!(mesh.uvs.len(), n, "{file}");
            assert_eq!(mesh.triangle_materials.len(), mesh.triangles.len(), "{file}");
            assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n), "{file}");
            for normal in &mesh.normals_local {
                let length = Vec3::from_array(*normal).length();
                assert!((length - 1.0).abs() < 1e-4, "{file}: normal {normal:?} is not unit");
            }
            for material in mesh.triangle_materials.iter().flatten() {
                assert!((*material as usize) < scene.materials.len(), "{file}");
            }
        }
        for material in &scene.materials {
            if let Some(texture) = material.base_color_texture {
                assert!((texture as usize) < scene.textures.len(), "{file}");
            }
        }
        for texture in &scene.textures {
            assert_eq!(texture.rgba8_srgb.len(), texture.width as usize * texture.height as usize * 4, "{file}");
        }
        for instance in &scene.instances {
            assert!((instance.mesh as usize) < scene.meshes.len(), "{file}");
            assert!(instance.world_from_local.is_finite(), "{file}");
        }
    }
}

#[test]
fn alien_keeps_all_source_triangles() {
    // SOURCES.md counts 292 triangles after dropping degenerate ones; the importer keeps them.
    let scene = load(&model("Alien/alien.glb"));
    assert!(scene.instanced_triangle_count() >= 292);
}

#[test]
fn pins_instances_share_meshes() {
    let scene = load(&model("MultiNodeScenes/pins.glb"));
    let unique: usize = scene.meshes.iter().map(|m| m.triangles.len()).sum();
    assert_eq!(unique, 1_838, "unique triangles of pins.glb (SOURCES.md)");
    assert_eq!(scene.instanced_triangle_count(), 3_408);
    assert!(scene.instances.len() > scene.meshes.len());
}

#[test]
fn textures_are_decoded() {
    let duck = load(&model("Duck/Duck.glb"));
    assert_eq!(duck.textures.len(), 1);
    let texture = &duck.textures[0];
    assert_eq!((texture.width, texture.height), (512, 512));
    assert!(duck.materials.iter().any(|m| m.base_color_texture == Some(0)));
    assert!(duck.meshes[0].triangle_materials.iter().all(|m| m.is_some()));

    for file in ["BoxTextured/BoxTextured.glb", "BoxTextured/BoxTextured.embedded.gltf"] {
        let scene = load(&model(file));
        assert_eq!(scene.textures.len(), 1, "{file}");
        assert!(scene.textures[0].width > 0, "{file}");
        assert!(scene.materials.iter().any(|m| m.base_color_texture.is_some()), "{file}");
    }
    let glb = load(&model("BoxTextured/BoxTextured.glb"));
    let embedded = load(&model("BoxTextured/BoxTextured.embedded.gltf"));
    assert_eq!(glb.meshes, embedded.meshes);
    assert_eq!(glb.textures, embedded.textures);
}

#[test]
fn ignored_features_are_reported_once() {
    let fox = load(&model("Fox/Fox.glb"));
    let lines: Vec<&String> = fox.warnings.iter().filter(|w| w.starts_with("ignored:")).collect();
    assert_eq!(lines.len(), 1, "{:?}", fox.warnings);
    assert!(lines[0].contains("1 skin"), "{}", lines[0]);
    assert!(lines[0].contains("animation"), "{}", lines[0]);
    assert_eq!(fox.textures.len(), 1);
    assert_eq!((fox.textures[0].width, fox.textures[0].height), (1024, 1024));

    let cubes = load(&model("Cubes/Cubes.glb"));
    assert!(cubes.warnings.iter().any(|w| w.starts_with("ignored:") && w.contains("light")), "{:?}", cubes.warnings);
    let bunny = load(&model("Bunny144k/bunny.glb"));
    assert!(bunny.warnings.iter().all(|w| !w.starts_with("ignored:")));
}

#[test]
fn external_bin_must_exist() {
    let bytes = std::fs::read(model("MultiNodeScenes/TestScene.gltf")).unwrap();
    let err = import_gltf_slice(&bytes, Some(Path::new("/nonexistent-dir")), "TestScene.gltf").unwrap_err();
    assert!(matches!(err, ImportError::Io { .. }), "{err}");
    assert!(err.to_string().contains("TestScene.gltf"), "{err}");
    let err = import_gltf_slice(&bytes, None, "TestScene.gltf").unwrap_err();
    assert!(err.to_string().contains("external"), "{err}");
}

fn collect_gltf_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            collect_gltf_files(&path, out);
        } else if matches!(path.extension().and_then(|e| e.to_str()), Some("gltf" | "glb")) {
            out.push(path);
        }
    }
}

/// How long one import may run before it counts as hung: a hang guard, not a speed test
/// (an invalid file is refused in milliseconds; the limit holds on a loaded 2-core machine).
const HANG_LIMIT: Duration = Duration::from_secs(60);

/// Imports in a thread: Ok(result), or Err when it panicked or took longer than [`HANG_LIMIT`].
fn import_guarded(path: &Path) -> Result<Result<Scene, ImportError>, String> {
    let (sender, receiver) = mpsc::channel();
    let owned = path.to_path_buf();
    std::thread::spawn(move || {
        let outcome = catch_unwind(AssertUnwindSafe(|| import_gltf(&owned)));
        let _ = sender.send(outcome);
    });
    match receiver.recv_timeout(HANG_LIMIT) {
        Ok(Ok(result)) => Ok(result),
        Ok(Err(_)) => Err(format!("{}: a panic escaped the importer", path.display())),
        Err(_) => Err(format!("{}: import took longer than {HANG_LIMIT:?}", path.display())),
    }
}

#[test]
fn invalid_files_never_panic_or_hang() {
    let mut files = Vec::new();
    collect_gltf_files(&manifest().join("tests/fixtures/invalid"), &mut files);
    files.sort();
    assert!(files.len() > 80, "expected the invalid fixtures, found {}", files.len());
    let mut failures = Vec::new();
    for file in &files {
        match import_guarded(file) {
            Ok(Ok(scene)) => {
                // Whatever loads must be internally consistent.
                for mesh in &scene.meshes {
                    let n = mesh.positions_local.len();
                    assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
                    assert!(mesh.positions_local.iter().flatten().all(|c| c.is_finite()));
                }
            }
            Ok(Err(err)) => {
                let message = err.to_string();
                let name = file.file_name().unwrap().to_string_lossy().to_string();
                assert!(message.contains(&name), "error does not name the file: {message}");
            }
            Err(problem) => failures.push(problem),
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The Khronos validator's error codes for `file` (its `.report.json`).
fn validator_errors(file: &Path) -> Vec<String> {
    let report = PathBuf::from(format!("{}.report.json", file.display()));
    let text = std::fs::read_to_string(report).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["severity"] == 0)
        .map(|m| m["code"].as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn validator_oracle_agrees_on_data_errors() {
    // Files whose reports name errors in data the importer reads must be refused.
    let refuse = [
        "ACCESSOR_INDEX_OOB",
        "NODE_LOOP",
        "NODE_PARENT_OVERRIDE",
        "UNRESOLVED_REFERENCE",
        "BUFFER_BYTE_LENGTH_MISMATCH",
        "INVALID_JSON",
        "GLB_UNEXPECTED_END_OF_CHUNK_DATA",
        "GLB_UNEXPECTED_END_OF_CHUNK_HEADER",
        "GLB_UNEXPECTED_END_OF_HEADER",
        "GLB_INVALID_MAGIC",
        "GLB_INVALID_VERSION",
        "ACCESSOR_INDEX_PRIMITIVE_RESTART",
    ];
    let mut files = Vec::new();
    collect_gltf_files(&manifest().join("tests/fixtures/invalid/gltf-validator"), &mut files);
    files.sort();
    let mut checked = 0;
    let mut refused = 0;
    for file in files {
        let errors = validator_errors(&file);
        if errors.is_empty() {
            // Valid files (some with odd features) must load.
            if let Err(err) = import_gltf(&file) {
                panic!("validator-clean file refused: {err}");
            }
        } else if errors.iter().any(|e| refuse.contains(&e.as_str())) {
            // Refused, or loaded safely without reading the bad data (e.g. a broken mesh
            // that no scene uses).
            match import_gltf(&file) {
                Err(_) => refused += 1,
                Ok(scene) => assert!(
                    scene.instances.is_empty(),
                    "{} has {errors:?} but loaded {} instances",
                    file.display(),
                    scene.instances.len()
                ),
            }
            checked += 1;
        }
    }
    assert!(checked >= 15, "only {checked} files checked");
    assert!(refused >= 12, "only {refused} of {checked} files refused");
}

fn expect_error(relative: &str, needle: &str) {
    let path = invalid_file(relative);
    match import_guarded(&path) {
        Ok(Ok(_)) => panic!("{relative} loaded"),
        Ok(Err(err)) => {
            let message = err.to_string().to_lowercase();
            assert!(message.contains(needle), "{relative}: {message}");
        }
        Err(problem) => panic!("{problem}"),
    }
}

#[test]
fn specific_invalid_files_are_refused_with_clear_messages() {
    expect_error("assimp/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "non-finite");
    expect_error("assimp/IndexOutOfRange/IndexOutOfRange.gltf", "index");
    expect_error("assimp/IndexOutOfRange/AllIndicesOutOfRange.gltf", "index");
    expect_error("assimp/glb_is_hexdump_text/Duck.glb", "glb");
    expect_error("gltf-validator/node/node_loop.gltf", "cycle");
    expect_error("gltf-validator/node/node_loop_scene.gltf", "cycle");
    expect_error("gltf-validator/node/node_parent_override.gltf", "two parents");
    expect_error("gltf-validator/mesh/unresolved_positions.gltf", "position");
    expect_error("gltf-validator/glb/truncated_chunk_data.glb", "truncated");
    expect_error("gltf-validator/glb/only_header.glb", "glb");
    expect_error("assimp/TestNoRootNode/NoScene.gltf", "scene");
}

// ---------------------------------------------------------------------------------
// Hand-built files

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A buffer holding `positions` (VEC3 float) followed by u16 `indices`.
struct Built {
    buffer: Vec<u8>,
}

impl Built {
    fn new() -> Self {
        Built { buffer: Vec::new() }
    }

    /// Appends data and returns (offset, length), padded to 4 bytes.
    fn push(&mut self, bytes: &[u8]) -> (usize, usize) {
        let offset = self.buffer.len();
        self.buffer.extend_from_slice(bytes);
        while !self.buffer.len().is_multiple_of(4) {
            self.buffer.push(0);
        }
        (offset, bytes.len())
    }

    fn uri(&self) -> String {
        format!("data:application/octet-stream;base64,{}", base64(&self.buffer))
    }
}

fn f32_bytes(values: &[[f32; 3]]) -> Vec<u8> {
    values.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
}

fn u16_bytes(values: &[u16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn min_max(values: &[[f32; 3]]) -> (Vec<f32>, Vec<f32>) {
    let mut min = vec![f32::INFINITY; 3];
    let mut max = vec![f32::NEG_INFINITY; 3];
    for v in values {
        for k in 0..3 {
            min[k] = min[k].min(v[k]);
            max[k] = max[k].max(v[k]);
        }
    }
    (min, max)
}

/// One mesh with one primitive of `mode` over `positions` (and `indices` if given),
/// placed by the given nodes JSON.
fn single_primitive_gltf(
    positions: &[[f32; 3]],
    indices: Option<&[u16]>,
    mode: u32,
    nodes: serde_json::Value,
    scene_roots: serde_json::Value,
) -> String {
    let mut built = Built::new();
    let (pos_offset, pos_len) = built.push(&f32_bytes(positions));
    let (min, max) = min_max(positions);
    let mut views = vec![serde_json::json!({"buffer": 0, "byteOffset": pos_offset, "byteLength": pos_len})];
    let mut accessors = vec![serde_json::json!({
        "bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3",
        "min": min, "max": max
    })];
    let mut primitive = serde_json::json!({"attributes": {"POSITION": 0}, "mode": mode});
    if let Some(indices) = indices {
        let (offset, len) = built.push(&u16_bytes(indices));
        views.push(serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": len}));
        accessors.push(serde_json::json!({
            "bufferView": 1, "componentType": 5123, "count": indices.len(), "type": "SCALAR"
        }));
        primitive["indices"] = serde_json::json!(1);
    }
    serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": scene_roots}],
        "nodes": nodes,
        "meshes": [{"primitives": [primitive]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": built.buffer.len(), "uri": built.uri()}],
    })
    .to_string()
}

fn import_json(json: &str) -> Result<Scene, ImportError> {
    import_gltf_slice(json.as_bytes(), None, "synthetic.gltf")
}

const QUAD: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];

#[test]
fn triangle_strip_alternates_winding() {
    let json = single_primitive_gltf(&QUAD, None, 5, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let scene = import_json(&json).unwrap();
    let mesh = &scene.meshes[0];
    // glTF: p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
    assert_eq!(mesh.positions_local, QUAD.to_vec());
    // Both triangles of this strip face +Z, so the computed normals are +Z.
    for normal in &mesh.normals_local {
        assert_eq!(*normal, [0.0, 0.0, 1.0]);
    }
    assert_eq!(mesh.uvs, vec![[0.0, 0.0]; 4]);
    assert_eq!(mesh.triangle_materials, vec![None, None]);
}

#[test]
fn indexed_strip_and_fan() {
    let strip =
        single_primitive_gltf(&QUAD, Some(&[3, 2, 1, 0]), 5, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    assert_eq!(import_json(&strip).unwrap().meshes[0].triangles, vec![[3, 2, 1], [2, 0, 1]]);
    // Fan around vertex 0 of a square: 0, 1, 3, 2 → p_i = {v_{i+1}, v_{i+2}, v_0}.
    let fan =
        single_primitive_gltf(&QUAD, Some(&[0, 1, 3, 2]), 6, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let scene = import_json(&fan).unwrap();
    assert_eq!(scene.meshes[0].triangles, vec![[1, 3, 0], [3, 2, 0]]);
    for normal in &scene.meshes[0].normals_local {
        assert_eq!(*normal, [0.0, 0.0, 1.0]);
    }
}

#[test]
fn non_indexed_triangles_use_vertex_order() {
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [5.0, 5.0, 5.0], // unreferenced tail vertex in a TRIANGLES list: kept, no triangle
    ];
    let json = single_primitive_gltf(&positions, None, 4, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let scene = import_json(&json).unwrap();
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [3, 4, 5]]);
    assert_eq!(mesh.positions_local.len(), 7);
    // Non-indexed vertices are not shared: each gets its own face's normal.
    assert_eq!(mesh.normals_local[0], [0.0, 0.0, 1.0]);
    assert_eq!(mesh.normals_local[3], [0.0, 1.0, 0.0]);
    // A vertex in no triangle gets +Z.
    assert_eq!(mesh.normals_local[6], [0.0, 0.0, 1.0]);
}

#[test]
fn computed_normals_are_area_weighted() {
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]];
    // Triangle 0 faces +Z with area 1/2; triangle 1 faces +Y with area 2.
    let json = single_primitive_gltf(
        &positions,
        Some(&[0, 1, 2, 0, 3, 4]),
        4,
        serde_json::json!([{"mesh": 0}]),
        serde_json::json!([0]),
    );
    let scene = import_json(&json).unwrap();
    let n = Vec3::from_array(scene.meshes[0].normals_local[0]);
    assert!((n - Vec3::new(0.0, 4.0, 1.0).normalize()).length() < 1e-6, "{n}");
}

#[test]
fn node_hierarchy_composes_transforms_and_shares_meshes() {
    let nodes = serde_json::json!([
        {"translation": [1.0, 2.0, 3.0], "scale": [2.0, 2.0, 2.0], "children": [1, 2]},
        {"translation": [1.0, 0.0, 0.0], "mesh": 0},
        {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,10,1], "mesh": 0},
        {"mesh": 0}
    ]);
    let json = single_primitive_gltf(&QUAD, None, 5, nodes, serde_json::json!([0]));
    let scene = import_json(&json).unwrap();
    assert_eq!(scene.meshes.len(), 1, "one mesh shared by two nodes");
    assert_eq!(scene.instances.len(), 2, "node 3 is not in the scene");
    let parent = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)) * Mat4::from_scale(Vec3::splat(2.0));
    let first = scene.instances[0].world_from_local;
    assert!(first.abs_diff_eq(parent * Mat4::from_translation(Vec3::X), 1e-6));
    // The local origin of node 1 lands at (1,2,3) + 2*(1,0,0).
    assert!(first.transform_point3(Vec3::ZERO).abs_diff_eq(Vec3::new(3.0, 2.0, 3.0), 1e-6));
    let second = scene.instances[1].world_from_local;
    assert!(second.transform_point3(Vec3::ZERO).abs_diff_eq(Vec3::new(1.0, 2.0, 23.0), 1e-6));
    assert_eq!(scene.instanced_triangle_count(), 4);
}

#[test]
fn lines_are_skipped_with_one_warning() {
    let json = single_primitive_gltf(&QUAD, None, 1, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let scene = import_json(&json).unwrap();
    assert_eq!(scene.instanced_triangle_count(), 0);
    assert!(scene.warnings.iter().any(|w| w.contains("point/line")), "{:?}", scene.warnings);
}

#[test]
fn synthetic_bad_data_is_refused() {
    let nan = single_primitive_gltf(
        &[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        4,
        serde_json::json!([{"mesh": 0}]),
        serde_json::json!([0]),
    );
    // serde_json writes NaN as null, which is not a number: build min/max by hand instead.
    let nan = nan.replace("null", "0.0");
    let err = import_json(&nan).unwrap_err().to_string();
    assert!(err.contains("non-finite") && err.contains("synthetic.gltf"), "{err}");

    let out_of_range =
        single_primitive_gltf(&QUAD, Some(&[0, 1, 4]), 4, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let err = import_json(&out_of_range).unwrap_err().to_string();
    assert!(err.contains("index 4"), "{err}");

    // A huge count over a tiny buffer is refused before anything is allocated.
    let huge = single_primitive_gltf(&QUAD, None, 4, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]))
        .replace("\"count\":4", "\"count\":4000000000000");
    let err = import_json(&huge).unwrap_err().to_string();
    assert!(err.contains("out of bounds"), "{err}");

    let cycle = single_primitive_gltf(
        &QUAD,
        None,
        4,
        serde_json::json!([{"mesh": 0, "children": [1]}, {"children": [0]}]),
        serde_json::json!([0]),
    );
    let err = import_json(&cycle).unwrap_err().to_string();
    assert!(err.contains("cycle"), "{err}");

    let twice = single_primitive_gltf(&QUAD, None, 4, serde_json::json!([{"mesh": 0}]), serde_json::json!([0, 0]));
    assert!(import_json(&twice).is_err());

    let text = b"00000000  67 6c 54 46 02 00 00 00  hexdump";
    let err = import_gltf_slice(text, None, "text.glb").unwrap_err().to_string();
    assert!(err.contains("text.glb"), "{err}");
}

/// QUAD as a strip, with a material whose base-colour image is `image_uri`.
fn textured_quad(image_uri: &str) -> String {
    let json = single_primitive_gltf(&QUAD, None, 5, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let mut value: serde_json::Value = serde_json::from_str(&json).unwrap();
    value["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    value["materials"] = serde_json::json!([{
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.5, 0.25, 1.0, 1.0],
            "baseColorTexture": {"index": 0}
        }
    }]);
    value["textures"] = serde_json::json!([{"source": 0}]);
    value["images"] = serde_json::json!([{"uri": image_uri}]);
    value.to_string()
}

#[test]
fn undecodable_texture_is_a_warning() {
    let garbage = format!("data:image/png;base64,{}", base64(b"not a png at all"));
    let scene = import_json(&textured_quad(&garbage)).unwrap();
    assert_eq!(scene.instanced_triangle_count(), 2);
    assert!(scene.textures.is_empty());
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[0].base_color_factor, [0.5, 0.25, 1.0, 1.0]);
    assert_eq!(scene.materials[0].base_color_texture, None);
    assert_eq!(scene.meshes[0].triangle_materials, vec![Some(0), Some(0)]);
    assert!(scene.warnings.iter().any(|w| w.contains("image 0")), "{:?}", scene.warnings);
}

#[test]
fn external_files_must_be_regular_relative_files() {
    // A device file would never end; an absolute path is not a relative reference.
    let device = textured_quad("dev/zero");
    let scene = import_gltf_slice(device.as_bytes(), Some(Path::new("/")), "device.gltf").unwrap();
    assert!(scene.textures.is_empty());
    assert!(scene.warnings.iter().any(|w| w.contains("not a regular file")), "{:?}", scene.warnings);
    let json = single_primitive_gltf(&QUAD, None, 5, serde_json::json!([{"mesh": 0}]), serde_json::json!([0]));
    let mut value: serde_json::Value = serde_json::from_str(&json).unwrap();
    value["buffers"][0]["uri"] = serde_json::json!("/dev/zero");
    let err =
        import_gltf_slice(value.to_string().as_bytes(), Some(Path::new("/")), "abs.gltf").unwrap_err().to_string();
    assert!(err.contains("absolute"), "{err}");
    value["buffers"][0]["uri"] = serde_json::json!("dev/zero");
    let err =
        import_gltf_slice(value.to_string().as_bytes(), Some(Path::new("/")), "dev.gltf").unwrap_err().to_string();
    assert!(err.contains("not a regular file"), "{err}");
}

#[test]
fn sparse_accessor_without_buffer_view() {
    // POSITION: 3 zero vertices, two of them replaced by sparse values.
    let mut built = Built::new();
    let (index_offset, index_len) = built.push(&u16_bytes(&[1, 2]));
    let (value_offset, value_len) = built.push(&f32_bytes(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]));
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{
            "componentType": 5126, "count": 3, "type": "VEC3",
            "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0],
            "sparse": {
                "count": 2,
                "indices": {"bufferView": 0, "componentType": 5123},
                "values": {"bufferView": 1}
            }
        }],
        "bufferViews": [
            {"buffer": 0, "byteOffset": index_offset, "byteLength": index_len},
            {"buffer": 0, "byteOffset": value_offset, "byteLength": value_len}
        ],
        "buffers": [{"byteLength": built.buffer.len(), "uri": built.uri()}],
    });
    let scene = import_json(&json.to_string()).unwrap();
    assert_eq!(scene.meshes[0].positions_local, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(scene.meshes[0].triangles, vec![[0, 1, 2]]);
    assert_eq!(scene.meshes[0].normals_local[0], [0.0, 0.0, 1.0]);
}
