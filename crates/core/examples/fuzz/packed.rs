//! The packed-file target: seeds, a structure-aware mutator and the oracle.
//!
//! The mutator knows the format (docs/FORMAT.md): it splits a seed into its header, four
//! sections and (version 2) the layers section, mutates elements (positions, indices, face-record words, colours), resizes
//! sections, drops or duplicates faces, changes counts and header fields, and then lays the
//! file out again with aligned offsets and — almost always — a recomputed CRC-32, so the
//! mutants get past the checksum and reach the content checks. A few mutants also get raw
//! byte edits (bit flips, insertions, truncation) before or after the checksum fix.
//!
//! The oracle ([`run`]): the reader must not panic; a file it accepts must keep every read
//! the face records imply (the addressing the shaders use, for every lattice point at every
//! level) inside the colour buffer, sample at every level, unpack or be refused by the
//! unpacker with an error, re-pack, and write and read back unchanged; accepted layers must
//! write and read back unchanged, and attach to the document or be refused with an error.

use std::path::Path;

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::{MAX_LOG2_RESOLUTION, Resolution};
use meshpaint_core::io::document::Document;
use meshpaint_core::packing::file as packed_file;
use meshpaint_core::packing::linear::{PackedMesh, unpack_word};
use meshpaint_core::packing::sampler;
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};

use super::rng::Rng;

const HEADER: usize = 128;
const ALIGN: usize = 256;
/// Element size of each section (the colour section's depends on the format).
const ELEMENT: [usize; 3] = [12, 12, 16];
/// `(offset, width)` of every header field after the magic.
const FIELDS: [(usize, usize); 18] = [
    (8, 4),
    (12, 4),
    (16, 8),
    (24, 4),
    (28, 4),
    (32, 4),
    (36, 4),
    (40, 4),
    (44, 4),
    (48, 8),
    (56, 8),
    (64, 8),
    (72, 8),
    (80, 8),
    (88, 8),
    (96, 8),
    (104, 8),
    (112, 8),
];

/// The seed files: small meshes at uniform and mixed resolutions in every colour format,
/// and the empty mesh. All are written by the real writer.
pub fn seeds(models: &Path) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let r = |value| Resolution::new(value).unwrap_or(Resolution::ONE);
    let open = |name: &str, resolution| Document::open(&models.join(name), resolution).ok();
    let mut add = |document: &Document, format| {
        if let Some(bytes) = document.pack(format).ok().and_then(|p| packed_file::to_bytes(&p).ok()) {
            out.push(bytes);
        }
    };
    if let Some(document) = open("BoxTextured/BoxTextured.glb", r(2)) {
        add(&document, ColorFormat::Rgba8Srgb);
        add(&document, ColorFormat::Rgba16F);
    }
    if let Some(document) = open("Cubes/Cubes.glb", r(1)) {
        add(&document, ColorFormat::Rgba32F);
    }
    if let Some(mut document) = open("BoxTextured/BoxTextured.glb", r(4)) {
        // Mixed resolutions: coarser and finer neighbours share edges.
        for (face, value) in [(0, 1), (1, 8), (2, 2), (5, 8), (7, 1)] {
            let _ = StoreWriter::new(&mut document.store, &mut UndoHistory::new(0)).set_face_resolution(face, r(value));
        }
        add(&document, ColorFormat::Rgba32F);
        add(&document, ColorFormat::Rgba8Srgb);
    }
    for format in [ColorFormat::Rgba8Srgb, ColorFormat::Rgba32F] {
        if let Some(bytes) = open("BoxTextured/BoxTextured.glb", r(4)).and_then(|d| layered_seed(d, format)) {
            out.push(bytes);
        }
    }
    if let Ok(bytes) = packed_file::to_bytes(&PackedMesh::default()) {
        out.push(bytes);
    }
    out
}

/// A version-2 seed: `document` with three layers (one masked and painted, one hidden
/// multiply layer) in `format`.
fn layered_seed(mut document: Document, format: ColorFormat) -> Option<Vec<u8>> {
    use meshpaint_core::layers::{BlendMode, LayerStack, PaintTarget};
    let mut stack = LayerStack::from_store(&document.store);
    stack.add_layer("paint", None).ok()?;
    stack.add_mask(1, 0.5, None).ok()?;
    stack.begin_paint(PaintTarget::Content, "seed").ok()?;
    stack.writer().ok()?.fill_with(|site| [site.barycentric[0], 0.25, 1.0, 0.75]);
    stack.end_paint();
    stack.add_layer("hidden multiply", None).ok()?;
    stack.set_blend(2, BlendMode::Multiply).ok()?;
    stack.set_visible(2, false).ok()?;
    stack.sync(&mut document.store);
    document.layers = Some(stack);
    let packed = document.pack(format).ok()?;
    packed_file::to_bytes_with_layers(&packed, document.layers_section(format).as_ref()).ok()
}

/// A decoded file: its header bytes, its four sections and its layers section (empty in
/// version 1).
struct Parts {
    header: [u8; HEADER],
    sections: [Vec<u8>; 4],
    layers: Vec<u8>,
}

fn read_u32(bytes: &[u8], at: usize) -> u32 {
    bytes.get(at..at + 4).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn read_u64(bytes: &[u8], at: usize) -> u64 {
    u64::from(read_u32(bytes, at)) | (u64::from(read_u32(bytes, at + 4)) << 32)
}

fn write_field(bytes: &mut [u8], at: usize, width: usize, value: u64) {
    if let Some(slot) = bytes.get_mut(at..at + width) {
        slot.copy_from_slice(&value.to_le_bytes()[..width]);
    }
}

impl Parts {
    /// Splits a valid seed (the writer's output) into header and sections.
    fn split(bytes: &[u8]) -> Parts {
        let mut header = [0u8; HEADER];
        header.copy_from_slice(&bytes[..HEADER]);
        let sections = std::array::from_fn(|k| {
            let offset = read_u64(bytes, 56 + 16 * k) as usize;
            let length = read_u64(bytes, 64 + 16 * k) as usize;
            bytes[offset..offset + length].to_vec()
        });
        let colors_end = read_u64(bytes, 104) as usize + read_u64(bytes, 112) as usize;
        let layers = bytes.get(colors_end.div_ceil(ALIGN) * ALIGN..).unwrap_or_default().to_vec();
        Parts { header, sections, layers }
    }

    fn bytes_per_sample(&self) -> usize {
        ColorFormat::from_code(read_u32(&self.header, 28)).map_or(4, ColorFormat::bytes_per_sample)
    }

    fn element(&self, section: usize) -> usize {
        ELEMENT.get(section).copied().unwrap_or_else(|| self.bytes_per_sample())
    }

    /// Lays the file out as the writer does (aligned sections, zero gaps), with the counts
    /// recomputed from the section lengths when `fix_counts`.
    fn assemble(&self, fix_counts: bool) -> Vec<u8> {
        let mut header = self.header;
        if fix_counts {
            write_field(&mut header, 32, 4, (self.sections[0].len() / 12) as u64);
            write_field(&mut header, 36, 4, (self.sections[1].len() / 12) as u64);
            write_field(&mut header, 48, 8, (self.sections[3].len() / self.bytes_per_sample()) as u64);
        }
        let mut out = header.to_vec();
        for (k, section) in self.sections.iter().enumerate() {
            let offset = out.len().div_ceil(ALIGN) * ALIGN;
            out.resize(offset, 0);
            write_field(&mut out, 56 + 16 * k, 8, offset as u64);
            write_field(&mut out, 64 + 16 * k, 8, section.len() as u64);
            out.extend_from_slice(section);
        }
        if !self.layers.is_empty() {
            out.resize(out.len().div_ceil(ALIGN) * ALIGN, 0);
            out.extend_from_slice(&self.layers);
        }
        let len = out.len() as u64;
        write_field(&mut out, 16, 8, len);
        out
    }
}

/// Recomputes the CRC-32 over everything but the checksum field (docs/FORMAT.md).
pub fn fix_checksum(bytes: &mut [u8]) {
    if bytes.len() < HEADER {
        return;
    }
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..124]);
    hasher.update(&bytes[128..]);
    let crc = hasher.finalize();
    bytes[124..128].copy_from_slice(&crc.to_le_bytes());
}

/// One mutation of the layers section: a record or header word set to an interesting
/// value, a name byte, a sample's bytes, or the section resized.
fn mutate_layers(parts: &mut Parts, rng: &mut Rng) {
    let data = &mut parts.layers;
    if data.len() < 4 {
        return;
    }
    match rng.below(4) {
        0 => {
            // Header words and the first records' flags, blend, opacity and name length.
            let at = rng.pick(&[0usize, 4, 8, 12, 16, 20, 24, 28, 288, 292, 296, 300]);
            let old = read_u32(data, at);
            let value = match rng.below(3) {
                0 => rng.interesting_u32(old),
                1 => rng.pick(&[f32::NAN.to_bits(), 1.5f32.to_bits(), (-0.0f32).to_bits(), 1.0f32.to_bits()]),
                _ => old ^ (1 << rng.below(32)),
            };
            write_field(data, at, 4, u64::from(value));
        }
        1 => {
            let at = 32 + rng.index(256);
            if let Some(byte) = data.get_mut(at) {
                *byte = rng.pick(&[0x00, 0x41, 0xFF, 0xC3]);
            }
        }
        2 => {
            let at = rng.index(data.len() / 4) * 4;
            write_field(data, at, 4, u64::from(rng.pick(&[0x7FC0_0000u32, 0xFF80_0000, 0xBF80_0000, 0x7F80_0000])));
        }
        _ => {
            if rng.chance(1, 2) {
                let keep = data.len().saturating_sub(4 * (1 + rng.index(8)));
                data.truncate(keep);
            } else {
                data.extend((0..4 * (1 + rng.index(4))).map(|_| rng.next_u64() as u8));
            }
        }
    }
}

/// One element-level mutation of a section.
fn mutate_element(parts: &mut Parts, rng: &mut Rng) {
    if !parts.layers.is_empty() && rng.chance(1, 3) {
        return mutate_layers(parts, rng);
    }
    let section = rng.index(4);
    let size = parts.element(section);
    let count = parts.sections[section].len() / size;
    if count == 0 {
        return;
    }
    let at = rng.index(count) * size;
    let vertex_count = (parts.sections[0].len() / 12) as u32;
    let sample_count = (parts.sections[3].len() / parts.bytes_per_sample().max(1)) as u32;
    let data = &mut parts.sections[section];
    match section {
        0 => {
            let word = at + 4 * rng.index(3);
            data[word..word + 4].copy_from_slice(&rng.interesting_f32().to_le_bytes());
        }
        1 => {
            let corner = rng.index(3);
            let other = read_u32(data, at + 4 * ((corner + 1) % 3));
            let value = match rng.below(4) {
                0 => other,
                1 => rng.interesting_u32(vertex_count),
                2 => rng.below(u64::from(vertex_count.max(1))) as u32,
                _ => vertex_count.wrapping_sub(rng.below(2) as u32),
            };
            data[at + 4 * corner..at + 4 * corner + 4].copy_from_slice(&value.to_le_bytes());
        }
        2 => {
            let word_at = at + 4 * rng.index(4);
            let (base, log2) = unpack_word(read_u32(data, word_at));
            let (base, log2) = match rng.below(5) {
                0 => (base, rng.below(16) as u32),
                1 => (base, log2.wrapping_add(rng.pick(&[1, u32::MAX])) & 15),
                2 => (rng.interesting_u32(sample_count) & ((1 << 28) - 1), log2),
                3 => (sample_count.wrapping_sub(rng.below(40) as u32) & ((1 << 28) - 1), log2),
                _ => (base, log2),
            };
            let word = if rng.chance(1, 8) { rng.next_u64() as u32 } else { base | (log2 << 28) };
            data[word_at..word_at + 4].copy_from_slice(&word.to_le_bytes());
        }
        _ => {
            let channel = rng.index(4) * (size / 4);
            let patterns: [&[u8]; 6] = [
                &[0x00, 0x7E],
                &[0x00, 0x7C],
                &[0x00, 0xFC],
                &[0x00, 0x00, 0xC0, 0x7F],
                &[0x00, 0x00, 0x80, 0x7F],
                &[0xFF, 0xFF, 0xFF, 0xFF],
            ];
            let pattern = rng.pick(&patterns);
            for (k, byte) in pattern.iter().enumerate() {
                if let Some(slot) = data.get_mut(at + (channel + k) % size) {
                    *slot = *byte;
                }
            }
        }
    }
}

/// One structural mutation: resize a section, drop / duplicate a face (indices and record
/// together), change the colour format or the vertex levels, or splice another seed's section.
fn mutate_structure(parts: &mut Parts, rng: &mut Rng, seeds: &[Vec<u8>]) {
    match rng.below(6) {
        0 => {
            let section = rng.index(4);
            let size = parts.element(section);
            let data = &mut parts.sections[section];
            let count = data.len() / size;
            if rng.chance(1, 2) {
                let keep = count.saturating_sub(1 + rng.index(3));
                data.truncate(keep * size);
            } else {
                let extra = 1 + rng.index(4);
                for _ in 0..extra {
                    if count > 0 && rng.chance(1, 2) {
                        let from = rng.index(count) * size;
                        let copy = data[from..from + size].to_vec();
                        data.extend(copy);
                    } else {
                        data.extend((0..size).map(|_| rng.next_u64() as u8));
                    }
                }
            }
        }
        1 => {
            let faces = parts.sections[1].len() / 12;
            if faces > 0 {
                let face = rng.index(faces);
                if rng.chance(1, 2) {
                    parts.sections[1].drain(face * 12..face * 12 + 12);
                    let len = parts.sections[2].len();
                    parts.sections[2].drain((face * 16).min(len)..(face * 16 + 16).min(len));
                } else {
                    let indices = parts.sections[1][face * 12..face * 12 + 12].to_vec();
                    parts.sections[1].extend(indices);
                    if let Some(record) = parts.sections[2].get(face * 16..face * 16 + 16).map(<[u8]>::to_vec) {
                        parts.sections[2].extend(record);
                    }
                }
            }
        }
        2 => {
            // A new format code, the colour section resized to the same sample count.
            let samples = parts.sections[3].len() / parts.bytes_per_sample();
            let code = if rng.chance(1, 6) { rng.interesting_u32(2) } else { rng.below(3) as u32 };
            write_field(&mut parts.header, 28, 4, u64::from(code));
            let size = parts.bytes_per_sample();
            parts.sections[3].resize(samples * size, 0x3C);
        }
        3 => {
            let levels = read_u32(&parts.header, 40);
            let new = match rng.below(3) {
                0 => levels.wrapping_add(1),
                1 => levels.wrapping_sub(1),
                _ => rng.below(u64::from(MAX_LOG2_RESOLUTION) + 3) as u32,
            };
            write_field(&mut parts.header, 40, 4, u64::from(new));
        }
        4 if !seeds.is_empty() => {
            let other = Parts::split(&seeds[rng.index(seeds.len())]);
            let section = rng.index(4);
            parts.sections[section] = other.sections[section].clone();
        }
        _ => {
            let faces = parts.sections[1].len() / 12;
            if faces >= 2 {
                // Swap two faces' records (their chains no longer match their edges).
                let (a, b) = (rng.index(faces), rng.index(faces));
                for k in 0..16 {
                    if let (Some(&x), Some(&y)) = (parts.sections[2].get(a * 16 + k), parts.sections[2].get(b * 16 + k))
                    {
                        parts.sections[2][a * 16 + k] = y;
                        parts.sections[2][b * 16 + k] = x;
                    }
                }
            }
        }
    }
}

/// Mutant number `rng` of `seeds` (see the module docs).
pub fn mutate(seeds: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let seed = &seeds[rng.index(seeds.len())];
    let mut parts = Parts::split(seed);
    for _ in 0..1 + rng.below(3) {
        if rng.chance(2, 3) {
            mutate_element(&mut parts, rng);
        } else {
            mutate_structure(&mut parts, rng, seeds);
        }
    }
    let mut bytes = parts.assemble(rng.chance(3, 4));
    if rng.chance(1, 4) {
        let (at, width) = rng.pick(&FIELDS);
        let old = read_u64(&bytes, at) & if width == 4 { u64::from(u32::MAX) } else { u64::MAX };
        let new = if width == 4 { u64::from(rng.interesting_u32(old as u32)) } else { rng.interesting_u64(old) };
        write_field(&mut bytes, at, width, new);
    }
    if rng.chance(1, 10) {
        for _ in 0..1 + rng.below(3) {
            rng.mutate_bytes(&mut bytes);
        }
        if rng.chance(1, 2) {
            let len = bytes.len() as u64;
            write_field(&mut bytes, 16, 8, len);
        }
    }
    if !rng.chance(1, 20) {
        fix_checksum(&mut bytes);
    }
    if rng.chance(1, 50) {
        rng.mutate_bytes(&mut bytes);
    }
    bytes
}

/// The error's variant name, e.g. `ChecksumMismatch`.
pub fn variant(debug: &str) -> String {
    debug.split(|c: char| !c.is_alphanumeric() && c != '_').next().unwrap_or("?").to_owned()
}

/// Lattice points checked per input (the checks are quadratic in `R`; mutants are small).
const READ_BUDGET: u64 = 400_000;

/// Every read the face records imply — lattice points and each edge's own samples at every
/// requested level — must lie inside the colour buffer, and the sampler must answer.
fn check_reads(mesh: &PackedMesh) {
    let samples = mesh.sample_count();
    let mut budget = READ_BUDGET;
    for face in 0..mesh.face_records.len() as u32 {
        let record = mesh.face_records[face as usize];
        let r_face = record.resolution().expect("an accepted file has a valid face resolution");
        for level in 0..=r_face.log2() + 1 {
            let r = r_face.get() >> level.min(r_face.log2());
            let points = u64::from(r + 1) * u64::from(r + 2) / 2;
            if points > budget {
                return;
            }
            budget -= points;
            for i in 0..=r {
                for j in 0..=r - i {
                    let index = sampler::packed_sample_index(mesh, face, level, i, j);
                    let index = index.unwrap_or_else(|| panic!("face {face} level {level} ({i}, {j}) has no sample"));
                    assert!(index < samples, "face {face} level {level} ({i}, {j}) reads sample {index} of {samples}");
                }
            }
            for k in 0..3u8 {
                let (_, r_edge) = record.edge(usize::from(k)).expect("an accepted file has valid edges");
                let r_e = r_edge.get() >> level.min(r_edge.log2());
                for p in 1..r_e {
                    let index = sampler::packed_edge_index(mesh, face, k, level, p)
                        .unwrap_or_else(|| panic!("face {face} edge {k} level {level} p {p} has no sample"));
                    assert!(index < samples, "face {face} edge {k} level {level} p {p} reads {index} of {samples}");
                }
            }
            for bary in [[1.0, 0.0, 0.0], [0.2, 0.3, 0.5], [0.0, 0.5, 0.5], [0.6, 0.0, 0.4]] {
                let color = sampler::sample_trilinear(mesh, face, bary, level as f32 + 0.5);
                assert!(color.is_some(), "face {face} cannot be sampled at level {level}");
            }
        }
    }
}

/// Runs one input through the reader and everything after it; returns the outcome's label.
/// Panics (the fuzzer catches them) when an accepted file breaks a promise.
pub fn run(bytes: &[u8]) -> String {
    let (mesh, layers) = match packed_file::from_bytes_with_layers(bytes) {
        Ok(read) => read,
        Err(error) => return format!("refused: {}", variant(&format!("{error:?}"))),
    };
    check_reads(&mesh);
    let written = packed_file::to_bytes_with_layers(&mesh, layers.as_ref())
        .expect("the writer refuses a file the reader accepted");
    let reread =
        packed_file::from_bytes_with_layers(&written).expect("the writer's output of an accepted file is refused");
    assert!(reread.0 == mesh && reread.1 == layers, "an accepted file does not survive write + read");
    if let Some(section) = &layers {
        return run_layers(&mesh, section);
    }
    let document = match Document::from_packed(&mesh) {
        Ok(document) => document,
        Err(error) => return format!("accepted, unpack refused: {}", variant(&format!("{error:?}"))),
    };
    let repacked = document.pack(mesh.format).expect("a store unpacked from a file does not pack");
    let bytes = packed_file::to_bytes(&repacked).expect("the writer refuses a re-packed store");
    let again = packed_file::from_bytes(&bytes).expect("a re-packed store does not read back");
    assert!(again == repacked, "a re-packed store does not survive write + read");
    "accepted, unpacked, re-packed".to_owned()
}

/// An accepted layers section must attach to its document or be refused with an error, and
/// an attached stack must save and read back as it was read.
fn run_layers(mesh: &PackedMesh, section: &packed_file::LayersSection) -> String {
    let mut document = match Document::from_packed(mesh) {
        Ok(document) => document,
        Err(error) => return format!("accepted, unpack refused: {}", variant(&format!("{error:?}"))),
    };
    let budget = meshpaint_core::colors::budget::Budget::from_environment();
    if let Err(error) = document.attach_layers(section, &budget) {
        return format!("accepted, layers refused: {}", variant(&format!("{error:?}")));
    }
    let saved = document.layers_section(mesh.format).expect("an attached stack has layers");
    let names = |s: &packed_file::LayersSection| -> Vec<(String, bool, u32, bool)> {
        s.layers.iter().map(|l| (l.name.clone(), l.visible, l.blend, l.mask.is_some())).collect()
    };
    assert!(names(&saved) == names(section) && saved.active == section.active, "attached layers lost properties");
    // Once attached, saving is a fixed point: save, read, attach, save gives the same section.
    let mut reopened = Document::from_packed(mesh).expect("the document unpacked once");
    reopened.attach_layers(&saved, &budget).expect("saved layers do not attach again");
    assert!(reopened.layers_section(mesh.format).as_ref() == Some(&saved), "saved layers change when reopened");
    "accepted with layers".to_owned()
}
