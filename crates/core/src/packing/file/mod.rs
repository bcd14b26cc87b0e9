//! The packed file: one self-contained little-endian binary file holding a [`PackedMesh`].
//!
//! This is both the "export packed buffers" output and the project's save format. The
//! byte-by-byte specification is `docs/FORMAT.md`; in short:
//!
//! ```text
//! offset 0     header (128 bytes, zero-padded to 256)
//! offset 256·k positions     vertex_count × [f32; 3]
//! offset 256·k indices       face_count × [u32; 3]
//! offset 256·k face records  face_count × 4 u32 (see crate::packing::linear)
//! offset 256·k colours       sample_count × bytes_per_sample(format)
//! offset 256·k layers        version 2 only: the document's layers ([`layers`])
//! ```
//!
//! A file without layers is written as version 1, byte for byte as before version 2; both
//! versions are read ([`from_bytes_with_layers`] also returns the layers section).
//!
//! Every section starts at a multiple of [`SECTION_ALIGN`] (256) bytes, so each can be
//! uploaded to the GPU with one write at an offset that satisfies wgpu's copy (4) and
//! storage-buffer offset (≤ 256) alignments. Gaps are zero (the reader checks). One CRC-32 (IEEE, as
//! `crc32fast` computes it) covers every byte of the file except the 4-byte checksum
//! field itself (header bytes 124..128).
//!
//! # Reading hostile files
//!
//! [`from_bytes`] checks every count, offset and index before using it: it never panics
//! and never allocates more than the file's own size justifies (every section length is
//! checked against `bytes.len()` before its vector is built). The checks run in this
//! order, so that the error says the most useful thing:
//!
//! 1. magic, header length, version, header size;
//! 2. the section table: aligned, in order, non-overlapping, inside the file, and the
//!    file ending exactly at the end of the colour section (truncation is reported as
//!    such, before the checksum);
//! 3. the checksum;
//! 4. flags, reserved fields, zero padding, colour format, counts against limits and
//!    section lengths;
//! 5. the content: finite positions, indices in range, no repeated corners, and every
//!    face record within the limits and its chains inside the colour buffer (the bounds
//!    that make any GPU read derived from the records safe), and every colour storable
//!    (finite, R, G, B in `[0, 65504]`, alpha in `[0, 1]`: a file with any other colour is
//!    refused, never repaired).
//! 6. version 2: the layers section ([`LayersSection::parse`]: counts, flags, names, blend
//!    codes, opacities, its exact length and every layer colour).
//!
//! Deeper layout consistency (e.g. two faces agreeing on a shared edge's chain base) is
//! the unpacker's job ([`crate::packing::packer`]), not this module's.

use std::path::Path;

use crate::colors::format::ColorFormat;
use crate::colors::layout::{MAX_LOG2_RESOLUTION, Resolution, edge_chain_len, interior_chain_len};
use crate::packing::linear::{FaceRecord, MAX_SAMPLES, PackedMesh, unpack_word};

mod error;
pub mod layers;
pub(crate) mod sections;

use sections::{Fields, Section, align_up, checksum, le_words, section_bytes};

pub use error::{Expected, PackedFileError};
pub use layers::{LayerRecord, LayersSection};

/// The first 8 bytes of every packed file.
pub const MAGIC: [u8; 8] = *b"MESHPAK\0";
/// The newest format version: 2 adds the layers section ([`layers`]). Files without layers
/// are still written as version 1 ([`VERSION_WITHOUT_LAYERS`], byte for byte as before), and
/// both versions are read.
pub const VERSION: u32 = 2;
/// The version of a file without a layers section.
pub const VERSION_WITHOUT_LAYERS: u32 = 1;
/// Flag bit (version 2): a layers section follows the colour section.
pub const FLAG_LAYERS: u32 = 1;
/// Size of the version-1 header in bytes (the header is zero-padded to [`SECTION_ALIGN`]).
pub const HEADER_SIZE: usize = 128;
/// Alignment of every section's offset in bytes.
pub const SECTION_ALIGN: u64 = sections::SECTION_ALIGN;
/// Flag bits defined by version 1 (none); any set bit is refused.
pub const KNOWN_FLAGS: u32 = 0;

/// The flag bits `version` defines.
fn known_flags(version: u32) -> u32 {
    if version == VERSION { FLAG_LAYERS } else { KNOWN_FLAGS }
}

/// Byte offset of the CRC-32 field in the header.
const CHECKSUM_OFFSET: usize = 124;
/// Bytes of one position (`[f32; 3]`).
const POSITION_SIZE: u64 = 12;
/// Bytes of one triangle's indices (`[u32; 3]`).
const TRIANGLE_SIZE: u64 = 12;
/// Bytes of one face record.
const RECORD_SIZE: u64 = 16;
/// Number of entries in the section table.
const SECTION_COUNT: usize = 4;
/// Section names, in table and file order.
const SECTION_NAMES: [&str; SECTION_COUNT] = ["positions", "indices", "face records", "colors"];

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
    vertex_levels: u32,
    reserved_44: u32,
    sample_count: u64,
    sections: [Section; SECTION_COUNT],
    reserved_120: u32,
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
        let vertex_levels = fields.u32();
        let reserved_44 = fields.u32();
        let sample_count = fields.u64();
        let mut sections = [Section::default(); SECTION_COUNT];
        for section in &mut sections {
            section.offset = fields.u64();
            section.length = fields.u64();
        }
        let reserved_120 = fields.u32();
        let checksum = fields.u32();
        Header {
            version,
            header_size,
            file_size,
            flags,
            format_code,
            vertex_count,
            face_count,
            vertex_levels,
            reserved_44,
            sample_count,
            sections,
            reserved_120,
            checksum,
        }
    }

    /// Appends the encoded header (exactly [`HEADER_SIZE`] bytes) to `out`.
    fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&self.version.to_le_bytes());
        out.extend_from_slice(&self.header_size.to_le_bytes());
        out.extend_from_slice(&self.file_size.to_le_bytes());
        out.extend_from_slice(&self.flags.to_le_bytes());
        out.extend_from_slice(&self.format_code.to_le_bytes());
        out.extend_from_slice(&self.vertex_count.to_le_bytes());
        out.extend_from_slice(&self.face_count.to_le_bytes());
        out.extend_from_slice(&self.vertex_levels.to_le_bytes());
        out.extend_from_slice(&self.reserved_44.to_le_bytes());
        out.extend_from_slice(&self.sample_count.to_le_bytes());
        for section in &self.sections {
            out.extend_from_slice(&section.offset.to_le_bytes());
            out.extend_from_slice(&section.length.to_le_bytes());
        }
        out.extend_from_slice(&self.reserved_120.to_le_bytes());
        out.extend_from_slice(&self.checksum.to_le_bytes());
    }
}

/// What a packed file holds, from its header alone ([`read_summary`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PackedSummary {
    /// Triangles.
    pub face_count: u32,
    /// Vertices.
    pub vertex_count: u32,
    /// Samples in the colour buffer (MIP chains included).
    pub sample_count: u64,
    /// The file's length as its header states it.
    pub file_size: u64,
}

/// What the packed file at `path` holds, read from its first [`HEADER_SIZE`] bytes only
/// (for a prompt about a large file; [`read_file`] checks everything). Refuses what is not a
/// packed file of this version.
pub fn read_summary(path: &Path) -> Result<PackedSummary, PackedFileError> {
    use std::io::Read;
    let io = |source| PackedFileError::Io { path: path.to_path_buf(), action: "read the header", source };
    let mut bytes = Vec::with_capacity(HEADER_SIZE);
    let file = std::fs::File::open(path).map_err(io)?;
    file.take(HEADER_SIZE as u64).read_to_end(&mut bytes).map_err(io)?;
    if !looks_like_packed(&bytes) {
        return Err(PackedFileError::NotPacked { found: bytes[..bytes.len().min(MAGIC.len())].to_vec() });
    }
    let Some(bytes) = bytes.first_chunk::<HEADER_SIZE>() else {
        let len = bytes.len() as u64;
        return Err(PackedFileError::Truncated { what: "the header ends".to_owned(), end: HEADER_SIZE as u64, len });
    };
    let header = Header::parse(bytes);
    if !(VERSION_WITHOUT_LAYERS..=VERSION).contains(&header.version) {
        return Err(PackedFileError::UnsupportedVersion(header.version));
    }
    Ok(PackedSummary {
        face_count: header.face_count,
        vertex_count: header.vertex_count,
        sample_count: header.sample_count,
        file_size: header.file_size,
    })
}

/// Whether `bytes` starts with the packed-file [`MAGIC`] (to choose a loader by content).
pub fn looks_like_packed(bytes: &[u8]) -> bool {
    bytes.starts_with(&MAGIC)
}

/// Checks the content of a mesh whose buffers have consistent sizes: the limits of the
/// format and the bounds that make GPU reads derived from the face records safe.
fn check_content(mesh: &PackedMesh, sample_count: u64) -> Result<(), PackedFileError> {
    if sample_count > MAX_SAMPLES {
        return Err(PackedFileError::TooManySamples(sample_count));
    }
    if mesh.vertex_levels > MAX_LOG2_RESOLUTION + 1 {
        return Err(PackedFileError::TooManyVertexLevels(mesh.vertex_levels));
    }
    let vertex_count = mesh.positions.len() as u64;
    let vertex_samples = vertex_count.checked_mul(u64::from(mesh.vertex_levels));
    if vertex_samples.is_none_or(|needed| needed > sample_count) {
        return Err(PackedFileError::VertexSamples {
            vertices: vertex_count,
            levels: mesh.vertex_levels,
            needed: vertex_samples.unwrap_or(u64::MAX),
            samples: sample_count,
        });
    }
    for (vertex, position) in (0u64..).zip(&mesh.positions) {
        if !position.iter().all(|c| c.is_finite()) {
            return Err(PackedFileError::NonFinitePosition { vertex, position: *position });
        }
    }
    for (triangle, corners) in (0u64..).zip(&mesh.indices) {
        for (corner, &index) in corners.iter().enumerate() {
            if u64::from(index) >= vertex_count {
                return Err(PackedFileError::IndexOutOfRange { triangle, corner, index, vertex_count });
            }
        }
        let [a, b, c] = *corners;
        if a == b || b == c || c == a {
            return Err(PackedFileError::RepeatedCorner { triangle, corners: *corners });
        }
    }
    for (face, record) in (0u64..).zip(&mesh.face_records) {
        check_record(face, record, mesh.vertex_levels, sample_count)?;
    }
    check_colors(mesh)
}

/// Refuses a colour the formats cannot hold (RGBA8 always can): NaN, infinity, negative
/// channels, channels above [`crate::colors::format::MAX_CHANNEL`], alpha outside `[0, 1]`.
fn check_colors(mesh: &PackedMesh) -> Result<(), PackedFileError> {
    if mesh.format == ColorFormat::Rgba8Srgb {
        return Ok(());
    }
    let size = mesh.format.bytes_per_sample();
    for (sample, bytes) in (0u64..).zip(mesh.colors.chunks_exact(size)) {
        let color = mesh.format.decode(bytes);
        if !crate::colors::format::is_storable(color) {
            return Err(PackedFileError::BadColor { sample, color });
        }
    }
    Ok(())
}

/// Checks one face record: resolutions within limits and chains inside the colour buffer.
fn check_record(face: u64, record: &FaceRecord, vertex_levels: u32, sample_count: u64) -> Result<(), PackedFileError> {
    const EDGE_NAMES: [&str; 3] = ["edge 0", "edge 1", "edge 2"];
    let (interior_base, face_log2) = unpack_word(record.interior);
    let Ok(face_r) = Resolution::from_log2(face_log2) else {
        return Err(PackedFileError::FaceResolution { face, log2: face_log2 });
    };
    let needed = face_r.level_count();
    if vertex_levels < needed {
        return Err(PackedFileError::VertexLevelsTooFew { face, log2: face_log2, needed, vertex_levels });
    }
    let chain_in_range = |chain: &'static str, base: u32, r: Resolution, len: u32| {
        // Both terms are below 2^32: no overflow in u64.
        let end = u64::from(base).saturating_add(u64::from(len));
        if end > sample_count {
            return Err(PackedFileError::ChainOutOfRange {
                face,
                chain,
                resolution: r.get(),
                base,
                end,
                samples: sample_count,
            });
        }
        Ok(())
    };
    if face_r.get() >= 4 {
        chain_in_range("interior", interior_base, face_r, interior_chain_len(face_r))?;
    }
    for ((edge, &word), name) in record.edges.iter().enumerate().zip(EDGE_NAMES) {
        let (base, log2) = unpack_word(word);
        let edge_r = match Resolution::from_log2(log2) {
            Ok(r) if log2 >= face_log2 => r,
            _ => {
                return Err(PackedFileError::EdgeResolution { face, edge, log2, face_log2 });
            }
        };
        if edge_r.get() >= 2 {
            chain_in_range(name, base, edge_r, edge_chain_len(edge_r))?;
        }
    }
    Ok(())
}

/// Encodes `mesh` as a packed file.
///
/// Deterministic: the same mesh always gives the same bytes. Refuses meshes the reader
/// would refuse (inconsistent buffer sizes, limits exceeded, non-finite positions,
/// indices out of range, face records out of bounds), so every written file reads back.
pub fn to_bytes(mesh: &PackedMesh) -> Result<Vec<u8>, PackedFileError> {
    to_bytes_with_layers(mesh, None)
}

/// [`to_bytes`] with a layers section: a version-2 file when `layers` is given, else the
/// version-1 file [`to_bytes`] writes.
pub fn to_bytes_with_layers(mesh: &PackedMesh, layers: Option<&LayersSection>) -> Result<Vec<u8>, PackedFileError> {
    let layer_bytes = layers.map(|section| section.to_bytes(mesh.format)).transpose()?;
    let vertex_count = u32::try_from(mesh.positions.len())
        .map_err(|_| PackedFileError::TooMany { what: "vertices", count: mesh.positions.len() as u64 })?;
    let face_count = u32::try_from(mesh.indices.len())
        .map_err(|_| PackedFileError::TooMany { what: "faces", count: mesh.indices.len() as u64 })?;
    if mesh.indices.len() != mesh.face_records.len() {
        return Err(PackedFileError::FaceCountMismatch {
            indices: mesh.indices.len() as u64,
            records: mesh.face_records.len() as u64,
        });
    }
    let bytes_per_sample = mesh.format.bytes_per_sample();
    if !mesh.colors.len().is_multiple_of(bytes_per_sample) {
        return Err(PackedFileError::PartialSample { len: mesh.colors.len() as u64, bytes_per_sample });
    }
    let sample_count = (mesh.colors.len() / bytes_per_sample) as u64;
    check_content(mesh, sample_count)?;

    // Section layout: each section at the next multiple of SECTION_ALIGN.
    let lengths = [
        u64::from(vertex_count) * POSITION_SIZE,
        u64::from(face_count) * TRIANGLE_SIZE,
        u64::from(face_count) * RECORD_SIZE,
        mesh.colors.len() as u64,
    ];
    let mut sections = [Section::default(); SECTION_COUNT];
    let mut cursor = HEADER_SIZE as u64;
    for (section, length) in sections.iter_mut().zip(lengths) {
        // Sizes here are bounded by the in-memory mesh, far below 2^64.
        section.offset = align_up(cursor).unwrap_or(u64::MAX);
        section.length = length;
        cursor = section.offset.saturating_add(length);
    }
    let [positions_at, indices_at, records_at, colors_at] = sections.map(|section| section.offset);
    let layers_at = align_up(cursor).unwrap_or(u64::MAX);
    let file_size = match &layer_bytes {
        Some(bytes) => layers_at.saturating_add(bytes.len() as u64),
        None => cursor,
    };
    let header = Header {
        version: if layer_bytes.is_some() { VERSION } else { VERSION_WITHOUT_LAYERS },
        header_size: HEADER_SIZE as u32,
        file_size,
        flags: if layer_bytes.is_some() { FLAG_LAYERS } else { 0 },
        format_code: mesh.format.code(),
        vertex_count,
        face_count,
        vertex_levels: mesh.vertex_levels,
        reserved_44: 0,
        sample_count,
        sections,
        reserved_120: 0,
        checksum: 0,
    };

    let capacity = usize::try_from(file_size).unwrap_or(0);
    let mut out = Vec::with_capacity(capacity);
    header.write(&mut out);
    let pad_to = |out: &mut Vec<u8>, offset: u64| {
        out.resize(usize::try_from(offset).unwrap_or(out.len()), 0);
    };
    pad_to(&mut out, positions_at);
    for position in &mesh.positions {
        for coordinate in position {
            out.extend_from_slice(&coordinate.to_le_bytes());
        }
    }
    pad_to(&mut out, indices_at);
    for triangle in &mesh.indices {
        for index in triangle {
            out.extend_from_slice(&index.to_le_bytes());
        }
    }
    pad_to(&mut out, records_at);
    for record in &mesh.face_records {
        out.extend_from_slice(&record.interior.to_le_bytes());
        for word in &record.edges {
            out.extend_from_slice(&word.to_le_bytes());
        }
    }
    pad_to(&mut out, colors_at);
    out.extend_from_slice(&mesh.colors);
    if let Some(bytes) = &layer_bytes {
        pad_to(&mut out, layers_at);
        out.extend_from_slice(bytes);
    }

    let crc = checksum(&out, CHECKSUM_OFFSET);
    if let Some(slot) = out.get_mut(CHECKSUM_OFFSET..CHECKSUM_OFFSET + 4) {
        for (dst, src) in slot.iter_mut().zip(crc.to_le_bytes()) {
            *dst = src;
        }
    }
    Ok(out)
}

/// Checks the section table against the file length (before the checksum, so that a
/// truncated file is reported as truncated).
fn check_sections(header: &Header, layers: Option<Section>, len: u64) -> Result<(), PackedFileError> {
    let mut previous = "header";
    let mut previous_end = HEADER_SIZE as u64;
    let table = header.sections.iter().copied().zip(SECTION_NAMES);
    for (section, name) in table.chain(layers.map(|section| (section, "layers"))) {
        if !section.offset.is_multiple_of(SECTION_ALIGN) {
            return Err(PackedFileError::SectionMisaligned { section: name, offset: section.offset });
        }
        if section.offset < previous_end {
            return Err(PackedFileError::SectionOverlap {
                section: name,
                offset: section.offset,
                previous,
                previous_end,
            });
        }
        let Some(end) = section.offset.checked_add(section.length) else {
            return Err(PackedFileError::SectionOverflow {
                section: name,
                offset: section.offset,
                length: section.length,
            });
        };
        if end > len {
            return Err(PackedFileError::Truncated { what: format!("header says {name} end"), end, len });
        }
        previous = name;
        previous_end = end;
    }
    if header.file_size > len {
        return Err(PackedFileError::Truncated {
            what: "header says the file ends".to_owned(),
            end: header.file_size,
            len,
        });
    }
    for (what, end) in [("file", header.file_size), ("last section", previous_end)] {
        if end < len {
            return Err(PackedFileError::TrailingBytes { what, end, extra: len.saturating_sub(end) });
        }
    }
    Ok(())
}

/// Checks that every byte outside the header fields and the sections is zero.
fn check_padding(bytes: &[u8], header: &Header, layers: Option<Section>) -> Result<(), PackedFileError> {
    let mut gap_start = HEADER_SIZE as u64;
    for section in header.sections.iter().chain(&layers) {
        let gap = section_bytes(bytes, Section { offset: gap_start, length: section.offset.saturating_sub(gap_start) });
        if let Some((at, &value)) = (gap_start..).zip(gap).find(|&(_, &byte)| byte != 0) {
            return Err(PackedFileError::NonZeroPadding { offset: at, value });
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
) -> Result<(), PackedFileError> {
    let expected = count.checked_mul(element_size);
    if expected != Some(section.length) {
        return Err(PackedFileError::SectionLength {
            section: SECTION_NAMES.get(index).copied().unwrap_or("?"),
            length: section.length,
            count,
            unit,
            expected: Expected(expected),
        });
    }
    Ok(())
}

/// Decodes a packed file, refusing anything truncated, corrupt or hostile.
///
/// Never panics, and allocates at most about the size of `bytes`. See the module
/// documentation for the checks and their order.
pub fn from_bytes(bytes: &[u8]) -> Result<PackedMesh, PackedFileError> {
    from_bytes_with_layers(bytes).map(|(mesh, _)| mesh)
}

/// [`from_bytes`] with the layers section of a version-2 file (`None` for version 1 or a
/// version-2 file without the [`FLAG_LAYERS`] flag), checked as strictly as the rest.
pub fn from_bytes_with_layers(bytes: &[u8]) -> Result<(PackedMesh, Option<LayersSection>), PackedFileError> {
    let len = bytes.len() as u64;
    if !looks_like_packed(bytes) {
        let found = bytes.get(..MAGIC.len()).unwrap_or(bytes);
        if MAGIC.starts_with(found) {
            return Err(PackedFileError::Truncated {
                what: "the header ends".to_owned(),
                end: HEADER_SIZE as u64,
                len,
            });
        }
        return Err(PackedFileError::NotPacked { found: found.to_vec() });
    }
    let Some(header_bytes) = bytes.first_chunk::<HEADER_SIZE>() else {
        return Err(PackedFileError::Truncated { what: "the header ends".to_owned(), end: HEADER_SIZE as u64, len });
    };
    let header = Header::parse(header_bytes);
    if !(VERSION_WITHOUT_LAYERS..=VERSION).contains(&header.version) {
        return Err(PackedFileError::UnsupportedVersion(header.version));
    }
    if header.header_size as usize != HEADER_SIZE {
        return Err(PackedFileError::HeaderSize(header.header_size));
    }
    let layers = layers_section(&header, len)?;
    check_sections(&header, layers, len)?;
    let computed = checksum(bytes, CHECKSUM_OFFSET);
    if computed != header.checksum {
        return Err(PackedFileError::ChecksumMismatch { stored: header.checksum, computed });
    }
    if header.flags & !known_flags(header.version) != 0 {
        return Err(PackedFileError::UnknownFlags(header.flags & !known_flags(header.version)));
    }
    if header.version == VERSION && header.flags & FLAG_LAYERS == 0 {
        return Err(PackedFileError::BadLayers("a version-2 file must set flag bit 0 and hold layers".to_owned()));
    }
    for (offset, value) in [(44, header.reserved_44), (120, header.reserved_120)] {
        if value != 0 {
            return Err(PackedFileError::ReservedNotZero { offset, value });
        }
    }
    check_padding(bytes, &header, layers)?;
    let format =
        ColorFormat::from_code(header.format_code).ok_or(PackedFileError::UnknownColorFormat(header.format_code))?;
    if header.sample_count > MAX_SAMPLES {
        return Err(PackedFileError::TooManySamples(header.sample_count));
    }
    if header.vertex_levels > MAX_LOG2_RESOLUTION + 1 {
        return Err(PackedFileError::TooManyVertexLevels(header.vertex_levels));
    }
    let vertex_count = u64::from(header.vertex_count);
    let face_count = u64::from(header.face_count);
    let [positions, indices, records, colors] = header.sections;
    check_length(positions, 0, vertex_count, POSITION_SIZE, "vertices")?;
    check_length(indices, 1, face_count, TRIANGLE_SIZE, "faces")?;
    check_length(records, 2, face_count, RECORD_SIZE, "faces")?;
    check_length(colors, 3, header.sample_count, format.bytes_per_sample() as u64, "samples")?;

    // Every section now lies inside `bytes` with the length its count implies, so the
    // vectors below are no larger than the file.
    let positions: Vec<[f32; 3]> =
        le_words::<3>(section_bytes(bytes, positions)).into_iter().map(|words| words.map(f32::from_bits)).collect();
    let indices = le_words::<3>(section_bytes(bytes, indices));
    let face_records = le_words::<4>(section_bytes(bytes, records))
        .into_iter()
        .map(|[interior, e0, e1, e2]| FaceRecord { interior, edges: [e0, e1, e2] })
        .collect();
    let mesh = PackedMesh {
        positions,
        indices,
        vertex_levels: header.vertex_levels,
        face_records,
        format,
        colors: section_bytes(bytes, colors).to_vec(),
    };
    check_content(&mesh, header.sample_count)?;
    let layers = layers.map(|section| LayersSection::parse(section_bytes(bytes, section), format)).transpose()?;
    Ok((mesh, layers))
}

/// Where a version-2 file's layers section lies: from the first multiple of
/// [`SECTION_ALIGN`] after the colour section to the end of the file (`None` without the
/// flag). The section table checks that follow report a truncated file as such.
fn layers_section(header: &Header, len: u64) -> Result<Option<Section>, PackedFileError> {
    if header.version != VERSION || header.flags & FLAG_LAYERS == 0 {
        // Refused later (flags are checked after the checksum).
        return Ok(None);
    }
    let colors = header.sections[SECTION_COUNT - 1];
    let Some(offset) = colors.offset.checked_add(colors.length).and_then(align_up) else {
        return Err(PackedFileError::SectionOverflow {
            section: "colors",
            offset: colors.offset,
            length: colors.length,
        });
    };
    let end = header.file_size.min(len).max(offset);
    Ok(Some(Section { offset, length: end - offset }))
}

/// Writes `mesh` to `path` atomically: the bytes go to a temporary file in the same
/// directory, which is flushed to disk and then renamed over `path`. Errors name the path.
pub fn write_file(path: &Path, mesh: &PackedMesh) -> Result<(), PackedFileError> {
    write_file_with_layers(path, mesh, None)
}

/// [`write_file`] with a layers section ([`to_bytes_with_layers`]).
pub fn write_file_with_layers(
    path: &Path,
    mesh: &PackedMesh,
    layers: Option<&LayersSection>,
) -> Result<(), PackedFileError> {
    let bytes = to_bytes_with_layers(mesh, layers)
        .map_err(|source| PackedFileError::File { path: path.to_path_buf(), source: Box::new(source) })?;
    crate::atomic_write::write_atomically(path, &bytes).map_err(|error| PackedFileError::Io {
        path: error.path,
        action: error.action,
        source: error.source,
    })
}

/// Reads and decodes the packed file at `path`. Errors name the path.
pub fn read_file(path: &Path) -> Result<PackedMesh, PackedFileError> {
    read_file_with_layers(path).map(|(mesh, _)| mesh)
}

/// [`read_file`] with the layers section ([`from_bytes_with_layers`]).
pub fn read_file_with_layers(path: &Path) -> Result<(PackedMesh, Option<LayersSection>), PackedFileError> {
    let bytes = std::fs::read(path).map_err(|source| PackedFileError::Io {
        path: path.to_path_buf(),
        action: "read the file",
        source,
    })?;
    from_bytes_with_layers(&bytes)
        .map_err(|source| PackedFileError::File { path: path.to_path_buf(), source: Box::new(source) })
}
