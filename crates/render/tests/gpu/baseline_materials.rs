//! The UV baseline (`render --baseline-uv`, the reference of `bench trade`) on a mesh with
//! several materials: a glTF written here with three quads side by side, one per primitive —
//! a solid texture times a base-colour factor, a factor without texture, and no material
//! (glTF's default, white). Truth: the colours computed by hand in this file (the sRGB
//! transfer function of IEC 61966-2-1 written out here, not the crate's), compared with the
//! unlit render at each quad's centre.

use crate::common;

use common::TempDir;
use meshpaint_core::camera::{BoundingSphere, default_camera};
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_render::{DrawItem, Gpu, RenderSettings, Shading};

/// sRGB-encoded 0..1 → linear (IEC 61966-2-1).
fn decode(encoded: f64) -> f64 {
    if encoded <= 0.04045 { encoded / 12.92 } else { ((encoded + 0.055) / 1.055).powf(2.4) }
}

/// Linear → sRGB-encoded 8-bit.
fn encode8(linear: f64) -> u8 {
    let linear = linear.clamp(0.0, 1.0);
    let encoded = if linear <= 0.0031308 { 12.92 * linear } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 };
    (encoded * 255.0).round() as u8
}

const TEXEL: [u8; 4] = [200, 100, 50, 255];
const FACTOR_TEXTURED: [f32; 4] = [0.5, 1.0, 0.25, 1.0];
const FACTOR_ONLY: [f32; 4] = [0.2, 0.4, 0.8, 1.0];

/// Three unit quads at x = -1.5, 0, 1.5 in the z = 0 plane (facing +z); quad k is primitive
/// k: material 0 (texture × factor), material 1 (factor only), no material.
fn write_gltf(dir: &TempDir) -> std::path::PathBuf {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    for k in 0..3 {
        let x0 = -2.0 + 1.5 * k as f32;
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            positions.push([x0 + dx, dy - 0.5, 0.0]);
            uvs.push([dx, 1.0 - dy]);
        }
    }
    let mut bin: Vec<u8> = Vec::new();
    for p in &positions {
        p.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    let uv_offset = bin.len();
    for uv in &uvs {
        uv.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    let index_offset = bin.len();
    for k in 0..3u16 {
        for i in [0u16, 1, 2, 1, 3, 2] {
            bin.extend_from_slice(&(4 * k + i).to_le_bytes());
        }
    }
    std::fs::write(dir.join("quads.bin"), &bin).unwrap();
    image::RgbaImage::from_pixel(4, 4, image::Rgba(TEXEL)).save(dir.join("solid.png")).unwrap();
    let mut accessors = vec![
        serde_json::json!({"bufferView": 0, "componentType": 5126, "count": 12, "type": "VEC3",
            "min": [-2.0, -0.5, 0.0], "max": [2.0, 0.5, 0.0]}),
        serde_json::json!({"bufferView": 1, "componentType": 5126, "count": 12, "type": "VEC2"}),
    ];
    for k in 0..3 {
        accessors.push(serde_json::json!({"bufferView": 2, "byteOffset": 12 * k, "componentType": 5123,
            "count": 6, "type": "SCALAR"}));
    }
    let primitive = |k: usize, material: Option<u32>| {
        let mut p = serde_json::json!({"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2 + k});
        if let Some(m) = material {
            p["material"] = m.into();
        }
        p
    };
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [primitive(0, Some(0)), primitive(1, Some(1)), primitive(2, None)]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": FACTOR_TEXTURED, "baseColorTexture": {"index": 0}}},
            {"pbrMetallicRoughness": {"baseColorFactor": FACTOR_ONLY}},
        ],
        "textures": [{"source": 0}],
        "images": [{"uri": "solid.png"}],
        "accessors": accessors,
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": uv_offset},
            {"buffer": 0, "byteOffset": uv_offset, "byteLength": index_offset - uv_offset},
            {"buffer": 0, "byteOffset": index_offset, "byteLength": bin.len() - index_offset},
        ],
        "buffers": [{"byteLength": bin.len(), "uri": "quads.bin"}],
    });
    let path = dir.join("quads.gltf");
    std::fs::write(&path, json.to_string()).unwrap();
    path
}

#[test]
fn baseline_draws_every_material_factor_times_texture_and_untextured_faces_at_their_factor() {
    let dir = TempDir::new("baseline_materials");
    let scene = import_gltf(&write_gltf(&dir)).unwrap();
    assert_eq!(scene.materials.len(), 2, "two materials imported");
    let gpu = Gpu::new_headless().unwrap();
    let baseline = gpu.upload_baseline(&scene).unwrap().expect("one material has a texture");
    assert_eq!(baseline.vertex_count, 18, "all six triangles are drawn");
    assert_eq!(baseline.draw_count(), 2, "one draw for the texture, one for the untextured faces");

    let positions: Vec<[f32; 3]> = (0..3).map(|k| [-1.5 + 1.5 * k as f32, 0.0, 0.0]).collect();
    // Yaw 0, pitch 0: looking along −z at the quads' fronts.
    let camera = default_camera(BoundingSphere { center: [0.0; 3], radius: 2.1 }, 0.0, 0.0, None);
    let mut settings = RenderSettings::new(camera);
    settings.shading = Shading::Unlit;
    settings.background = [0.0; 4];
    let (width, height) = (240, 120);
    let image = gpu.render_image(DrawItem::Baseline(&baseline), &settings, width, height).unwrap();

    let texel_linear: Vec<f64> = TEXEL[..3].iter().map(|&b| decode(f64::from(b) / 255.0)).collect();
    let expected: [[u8; 3]; 3] = [
        std::array::from_fn(|c| encode8(texel_linear[c] * f64::from(FACTOR_TEXTURED[c]))),
        std::array::from_fn(|c| encode8(f64::from(FACTOR_ONLY[c]))),
        [255, 255, 255],
    ];
    let names = ["texture × factor", "factor only", "no material (white)"];
    for ((center, want), name) in positions.iter().zip(expected).zip(names) {
        let world = glam::DVec3::new(f64::from(center[0]), f64::from(center[1]), f64::from(center[2]));
        let (x, y) = camera.project(world, width, height).expect("quad centre in view");
        let got = image.get_pixel(x as u32, y as u32).0;
        for c in 0..3 {
            assert!(
                (i32::from(got[c]) - i32::from(want[c])).abs() <= 1,
                "{name}: pixel ({x:.0}, {y:.0}) is {got:?}, expected {want:?} (±1 step)"
            );
        }
        assert_eq!(got[3], 255, "{name}: opaque");
    }
}
