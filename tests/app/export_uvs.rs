//! `export --texture SIZE` with the UVs it chooses: `--uvs new` generates a non-overlapping
//! atlas, `--uvs FILE` bakes into that model's UVs, and by default the document's own UVs
//! are used when every face has some and none overlap, else new ones — the output says
//! which and why. A scan without UVs (the Stanford bunny as a binary PLY, painted through
//! `meshpaint paint`) bakes into generated UVs: the Khronos validator accepts the file and
//! its render through the UV baseline matches the mesh-colors render.

use std::path::Path;
use std::process::Command;

use crate::common::{TempDir, model, psnr_over_foreground as psnr};
use crate::validator::validate;

use meshpaint_core::camera::default_camera;
use meshpaint_core::io::document::Document;
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::weld::weld_scene;
use meshpaint_render::{DrawItem, Gpu, RenderSettings};

/// Runs `meshpaint ARGS`; returns (success, stderr).
fn meshpaint(args: &[&str]) -> (bool, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_meshpaint")).args(args).output().unwrap();
    (output.status.success(), String::from_utf8_lossy(&output.stderr).into_owned())
}

fn s(path: &Path) -> String {
    path.to_str().unwrap().to_owned()
}

/// The line of `export`'s output naming the UVs used.
fn uvs_line(stderr: &str) -> &str {
    stderr.lines().find(|line| line.contains("UVs: ")).unwrap_or_else(|| panic!("no UV line in: {stderr}"))
}

#[test]
fn the_default_uvs_are_the_models_own_unless_they_overlap_or_are_missing() {
    let dir = TempDir::new("export_uvs");
    let duck = s(&model("Duck/Duck.glb"));
    // The Duck's mirrored halves share texels: new UVs.
    let first = s(&dir.join("duck_new.glb"));
    let (ok, stderr) = meshpaint(&["export", &duck, "-o", &first, "--texture", "512"]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: new UVs: the model's UV islands overlap"), "{stderr}");
    assert!(stderr.contains("generated atlas: "), "{stderr}");
    // That file's UVs are generated, so they do not overlap: exported again, they are kept.
    let (ok, stderr) = meshpaint(&["export", &first, "-o", &s(&dir.join("again.glb")), "--texture", "512"]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: the model's own UVs: every face has UV area"), "{stderr}");
    // A PLY without UVs: new UVs.
    let ply = s(&model("PlyExamples/tetrahedron_big_endian.ply"));
    let (ok, stderr) = meshpaint(&["export", &ply, "-o", &s(&dir.join("tetra.glb")), "--texture", "64"]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: new UVs: the model has no UVs"), "{stderr}");
    // Asked for: new UVs even where the model's own would do.
    let (ok, stderr) =
        meshpaint(&["export", &first, "-o", &s(&dir.join("new.png")), "--texture", "256", "--uvs", "new"]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: new UVs, as asked"), "{stderr}");
    // A packed file keeps no UVs: new ones by default, the source's with --uvs FILE (today's
    // meaning, overlaps and all, with the paint lost there said).
    let mpk = s(&dir.join("duck.mpk"));
    let (ok, stderr) = meshpaint(&["export", &duck, "-o", &mpk]);
    assert!(ok, "{stderr}");
    let (ok, stderr) = meshpaint(&["export", &mpk, "-o", &s(&dir.join("mpk.glb")), "--texture", "256"]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: new UVs: the document keeps no UVs"), "{stderr}");
    let (ok, stderr) = meshpaint(&["export", &mpk, "-o", &s(&dir.join("src.glb")), "--texture", "256", "--uvs", &duck]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: the model's UVs, as asked"), "{stderr}");
}

/// Writes `positions` and `triangles` as a binary little-endian PLY with nothing else.
fn write_ply(path: &Path, positions: &[[f32; 3]], triangles: &[[u32; 3]]) {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\ncomment the Stanford bunny, no UVs or normals\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        positions.len(),
        triangles.len()
    )
    .into_bytes();
    for p in positions {
        p.iter().for_each(|c| bytes.extend_from_slice(&c.to_le_bytes()));
    }
    for t in triangles {
        bytes.push(3);
        t.iter().for_each(|&v| bytes.extend_from_slice(&(v as i32).to_le_bytes()));
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn a_ply_scan_without_uvs_bakes_into_generated_uvs() {
    let dir = TempDir::new("scan_bake");
    let welded = weld_scene(&import_gltf(&model("Bunny144k/bunny.glb")).unwrap());
    let ply = dir.join("bunny.ply");
    write_ply(&ply, &welded.positions_world, &welded.triangles);
    // Paint a stroke across it (the editor's camera, pick and brush), then bake the result.
    let painted = s(&dir.join("bunny.mpk"));
    let stroke = "150,200 250,260 350,240 450,300";
    let (ok, stderr) = meshpaint(&["paint", &s(&ply), "--stroke", stroke, "--color", "#2040ff", "-o", &painted]);
    assert!(ok, "{stderr}");
    let glb = dir.join("bunny.glb");
    let (ok, stderr) = meshpaint(&["export", &s(&ply), "-o", &s(&glb), "--texture", "2048"]);
    assert!(ok, "{stderr}");
    assert!(uvs_line(&stderr).contains("UVs: new UVs: the model has no UVs"), "{stderr}");
    eprintln!("{stderr}");
    let report = validate(&glb);
    assert_eq!(report["numErrors"].as_u64(), Some(0), "{report}");
    let baked = dir.join("bunny_painted.glb");
    let (ok, stderr) = meshpaint(&["export", &painted, "-o", &s(&baked), "--texture", "2048"]);
    assert!(ok, "{stderr}");
    eprintln!("{stderr}");
    let report = validate(&baked);
    assert_eq!(report["numErrors"].as_u64(), Some(0), "{report}");
    // Every face is in the texture, and the render matches the painted mesh colors.
    let scene = import_gltf(&baked).unwrap();
    assert_eq!(weld_scene(&scene).triangles.len(), welded.triangles.len());
    let gpu = Gpu::new_headless().unwrap();
    let document =
        Document::open(Path::new(&painted), meshpaint_core::colors::layout::Resolution::new(8).unwrap()).unwrap();
    let colors = gpu.upload(&document.pack(document.display_format()).unwrap()).unwrap();
    let baseline = gpu.upload_baseline(&scene).unwrap().unwrap();
    for (yaw, pitch) in [(0.0, 0.0), (30.0, 20.0), (180.0, 10.0)] {
        let mut settings = RenderSettings::new(default_camera(colors.bounds, yaw, pitch, None));
        settings.filter = meshpaint_render::FilterMode::Linear;
        let a = gpu.render_image(DrawItem::MeshColors(&colors), &settings, 512, 512).unwrap();
        let b = gpu.render_image(DrawItem::Baseline(&baseline), &settings, 512, 512).unwrap();
        let db = psnr(&a, &b);
        eprintln!("bunny scan, view ({yaw}, {pitch}): {db:.1} dB");
        assert!(db >= 35.0, "view ({yaw}, {pitch}): {db:.1} dB");
    }
}
