//! The MCT file: one self-contained little-endian binary file holding everything needed to
//! render a [`MeshColorTexture`] without meshpaint's store — the mesh, the face records, the
//! band table and the atlas.
//!
//! The byte-by-byte specification is `docs/MCT_FORMAT.md`; in short:
//!
//! ```text
//! offset 0     header (144 bytes, zero-padded to 256)
//! offset 256·k positions     vertex_count × [f32; 4]: x, y, z and the LOD density
//! offset 256·k indices       face_count × [u32; 3]
//! offset 256·k face records  face_count × u32 (MctFaceRecord), then the strip-row masks (u32 each)
//! offset 256·k band table    169 × [u32; 4] (MctBands, 2704 bytes)
//! offset 256·k atlas texels  width × height × bytes_per_sample(format), row-major
//! ```
//!
//! It follows the packed file (`docs/FORMAT.md`, [`crate::packing::file`]): sections at
//! multiples of [`SECTION_ALIGN`] (one GPU upload each), zero gaps, one CRC-32 over every byte
//! except the checksum field (header bytes 140..144), deterministic output, atomic writes.
//!
//! # Reading hostile files
//!
//! [`from_bytes`] checks every count, offset and record before using it: it never panics, and
//! everything it allocates is bounded by the file's own size (every section length is checked
//! against `bytes.len()` and against its count before its vector is built; the rebuilt pair
//! lists hold at most one entry per face). In order:
//!
//! 1. magic, header length, version, header size;
//! 2. the section table: aligned, in order, inside the file, and the file ending exactly at
//!    the end of the texel section;
//! 3. the checksum;
//! 4. flags, reserved fields, zero padding, colour format, atlas size (each side
//!    `1..=`[`MAX_ATLAS_SIDE`]), levels (`1..=13`), section lengths against the counts;
//! 5. the content: finite positions, indices in range, records (corner, block resolution
//!    within the levels, pair index within its group), the band table (reserved words zero,
//!    a non-zero row width wherever a face reads it), the pairs (numbered from 0 without
//!    gaps, each with a first face, no slot claimed twice, both faces sharing the edge their
//!    records name) and every face's block at every level inside the atlas.
//!
//! Texel values are not checked: ring texels are extrapolated (`c₁ + c₂ − c₀`) and may be
//! negative, above 1 or (RGBA16F) infinite in a valid file. Blocks of different pairs
//! overlapping each other is not checked either (a file that does so renders wrong colours,
//! but every read stays inside the atlas).
//!
//! [`MctStats`] are the builder's counts and are not stored: a file reads back with default
//! stats.

use std::path::Path;

use crate::colors::budget::ATLAS_MAX_WIDTH;
use crate::colors::format::ColorFormat;
use crate::mct::layout::{GROUPS, MctBands, MctFaceRecord, MctLayout};
use crate::mct::{MctStats, MeshColorTexture};
use crate::packing::file::Expected;
use crate::packing::file::sections::{self, Fields, Section, align_up, checksum, le_words, section_bytes};

mod check;
mod error;

use check::{Content, check_content, check_limits};
pub use error::MctFileError;

/// The first 8 bytes of every MCT file.
pub const MAGIC: [u8; 8] = *b"MESHMCT\0";
/// The format version this module writes and reads.
pub const VERSION: u32 = 3;
/// Size of the version-1 header in bytes (zero-padded to [`SECTION_ALIGN`]).
pub const HEADER_SIZE: usize = 144;
/// Alignment of every section's offset in bytes.
pub const SECTION_ALIGN: u64 = sections::SECTION_ALIGN;
/// Flag bits defined by this version (none); any set bit is refused.
pub const KNOWN_FLAGS: u32 = 0;
/// The largest atlas side in texels: the GPU colour atlas width meshpaint uses
/// ([`crate::colors::budget::ATLAS_MAX_WIDTH`], 16384), so every file fits one texture on
/// any device that renders meshpaint's own atlas.
pub const MAX_ATLAS_SIDE: u32 = ATLAS_MAX_WIDTH as u32;
/// Largest number of MIP levels (`1 + log2 4096`).
pub const MAX_LEVELS: u32 = GROUPS as u32;

/// Byte offset of the CRC-32 field in the header.
const CHECKSUM_OFFSET: usize = 140;
/// Bytes of one vertex (`[f32; 4]`: position and level-of-detail density).
const POSITION_SIZE: u64 = 16;
/// Bytes of one triangle's indices (`[u32; 3]`).
const TRIANGLE_SIZE: u64 = 12;
/// Bytes of one face record.
const RECORD_SIZE: u64 = 4;
/// Bytes of the band table.
const BANDS_SIZE: u64 = std::mem::size_of::<MctBands>() as u64;
/// Number of entries in the section table.
const SECTION_COUNT: usize = 5;
/// Section names, in table and file order.
const SECTION_NAMES: [&str; SECTION_COUNT] = ["positions", "indices", "face records", "band table", "texels"];

/// A decoded MCT file: the mesh and its Mesh Color Texture (whose `pairs` are rebuilt from
/// the records and whose `stats` are the default: the file does not store them).
#[derive(Debug, Clone, PartialEq)]
pub struct MctFile {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as vertex ids.
    pub indices: Vec<[u32; 3]>,
    /// Records, band table, atlas.
    pub mct: MeshColorTexture,
}

/// The decoded version-1 header.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Header {
    version: u32,
    header_size: u32,
    file_size: u64,
    flags: u32,
    format_code: u32,
    vertex_count: u32,
    face_count: u32,
    width: u32,
    height: u32,
    levels: u32,
    reserved_52: u32,
    sections: [Section; SECTION_COUNT],
    reserved_136: u32,
    checksum: u32,
}

impl Header {
    /// Decodes the header fields (after the magic) from the first [`HEADER_SIZE`] bytes.
    fn parse(bytes: &[u8; HEADER_SIZE]) -> Header {
        let mut fields = Fields(bytes.get(MAGIC.len()..).unwrap_or_default());
        let version = fields.u32();
        let header_size = fields.u32();
        let file_size = fields.u64();
        let flags = fields.u32();
        let format_code = fields.u32();
        let vertex_count = fields.u32();
        let face_count = fields.u32();
        let width = fields.u32();
        let height = fields.u32();
        let levels = fields.u32();
        let reserved_52 = fields.u32();
        let mut sections = [Section::default(); SECTION_COUNT];
        for section in &mut sections {
            section.offset = fields.u64();
            section.length = fields.u64();
        }
        let reserved_136 = fields.u32();
        let checksum = fields.u32();
        Header {
            version,
            header_size,
            file_size,
            flags,
            format_code,
            vertex_count,
            face_count,
            width,
            height,
            levels,
            reserved_52,
            sections,
            reserved_136,
            checksum,
        }
    }

    /// Appends the encoded header (exactly [`HEADER_SIZE`] bytes) to `out`.
    fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        for word in [self.version, self.header_size] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(&self.file_size.to_le_bytes());
        for word in [
            self.flags,
            self.format_code,
            self.vertex_count,
            self.face_count,
            self.width,
            self.height,
            self.levels,
            self.reserved_52,
        ] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        for section in &self.sections {
            out.extend_from_slice(&section.offset.to_le_bytes());
            out.extend_from_slice(&section.length.to_le_bytes());
        }
        out.extend_from_slice(&self.reserved_136.to_le_bytes());
        out.extend_from_slice(&self.checksum.to_le_bytes());
    }
}

/// Whether `bytes` starts with the MCT-file [`MAGIC`].
pub fn looks_like_mct(bytes: &[u8]) -> bool {
    bytes.starts_with(&MAGIC)
}

/// Encodes a mesh and its Mesh Color Texture as an MCT file.
///
/// Deterministic: the same input always gives the same bytes. Refuses what the reader would
/// refuse (plus buffers of inconsistent sizes, and pair lists the records do not describe),
/// so every file it writes reads back equal (with default stats).
pub fn to_bytes(positions: &[[f32; 3]], indices: &[[u32; 3]], mct: &MeshColorTexture) -> Result<Vec<u8>, MctFileError> {
    let layout = &mct.layout;
    let vertex_count = u32::try_from(positions.len())
        .map_err(|_| MctFileError::TooMany { what: "vertices", count: positions.len() as u64 })?;
    let face_count = u32::try_from(indices.len())
        .map_err(|_| MctFileError::TooMany { what: "faces", count: indices.len() as u64 })?;
    if mct.vertex_density.len() != positions.len() {
        return Err(MctFileError::DensityCount {
            densities: mct.vertex_density.len() as u64,
            vertices: positions.len() as u64,
        });
    }
    if indices.len() != layout.records.len() {
        return Err(MctFileError::FaceCountMismatch {
            indices: indices.len() as u64,
            records: layout.records.len() as u64,
        });
    }
    check_limits(layout.width, layout.height, layout.levels)?;
    let texel_bytes = layout.texel_count() * mct.format.bytes_per_sample() as u64;
    if mct.texels.len() as u64 != texel_bytes {
        return Err(MctFileError::TexelBytes {
            len: mct.texels.len() as u64,
            width: layout.width,
            height: layout.height,
            format: mct.format.name(),
            expected: texel_bytes,
        });
    }
    let pairs = check_content(&Content {
        positions,
        density: &mct.vertex_density,
        indices,
        records: &layout.records,
        masks: &layout.masks,
        bands: &layout.bands,
        width: layout.width,
        height: layout.height,
        levels: layout.levels,
    })?;
    check_same_pairs(&layout.pairs, &pairs)?;

    let lengths = [
        u64::from(vertex_count) * POSITION_SIZE,
        u64::from(face_count) * TRIANGLE_SIZE,
        (u64::from(face_count) + layout.masks.len() as u64) * RECORD_SIZE,
        BANDS_SIZE,
        texel_bytes,
    ];
    let mut sections = [Section::default(); SECTION_COUNT];
    let mut cursor = HEADER_SIZE as u64;
    for (section, length) in sections.iter_mut().zip(lengths) {
        // Sizes here are bounded by the in-memory buffers, far below 2^64.
        section.offset = align_up(cursor).unwrap_or(u64::MAX);
        section.length = length;
        cursor = section.offset.saturating_add(length);
    }
    let header = Header {
        version: VERSION,
        header_size: HEADER_SIZE as u32,
        file_size: cursor,
        flags: 0,
        format_code: mct.format.code(),
        vertex_count,
        face_count,
        width: layout.width,
        height: layout.height,
        levels: layout.levels,
        reserved_52: 0,
        sections,
        reserved_136: 0,
        checksum: 0,
    };
    let mut out = Vec::with_capacity(usize::try_from(cursor).unwrap_or(0));
    header.write(&mut out);
    let pad_to = |out: &mut Vec<u8>, section: Section| {
        out.resize(usize::try_from(section.offset).unwrap_or(out.len()), 0);
    };
    pad_to(&mut out, sections[0]);
    for (position, density) in positions.iter().zip(&mct.vertex_density) {
        out.extend(position.iter().chain([density]).flat_map(|c| c.to_le_bytes()));
    }
    pad_to(&mut out, sections[1]);
    out.extend(indices.iter().flatten().flat_map(|i| i.to_le_bytes()));
    pad_to(&mut out, sections[2]);
    out.extend(layout.records.iter().flat_map(|r| r.0.to_le_bytes()));
    out.extend(layout.masks.iter().flat_map(|m| m.to_le_bytes()));
    pad_to(&mut out, sections[3]);
    out.extend(layout.bands.bands.iter().flatten().flat_map(|w| w.to_le_bytes()));
    pad_to(&mut out, sections[4]);
    out.extend_from_slice(&mct.texels);

    let crc = checksum(&out, CHECKSUM_OFFSET);
    if let Some(slot) = out.get_mut(CHECKSUM_OFFSET..CHECKSUM_OFFSET + 4) {
        slot.copy_from_slice(&crc.to_le_bytes());
    }
    Ok(out)
}

/// Refuses a layout whose pair lists are not the ones its records describe.
fn check_same_pairs(stored: &[Vec<[u32; 2]>], rebuilt: &[Vec<[u32; 2]>]) -> Result<(), MctFileError> {
    for g in 0..GROUPS.max(stored.len()) {
        let (a, b) = (stored.get(g).map_or(&[][..], Vec::as_slice), rebuilt.get(g).map_or(&[][..], Vec::as_slice));
        if a == b {
            continue;
        }
        let pair = a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len()));
        return Err(MctFileError::PairsMismatch {
            resolution: 1u32.checked_shl(g as u32).unwrap_or(0),
            pair: pair as u64,
            stored: a.get(pair).copied(),
            rebuilt: b.get(pair).copied(),
        });
    }
    Ok(())
}

/// Checks the section table against the file length (before the checksum, so that a
/// truncated file is reported as truncated).
fn check_sections(header: &Header, len: u64) -> Result<(), MctFileError> {
    let mut previous = "header";
    let mut previous_end = HEADER_SIZE as u64;
    for (section, name) in header.sections.iter().zip(SECTION_NAMES) {
        if !section.offset.is_multiple_of(SECTION_ALIGN) {
            return Err(MctFileError::SectionMisaligned { section: name, offset: section.offset });
        }
        if section.offset < previous_end {
            return Err(MctFileError::SectionOverlap { section: name, offset: section.offset, previous, previous_end });
        }
        let Some(end) = section.offset.checked_add(section.length) else {
            return Err(MctFileError::SectionOverflow {
                section: name,
                offset: section.offset,
                length: section.length,
            });
        };
        if end > len {
            return Err(MctFileError::Truncated { what: format!("header says {name} end"), end, len });
        }
        previous = name;
        previous_end = end;
    }
    if header.file_size > len {
        return Err(MctFileError::Truncated {
            what: "header says the file ends".to_owned(),
            end: header.file_size,
            len,
        });
    }
    for (what, end) in [("file", header.file_size), ("last section", previous_end)] {
        if end < len {
            return Err(MctFileError::TrailingBytes { what, end, extra: len.saturating_sub(end) });
        }
    }
    Ok(())
}

/// Checks that every byte outside the header fields and the sections is zero.
fn check_padding(bytes: &[u8], header: &Header) -> Result<(), MctFileError> {
    let mut gap_start = HEADER_SIZE as u64;
    for section in &header.sections {
        let gap = section_bytes(bytes, Section { offset: gap_start, length: section.offset.saturating_sub(gap_start) });
        if let Some((at, &value)) = (gap_start..).zip(gap).find(|&(_, &byte)| byte != 0) {
            return Err(MctFileError::NonZeroPadding { offset: at, value });
        }
        gap_start = section.offset.saturating_add(section.length);
    }
    Ok(())
}

/// Checks that a section's length is `count × element_size`.
fn check_length(
    section: Section,
    index: usize,
    count: u64,
    element_size: u64,
    unit: &'static str,
) -> Result<(), MctFileError> {
    let expected = count.checked_mul(element_size);
    if expected != Some(section.length) {
        return Err(MctFileError::SectionLength {
            section: SECTION_NAMES.get(index).copied().unwrap_or("?"),
            length: section.length,
            count,
            unit,
            expected: Expected(expected),
        });
    }
    Ok(())
}

/// Decodes an MCT file, refusing anything truncated, corrupt or hostile.
///
/// Never panics, and allocates at most about the size of `bytes`. See the module
/// documentation for the checks and their order.
pub fn from_bytes(bytes: &[u8]) -> Result<MctFile, MctFileError> {
    let len = bytes.len() as u64;
    let truncated_header =
        || MctFileError::Truncated { what: "the header ends".to_owned(), end: HEADER_SIZE as u64, len };
    if !looks_like_mct(bytes) {
        let found = bytes.get(..MAGIC.len()).unwrap_or(bytes);
        if MAGIC.starts_with(found) {
            return Err(truncated_header());
        }
        return Err(MctFileError::NotMct { found: found.to_vec() });
    }
    let Some(header_bytes) = bytes.first_chunk::<HEADER_SIZE>() else {
        return Err(truncated_header());
    };
    let header = Header::parse(header_bytes);
    if header.version == 1 || header.version == 2 {
        return Err(MctFileError::OldVersion(header.version));
    }
    if header.version != VERSION {
        return Err(MctFileError::UnsupportedVersion(header.version));
    }
    if header.header_size as usize != HEADER_SIZE {
        return Err(MctFileError::HeaderSize(header.header_size));
    }
    check_sections(&header, len)?;
    let computed = checksum(bytes, CHECKSUM_OFFSET);
    if computed != header.checksum {
        return Err(MctFileError::ChecksumMismatch { stored: header.checksum, computed });
    }
    if header.flags & !KNOWN_FLAGS != 0 {
        return Err(MctFileError::UnknownFlags(header.flags & !KNOWN_FLAGS));
    }
    for (offset, value) in [(52, header.reserved_52), (136, header.reserved_136)] {
        if value != 0 {
            return Err(MctFileError::ReservedNotZero { offset, value });
        }
    }
    check_padding(bytes, &header)?;
    let format =
        ColorFormat::from_code(header.format_code).ok_or(MctFileError::UnknownColorFormat(header.format_code))?;
    check_limits(header.width, header.height, header.levels)?;
    let vertex_count = u64::from(header.vertex_count);
    let face_count = u64::from(header.face_count);
    let texel_count = u64::from(header.width) * u64::from(header.height);
    let [positions, indices, records, bands, texels] = header.sections;
    check_length(positions, 0, vertex_count, POSITION_SIZE, "vertices")?;
    check_length(indices, 1, face_count, TRIANGLE_SIZE, "faces")?;
    // Face records, then the strip-row masks (their number is checked against the records).
    let mask_count = (records.length / RECORD_SIZE).saturating_sub(face_count);
    check_length(records, 2, face_count + mask_count, RECORD_SIZE, "faces and strip-row masks")?;
    check_length(bands, 3, 1, BANDS_SIZE, "band tables")?;
    check_length(texels, 4, texel_count, format.bytes_per_sample() as u64, "texels")?;

    // Every section now lies inside `bytes` with the length its count implies, so the
    // vectors below are no larger than the file.
    let (positions, density): (Vec<[f32; 3]>, Vec<f32>) = le_words::<4>(section_bytes(bytes, positions))
        .into_iter()
        .map(|[x, y, z, d]| ([x, y, z].map(f32::from_bits), f32::from_bits(d)))
        .unzip();
    let indices = le_words::<3>(section_bytes(bytes, indices));
    let mut words = le_words::<1>(section_bytes(bytes, records));
    let masks: Vec<u32> = words
        .split_off(usize::try_from(face_count).unwrap_or(usize::MAX).min(words.len()))
        .into_iter()
        .map(|[word]| word)
        .collect();
    let records: Vec<MctFaceRecord> = words.into_iter().map(|[word]| MctFaceRecord(word)).collect();
    let mut band_table = MctBands::default();
    for (entry, words) in band_table.bands.iter_mut().zip(le_words::<4>(section_bytes(bytes, bands))) {
        *entry = words;
    }
    let pairs = check_content(&Content {
        positions: &positions,
        density: &density,
        indices: &indices,
        records: &records,
        masks: &masks,
        bands: &band_table,
        width: header.width,
        height: header.height,
        levels: header.levels,
    })?;
    let layout = MctLayout {
        records,
        bands: band_table,
        width: header.width,
        height: header.height,
        pairs,
        levels: header.levels,
        masks,
    };
    let texels = section_bytes(bytes, texels).to_vec();
    let mct = MeshColorTexture { layout, format, texels, stats: MctStats::default(), vertex_density: density };
    Ok(MctFile { positions, indices, mct })
}

/// Writes the MCT file of `positions`, `indices` and `mct` to `path` atomically
/// ([`crate::atomic_write`]). Errors name the path.
pub fn write_mct(
    path: &Path,
    positions: &[[f32; 3]],
    indices: &[[u32; 3]],
    mct: &MeshColorTexture,
) -> Result<(), MctFileError> {
    let bytes = to_bytes(positions, indices, mct)
        .map_err(|source| MctFileError::File { path: path.to_path_buf(), source: Box::new(source) })?;
    crate::atomic_write::write_atomically(path, &bytes).map_err(|error| MctFileError::Io {
        path: error.path,
        action: error.action,
        source: error.source,
    })
}

/// Reads and decodes the MCT file at `path`. Errors name the path.
pub fn read_mct(path: &Path) -> Result<MctFile, MctFileError> {
    let bytes = std::fs::read(path).map_err(|source| MctFileError::Io {
        path: path.to_path_buf(),
        action: "read the file",
        source,
    })?;
    from_bytes(&bytes).map_err(|source| MctFileError::File { path: path.to_path_buf(), source: Box::new(source) })
}
