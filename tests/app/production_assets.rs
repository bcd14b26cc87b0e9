//! The production-like test assets (`meshpaint synth`, crates/core/src/synth/production):
//! every class opens (`meshpaint info`), passes the Khronos glTF-Validator with no errors
//! or warnings, has the counts its documentation gives (read back with the gltf crate, not
//! with our importer), is closed and consistently wound where it should be, and the same
//! options write the same bytes.

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::common::TempDir;
use crate::validator::validate;

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

/// Runs `meshpaint args`, asserts success and returns stdout.
fn run(args: &[&str]) -> String {
    let output = Command::new(BIN).args(args).output().expect("cannot start the meshpaint binary");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "meshpaint {}\nstdout: {stdout}\nstderr: {stderr}", args.join(" "));
    stdout
}

/// Writes `class` with `extra` options to `dir/name` twice; asserts both writes are
/// byte-identical, the validator reports no error, and returns (summary, info, document).
fn synth(dir: &TempDir, class: &str, extra: &[&str]) -> (Value, Value, gltf::Gltf) {
    let first = dir.join(&format!("{class}.glb"));
    let second = dir.join(&format!("{class}-again.glb"));
    let mut summaries = Vec::new();
    for path in [&first, &second] {
        let mut args = vec!["synth", class, "-o", path.to_str().unwrap()];
        args.extend_from_slice(extra);
        summaries.push(serde_json::from_str::<Value>(run(&args).trim()).unwrap());
    }
    let bytes = std::fs::read(&first).unwrap();
    assert!(bytes == std::fs::read(&second).unwrap(), "{class}: two runs wrote different bytes");
    let report = validate(&first);
    assert_eq!(report["numErrors"], 0, "{class}: validator errors: {report}");
    assert_eq!(report["numWarnings"], 0, "{class}: validator warnings: {report}");
    let info: Value = serde_json::from_str(run(&["info", first.to_str().unwrap(), "--json"]).trim()).unwrap();
    let document = gltf::Gltf::from_slice(&bytes).unwrap();
    (summaries.remove(0), info, document)
}

/// Triangles over every node of the default scene, from the glTF accessors.
fn gltf_triangles(document: &gltf::Gltf) -> u64 {
    let scene = document.default_scene().unwrap();
    scene
        .nodes()
        .filter_map(|node| node.mesh())
        .flat_map(|mesh| mesh.primitives().map(|p| p.indices().unwrap().count() as u64 / 3).collect::<Vec<_>>())
        .sum()
}

/// Width and height of each image (from the PNG headers in the binary chunk).
fn image_sizes(document: &gltf::Gltf) -> Vec<(u32, u32)> {
    let blob = document.blob.as_deref().unwrap();
    document
        .images()
        .map(|image| match image.source() {
            gltf::image::Source::View { view, .. } => {
                let png = &blob[view.offset()..view.offset() + view.length()];
                let decoded = image::load_from_memory(png).unwrap();
                (decoded.width(), decoded.height())
            }
            gltf::image::Source::Uri { .. } => panic!("images must be embedded"),
        })
        .collect()
}

fn closed_and_consistent(info: &Value, what: &str) {
    assert_eq!(info["inconsistent_edges"], 0, "{what}: {info}");
    assert_eq!(info["inverted_components"], 0, "{what}: {info}");
    assert_eq!(info["nonmanifold_edges"], 0, "{what}: {info}");
}

#[test]
fn the_truck_has_two_large_faces_per_side_carrying_the_logo_and_text() {
    let dir = TempDir::new("synth-truck");
    let (summary, info, document) = synth(&dir, "truck", &["--texture-size", "1024"]);
    let triangles = gltf_triangles(&document);
    assert_eq!(summary["triangles"].as_u64(), Some(triangles), "{summary}");
    assert_eq!(info["triangles"].as_u64(), Some(triangles), "{info}");
    assert!((5000..7500).contains(&triangles), "about 6000 triangles by default, got {triangles}");
    assert_eq!(image_sizes(&document), vec![(1024, 1024)]);
    assert_eq!(document.materials().count(), 1);
    assert_eq!(document.nodes().count(), 7, "the body and six wheel instances");
    assert_eq!(info["boundary_edges"], 0, "every part is closed: {info}");
    closed_and_consistent(&info, "truck");
    // The named faces carry the panel: their UVs (read with the gltf crate) span the
    // logo's rectangle, and they are the largest faces of the file.
    let logo = summary["regions"].as_array().unwrap().iter().find(|r| r["name"] == "logo").unwrap();
    assert_eq!(logo["faces"], serde_json::json!([0, 1]), "{logo}");
    let rect: Vec<f64> = logo["uv_rect"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let (min, max) = face_uv_bounds(&document, &[0, 1]);
    assert!(
        min[0] <= rect[0] && min[1] <= rect[1] && max[0] >= rect[2] && max[1] >= rect[3],
        "{min:?} {max:?} {rect:?}"
    );
    let centre: Vec<f64> = logo["center"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert!((centre[2] - 1.25).abs() < 1e-6, "the logo lies on the +z side: {logo}");
}

/// The UV bounds of the first primitive's triangles `faces` (file order).
fn face_uv_bounds(document: &gltf::Gltf, faces: &[usize]) -> ([f64; 2], [f64; 2]) {
    let blob = document.blob.as_deref().unwrap();
    let primitive = document.meshes().next().unwrap().primitives().next().unwrap();
    let reader = primitive.reader(|_| Some(blob));
    let uvs: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    for &face in faces {
        for k in 0..3 {
            let uv = uvs[indices[face * 3 + k] as usize];
            for a in 0..2 {
                min[a] = min[a].min(f64::from(uv[a]));
                max[a] = max[a].max(f64::from(uv[a]));
            }
        }
    }
    (min, max)
}

#[test]
fn the_materials_asset_has_nine_materials_four_textures_and_vertex_colours() {
    let dir = TempDir::new("synth-materials");
    let (summary, info, document) = synth(&dir, "materials", &[]);
    assert_eq!(document.materials().count(), 9);
    assert_eq!(image_sizes(&document), vec![(512, 512), (1024, 1024), (256, 128), (128, 128)]);
    let textured: Vec<Option<usize>> = document
        .materials()
        .map(|m| m.pbr_metallic_roughness().base_color_texture().map(|t| t.texture().source().index()))
        .collect();
    assert_eq!(textured, vec![Some(0), Some(0), Some(1), Some(2), None, None, None, Some(3), Some(1)]);
    let primitives: Vec<gltf::Primitive> = document.meshes().flat_map(|m| m.primitives().collect::<Vec<_>>()).collect();
    let coloured = primitives.iter().filter(|p| p.get(&gltf::Semantic::Colors(0)).is_some()).count();
    assert_eq!(coloured, 2, "the bottles' two primitives carry COLOR_0");
    assert_eq!(
        primitives.iter().filter(|p| p.material().index().is_none()).count(),
        1,
        "one primitive has no material"
    );
    let triangles = gltf_triangles(&document);
    assert_eq!(info["triangles"].as_u64(), Some(triangles), "{info}");
    assert_eq!(summary["triangles"].as_u64(), Some(triangles), "{summary}");
    closed_and_consistent(&info, "materials");
}

#[test]
fn the_islands_asset_has_the_exact_triangle_count_and_is_one_closed_surface() {
    let dir = TempDir::new("synth-islands");
    // 12,002 = 2 mod 4: the lattice alone cannot reach it, a centroid split must.
    let (summary, info, document) = synth(&dir, "islands", &["--triangles", "12002", "--texture-size", "512"]);
    assert_eq!(gltf_triangles(&document), 12_002);
    assert_eq!(info["triangles"].as_u64(), Some(12_002), "{info}");
    assert_eq!(summary["triangles"].as_u64(), Some(12_002));
    assert_eq!(image_sizes(&document), vec![(512, 512)]);
    // Island seams weld: one closed component, outward.
    assert_eq!(info["boundary_edges"], 0, "{info}");
    assert_eq!(info["components"], 1, "{info}");
    assert!(info["closed_signed_volume"].as_f64().unwrap() > 0.0, "{info}");
    closed_and_consistent(&info, "islands");
    let (min, max) = face_uv_bounds(&document, &(0..12_002).collect::<Vec<_>>());
    assert!(min[0] >= 0.0 && min[1] >= 0.0 && max[0] <= 1.0 && max[1] <= 1.0, "{min:?} {max:?}");
}

#[test]
fn an_odd_triangle_count_or_a_bad_texture_size_is_refused() {
    let dir = TempDir::new("synth-refused");
    let out = dir.join("x.glb");
    for args in [["islands", "--triangles", "12001"], ["truck", "--texture-size", "1000"]] {
        let mut all = vec!["synth", args[0], "-o", out.to_str().unwrap()];
        all.extend_from_slice(&args[1..]);
        let output = Command::new(BIN).args(&all).output().unwrap();
        assert!(!output.status.success(), "{all:?} must fail");
        assert!(!Path::new(&out).exists(), "{all:?} wrote a file");
    }
}
