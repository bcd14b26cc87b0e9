//! Baking mesh colors into the model's UV texture (`export --texture`).
//!
//! Truths: a linear colour field, which the mesh-colors linear filter reproduces exactly, must
//! come out in every covered texel as the closed form at the texel centre's UV; padding must
//! leave no texel of an unrelated colour; the textured model rendered through the UV baseline
//! (`render --baseline-uv`'s pipeline) must match the mesh-colors render of the document it was
//! baked from (PSNR over the mesh pixels, printed per model and view); the Khronos validator must
//! accept the .glb; a mesh without UVs is reported face by face.

use std::path::Path;
use std::process::Command;

use crate::common;
use crate::common::WriteThrough;
use common::{TempDir, model, workspace_path};

use meshpaint_core::camera::default_camera;
use meshpaint_core::colors::budget::Budget;
use meshpaint_core::colors::format::encode_rgba8_srgb;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::convert::bake_uv::{bake_uv_texture, default_padding};
use meshpaint_core::convert::least_squares::BakeFit;
use meshpaint_core::io::document::{Document, OpenPhases};
use meshpaint_core::io::export_textured::{TexturedMesh, encode_png, textured_glb};
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::mesh::weld::weld_scene;
use meshpaint_render::{DrawItem, Gpu, RenderSettings};

/// A linear colour in UV space: r = u, g = v, b = 1 − u (all in [0, 1] on the unit square).
fn field(u: f64, v: f64) -> [f64; 3] {
    [u, v, 1.0 - u]
}

#[test]
fn a_linear_field_is_baked_exactly_and_padding_keeps_island_colours() {
    // Two triangles covering the UV square [0.1, 0.9]², positions = UVs (z = 0), R = 4.
    let (lo, hi) = (0.1f32, 0.9f32);
    let positions = [[lo, lo, 0.0], [hi, lo, 0.0], [hi, hi, 0.0], [lo, hi, 0.0]];
    let triangles = vec![[0u32, 1, 2], [0, 2, 3]];
    let topology = Topology::build(4, &triangles).unwrap();
    let mut store = ColorStore::uniform(topology, Resolution::new(4).unwrap(), [0.0; 4]);
    let corners = triangles.clone();
    store.write_all(|site| {
        let face = corners[site.face as usize];
        let p = |a: usize| {
            (0..3).map(|k| f64::from(site.barycentric[k]) * f64::from(positions[face[k] as usize][a])).sum::<f64>()
        };
        let [r, g, b] = field(p(0), p(1));
        [r as f32, g as f32, b as f32, 1.0]
    });
    let uvs: Vec<[[f32; 2]; 3]> =
        triangles.iter().map(|t| t.map(|v| [positions[v as usize][0], positions[v as usize][1]])).collect();
    let size = 64u32;
    let bake = bake_uv_texture(&store, &uvs, size, 8).unwrap();
    assert!(bake.faces_without_uvs.is_empty());
    let n = f64::from(size);
    let texel = |x: u32, y: u32| {
        let at = 4 * (y * size + x) as usize;
        [bake.rgba8_srgb[at], bake.rgba8_srgb[at + 1], bake.rgba8_srgb[at + 2]]
    };
    let mut inside = 0;
    for y in 0..size {
        for x in 0..size {
            let (u, v) = ((f64::from(x) + 0.5) / n, (f64::from(y) + 0.5) / n);
            let got = texel(x, y);
            if u > f64::from(lo) && u < f64::from(hi) && v > f64::from(lo) && v < f64::from(hi) {
                inside += 1;
                let [r, g, b] = field(u, v);
                let expected = encode_rgba8_srgb([r as f32, g as f32, b as f32, 1.0]);
                for k in 0..3 {
                    assert!(got[k].abs_diff(expected[k]) <= 1, "texel ({x}, {y}): {got:?} vs {expected:?}");
                }
            } else {
                // Padding: within the field's range clamped to the island (a neighbour's
                // average), never an unrelated colour.
                let clamp = |t: f64| t.clamp(f64::from(lo), f64::from(hi));
                let [r, g, b] = field(clamp(u), clamp(v));
                let near = encode_rgba8_srgb([r as f32, g as f32, b as f32, 1.0]);
                for k in 0..3 {
                    assert!(got[k].abs_diff(near[k]) <= 40, "padding texel ({x}, {y}): {got:?} far from {near:?}");
                }
            }
        }
    }
    assert_eq!(inside as u64, bake.covered_texels, "every texel centre inside the square, and only those");
}

/// Two faces on the same UV triangle (mirrored islands) with different colours: every texel
/// strictly inside is counted as overlapping and, the colours being far apart, conflicting.
#[test]
fn overlapping_uvs_are_counted() {
    let triangles = [[0u32, 1, 2], [3, 4, 5]];
    let mut store = ColorStore::uniform(Topology::build(6, &triangles).unwrap(), Resolution::new(2).unwrap(), [0.0; 4]);
    store.write_all(|site| if site.face == 0 { [1.0, 0.0, 0.0, 1.0] } else { [0.0, 0.0, 1.0, 1.0] });
    let uv = [[0.1, 0.1], [0.9, 0.1], [0.1, 0.9]];
    let size = 32u32;
    let bake = bake_uv_texture(&store, &[uv, uv], size, 4).unwrap();
    // Texel centres strictly inside u > 0.1, v > 0.1, u + v < 1.0 (none lies on an edge here).
    let n = f64::from(size);
    let inside = (0..size * size)
        .filter(|t| {
            let (u, v) = ((f64::from(t % size) + 0.5) / n, (f64::from(t / size) + 0.5) / n);
            u > 0.1 && v > 0.1 && u + v < 1.0
        })
        .count() as u64;
    assert!(inside > 100);
    assert_eq!((bake.overlapping_texels, bake.conflicting_texels), (inside, inside));
    // A mesh without overlaps has none.
    let quad = [[[0.1f32, 0.1], [0.9, 0.1], [0.9, 0.9]], [[0.1, 0.1], [0.9, 0.9], [0.1, 0.9]]];
    let bake = bake_uv_texture(&store, &quad, size, 4).unwrap();
    assert_eq!((bake.overlapping_texels, bake.conflicting_texels), (0, 0));
}

/// PSNR in dB of `a` against `b` over the pixels where either is not the background.
fn psnr(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u64) {
    let background = *a.get_pixel(0, 0);
    let (mut sum, mut count) = (0.0f64, 0u64);
    for (p, q) in a.pixels().zip(b.pixels()) {
        if *p == background && *q == background {
            continue;
        }
        for k in 0..3 {
            let d = f64::from(p[k]) - f64::from(q[k]);
            sum += d * d;
        }
        count += 1;
    }
    let mse = sum / (3.0 * count.max(1) as f64);
    (10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10(), count)
}

/// The PSNR table of the issue: every shared textured model, baked at its source texture's
/// size, from documents converted with the point bake (≥ 35 dB) and with the least-squares
/// fit, the default (≥ 34 dB on the Duck and Fox: the fit's colours are sharper, and the
/// baked texture is drawn through the viewer's mips; seen 36.0 and 34.2 on their worst
/// views). BoxTextured's six sides map the same texels, so the texture keeps one side's
/// colours: the point bake gives every side the same prefiltered texture and the sides
/// nearly agree (743 texels conflict); the fit fits each side's own triangulation and the
/// sides differ (56,856 conflicts, other sides' views 21.5 dB), which measures how two fits
/// of a hard-edged logo differ, not this export, so it is measured with the point bake only.
#[test]
fn baked_textures_render_like_the_mesh_colors() {
    let gpu = Gpu::new_headless().unwrap();
    let dir = TempDir::new("psnr");
    let r8 = Resolution::new(8).unwrap();
    eprintln!(
        "| bake | model | texture | R | view (yaw, pitch) | mesh pixels | PSNR (dB) |\n|---|---|---|---|---|---|---|"
    );
    for (fit, floor, files) in [
        (BakeFit::Point, 35.0, &["BoxTextured/BoxTextured.glb", "Duck/Duck.glb", "Fox/Fox.glb"][..]),
        (BakeFit::LeastSquares, 34.0, &["Duck/Duck.glb", "Fox/Fox.glb"][..]),
    ] {
        let worst = worst_view(&gpu, &dir, r8, fit, files);
        assert!(worst >= floor, "{fit:?}: worst PSNR {worst:.1} dB < {floor} dB");
    }
}

/// The worst view (module docs of the test above) over `files` converted with `fit`.
fn worst_view(gpu: &Gpu, dir: &TempDir, r8: Resolution, fit: BakeFit, files: &[&str]) -> f64 {
    let mut worst = f64::INFINITY;
    for &file in files {
        let path = model(file);
        let scene = import_gltf(&path).unwrap();
        let size = scene.textures[0].width.max(scene.textures[0].height);
        let welded = weld_scene(&scene);
        let document = Document::from_scene_phased(
            scene.clone(),
            r8,
            fit,
            &path,
            &Budget::from_environment(),
            &mut OpenPhases::default(),
            meshpaint_core::progress::Reporter::silent().progress(),
        )
        .unwrap();
        let bake = bake_uv_texture(&document.store, &welded.corner_uvs, size, default_padding(size)).unwrap();
        assert!(bake.faces_without_uvs.is_empty(), "{file}");
        let mesh = TexturedMesh {
            positions: &welded.positions_world,
            triangles: &welded.triangles,
            corner_uvs: &welded.corner_uvs,
            corner_normals: &welded.corner_normals_world,
        };
        let glb = textured_glb(&mesh, &encode_png(&bake).unwrap()).unwrap();
        let out = dir.join(&format!("{fit:?}_{}.glb", file.replace('/', "_")));
        std::fs::write(&out, &glb.bytes).unwrap();
        let report = validate(&out);
        assert_eq!(
            (report["numErrors"].as_u64(), report["numWarnings"].as_u64()),
            (Some(0), Some(0)),
            "{file}: {report}"
        );
        let baked_scene = import_gltf(&out).unwrap();
        let baseline = gpu.upload_baseline(&baked_scene).unwrap().expect("the export has a base-colour texture");
        let colors = gpu.upload(&document.pack(document.display_format()).unwrap()).unwrap();
        let mut views = Vec::new();
        for (yaw, pitch) in [(30.0, 20.0), (210.0, -15.0), (120.0, 60.0)] {
            let mut settings = RenderSettings::new(default_camera(colors.bounds, yaw, pitch, None));
            // The bake stores the linear filter at level 0 at each texel centre: compare with
            // that (the default trilinear adds meshpaint's own level-of-detail choice, which is
            // not what the bake is asked to reproduce; the baked side keeps the viewer's mips).
            settings.filter = meshpaint_render::FilterMode::Linear;
            let a = gpu.render_image(DrawItem::MeshColors(&colors), &settings, 512, 512).unwrap();
            let b = gpu.render_image(DrawItem::Baseline(&baseline), &settings, 512, 512).unwrap();
            let (db, pixels) = psnr(&a, &b);
            eprintln!("| {fit:?} | {file} | {size}² | 8 | ({yaw}, {pitch}) | {pixels} | {db:.1} |");
            views.push(db);
            if (yaw, pitch) == (30.0, 20.0) && fit == BakeFit::default() {
                let name = file.split('/').next().unwrap();
                a.save(common::output_dir().join(format!("bake_uv_{name}_mesh_colors.png"))).unwrap();
                b.save(common::output_dir().join(format!("bake_uv_{name}_baked.png"))).unwrap();
            }
        }
        views.sort_by(f64::total_cmp);
        eprintln!("{file}: {} of {} covered texels conflict", bake.conflicting_texels, bake.covered_texels);
        // Duck: 35 of 159k covered texels conflict (mirrored islands); BoxTextured: 743 of 44.5k.
        if bake.conflicting_texels * 1000 <= bake.covered_texels {
            worst = worst.min(views[0]);
        } else {
            // Faces share texels with clearly different colours (BoxTextured: all 6 sides map
            // the whole texture; their R = 8 lattices meet the logo differently, 743 texels
            // differ by > 32 steps): the texture can hold one face's colours, so a view of
            // the other sides measures how two sides' samples differ, not the bake. The bar
            // holds on the best view (the kept side, seen 38.7 dB); the others must still be
            // close (seen 33.3, 33.6 dB).
            assert!(views[0] >= 30.0, "{file}: a view of the faces the texture could not keep: {:.1} dB", views[0]);
            worst = worst.min(views[views.len() - 1]);
        }
    }
    worst
}

use crate::validator::validate;

/// Runs `meshpaint export ARGS`; returns (success, stderr).
fn export(args: &[&str]) -> (bool, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_meshpaint")).arg("export").args(args).output().unwrap();
    (output.status.success(), String::from_utf8_lossy(&output.stderr).into_owned())
}

#[test]
fn the_command_line_writes_glb_and_png_and_reports_faces_without_uvs() {
    let dir = TempDir::new("cli");
    let duck = model("Duck/Duck.glb");
    let (glb, png, mpk) = (dir.join("duck.glb"), dir.join("duck.png"), dir.join("duck.mpk"));
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    let (ok, stderr) = export(&[&s(&duck), "-o", &s(&glb), "--texture", "256"]);
    assert!(ok, "{stderr}");
    let scene = import_gltf(&glb).unwrap();
    assert_eq!(scene.textures.len(), 1);
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (256, 256));
    assert_eq!(scene.instanced_triangle_count(), 4212);
    // Into the Duck's own UVs (asked for: they overlap, so by default new ones are made).
    let (ok, stderr) = export(&[&s(&duck), "-o", &s(&png), "--texture", "128", "--uvs", &s(&duck)]);
    assert!(ok, "{stderr}");
    assert_eq!(image::open(&png).unwrap().to_rgba8().dimensions(), (128, 128));

    // A packed file keeps no UVs (new ones by default); with the source's UVs it bakes the
    // same texture.
    let run = Command::new(env!("CARGO_BIN_EXE_meshpaint")).args(["pack", &s(&duck), "-o", &s(&mpk)]).output().unwrap();
    assert!(run.status.success());
    let (ok, stderr) = export(&[&s(&mpk), "-o", &s(&dir.join("new_uvs.png")), "--texture", "128"]);
    assert!(ok && stderr.contains("UVs: new UVs: the document keeps no UVs"), "{stderr}");
    let from_packed = dir.join("from_packed.png");
    let (ok, stderr) = export(&[&s(&mpk), "--uvs", &s(&duck), "-o", &s(&from_packed), "--texture", "128"]);
    assert!(ok, "{stderr}");
    let (a, b) = (image::open(&png).unwrap().to_rgba8(), image::open(&from_packed).unwrap().to_rgba8());
    // Each packed sample is within half an 8-bit step of the document's (sRGB-encoded); the
    // bake interpolates samples in linear light, and where the result is darker than the
    // samples it mixes the sRGB curve is steeper, so that half step can grow a little; the
    // texel's own rounding adds one. So: at most 2 steps, and more than 1 only rarely.
    let diffs: Vec<u8> = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).collect();
    let worst = diffs.iter().copied().max().unwrap();
    let over_one = diffs.iter().filter(|&&d| d > 1).count();
    assert!(
        worst <= 2 && over_one * 1000 <= diffs.len(),
        "the packed file's bake differs by up to {worst}, {over_one} of {} channels by more than 1",
        diffs.len()
    );
    // The Duck's two sides share their UVs: the command says so.
    assert!(stderr.contains("texels strictly inside two faces' UVs (paint there is lost)"), "{stderr}");
    // UVs of another mesh are refused.
    let (ok, stderr) =
        export(&[&s(&mpk), "--uvs", &s(&model("BoxTextured/BoxTextured.glb")), "-o", &s(&png), "--texture", "64"]);
    assert!(!ok && stderr.contains("is not the mesh of"), "{stderr}");

    // An STL has no UVs: new ones by default; baked into its own, every face is reported.
    let stl = workspace_path("assets/models/AssimpTestModels/sphereWithHole.stl");
    let (ok, stderr) = export(&[&s(&stl), "-o", &s(&png), "--texture", "64"]);
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("UVs: new UVs: the model has no UVs") && stderr.contains("0 of 285 faces without UVs"),
        "{stderr}"
    );
    let (ok, stderr) = export(&[&s(&stl), "-o", &s(&png), "--texture", "64", "--uvs", &s(&stl)]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("285 of 285 faces have no UVs"), "{stderr}");
}

/// UV-island texels against counts made by hand: a texel counts when its centre is in a
/// face's UV triangle, once however many faces cover it, wherever the UVs repeat.
#[test]
fn uv_island_texels_count_covered_texel_centres_once() {
    use meshpaint_core::convert::bake_uv::uv_island_texels;
    let square = [[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]]];
    assert_eq!(uv_island_texels(&square, [8, 4]), 32, "the whole texture");
    // The lower-left half u + v ≤ 1 of an 8 × 8 texture: centres (i + ½, j + ½) / 8 with
    // i + j + 1 ≤ 8, i.e. i + j ≤ 7: 36 texels.
    let half = [[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]];
    assert_eq!(uv_island_texels(&half, [8, 8]), 36);
    // Mirrored (the same triangle wound the other way) and stacked islands count once; UVs
    // shifted by whole repeats cover the same texels.
    let mirrored = [half[0], [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]], [[3.0, -2.0], [4.0, -2.0], [3.0, -1.0]]];
    assert_eq!(uv_island_texels(&mirrored, [8, 8]), 36);
    // A face with no UV area covers nothing.
    assert_eq!(uv_island_texels(&[[[0.5, 0.5]; 3]], [8, 8]), 0);
}
