//! The vertex-colour export that fits the content (`export --level / --max-vertices / --colors`).
//!
//! Truths: linear interpolation is exact at lattice points (error 0 against itself) and the
//! 2× reduction keeps a linear colour field, which the coarse faces then reproduce at every
//! original sample (closed form); `--max-vertices` takes the finest level that fits (the
//! counts of the written files, read back by the importer, one level finer does not fit);
//! normalized COLOR_0 read back by the importer equals the float export within the encoding's
//! step; the Khronos validator accepts normalized u8 and u16 colours.

use std::process::Command;

use crate::common;
use crate::common::WriteThrough;
use common::{TempDir, model};

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::io::document::Document;
use meshpaint_core::io::export_fit::{FitOptions, coarser, error_steps, smallest_encoding, write_fitted_glb};
use meshpaint_core::io::export_gltf::{ColorEncoding, tessellation_counts};
use meshpaint_core::mesh::import::import_gltf;
use meshpaint_core::mesh::topology::Topology;

/// A flat 2-triangle square at R = 8 coloured with a linear field of the position.
fn linear_square() -> (Vec<[f32; 3]>, ColorStore) {
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let triangles = [[0u32, 1, 2], [0, 2, 3]];
    let mut store = ColorStore::uniform(Topology::build(4, &triangles).unwrap(), Resolution::new(8).unwrap(), [0.0; 4]);
    let p = positions.clone();
    store.write_all(|site| {
        let face = triangles[site.face as usize];
        let at = |a: usize| (0..3).map(|k| site.barycentric[k] * p[face[k] as usize][a]).sum::<f32>();
        [0.2 + 0.6 * at(0), 0.9 - 0.5 * at(1), 0.5 * (at(0) + at(1)), 1.0]
    });
    (positions, store)
}

#[test]
fn errors_are_zero_where_the_coarse_level_is_exact() {
    let (_, store) = linear_square();
    assert_eq!(error_steps(&store, &store), (0.0, 0.0));
    for levels in 1..=3 {
        let coarse = coarser(&store, levels);
        assert!(coarse.face_resolutions().iter().all(|r| r.get() == 8 >> levels));
        let (max, rms) = error_steps(&store, &coarse);
        assert!(max <= 1.0 && rms < 0.5, "level {levels}: a linear field is kept, error max {max} RMS {rms}");
    }
    // A real texture loses detail: the error grows with the level.
    let duck = Document::open(&model("Duck/Duck.glb"), Resolution::new(8).unwrap()).unwrap();
    let errors: Vec<f64> = (1..=3).map(|l| error_steps(&duck.store, &coarser(&duck.store, l)).1).collect();
    assert!(errors[0] > 0.5 && errors[0] < errors[1] && errors[1] < errors[2], "{errors:?}");
}

#[test]
fn max_vertices_picks_the_finest_level_that_fits() {
    let dir = TempDir::new("max-vertices");
    let duck = Document::open(&model("Duck/Duck.glb"), Resolution::new(8).unwrap()).unwrap();
    for max in [200_000u64, 100_000, 20_000, 3_000] {
        let path = dir.join(&format!("duck_{max}.glb"));
        let options = FitOptions { max_vertices: Some(max), ..FitOptions::default() };
        let summary = write_fitted_glb(&path, &duck.positions, &duck.store, ColorFormat::Rgba8Srgb, options).unwrap();
        let mesh = import_gltf(&path).unwrap().meshes.remove(0);
        assert_eq!(mesh.positions_local.len() as u64, summary.vertices);
        assert!(summary.vertices <= max, "{max}: {} vertices", summary.vertices);
        if summary.level > 0 {
            let (finer, _) = tessellation_counts(&coarser(&duck.store, summary.level - 1));
            assert!(finer > max, "{max}: level {} - 1 has {finer} vertices and would fit", summary.level);
        }
    }
    let options = FitOptions { max_vertices: Some(100), ..FitOptions::default() };
    let error = write_fitted_glb(&dir.join("x.glb"), &duck.positions, &duck.store, ColorFormat::Rgba8Srgb, options);
    assert!(error.unwrap_err().to_string().contains("2108 vertices"));
}

#[test]
fn normalized_colors_read_back_within_their_step_and_validate() {
    let dir = TempDir::new("encodings");
    let (positions, store) = linear_square();
    let mut colors_by_encoding = Vec::new();
    for encoding in [ColorEncoding::Float, ColorEncoding::Unorm16, ColorEncoding::Unorm8] {
        let path = dir.join(&format!("{encoding:?}.glb"));
        let options = FitOptions { encoding: Some(encoding), ..FitOptions::default() };
        let summary = write_fitted_glb(&path, &positions, &store, ColorFormat::Rgba8Srgb, options).unwrap();
        assert_eq!(summary.color_bytes, (summary.vertices * encoding.bytes() as u64, summary.vertices * 16));
        colors_by_encoding.push(import_gltf(&path).unwrap().meshes.remove(0).colors);
        let report = validate(&path);
        assert_eq!(report["numErrors"], 0, "{encoding:?}: {report}");
        assert_eq!(report["numWarnings"], 0, "{encoding:?}: {report}");
    }
    for (k, step) in [(1, 1.0 / 65535.0), (2, 1.0 / 255.0)] {
        let worst = colors_by_encoding[0]
            .iter()
            .zip(&colors_by_encoding[k])
            .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst <= 0.5 * step + 1e-7, "encoding {k}: read back {worst} away");
    }
    // The choice: u16 for sRGB8 content with dark colours, u8 only where it cannot be seen.
    assert_eq!(smallest_encoding(&[[0.001, 0.5, 0.9, 1.0]], ColorFormat::Rgba8Srgb), ColorEncoding::Unorm16);
    assert_eq!(smallest_encoding(&[[1.0, 0.0, 1.0, 1.0]], ColorFormat::Rgba8Srgb), ColorEncoding::Unorm8);
    assert_eq!(smallest_encoding(&[[0.3, 0.5, 0.9, 1.0]], ColorFormat::Rgba32F), ColorEncoding::Float);
}

use crate::validator::validate;

#[test]
fn the_command_line_reports_level_error_and_savings() {
    let dir = TempDir::new("cli");
    let out = dir.join("duck.glb");
    let output = Command::new(env!("CARGO_BIN_EXE_meshpaint"))
        .arg("export")
        .arg(model("Duck/Duck.glb"))
        .arg("-o")
        .arg(&out)
        .args(["--max-vertices", "40000"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("level 1") && stderr.contains("Unorm16") && stderr.contains("RMS"), "{stderr}");
    assert!(import_gltf(&out).unwrap().meshes[0].positions_local.len() <= 40_000);
}
