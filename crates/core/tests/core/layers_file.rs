//! Documents with layers in the packed file (docs/FORMAT.md, "Layers section"): a saved
//! document with layers reopens identical, files without layers stay version 1 byte for
//! byte, the documented layout holds (offsets hard-coded from the doc), and hostile layers
//! sections are refused with a message, never a panic.

use crate::common::{Rng, TempDir, WriteThrough, octahedron};
use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::{ColorStore, SampleRef};
use meshpaint_core::io::document::Document;
use meshpaint_core::layers::{BlendMode, LayerStack, PaintTarget};
use meshpaint_core::packing::file::{self as packed_file, PackedFileError};
use meshpaint_core::packing::packer;

/// The octahedron at R = 1, 2, 4, 8 with random colours, and three layers: a painted
/// overlay layer with a painted mask at opacity 0.7, and a hidden multiply layer.
fn layered_document(format: ColorFormat) -> Document {
    let (positions, topology) = octahedron();
    let faces = topology.face_count() as usize;
    let resolutions = (0..faces).map(|f| Resolution::new(1 << (f % 4)).unwrap()).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.5; 4]).unwrap();
    let mut rng = Rng(21);
    store.write_all(|_| rng.color());
    let mut document = Document::from_packed(&packer::pack(&store, &positions, format).unwrap()).unwrap();
    let mut stack = LayerStack::from_store(&document.store);
    stack.add_layer("rust — ржавчина", None).unwrap();
    stack.begin_paint(PaintTarget::Content, "paint").unwrap();
    stack.writer().unwrap().fill_with(|_| rng.color());
    stack.end_paint();
    stack.add_mask(1, 1.0, None).unwrap();
    stack.begin_paint(PaintTarget::Mask, "mask").unwrap();
    stack.writer().unwrap().fill_with(|_| [rng.unit(), 0.0, 0.0, 1.0]);
    stack.end_paint();
    stack.set_blend(1, BlendMode::Overlay).unwrap();
    stack.set_opacity(1, 0.7).unwrap();
    stack.add_layer("hidden", None).unwrap();
    stack.set_blend(2, BlendMode::Multiply).unwrap();
    stack.set_visible(2, false).unwrap();
    stack.set_active(1).unwrap();
    stack.sync(&mut document.store);
    document.layers = Some(stack);
    document
}

fn store_bits(store: &ColorStore) -> Vec<(SampleRef, [u32; 4])> {
    let mut all = Vec::new();
    store.for_each_site(|site| all.push((site.sample, store.get(site.sample).unwrap().map(f32::to_bits))));
    all
}

type LayerBits = (String, bool, u32, BlendMode, Vec<(SampleRef, [u32; 4])>, Option<Vec<(SampleRef, [u32; 4])>>);

/// Every layer's properties and samples, bit for bit, with `quantize` applied to samples.
fn layers_bits(document: &Document, quantize: impl Fn([f32; 4]) -> [f32; 4]) -> (usize, Vec<LayerBits>) {
    let stack = document.layers.as_ref().expect("the document has layers");
    let q = |store: &ColorStore| -> Vec<(SampleRef, [u32; 4])> {
        let mut all = Vec::new();
        store
            .for_each_site(|site| all.push((site.sample, quantize(store.get(site.sample).unwrap()).map(f32::to_bits))));
        all
    };
    let layers = stack
        .layers()
        .iter()
        .map(|l| (l.name().to_owned(), l.visible(), l.opacity().to_bits(), l.blend(), q(l.content()), l.mask().map(q)))
        .collect();
    (stack.active(), layers)
}

#[test]
fn a_saved_document_with_layers_reopens_identical() {
    let dir = TempDir::new("layers-reopen");
    for format in ColorFormat::ALL {
        let document = layered_document(format);
        let path = dir.join(&format!("layered-{}.mpk", format.name()));
        document.write_packed(&path, format).unwrap();
        let reopened = Document::open(&path, Resolution::ONE).unwrap();
        // The layers come back as the format stores them (RGBA32F: bit for bit).
        let quantize = |c| format.quantize(c);
        assert_eq!(layers_bits(&reopened, |c| c), layers_bits(&document, quantize), "{format:?}: layers");
        if format == ColorFormat::Rgba32F {
            assert_eq!(store_bits(&reopened.store), store_bits(&document.store), "composite, bit for bit");
        }
        // The composite is recomputed from the layers, so a second save reopens the same.
        let again = dir.join(&format!("again-{}.mpk", format.name()));
        reopened.write_packed(&again, format).unwrap();
        let third = Document::open(&again, Resolution::ONE).unwrap();
        assert_eq!(layers_bits(&third, |c| c), layers_bits(&reopened, |c| c), "{format:?}: second save");
        assert_eq!(store_bits(&third.store), store_bits(&reopened.store), "{format:?}: second composite");
        assert_eq!(std::fs::read(&again).unwrap(), {
            let path = dir.join("third.mpk");
            third.write_packed(&path, format).unwrap();
            std::fs::read(&path).unwrap()
        });
    }
}

#[test]
fn documents_without_layers_still_write_version_1_byte_for_byte() {
    let mut document = layered_document(ColorFormat::Rgba8Srgb);
    document.layers = None;
    let packed = document.pack(ColorFormat::Rgba8Srgb).unwrap();
    let plain = packed_file::to_bytes(&packed).unwrap();
    assert_eq!(packed_file::to_bytes_with_layers(&packed, None).unwrap(), plain);
    assert_eq!(u32::from_le_bytes(plain[8..12].try_into().unwrap()), 1);
    let (back, layers) = packed_file::from_bytes_with_layers(&plain).unwrap();
    assert!(back == packed && layers.is_none());
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
}

#[test]
fn the_layers_section_has_the_documented_layout() {
    let format = ColorFormat::Rgba8Srgb;
    let document = layered_document(format);
    let packed = document.pack(format).unwrap();
    let bytes = packed_file::to_bytes_with_layers(&packed, document.layers_section(format).as_ref()).unwrap();
    assert_eq!(u32_at(&bytes, 8), 2, "version");
    assert_eq!(u32_at(&bytes, 24), 1, "flag bit 0");
    assert_eq!(u64_at(&bytes, 16), bytes.len() as u64, "file_size");
    let colors_end = (u64_at(&bytes, 104) + u64_at(&bytes, 112)) as usize;
    let at = colors_end.div_ceil(256) * 256;
    assert!(bytes[colors_end..at].iter().all(|&b| b == 0), "zero gap before the layers");
    let layers = &bytes[at..];
    let samples = document.store.sample_count();
    assert_eq!(u32_at(layers, 0), 3, "layer_count");
    assert_eq!(u32_at(layers, 4), 1, "active");
    assert_eq!(u64_at(layers, 8), samples, "samples_per_store");
    // Records of 272 bytes from 16: flags, blend, opacity, name length, name.
    let record = |k: usize| &layers[16 + 272 * k..16 + 272 * (k + 1)];
    assert_eq!((u32_at(record(0), 0), u32_at(record(0), 4), u32_at(record(0), 8)), (1, 0, 1.0f32.to_bits()));
    assert_eq!((u32_at(record(1), 0), u32_at(record(1), 4), u32_at(record(1), 8)), (3, 3, 0.7f32.to_bits()));
    assert_eq!((u32_at(record(2), 0), u32_at(record(2), 4)), (0, 1), "hidden, multiply");
    let name = "rust — ржавчина".as_bytes();
    assert_eq!(u32_at(record(1), 12) as usize, name.len());
    assert_eq!(&record(1)[16..16 + name.len()], name);
    assert!(record(1)[16 + name.len()..].iter().all(|&b| b == 0));
    // Then the stores: base, layer 1 content and mask, layer 2, each `samples` × 4 bytes.
    assert_eq!(layers.len() as u64, 16 + 3 * 272 + 4 * samples * 4);
    let store = |k: u64| &layers[(16 + 3 * 272 + k * samples * 4) as usize..][..(samples * 4) as usize];
    let stack = document.layers.as_ref().unwrap();
    // Store order: vertices, then edges by id, then interiors by face.
    let mask = stack.layers()[1].mask().unwrap();
    let mut expected = Vec::new();
    for v in 0..mask.topology().vertex_count {
        format.encode_into(mask.vertex_color(v).unwrap(), &mut expected);
    }
    for e in 0..mask.topology().edge_count() {
        mask.edge_samples(e).iter().for_each(|&c| format.encode_into(c, &mut expected));
    }
    for f in 0..mask.topology().face_count() {
        mask.interior_samples(f).iter().for_each(|&c| format.encode_into(c, &mut expected));
    }
    assert_eq!(store(2), &expected[..], "layer 1's mask is the third store");
    // The example of docs/FORMAT.md.
    assert_eq!((samples, colors_end, at, layers.len(), bytes.len()), (101, 1616, 1792, 2448, 4240));
}

/// A valid layered file with its layers section patched by `patch` (offsets within the
/// section) and the checksum recomputed; the reader's message.
fn hostile_layers(patch: impl FnOnce(&mut Vec<u8>, usize)) -> String {
    let format = ColorFormat::Rgba16F;
    let document = layered_document(format);
    let packed = document.pack(format).unwrap();
    let mut bytes = packed_file::to_bytes_with_layers(&packed, document.layers_section(format).as_ref()).unwrap();
    let colors_end = (u64_at(&bytes, 104) + u64_at(&bytes, 112)) as usize;
    patch(&mut bytes, colors_end.div_ceil(256) * 256);
    let len = bytes.len() as u64;
    bytes[16..24].copy_from_slice(&len.to_le_bytes());
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..124]);
    hasher.update(&bytes[128..]);
    let crc = hasher.finalize();
    bytes[124..128].copy_from_slice(&crc.to_le_bytes());
    match packed_file::from_bytes_with_layers(&bytes) {
        Ok(_) => panic!("hostile layers accepted"),
        Err(error) => error.to_string(),
    }
}

#[test]
fn hostile_layers_sections_are_refused_with_a_message() {
    let put = |b: &mut Vec<u8>, at: usize, v: u32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    type Patch = Box<dyn FnOnce(&mut Vec<u8>, usize)>;
    let cases: Vec<(&str, Patch)> = vec![
        ("0 layers", Box::new(move |b, s| put(b, s, 0))),
        ("257 layers", Box::new(move |b, s| put(b, s, 257))),
        ("active layer 3 of 3", Box::new(move |b, s| put(b, s + 4, 3))),
        ("need Some", Box::new(move |b, s| put(b, s + 8, 7))),
        ("need None", Box::new(move |b, s| put(b, s + 12, u32::MAX))),
        ("unknown flag bits 0x4", Box::new(move |b, s| put(b, s + 16, 5))),
        ("unknown blend mode 4", Box::new(move |b, s| put(b, s + 16 + 4, 4))),
        ("opacity NaN", Box::new(move |b, s| put(b, s + 16 + 8, f32::NAN.to_bits()))),
        ("opacity 1.5", Box::new(move |b, s| put(b, s + 16 + 8, 1.5f32.to_bits()))),
        ("name length 300", Box::new(move |b, s| put(b, s + 16 + 12, 300))),
        ("padding not zero", Box::new(move |b, s| b[s + 16 + 16 + 200] = 1)),
        ("not UTF-8", Box::new(move |b, s| b[s + 16 + 16] = 0xFF)),
        ("sample 0 is not a storable colour", Box::new(move |b, s| put(b, s + 16 + 3 * 272, 0x7E00_7E00))),
        ("shorter than its records", Box::new(move |b, s| b.truncate(s + 100))),
        ("need Some", Box::new(move |b, _| b.extend_from_slice(&[0; 8]))),
        ("unexpected bytes after", Box::new(move |b, _| put(b, 24, 0))),
        ("unknown flag bits 0x00000002", Box::new(move |b, _| put(b, 24, 3))),
    ];
    for (needle, patch) in cases {
        let message = hostile_layers(patch);
        assert!(message.contains(needle), "{message:?} does not mention {needle:?}");
    }
}

#[test]
fn layers_that_do_not_fit_the_document_or_the_budget_are_refused_on_open() {
    let format = ColorFormat::Rgba8Srgb;
    let document = layered_document(format);
    let section = document.layers_section(format).unwrap();
    let mut other = Document::from_packed(&document.pack(format).unwrap()).unwrap();
    let tight =
        meshpaint_core::colors::budget::Budget::with_memory(10_000, meshpaint_core::colors::budget::MemorySource::Set);
    let error = other.attach_layers(&section, &tight).unwrap_err().to_string();
    assert!(error.contains("more than the budget"), "{error}");
    let mut wrong = section.clone();
    wrong.samples_per_store -= 1;
    for layer in &mut wrong.layers {
        layer.content.truncate(layer.content.len() - 4);
        if let Some(mask) = &mut layer.mask {
            mask.truncate(mask.len() - 4);
        }
    }
    let error = other.attach_layers(&wrong, &meshpaint_core::colors::budget::Budget::from_environment()).unwrap_err();
    assert!(error.to_string().contains("samples per layer"), "{error}");
    assert!(other.layers.is_none());
    let _ = PackedFileError::BadLayers(String::new());
}

#[test]
fn a_store_changed_outside_its_layers_is_reported_out_of_sync() {
    let mut document = layered_document(ColorFormat::Rgba32F);
    assert!(document.layers_in_sync());
    let site = {
        let mut first = None;
        document.store.for_each_site(|site| {
            first.get_or_insert(site.sample);
        });
        first.unwrap()
    };
    let mut history = meshpaint_core::paint::undo::UndoHistory::new(0);
    history.set_sample(&mut document.store, site, [9.0, 0.0, 0.0, 1.0]);
    assert!(!document.layers_in_sync(), "a tool painted the store, not the layers");
    document.layers = None;
    assert!(document.layers_in_sync());
}
