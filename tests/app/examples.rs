//! The examples in examples/ run and do what they say. Each example's work is a function
//! (its `main` only reads the command line), included here as a module and called directly:
//! integration tests have no `cargo run --example`.

use crate::common;
use common::{TempDir, model};

#[path = "../../crates/core/examples/paint_stroke.rs"]
#[allow(dead_code)] // the example's `main`
mod paint_stroke;

#[path = "../../crates/render/examples/render_offscreen.rs"]
#[allow(dead_code)] // the example's `main`
mod render_offscreen;

#[path = "../../examples/view_packed.rs"]
#[allow(dead_code)] // the example's `main`
mod view_packed;

use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::io::document::{Document, SourceKind};

/// Every sample's colour, in `for_each_site` order.
fn colors(store: &ColorStore) -> Vec<[f32; 4]> {
    let mut out = Vec::new();
    store.for_each_site(|site| out.push(store.get(site.sample).unwrap()));
    out
}

#[test]
fn paint_stroke_writes_a_packed_file_with_painted_samples() {
    let dir = TempDir::new("paint-stroke");
    let input = model("Duck/Duck.glb");
    let output = dir.join("painted.mpk");
    let changed = paint_stroke::paint_stroke(&input, &output).unwrap();
    assert!(changed > 100, "the stroke changed only {changed} samples");

    let r8 = Resolution::new(8).unwrap();
    let painted = Document::open(&output, r8).expect("the example's output does not reopen");
    let SourceKind::Packed(format) = painted.source else { panic!("not a packed file: {:?}", painted.source) };
    // The unpainted Duck, quantised exactly as the example's save was.
    let original = Document::open(&input, r8).unwrap();
    let original = Document::from_packed(&original.pack(format).unwrap()).unwrap();
    let (before, after) = (colors(&original.store), colors(&painted.store));
    assert_eq!(before.len(), after.len(), "the sample count changed");
    let differ = before.iter().zip(&after).filter(|(a, b)| a != b).count() as u64;
    assert!(differ > 100 && differ <= changed, "{differ} samples differ after reopening, {changed} changed");
    // Every changed sample moved towards the brush colour (mix blend).
    let distance = |c: &[f32; 4]| c.iter().zip(paint_stroke::COLOR).map(|(a, b)| (a - b) * (a - b)).sum::<f32>();
    for (old, new) in before.iter().zip(&after).filter(|(a, b)| a != b) {
        assert!(distance(new) <= distance(old) + 1e-4, "{old:?} → {new:?} is not towards {:?}", paint_stroke::COLOR);
    }
}

#[test]
fn render_offscreen_writes_a_png_of_the_mesh() {
    let dir = TempDir::new("render-offscreen");
    let output = dir.join("duck.png");
    let adapter = render_offscreen::render_offscreen(&model("Duck/Duck.glb"), &output, 320, 240).unwrap();
    eprintln!("adapter: {adapter}");
    assert!(std::fs::metadata(&output).unwrap().len() > 0, "empty PNG");
    let image = image::open(&output).expect("not a readable PNG").to_rgba8();
    assert_eq!(image.dimensions(), (320, 240));
    let background = *image.get_pixel(0, 0);
    let covered = image.pixels().filter(|p| **p != background).count();
    assert!(covered > 320 * 240 / 20, "only {covered} pixels differ from the background");
}

/// `view_packed` (packed file read by its documented layout, drawn with the shipped WGSL, no
/// meshpaint code) renders the same pixels as `meshpaint render` of the same file and camera,
/// within one step per channel: in RGBA8 and RGBA16F, with a painted file's mixed resolutions.
#[test]
fn view_packed_renders_what_meshpaint_render_renders() {
    let dir = TempDir::new("view-packed");
    let bin = env!("CARGO_BIN_EXE_meshpaint");
    let run = |args: &[&str]| {
        let output = std::process::Command::new(bin).args(args).output().unwrap();
        assert!(output.status.success(), "meshpaint {args:?}: {}", String::from_utf8_lossy(&output.stderr));
    };
    // A painted file (the paint_stroke example's output) with some faces raised to R = 16.
    let (painted, mixed) = (dir.join("painted.mpk"), dir.join("mixed.mpk"));
    paint_stroke::paint_stroke(&model("Duck/Duck.glb"), &painted).unwrap();
    let (painted_arg, mixed_arg) = (painted.to_str().unwrap(), mixed.to_str().unwrap());
    run(&["paint", painted_arg, "--tool", "raise", "--stroke", "470,330 560,360", "-o", mixed_arg]);
    let mixed_document = Document::open(&mixed, Resolution::ONE).unwrap();
    let resolutions = mixed_document.store.face_resolutions();
    assert!(resolutions.iter().min() < resolutions.iter().max(), "the raise stroke left one resolution");
    // The textured Fox in RGBA16F.
    let fox = dir.join("fox16f.mpk");
    run(&[
        "pack",
        model("Fox/Fox.glb").to_str().unwrap(),
        "-o",
        fox.to_str().unwrap(),
        "--format",
        "rgba16f",
        "-r",
        "4",
    ]);
    for (file, yaw, pitch) in [(&mixed, 30.0, 20.0), (&fox, -60.0, 35.0)] {
        let (reference, ours) = (dir.join("render.png"), dir.join("view.png"));
        let (yaw_arg, pitch_arg) = (format!("--yaw={yaw}"), format!("--pitch={pitch}"));
        run(&[
            "render",
            file.to_str().unwrap(),
            "-o",
            reference.to_str().unwrap(),
            "--width",
            "320",
            "--height",
            "240",
            &yaw_arg,
            &pitch_arg,
        ]);
        view_packed::view_packed(file, &ours, (320, 240), yaw, pitch).unwrap();
        let (a, b) = (image::open(&reference).unwrap().to_rgba8(), image::open(&ours).unwrap().to_rgba8());
        assert_eq!(a.dimensions(), b.dimensions());
        let worst = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        let background = *a.get_pixel(0, 0);
        let covered = a.pixels().filter(|p| **p != background).count();
        assert!(covered > 320 * 240 / 20, "{}: only {covered} mesh pixels", file.display());
        assert!(worst <= 1, "{}: a channel differs by {worst} steps", file.display());
    }
}
