//! The MCT-file target: seeds, a structure-aware mutator and the oracle.
//!
//! Like the packed-file target (`packed.rs`): the mutator knows the format
//! (docs/MCT_FORMAT.md). It splits a seed into its header and five sections, mutates
//! elements (positions, indices, face-record fields, band-table words, texels), resizes
//! sections, drops or duplicates faces, changes the colour format, the level count and the
//! atlas size (resizing the texel section to match), and then lays the file out again with
//! aligned offsets and — almost always — a recomputed CRC-32, so the mutants get past the
//! checksum and reach the content checks. A few mutants also get raw byte edits.
//!
//! The oracle ([`run`]): the reader must not panic; a file it accepts must keep every texel
//! of every face's block (lattice points and ring, counted one by one, not the reader's five
//! hull points) at every level inside the atlas, sample at every level and level of detail,
//! and write and read back unchanged.

use meshpaint_core::colors::format::ColorFormat;
use meshpaint_core::colors::layout::Resolution;
use meshpaint_core::colors::store::ColorStore;
use meshpaint_core::mct;
use meshpaint_core::mct::file::{self as mct_file, MctFile};
use meshpaint_core::mct::layout::frame_of;
use meshpaint_core::mesh::topology::Topology;
use meshpaint_core::packing::packer::pack;
use meshpaint_core::paint::undo::{StoreWriter, UndoHistory};
use meshpaint_core::synth::SplitMix64;
use meshpaint_core::synth::shapes::{OCTAHEDRON_TRIANGLES, icosphere, octahedron_positions};

use super::packed::variant;
use super::rng::Rng;

const HEADER: usize = 144;
const ALIGN: usize = 256;
const SECTIONS: usize = 5;
const SECTIONS_AT: usize = 56;
const CHECKSUM_AT: usize = 140;
/// Element size of each section but the texels (whose depends on the format).
const ELEMENT: [usize; 4] = [12, 12, 4, 16];
/// `(offset, width)` of every header field after the magic.
const FIELDS: [(usize, usize); 22] = [
    (8, 4),
    (12, 4),
    (16, 8),
    (24, 4),
    (28, 4),
    (32, 4),
    (36, 4),
    (40, 4),
    (44, 4),
    (48, 4),
    (52, 4),
    (56, 8),
    (64, 8),
    (72, 8),
    (80, 8),
    (88, 8),
    (96, 8),
    (104, 8),
    (112, 8),
    (120, 8),
    (128, 8),
    (136, 4),
];

/// One seed: a mesh built in code at per-face resolutions, its MCT in `format`.
fn seed(
    positions: Vec<[f32; 3]>,
    triangles: &[[u32; 3]],
    resolution: impl Fn(usize) -> u64,
    format: ColorFormat,
) -> Option<Vec<u8>> {
    let topology = Topology::build(positions.len() as u32, triangles).ok()?;
    let resolutions = (0..triangles.len()).map(|f| Resolution::new(resolution(f)).unwrap_or(Resolution::ONE)).collect();
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4]).ok()?;
    let mut rng = SplitMix64(triangles.len() as u64);
    StoreWriter::new(&mut store, &mut UndoHistory::new(0)).fill_with(|_| rng.color());
    let packed = pack(&store, &positions, format).ok()?;
    let texture = mct::build(&packed, 4096, 64 << 20).ok()?;
    mct_file::to_bytes(&packed.positions, &packed.indices, &texture).ok()
}

/// The seed files: small meshes built in code (a quad, the octahedron, an icosphere at mixed
/// resolutions, so there are pairs, lone faces and several groups) in every colour format.
/// All are written by the real writer.
pub fn seeds() -> Vec<Vec<u8>> {
    let quad = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let (sphere, sphere_triangles) = icosphere(1);
    let mixed = |face: usize| 1u64 << ((face * 7 + face / 5) % 4);
    [
        seed(quad, &[[0, 1, 2], [0, 2, 3]], |_| 2, ColorFormat::Rgba8Srgb),
        seed(octahedron_positions(), &OCTAHEDRON_TRIANGLES, |f| 1 << (f % 3), ColorFormat::Rgba16F),
        seed(octahedron_positions(), &OCTAHEDRON_TRIANGLES[..5], |_| 1, ColorFormat::Rgba32F),
        seed(sphere.clone(), &sphere_triangles, mixed, ColorFormat::Rgba8Srgb),
        seed(sphere, &sphere_triangles, mixed, ColorFormat::Rgba16F),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// A decoded file: its header bytes and its five sections.
struct Parts {
    header: [u8; HEADER],
    sections: [Vec<u8>; SECTIONS],
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
            let offset = read_u64(bytes, SECTIONS_AT + 16 * k) as usize;
            let length = read_u64(bytes, SECTIONS_AT + 16 * k + 8) as usize;
            bytes[offset..offset + length].to_vec()
        });
        Parts { header, sections }
    }

    fn bytes_per_sample(&self) -> usize {
        ColorFormat::from_code(read_u32(&self.header, 28)).map_or(4, ColorFormat::bytes_per_sample)
    }

    fn element(&self, section: usize) -> usize {
        ELEMENT.get(section).copied().unwrap_or_else(|| self.bytes_per_sample())
    }

    fn faces(&self) -> usize {
        self.sections[1].len() / 12
    }

    /// Lays the file out as the writer does (aligned sections, zero gaps), with the vertex
    /// and face counts recomputed from the section lengths when `fix_counts`.
    fn assemble(&self, fix_counts: bool) -> Vec<u8> {
        let mut header = self.header;
        if fix_counts {
            write_field(&mut header, 32, 4, (self.sections[0].len() / 12) as u64);
            write_field(&mut header, 36, 4, (self.sections[1].len() / 12) as u64);
        }
        let mut out = header.to_vec();
        for (k, section) in self.sections.iter().enumerate() {
            let offset = out.len().div_ceil(ALIGN) * ALIGN;
            out.resize(offset, 0);
            write_field(&mut out, SECTIONS_AT + 16 * k, 8, offset as u64);
            write_field(&mut out, SECTIONS_AT + 16 * k + 8, 8, section.len() as u64);
            out.extend_from_slice(section);
        }
        let len = out.len() as u64;
        write_field(&mut out, 16, 8, len);
        out
    }
}

/// Recomputes the CRC-32 over everything but the checksum field (docs/MCT_FORMAT.md).
pub fn fix_checksum(bytes: &mut [u8]) {
    if bytes.len() < HEADER {
        return;
    }
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..CHECKSUM_AT]);
    hasher.update(&bytes[CHECKSUM_AT + 4..]);
    let crc = hasher.finalize();
    bytes[CHECKSUM_AT..CHECKSUM_AT + 4].copy_from_slice(&crc.to_le_bytes());
}

/// A face record with one field changed: corner, direction bit, side bit, block resolution,
/// flip or swap bit, pair index (near its value, near the group's size, or anything), or
/// random bits.
fn mutate_record(record: u32, faces: u32, rng: &mut Rng) -> u32 {
    let pair = record >> 10;
    match rng.below(8) {
        0 => (record & !3) | rng.below(4) as u32,
        1 => record ^ 4,
        2 => record ^ 8,
        3 => (record & !0xf0) | ((rng.below(16) as u32) << 4),
        4 => (record & 0x3ff) | ((pair.wrapping_add(rng.pick(&[1, u32::MAX, 2])) & 0x3f_ffff) << 10),
        5 => (record & 0x3ff) | ((rng.interesting_u32(faces) & 0x3f_ffff) << 10),
        6 => record ^ (256 << rng.below(2)),
        _ => rng.next_u64() as u32,
    }
}

/// One element-level mutation of a section.
fn mutate_element(parts: &mut Parts, rng: &mut Rng) {
    let section = rng.index(SECTIONS);
    let size = parts.element(section);
    let count = parts.sections[section].len() / size;
    if count == 0 {
        return;
    }
    let at = rng.index(count) * size;
    let vertex_count = (parts.sections[0].len() / 12) as u32;
    let faces = parts.faces() as u32;
    let (width, height) = (read_u32(&parts.header, 40), read_u32(&parts.header, 44));
    let data = &mut parts.sections[section];
    match section {
        0 => {
            let word = at + 4 * rng.index(3);
            data[word..word + 4].copy_from_slice(&rng.interesting_f32().to_le_bytes());
        }
        1 => {
            let corner = rng.index(3);
            let value = match rng.below(3) {
                0 => rng.interesting_u32(vertex_count),
                1 => rng.below(u64::from(vertex_count.max(1))) as u32,
                _ => vertex_count.wrapping_sub(rng.below(2) as u32),
            };
            data[at + 4 * corner..at + 4 * corner + 4].copy_from_slice(&value.to_le_bytes());
        }
        2 => {
            let record = mutate_record(read_u32(data, at), faces, rng);
            data[at..at + 4].copy_from_slice(&record.to_le_bytes());
        }
        3 => {
            // A band: its y (near the atlas height), its row width (0, ±1, huge) or a
            // reserved word.
            let word = rng.index(4);
            let old = read_u32(data, at + 4 * word);
            let value = match (word, rng.below(4)) {
                (0, 0) => height.wrapping_sub(rng.below(4) as u32),
                (1, 0) => rng.pick(&[0, 1, width, width / 2]),
                (0 | 1, 1) => old.wrapping_add(rng.pick(&[1, u32::MAX])),
                (0 | 1, 2) => rng.interesting_u32(old),
                _ => rng.next_u64() as u32 & rng.pick(&[0, 1, u32::MAX]),
            };
            data[at + 4 * word..at + 4 * word + 4].copy_from_slice(&value.to_le_bytes());
        }
        _ => {
            for byte in &mut data[at..at + size] {
                *byte = rng.next_u64() as u8;
            }
        }
    }
}

/// One structural mutation: resize a section, drop / duplicate a face (indices and record
/// together), change the colour format, the levels or the atlas size (texels resized to
/// match), swap two faces' records, or splice another seed's section.
fn mutate_structure(parts: &mut Parts, rng: &mut Rng, seeds: &[Vec<u8>]) {
    match rng.below(7) {
        0 => {
            let section = rng.index(SECTIONS);
            let size = parts.element(section);
            let data = &mut parts.sections[section];
            let count = data.len() / size;
            if rng.chance(1, 2) {
                data.truncate(count.saturating_sub(1 + rng.index(3)) * size);
            } else {
                for _ in 0..1 + rng.index(4) {
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
            let faces = parts.faces();
            if faces > 0 {
                let face = rng.index(faces);
                if rng.chance(1, 2) {
                    parts.sections[1].drain(face * 12..face * 12 + 12);
                    let len = parts.sections[2].len();
                    parts.sections[2].drain((face * 4).min(len)..(face * 4 + 4).min(len));
                } else {
                    let indices = parts.sections[1][face * 12..face * 12 + 12].to_vec();
                    parts.sections[1].extend(indices);
                    if let Some(record) = parts.sections[2].get(face * 4..face * 4 + 4).map(<[u8]>::to_vec) {
                        parts.sections[2].extend(record);
                    }
                }
            }
        }
        2 => {
            let texels = parts.sections[4].len() / parts.bytes_per_sample();
            let code = if rng.chance(1, 6) { rng.interesting_u32(2) } else { rng.below(3) as u32 };
            write_field(&mut parts.header, 28, 4, u64::from(code));
            let size = parts.bytes_per_sample();
            parts.sections[4].resize(texels * size, 0x3C);
        }
        3 => {
            let levels = read_u32(&parts.header, 48);
            let new = match rng.below(3) {
                0 => levels.wrapping_add(1),
                1 => levels.wrapping_sub(1),
                _ => rng.below(16) as u32,
            };
            write_field(&mut parts.header, 48, 4, u64::from(new));
        }
        4 => {
            // A smaller or larger atlas, the texel section resized to match (rows kept).
            let (width, height) = (read_u32(&parts.header, 40), read_u32(&parts.header, 44));
            let (w, h) = match rng.below(4) {
                0 => (width, height.saturating_sub(1 + rng.below(3) as u32)),
                1 => (width.saturating_sub(1 + rng.below(3) as u32), height),
                2 => (width, height + 1 + rng.below(3) as u32),
                _ => (width + 1, height),
            };
            write_field(&mut parts.header, 40, 4, u64::from(w));
            write_field(&mut parts.header, 44, 4, u64::from(h));
            let size = parts.bytes_per_sample();
            parts.sections[4].resize(w as usize * h as usize * size, 0);
        }
        5 => {
            let faces = parts.faces().min(parts.sections[2].len() / 4);
            if faces >= 2 {
                let (a, b) = (rng.index(faces), rng.index(faces));
                for k in 0..4 {
                    parts.sections[2].swap(a * 4 + k, b * 4 + k);
                }
            }
        }
        _ if !seeds.is_empty() => {
            let other = Parts::split(&seeds[rng.index(seeds.len())]);
            let section = rng.index(SECTIONS);
            parts.sections[section] = other.sections[section].clone();
        }
        _ => {}
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
    if rng.chance(1, 5) {
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

/// Texels checked per input (the checks are quadratic in the block resolution).
const TEXEL_BUDGET: u64 = 400_000;

/// Every texel of every block (lattice and ring) at every level lies in the atlas (x wraps
/// around: up to twice the width), and the
/// CPU sampler answers at every level and level of detail.
fn check_blocks(file: &MctFile) {
    let layout = &file.mct.layout;
    let (w, h) = (i64::from(layout.width), i64::from(layout.height));
    let mut budget = TEXEL_BUDGET;
    for (face, &record) in (0u32..).zip(&layout.records) {
        for level in 0..layout.levels {
            let frame = frame_of(record, &layout.bands, &layout.masks, level);
            let r = frame.r;
            let texels = u64::from(r + 2) * u64::from(r + 3) / 2;
            if texels <= budget {
                budget -= texels;
                for beta in 0..=r + 1 {
                    for alpha in 0..=r + 1 - beta {
                        if alpha + beta == r + 1 && (alpha == 0 || beta == 0) {
                            continue;
                        }
                        let [x, y] = frame.texel(alpha, beta);
                        assert!(
                            (0..2 * w).contains(&x) && (0..h).contains(&y),
                            "face {face} level {level} ({alpha}, {beta}) at texel ({x}, {y}) outside the {w}×{h} atlas"
                        );
                    }
                }
            }
            for bary in [[1.0, 0.0, 0.0], [0.2, 0.3, 0.5], [0.0, 0.5, 0.5], [0.6, 0.0, 0.4]] {
                assert!(
                    file.mct.sample_level(face, bary, level).is_some(),
                    "face {face} has no colour at level {level}"
                );
                let lod = level as f32 + 0.5;
                assert!(file.mct.sample_trilinear(face, bary, lod).is_some(), "face {face} has no colour at lod {lod}");
            }
        }
    }
}

/// Runs one input through the reader and everything after it; returns the outcome's label.
/// Panics (the fuzzer catches them) when an accepted file breaks a promise.
pub fn run(bytes: &[u8]) -> String {
    let file = match mct_file::from_bytes(bytes) {
        Ok(file) => file,
        Err(error) => return format!("refused: {}", variant(&format!("{error:?}"))),
    };
    check_blocks(&file);
    let written = mct_file::to_bytes(&file.positions, &file.indices, &file.mct)
        .expect("the writer refuses a file the reader accepted");
    let reread = mct_file::from_bytes(&written).expect("the writer's output of an accepted file is refused");
    assert!(reread == file, "an accepted file does not survive write + read");
    if written == bytes { "accepted, rewritten byte for byte".to_owned() } else { "accepted, rewritten".to_owned() }
}
