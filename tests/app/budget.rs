//! The sample and memory budget: counts against what the store, the packer and the paint
//! layout really allocate, and every refusal path (import after instancing, open at R, set
//! R for all, the resolution brush, undo / redo, the command line) on budgets small enough
//! for CI, plus the finite-colour rule of the packed reader, the store and the blend modes.

use std::process::Command;

use meshpaint_core::colors::budget::{Budget, BudgetError, MemorySource, SampleCounts, SampleTracker};
use meshpaint_core::colors::format::{ColorFormat, MAX_CHANNEL, Rgba};
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::io::document::{Document, DocumentError};
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::file as packed_file;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::packer::PackLayout;
use meshpaint_core::packing::paint_layout::PaintLayout;
use meshpaint_core::paint::brush::{self, BlendMode, BrushError};
use meshpaint_core::paint::undo::{UndoError, UndoHistory};

use crate::common;
use crate::common::WriteThrough;
use common::{SplitMix64, TempFile, icosphere, model, output_dir};

const BIN: &str = env!("CARGO_BIN_EXE_meshpaint");

fn r(value: u64) -> Resolution {
    Resolution::new(value).unwrap()
}

fn sphere_store(levels: u32, resolution: u64) -> ColorStore {
    let (positions, triangles) = icosphere(levels);
    ColorStore::uniform(Topology::build(positions.len() as u32, &triangles).unwrap(), r(resolution), [0.5; 4])
}

/// A budget of `bytes` of memory (the packed limit, no GPU).
fn memory(bytes: u64) -> Budget {
    Budget::with_memory(bytes, MemorySource::Set)
}

/// The counts the store, the packer and the paint layout actually allocate.
fn allocated(store: &ColorStore) -> (u64, u64, u64) {
    let paint = PaintLayout::new(store);
    // The paint layout reserves 1.5× its blocks: capacity = end + end / 2.
    let end = paint.capacity() * 2 / 3;
    (store.sample_count(), PackLayout::of(store).unwrap().sample_count, end)
}

#[test]
fn counts_match_what_the_store_packer_and_paint_layout_allocate() {
    let mut rng = SplitMix64(7);
    for resolution in [1, 2, 4, 8, 32] {
        let store = sphere_store(2, resolution);
        let counts = SampleCounts::uniform_on(store.topology(), r(resolution));
        let (samples, with_mips, paint) = allocated(&store);
        assert_eq!((counts.samples, counts.samples_with_mips), (samples, with_mips), "R = {resolution}");
        assert!(paint.abs_diff(counts.paint_samples) <= 1, "R = {resolution}: {paint} vs {}", counts.paint_samples);
        assert_eq!(SampleCounts::of_store(&store), counts);
    }
    // Random per-face resolutions, then random single-face changes through the tracker.
    let mut store = sphere_store(2, 1);
    for face in 0..store.topology().face_count() {
        store.write_resolution(face, r(1 << rng.below(6))).unwrap();
    }
    let counts = SampleCounts::of_store(&store);
    let (samples, with_mips, _) = allocated(&store);
    assert_eq!((counts.samples, counts.samples_with_mips), (samples, with_mips));
    let mut tracker = SampleTracker::new(&store);
    let unlimited = memory(u64::MAX);
    for _ in 0..200 {
        let face = rng.below(u64::from(store.topology().face_count())) as u32;
        let target = r(1 << rng.below(7));
        tracker.admit(&store, face, target, &unlimited, ColorFormat::Rgba8Srgb).unwrap();
        store.write_resolution(face, target).unwrap();
        let (samples, with_mips, _) = allocated(&store);
        let tracked = tracker.counts();
        assert_eq!((tracked.samples, tracked.samples_with_mips), (samples, with_mips));
        assert_eq!(tracked.paint_samples, SampleCounts::of_store(&store).paint_samples);
    }
}

#[test]
fn limits_come_from_meminfo_and_byte_counts_parse() {
    let meminfo = "MemTotal:       24576000 kB\nMemFree:        1000 kB\n";
    assert_eq!(meshpaint_core::colors::budget::mem_total_bytes(meminfo), Some(24_576_000 * 1024));
    assert_eq!(meshpaint_core::colors::budget::mem_total_bytes("MemFree: 3 kB\n"), None);
    let parse = meshpaint_core::colors::budget::parse_bytes;
    assert_eq!(parse("512M"), Some(512 << 20));
    assert_eq!(parse("2GiB"), Some(2 << 30));
    assert_eq!(parse("1000"), Some(1000));
    assert_eq!(parse("0"), None);
    assert_eq!(parse("lots"), None);
    let machine = Budget::from_environment();
    assert!(machine.memory_bytes > 0);
    assert_eq!(machine.sample_limit().0, 1 << 28);
}

#[test]
fn set_r_for_all_is_refused_before_any_face_changes() {
    let mut store = sphere_store(2, 4);
    let before = store.clone();
    let needed = SampleCounts::uniform_on(store.topology(), r(64));
    // A packed limit just under what R = 64 needs.
    let budget = Budget { max_samples: needed.samples_with_mips.max(needed.paint_samples) - 1, ..memory(u64::MAX) };
    let mut history = UndoHistory::default();
    let error = brush::set_resolution(&mut store, &mut history, None, r(64), Some((&budget, ColorFormat::Rgba8Srgb)))
        .unwrap_err();
    let BrushError::Budget(BudgetError::Samples { needed: n, allowed, .. }) = &error else {
        panic!("{error:?}");
    };
    assert_eq!((*n, *allowed), (needed.samples_with_mips.max(needed.paint_samples), budget.max_samples));
    assert!(error.to_string().contains("R = 64 on every face"), "{error}");
    assert_eq!(store.face_resolutions(), before.face_resolutions());
    assert_eq!(history.undo_len(), 0);
    // A memory budget refuses too, and R = 8 fits.
    let tight = memory(needed.estimated_bytes(ColorFormat::Rgba8Srgb) - 1);
    let error = brush::set_resolution(&mut store, &mut history, None, r(64), Some((&tight, ColorFormat::Rgba8Srgb)))
        .unwrap_err();
    assert!(matches!(error, BrushError::Budget(BudgetError::Memory { .. })), "{error:?}");
    assert!(
        brush::set_resolution(&mut store, &mut history, None, r(8), Some((&tight, ColorFormat::Rgba8Srgb))).is_ok()
    );
}

#[test]
fn the_resolution_brush_stops_at_the_budget_and_undo_redo_respect_it() {
    let mut store = sphere_store(2, 2);
    let faces: Vec<u32> = (0..store.topology().face_count()).collect();
    let start = SampleCounts::of_store(&store);
    // Allow a few raised faces only.
    let budget = Budget { max_samples: start.samples_with_mips.max(start.paint_samples) + 5000, ..memory(u64::MAX) };
    let mut tracker = SampleTracker::new(&store);
    let mut raised = 0;
    for &face in &faces {
        match tracker.admit(&store, face, r(16), &budget, ColorFormat::Rgba8Srgb) {
            Ok(()) => {
                store.write_resolution(face, r(16)).unwrap();
                raised += 1;
            }
            Err(error) => {
                assert!(matches!(error, BudgetError::Samples { .. }), "{error:?}");
                break;
            }
        }
    }
    assert!(raised > 0 && raised < faces.len(), "{raised}");
    let counts = SampleCounts::of_store(&store);
    assert!(counts.samples_with_mips.max(counts.paint_samples) <= budget.max_samples);

    // Undo / redo: a "set resolution" step made without a budget cannot be redone within one.
    let mut store = sphere_store(2, 2);
    let mut history = UndoHistory::default();
    brush::set_resolution(&mut store, &mut history, None, r(32), None).unwrap();
    history.undo(&mut store).unwrap();
    let small = SampleCounts::of_store(&store);
    history.set_budget(Some((
        Budget { max_samples: small.samples_with_mips * 2, ..memory(u64::MAX) },
        ColorFormat::Rgba8Srgb,
    )));
    let before = store.clone();
    let error = history.redo(&mut store).unwrap_err();
    assert!(matches!(error, UndoError::Budget(BudgetError::Samples { .. })), "{error:?}");
    assert_eq!(store.face_resolutions(), before.face_resolutions());
    assert_eq!(history.redo_len(), 1, "the refused step is kept");
    history.set_budget(None);
    assert!(history.redo(&mut store).unwrap());
    // Undo back down always passes, however small the budget.
    history.set_budget(Some((Budget { max_samples: 1, ..memory(1) }, ColorFormat::Rgba8Srgb)));
    assert!(history.undo(&mut store).unwrap());
}

#[test]
fn opening_at_r_is_refused_before_the_store_exists() {
    let duck = model("Duck/Duck.glb");
    // R = 4096 on the Duck is past the packed limit on any machine.
    let error = Document::open_within(&duck, r(4096), &Budget::from_environment()).unwrap_err();
    let DocumentError::Budget { source: BudgetError::Samples { needed, allowed, .. }, .. } = &error else {
        panic!("{error:?}");
    };
    assert_eq!(*allowed, 1 << 28);
    assert!(*needed > 1 << 28);
    let text = error.to_string();
    assert!(text.contains("Duck.glb") && text.contains("R = 4096"), "{text}");
    // A small memory budget refuses R = 16 and admits R = 1.
    let error = Document::open_within(&duck, r(16), &memory(16 << 20)).unwrap_err();
    assert!(matches!(error, DocumentError::Budget { source: BudgetError::Memory { .. }, .. }), "{error:?}");
    assert!(Document::open_within(&duck, r(1), &memory(16 << 20)).is_ok());
    // A packed file is checked before it is unpacked.
    let document = Document::open_within(&duck, r(8), &memory(1 << 30)).unwrap();
    let file = TempFile::new("budget", "duck.mpk");
    packed_file::write_file(file.path(), &document.pack(ColorFormat::Rgba8Srgb).unwrap()).unwrap();
    let error = Document::open_within(file.path(), r(1), &memory(8 << 20)).unwrap_err();
    assert!(matches!(error, DocumentError::Budget { .. }), "{error:?}");
    assert!(Document::open_within(file.path(), r(1), &memory(1 << 30)).is_ok());
}

/// Duck.glb with `extra` more scene nodes that each instance the Duck's mesh.
fn duck_with_instances(extra: usize) -> Vec<u8> {
    let bytes = std::fs::read(model("Duck/Duck.glb")).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let rest = &bytes[20 + json_len..];
    let mesh = json["nodes"].as_array().unwrap().iter().find_map(|n| n.get("mesh").cloned()).unwrap();
    let first = json["nodes"].as_array().unwrap().len();
    let scene = json["scene"].as_u64().unwrap_or(0) as usize;
    for k in 0..extra {
        json["nodes"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({ "mesh": mesh, "translation": [k as f32, 0.0, 0.0] }));
        json["scenes"][scene]["nodes"].as_array_mut().unwrap().push((first + k).into());
    }
    let mut text = serde_json::to_vec(&json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + rest.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(rest);
    out
}

#[test]
fn instancing_past_the_triangle_budget_is_refused_while_the_file_is_read() {
    let path = output_dir().join("budget_duck_20000_nodes.glb");
    std::fs::write(&path, duck_with_instances(20_000)).unwrap();
    // 20 001 instances of 4 212 triangles: 84 M triangles, past 8 GiB at 600 B each.
    let error = Document::open_within(&path, r(1), &memory(8 << 30)).unwrap_err();
    let text = error.to_string();
    assert!(matches!(error, DocumentError::Import(_)), "{error:?}");
    assert!(text.contains("84 244 212") || text.contains("84244212"), "{text}");
    // A few instances are fine.
    let few = output_dir().join("budget_duck_3_nodes.glb");
    std::fs::write(&few, duck_with_instances(3)).unwrap();
    let document = Document::open_within(&few, r(1), &memory(8 << 30)).unwrap();
    assert_eq!(document.store.topology().face_count(), 4 * 4212);
}

/// Runs the binary with a memory budget and returns (exit code, stderr).
fn run(args: &[&str], budget: &str) -> (Option<i32>, String) {
    // A valid runtime directory, so the GPU stack prints nothing of its own.
    let runtime = output_dir().join("budget_runtime");
    std::fs::create_dir_all(&runtime).unwrap();
    std::fs::set_permissions(&runtime, std::os::unix::fs::PermissionsExt::from_mode(0o700)).unwrap();
    let output = Command::new(BIN)
        .args(args)
        .env("MESHPAINT_MEMORY_BUDGET", budget)
        .env("XDG_RUNTIME_DIR", &runtime)
        .output()
        .unwrap();
    (output.status.code(), String::from_utf8_lossy(&output.stderr).into_owned())
}

/// Asserts a clean refusal: exit 1 and one `error:` line naming `needles`.
fn assert_refused(args: &[&str], budget: &str, needles: &[&str]) {
    let (code, stderr) = run(args, budget);
    assert_eq!(code, Some(1), "meshpaint {}: {stderr}", args.join(" "));
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for needle in needles {
        assert!(lines[0].contains(needle), "'{needle}' missing: {stderr}");
    }
}

#[test]
fn the_command_line_refuses_each_reproduction_with_one_line() {
    let duck = model("Duck/Duck.glb");
    let duck = duck.to_str().unwrap();
    let bunny = model("Bunny144k/bunny.glb");
    let bunny = bunny.to_str().unwrap();
    let out = output_dir().join("budget_out.mpk");
    let out = out.to_str().unwrap();
    let glb = output_dir().join("budget_out.glb");
    let glb = glb.to_str().unwrap();
    let packed_limit = "268 435 456";
    let _ = std::fs::remove_file(out);
    for (args, needles) in [
        (vec!["pack", duck, "-r", "4096", "-o", out], vec!["R = 4096", packed_limit]),
        (vec!["pack", bunny, "-r", "64", "-o", out], vec!["R = 64", packed_limit]),
        (vec!["export", duck, "-r", "4096", "-o", out], vec!["R = 4096", packed_limit]),
        (vec!["paint", duck, "-r", "4096", "--stroke", "1,1", "-o", out], vec!["R = 4096", packed_limit]),
        // Past a 2 GiB memory budget at R = 256, and past the GLB's 4 GiB as a .glb.
        (vec!["pack", duck, "-r", "256", "-o", out], vec!["R = 256", "of memory", "2.0 GiB"]),
        (vec!["export", duck, "-r", "256", "-o", glb], vec!["R = 256"]),
    ] {
        assert_refused(&args, "2G", &needles);
    }
    assert!(!std::path::Path::new(out).exists(), "a refused command writes nothing");
    let many = output_dir().join("budget_cli_20000_nodes.glb");
    std::fs::write(&many, duck_with_instances(20_000)).unwrap();
    let many = many.to_str().unwrap();
    for command in ["info", "pack"] {
        let mut args = vec![command, many];
        if command == "pack" {
            args.extend(["-o", out]);
        }
        assert_refused(&args, "8G", &["triangles", "more than"]);
    }
    // `info` reports the budget at any R without allocating it.
    let output = Command::new(BIN).args(["info", duck, "-r", "4096", "--json"]).output().unwrap();
    assert!(output.status.success());
    let info: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(info["fits_budget"], false);
    assert!(info["budget_refusal"].as_str().unwrap().contains(packed_limit));
}

#[test]
fn render_is_refused_past_the_gpu_and_packed_limits() {
    let duck = model("Duck/Duck.glb");
    let png = output_dir().join("budget_render.png");
    assert_refused(
        &["render", duck.to_str().unwrap(), "-r", "4096", "-o", png.to_str().unwrap()],
        "8G",
        &["R = 4096", "268 435 456"],
    );
}

// ---------------------------------------------------------------- finite colours

/// The bytes of a packed file whose vertex 1 has colour `bad`: written with a valid colour
/// (the writer refuses bad ones too), then patched with the checksum recomputed, so the
/// colour reaches the reader's content checks.
fn file_with_color(format: ColorFormat, bad: [f32; 4]) -> Vec<u8> {
    let mut bytes = packed_file::to_bytes(&packed_with_color(format, [0.75; 4])).unwrap();
    let size = format.bytes_per_sample();
    // The colour section ends the file: samples 0, 1, 2 are its last 3 · size bytes.
    let start = bytes.len() - 2 * size;
    let patch = packed_with_color(format, bad).colors;
    bytes[start..start + size].copy_from_slice(&patch[size..2 * size]);
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..124]);
    hasher.update(&bytes[128..]);
    let crc = hasher.finalize();
    bytes[124..128].copy_from_slice(&crc.to_le_bytes());
    bytes
}

/// A one-triangle packed mesh at R = 1 in `format` whose vertex 1 has colour `bad`.
fn packed_with_color(format: ColorFormat, bad: [f32; 4]) -> PackedMesh {
    let mut colors = Vec::new();
    for color in [[0.5f32; 4], bad, [0.25; 4]] {
        for channel in color {
            match format {
                ColorFormat::Rgba16F => colors.extend_from_slice(&half::f16::from_f32(channel).to_bits().to_le_bytes()),
                _ => colors.extend_from_slice(&channel.to_le_bytes()),
            }
        }
    }
    PackedMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        indices: vec![[0, 1, 2]],
        vertex_levels: 1,
        face_records: vec![meshpaint_core::packing::linear::FaceRecord { interior: 0, edges: [0; 3] }],
        format,
        colors,
    }
}

#[test]
fn the_packed_reader_refuses_colours_the_formats_cannot_hold() {
    for format in [ColorFormat::Rgba16F, ColorFormat::Rgba32F] {
        let good = packed_file::to_bytes(&packed_with_color(format, [5.0, 0.0, 65504.0, 1.0])).unwrap();
        let mesh = packed_file::from_bytes(&good).unwrap();
        assert_eq!(mesh.color(1).unwrap(), [5.0, 0.0, 65504.0, 1.0], "{format:?}: HDR values in range are kept");
        for bad in [
            [f32::NAN, 0.0, 0.0, 1.0],
            [f32::INFINITY, 0.0, 0.0, 1.0],
            [0.0, f32::NEG_INFINITY, 0.0, 1.0],
            [-3.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0, 2.0],
        ] {
            assert!(packed_file::to_bytes(&packed_with_color(format, bad)).is_err(), "the writer refuses too");
            let error = packed_file::from_bytes(&file_with_color(format, bad)).unwrap_err();
            let text = error.to_string();
            assert!(text.contains("sample 1") && text.contains("finite"), "{format:?} {bad:?}: {text}");
        }
    }
    let bytes = file_with_color(ColorFormat::Rgba32F, [70000.0, 0.0, 0.0, 1.0]);
    assert!(packed_file::from_bytes(&bytes).is_err(), "above RGBA16F's largest finite value");
    // The same file with a valid colour reads: the patching itself is sound.
    let bytes = file_with_color(ColorFormat::Rgba32F, [0.125, 0.0, 0.0, 1.0]);
    assert_eq!(packed_file::from_bytes(&bytes).unwrap().color(1).unwrap(), [0.125, 0.0, 0.0, 1.0]);
}

#[test]
fn the_store_blends_and_encoders_never_hold_a_non_finite_colour() {
    let mut store = sphere_store(1, 4);
    let sample = SampleRef::Vertex(0);
    for (written, stored) in [
        ([f32::NAN, 1.0, 0.5, 1.0], [0.0, 1.0, 0.5, 1.0]),
        ([f32::INFINITY, -1.0, 1e9, 3.0], [MAX_CHANNEL, 0.0, MAX_CHANNEL, 1.0]),
    ] {
        store.write_sample(sample, written);
        assert_eq!(store.get(sample).unwrap(), stored);
    }
    // Add at the largest value stays the largest value, never infinity.
    let top: Rgba = [MAX_CHANNEL, MAX_CHANNEL, 1.0, 1.0];
    let added = BlendMode::Add.blend(top, top, top, 1.0);
    assert!(added.iter().all(|c| c.is_finite()));
    assert_eq!(added, [MAX_CHANNEL, MAX_CHANNEL, 2.0f32.min(MAX_CHANNEL), 1.0]);
    // Encoders clamp whatever they are given: no NaN reaches a file or the GPU.
    for format in ColorFormat::ALL {
        let mut bytes = Vec::new();
        format.encode_into([f32::NAN, f32::INFINITY, -2.0, 0.5], &mut bytes);
        let decoded = format.decode(&bytes);
        assert!(meshpaint_core::colors::format::is_storable(decoded), "{format:?}: {decoded:?}");
    }
}

#[test]
fn gpu_texture_limits_and_texture_sizes_are_part_of_the_budget() {
    use meshpaint_core::colors::budget::GpuLimits;
    let duck = model("Duck/Duck.glb");
    // A 256 × 256 atlas holds 65 536 samples; the Duck at R = 8 needs 179 018 with MIP chains
    // and 187 436 in the paint-mode layout (the larger decides).
    let small_gpu = memory(1 << 30).with_gpu(GpuLimits { max_texture_dimension_2d: 256 });
    assert_eq!(small_gpu.sample_limit().0, 256 * 256);
    let error = Document::open_within(&duck, r(8), &small_gpu).unwrap_err();
    let text = error.to_string();
    assert!(text.contains("187 436 samples in the paint-mode layout") && text.contains("65 536"), "{text}");
    assert!(text.contains("colour atlas"), "{text}");
    assert!(Document::open_within(&duck, r(2), &small_gpu).is_ok());
    // Texture texels are checked from the image header: past the limit the texture is skipped
    // with a warning naming its size and the limit.
    let limits = meshpaint_core::mesh::import::ImportLimits { max_texels: 1000, ..Default::default() };
    let scene = meshpaint_core::mesh::import::import_gltf_within(&duck, &limits).unwrap();
    assert!(scene.textures.is_empty());
    let warning = scene.warnings.iter().find(|w| w.contains("texels")).expect("a warning about the texture");
    assert!(warning.contains("1000"), "{warning}");
    let scene = meshpaint_core::mesh::import::import_gltf_within(&duck, &Default::default()).unwrap();
    assert_eq!(scene.textures.len(), 1);
}
