//! `meshpaint render --representation ptex`: a coloured, mixed-R Duck drawn as a packed Ptex
//! stays within the stated PSNR of mesh colors' linear filter (docs/PTEX.md); `export
//! --representation ptex` writes a packed Ptex file that `render` draws as its source.

use crate::common;
use crate::common::WriteThrough;

use common::model;
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn run_cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(BIN).args(args).output().unwrap()
}

#[test]
fn cli_render_ptex_of_a_painted_mixed_resolution_duck_is_close_to_mesh_colors_linear() {
    let mut document =
        meshpaint_core::io::document::Document::open(&model("Duck/Duck.glb"), Resolution::new(16).unwrap()).unwrap();
    document.store = meshpaint_core::io::document::position_colored(&document.store, &document.positions);
    let faces = document.store.topology().face_count();
    for face in 0..faces {
        document.store.write_resolution(face, Resolution::from_log2(1 + face % 5).unwrap()).unwrap();
    }
    let dir = common::TempDir::new("ptex-render");
    let file = dir.join("duck.mpk");
    meshpaint_core::packing::file::write_file(&file, &document.pack(ColorFormat::Rgba8Srgb).unwrap()).unwrap();
    let render = |representation: &str, filter: &str| {
        let out = dir.join(&format!("{representation}-{filter}.png"));
        let output = run_cli(&[
            "render",
            file.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--filter",
            filter,
            "--shading",
            "unlit",
            "--representation",
            representation,
        ]);
        assert!(output.status.success(), "{representation}: {}", String::from_utf8_lossy(&output.stderr));
        image::open(&out).unwrap().to_rgba8()
    };
    for (filter, stated_db) in [("linear", 57.0), ("trilinear", 53.0)] {
        let (mesh_colors, ptex) = (render("mesh-colors", filter), render("ptex", filter));
        let mut squared = 0.0f64;
        let mut count = 0u64;
        for (a, b) in mesh_colors.pixels().zip(ptex.pixels()) {
            for c in 0..3 {
                squared += (f64::from(a[c]) - f64::from(b[c])).powi(2);
            }
            count += 3;
        }
        let psnr = 10.0 * (255.0f64.powi(2) / (squared / count as f64).max(1e-12)).log10();
        println!("packed Ptex vs mesh colors {filter}, coloured mixed-R Duck: {psnr:.1} dB");
        assert!(psnr >= stated_db, "{filter}: {psnr} dB");
    }
}

/// `export --representation ptex` writes a packed Ptex file that `render` reads back and draws
/// exactly as `render SOURCE --representation ptex` (the same pixels).
#[test]
fn cli_export_ptex_round_trips_through_render() {
    let dir = common::TempDir::new("ptex-export");
    let out = dir.join("duck.ptx");
    let input = model("Duck/Duck.glb");
    let input = input.to_str().unwrap();
    let output = run_cli(&["export", input, "-r", "4", "--representation", "ptex", "-o", out.to_str().unwrap()]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let file = meshpaint_core::ptex::file::read_ptex(&out).unwrap();
    assert!(!file.ptex.texels.is_empty());
    let (a, b) = (dir.join("from_file.png"), dir.join("from_source.png"));
    let from_file = run_cli(&["render", out.to_str().unwrap(), "-o", a.to_str().unwrap(), "--shading", "unlit"]);
    assert!(from_file.status.success(), "{}", String::from_utf8_lossy(&from_file.stderr));
    let args =
        ["render", input, "-r", "4", "-o", b.to_str().unwrap(), "--shading", "unlit", "--representation", "ptex"];
    let from_source = run_cli(&args);
    assert!(from_source.status.success(), "{}", String::from_utf8_lossy(&from_source.stderr));
    let (a, b) = (image::open(&a).unwrap().to_rgba8(), image::open(&b).unwrap().to_rgba8());
    assert_eq!(a.dimensions(), b.dimensions());
    let differ = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    assert_eq!(differ, 0, "the file draws as its source");
}
