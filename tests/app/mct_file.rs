//! Issue 41: an exported MCT file renders as the source does (`render FILE.mct` against
//! `render SOURCE --representation mct`), `info` reads it, and a damaged one is refused with
//! a message naming it.

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;

use crate::common::WriteThrough;

use crate::common::{TempDir, model};

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn run_cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(BIN).args(args).output().unwrap()
}

/// A position-coloured Duck with R from 2 to 32 by face (so block resolutions differ from
/// face resolutions on mixed edges, and the level of detail needs each face's own R).
fn mixed_duck(dir: &TempDir) -> std::path::PathBuf {
    let mut document =
        meshpaint_core::io::document::Document::open(&model("Duck/Duck.glb"), Resolution::new(16).unwrap()).unwrap();
    document.store = meshpaint_core::io::document::position_colored(&document.store, &document.positions);
    for face in 0..document.store.topology().face_count() {
        document.store.write_resolution(face, Resolution::from_log2(1 + face % 5).unwrap()).unwrap();
    }
    let file = dir.join("duck.mpk");
    meshpaint_core::packing::file::write_file(&file, &document.pack(ColorFormat::Rgba8Srgb).unwrap()).unwrap();
    file
}

fn render(input: &std::path::Path, out: &std::path::Path, extra: &[&str]) -> image::RgbaImage {
    let mut args = vec!["render", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--shading", "unlit"];
    args.extend_from_slice(extra);
    let output = run_cli(&args);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    image::open(out).unwrap().to_rgba8()
}

#[test]
fn an_exported_mct_file_renders_as_its_source_and_info_reads_it() {
    let dir = TempDir::new("mct-file-render");
    let source = mixed_duck(&dir);
    let mct = dir.join("duck.mct");
    let output = run_cli(&["export", source.to_str().unwrap(), "-o", mct.to_str().unwrap(), "--representation", "mct"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    for filter in [&["--filter", "trilinear"][..], &["--filter", "linear"], &["--filter", "mip", "--level", "2"]] {
        let from_source =
            render(&source, &dir.join("source.png"), &[&["--representation", "mct"][..], filter].concat());
        let from_file = render(&mct, &dir.join("file.png"), filter);
        let worst = from_source
            .pixels()
            .zip(from_file.pixels())
            .map(|(a, b)| (0..4).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0))
            .max()
            .unwrap_or(0);
        let covered = from_file.pixels().filter(|p| p[3] > 0 && p.0 != from_file.get_pixel(0, 0).0).count();
        println!("{filter:?}: largest difference {worst} steps, {covered} pixels on the duck");
        assert!(worst <= 1 && covered > 10_000, "{filter:?}: {worst} steps, {covered} pixels");
    }
    let output = run_cli(&["info", mct.to_str().unwrap(), "--json"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let info: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(info["kind"], "mct");
    assert_eq!(info["faces"], 4212);
    assert_eq!(info["levels"], 6);
    // A damaged file is refused, naming it.
    let bytes = std::fs::read(&mct).unwrap();
    let damaged = dir.join("damaged.mct");
    std::fs::write(&damaged, &bytes[..bytes.len() - 7]).unwrap();
    let output = run_cli(&["render", damaged.to_str().unwrap(), "-o", dir.join("x.png").to_str().unwrap()]);
    let error = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && error.contains("damaged.mct") && error.contains("truncated"), "{error}");
}
