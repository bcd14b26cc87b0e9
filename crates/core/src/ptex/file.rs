//! The packed Ptex file: one self-contained little-endian binary file holding everything needed
//! to render a [`PackedPtex`] without meshpaint's store — the mesh, the face records, the
//! paper's tables and the texture. The byte-by-byte specification is `docs/PTEX_FORMAT.md`:
//!
//! ```text
//! offset 0     header (144 bytes, zero-padded to 256)
//! offset 256·k positions     vertex_count × [f32; 4]: x, y, z and the LOD density
//! offset 256·k indices       face_count × [u32; 3]
//! offset 256·k face records  face_count × u32 (PtexFaceRecord)
//! offset 256·k tables        13 × [u32; 3]: nRes, nRow, blocks per row
//! offset 256·k texels        width × height × bytes_per_sample(format), row-major
//! ```
//!
//! As the packed and MCT files: sections at multiples of 256, zero gaps, one CRC-32 over every
//! byte except the checksum field (header bytes 140..144), deterministic output, atomic writes.
//!
//! # Reading hostile files
//!
//! [`from_bytes`] never panics and allocates at most about the file's size. In order: magic,
//! version, header size; the section table (aligned, in order, inside the file, the file
//! ending at the last section); the checksum; flags, reserved field and padding zero; colour
//! format, texture sides `1..=16384`, levels `1..=13`, section lengths against the counts;
//! then the content: finite positions and densities (≥ 0), indices below the vertex count,
//! records (corner below 3, block below the block count, the last block named by one) and the
//! tables — `nRes` starting at 0
//! and non-decreasing up to the block count, blocks per row `max(1, ⌊W / (2^k + 2)⌋)` with
//! every non-empty slice's block fitting the width, and `nRow` the slices stacked from the
//! finest down ending at the texture's height — so that every block at every slice lies inside
//! the texture and no two overlap. Texel values are not checked.
//!
//! A file reads back without the builder's block list (`PtexLayout::blocks` empty: rendering
//! and the CPU evaluation need only records and tables) and with default stats.

use std::path::Path;

use crate::colors::budget::ATLAS_MAX_WIDTH;
use crate::colors::format::ColorFormat;
use crate::packing::file::sections::{Fields, Section, align_up, checksum, le_words, section_bytes};
use crate::ptex::layout::{PtexFaceRecord, PtexLayout, PtexTables, SLICES};
use crate::ptex::{PackedPtex, PtexStats};

/// The first 8 bytes of every packed Ptex file.
pub const MAGIC: [u8; 8] = *b"MESHPTX\0";
/// The format version this module writes and reads.
pub const VERSION: u32 = 1;
/// Size of the header in bytes (zero-padded to the section alignment).
pub const HEADER_SIZE: usize = 144;
/// The largest texture side in texels.
pub const MAX_SIDE: u32 = ATLAS_MAX_WIDTH as u32;
/// Byte offset of the CRC-32 field.
const CHECKSUM_OFFSET: usize = 140;
const SECTION_COUNT: usize = 5;
const SECTION_NAMES: [&str; SECTION_COUNT] = ["positions", "indices", "face records", "tables", "texels"];
/// Bytes of the tables section.
const TABLES_SIZE: u64 = 12 * SLICES as u64;

/// Why a packed Ptex file cannot be written or read.
#[derive(Debug, thiserror::Error)]
pub enum PtexFileError {
    /// Not a packed Ptex file.
    #[error("not a packed Ptex file (starts with {found:02x?})")]
    NotPtex {
        /// The first bytes.
        found: Vec<u8>,
    },
    /// The file ends before something it declares.
    #[error("truncated: {what} at byte {end}, but the file has {len}")]
    Truncated {
        /// What ends there.
        what: String,
        /// Where it ends.
        end: u64,
        /// File length.
        len: u64,
    },
    /// Another version.
    #[error("packed Ptex version {0} is not supported (this build reads version 1)")]
    UnsupportedVersion(u32),
    /// A header field or the section table is invalid.
    #[error("invalid header: {0}")]
    Header(String),
    /// The stored checksum is not the bytes' CRC-32.
    #[error("checksum mismatch: stored {stored:08x}, computed {computed:08x}")]
    ChecksumMismatch {
        /// Stored.
        stored: u32,
        /// Computed.
        computed: u32,
    },
    /// A section's content is invalid.
    #[error("invalid {section}: {problem}")]
    Content {
        /// The section.
        section: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// Reading or writing failed.
    #[error("{path}: could not {action}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What was attempted.
        action: &'static str,
        /// Why it failed.
        source: std::io::Error,
    },
    /// A file's error, with its path.
    #[error("{path}: {source}")]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// The error.
        source: Box<PtexFileError>,
    },
}

fn content(section: &'static str, problem: String) -> PtexFileError {
    PtexFileError::Content { section, problem }
}

/// A decoded packed Ptex file.
#[derive(Debug, Clone, PartialEq)]
pub struct PtexFile {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as vertex ids.
    pub indices: Vec<[u32; 3]>,
    /// Records, tables, texture (no block list, default stats).
    pub ptex: PackedPtex,
}

/// Whether `bytes` starts with the packed Ptex [`MAGIC`].
pub fn looks_like_ptex(bytes: &[u8]) -> bool {
    bytes.starts_with(&MAGIC)
}

#[derive(Debug, Clone, Copy, Default)]
struct Header {
    version: u32,
    header_size: u32,
    file_size: u64,
    flags: u32,
    format_code: u32,
    counts: [u32; 3],
    width: u32,
    height: u32,
    levels: u32,
    sections: [Section; SECTION_COUNT],
    reserved: u32,
    checksum: u32,
}

impl Header {
    fn parse(bytes: &[u8; HEADER_SIZE]) -> Header {
        let mut f = Fields(bytes.get(MAGIC.len()..).unwrap_or_default());
        let (version, header_size, file_size) = (f.u32(), f.u32(), f.u64());
        let (flags, format_code) = (f.u32(), f.u32());
        let counts = [f.u32(), f.u32(), f.u32()];
        let (width, height, levels) = (f.u32(), f.u32(), f.u32());
        let mut sections = [Section::default(); SECTION_COUNT];
        for section in &mut sections {
            section.offset = f.u64();
            section.length = f.u64();
        }
        let (reserved, checksum) = (f.u32(), f.u32());
        Header {
            version,
            header_size,
            file_size,
            flags,
            format_code,
            counts,
            width,
            height,
            levels,
            sections,
            reserved,
            checksum,
        }
    }

    fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&self.version.to_le_bytes());
        out.extend_from_slice(&self.header_size.to_le_bytes());
        out.extend_from_slice(&self.file_size.to_le_bytes());
        let words = [self.flags, self.format_code, self.counts[0], self.counts[1], self.counts[2]];
        for word in words.into_iter().chain([self.width, self.height, self.levels]) {
            out.extend_from_slice(&word.to_le_bytes());
        }
        for section in &self.sections {
            out.extend_from_slice(&section.offset.to_le_bytes());
            out.extend_from_slice(&section.length.to_le_bytes());
        }
        out.extend_from_slice(&self.reserved.to_le_bytes());
        out.extend_from_slice(&self.checksum.to_le_bytes());
    }
}

/// The number of blocks: one more than the largest block a record names (0 without faces).
fn block_count(records: &[PtexFaceRecord]) -> u32 {
    records.iter().map(|r| r.block().saturating_add(1)).max().unwrap_or(0)
}

/// Encodes a mesh and its packed Ptex. Deterministic; refuses what the reader would refuse.
pub fn to_bytes(positions: &[[f32; 3]], indices: &[[u32; 3]], ptex: &PackedPtex) -> Result<Vec<u8>, PtexFileError> {
    let layout = &ptex.layout;
    let too_many = |what: &str| PtexFileError::Header(format!("too many {what}"));
    let vertex_count = u32::try_from(positions.len()).map_err(|_| too_many("vertices"))?;
    let face_count = u32::try_from(indices.len()).map_err(|_| too_many("faces"))?;
    if ptex.vertex_density.len() != positions.len() || layout.records.len() != indices.len() {
        return Err(PtexFileError::Header("densities, records and the mesh disagree in count".into()));
    }
    let blocks = block_count(&layout.records);
    if !layout.blocks.is_empty() && layout.blocks.len() as u64 != u64::from(blocks) {
        return Err(PtexFileError::Header(format!("{} blocks, the records name {blocks}", layout.blocks.len())));
    }
    let texel_bytes = layout.texel_count() * ptex.format.bytes_per_sample() as u64;
    if ptex.texels.len() as u64 != texel_bytes {
        return Err(PtexFileError::Header(format!("{} texel bytes, expected {texel_bytes}", ptex.texels.len())));
    }
    let header_fields = (layout.width, layout.height, layout.levels);
    check_content(positions, &ptex.vertex_density, indices, &layout.records, &layout.tables, blocks, header_fields)?;
    let lengths =
        [u64::from(vertex_count) * 16, u64::from(face_count) * 12, u64::from(face_count) * 4, TABLES_SIZE, texel_bytes];
    let mut sections = [Section::default(); SECTION_COUNT];
    let mut cursor = HEADER_SIZE as u64;
    for (section, length) in sections.iter_mut().zip(lengths) {
        section.offset = align_up(cursor).unwrap_or(u64::MAX);
        section.length = length;
        cursor = section.offset.saturating_add(length);
    }
    let header = Header {
        version: VERSION,
        header_size: HEADER_SIZE as u32,
        file_size: cursor,
        format_code: ptex.format.code(),
        counts: [vertex_count, face_count, blocks],
        width: layout.width,
        height: layout.height,
        levels: layout.levels,
        sections,
        ..Header::default()
    };
    let mut out = Vec::with_capacity(usize::try_from(cursor).unwrap_or(0));
    header.write(&mut out);
    let pad_to = |out: &mut Vec<u8>, s: Section| out.resize(usize::try_from(s.offset).unwrap_or(out.len()), 0);
    pad_to(&mut out, sections[0]);
    for (p, d) in positions.iter().zip(&ptex.vertex_density) {
        out.extend(p.iter().chain([d]).flat_map(|c| c.to_le_bytes()));
    }
    pad_to(&mut out, sections[1]);
    out.extend(indices.iter().flatten().flat_map(|i| i.to_le_bytes()));
    pad_to(&mut out, sections[2]);
    out.extend(layout.records.iter().flat_map(|r| r.0.to_le_bytes()));
    pad_to(&mut out, sections[3]);
    for k in 0..SLICES {
        let t = &layout.tables;
        out.extend([t.n_res[k], t.n_row[k], t.per_row[k]].iter().flat_map(|w| w.to_le_bytes()));
    }
    pad_to(&mut out, sections[4]);
    out.extend_from_slice(&ptex.texels);
    let crc = checksum(&out, CHECKSUM_OFFSET);
    if let Some(slot) = out.get_mut(CHECKSUM_OFFSET..CHECKSUM_OFFSET + 4) {
        slot.copy_from_slice(&crc.to_le_bytes());
    }
    Ok(out)
}

/// The section table against the file length, then every gap zero.
fn check_sections(bytes: &[u8], header: &Header) -> Result<(), PtexFileError> {
    let len = bytes.len() as u64;
    let mut previous_end = HEADER_SIZE as u64;
    for (section, name) in header.sections.iter().zip(SECTION_NAMES) {
        if !section.offset.is_multiple_of(256) || section.offset < previous_end {
            return Err(PtexFileError::Header(format!("{name} at {} (misaligned or overlapping)", section.offset)));
        }
        let end = section
            .offset
            .checked_add(section.length)
            .ok_or_else(|| PtexFileError::Header(format!("{name} ends past 2^64")))?;
        if end > len {
            return Err(PtexFileError::Truncated { what: format!("{name} end"), end, len });
        }
        previous_end = end;
    }
    if header.file_size != len || previous_end != len {
        return Err(PtexFileError::Header(format!(
            "file size {} and last section end {previous_end} must both be the file's length {len}",
            header.file_size
        )));
    }
    Ok(())
}

fn check_padding(bytes: &[u8], header: &Header) -> Result<(), PtexFileError> {
    let mut gap_start = HEADER_SIZE as u64;
    for section in &header.sections {
        let gap = section_bytes(bytes, Section { offset: gap_start, length: section.offset.saturating_sub(gap_start) });
        if let Some(at) = gap.iter().position(|&b| b != 0) {
            return Err(PtexFileError::Header(format!("non-zero padding at byte {}", gap_start + at as u64)));
        }
        gap_start = section.offset.saturating_add(section.length);
    }
    Ok(())
}

/// Every content rule of the module docs.
fn check_content(
    positions: &[[f32; 3]],
    density: &[f32],
    indices: &[[u32; 3]],
    records: &[PtexFaceRecord],
    tables: &PtexTables,
    blocks: u32,
    (width, height, levels): (u32, u32, u32),
) -> Result<(), PtexFileError> {
    if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
        return Err(PtexFileError::Header(format!("texture {width}×{height} outside 1..={MAX_SIDE} a side")));
    }
    if !(1..=SLICES as u32).contains(&levels) {
        return Err(PtexFileError::Header(format!("{levels} levels outside 1..={SLICES}")));
    }
    if let Some(v) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(content("positions", format!("vertex {v} is not finite")));
    }
    if let Some(v) = density.iter().position(|d| !(d.is_finite() && *d >= 0.0)) {
        return Err(content("positions", format!("vertex {v}'s density is not a finite number ≥ 0")));
    }
    let vertices = positions.len() as u64;
    if let Some(f) = indices.iter().position(|t| t.iter().any(|&i| u64::from(i) >= vertices)) {
        return Err(content("indices", format!("face {f} names a vertex past {vertices}")));
    }
    if let Some(f) = records.iter().position(|r| r.0 & 3 == 3 || r.block() >= blocks) {
        return Err(content("face records", format!("face {f}: corner 3 or block past {blocks}")));
    }
    if tables.n_res[0] != 0 || tables.n_res.windows(2).any(|w| w[0] > w[1]) || tables.n_res[SLICES - 1] > blocks {
        return Err(content("tables", format!("nRes must rise from 0 to at most {blocks}: {:?}", tables.n_res)));
    }
    let mut y = 0u64;
    for k in (0..SLICES).rev() {
        let s = (1u64 << k) + 2;
        let per_row = (u64::from(width) / s).max(1);
        let count = u64::from(blocks - tables.n_res[k]);
        if u64::from(tables.per_row[k]) != per_row || (count > 0 && s > u64::from(width)) {
            return Err(content("tables", format!("slice {k}: {} blocks per row, {per_row} fit", tables.per_row[k])));
        }
        if u64::from(tables.n_row[k]) != y {
            return Err(content("tables", format!("slice {k} starts at row {}, not {y}", tables.n_row[k])));
        }
        y += count.div_ceil(per_row) * s;
    }
    if y != u64::from(height) && !(y == 0 && height == 1) {
        return Err(content("tables", format!("slices end at row {y}, the texture has {height}")));
    }
    Ok(())
}

/// Decodes a packed Ptex file, refusing anything truncated, corrupt or hostile (never panics).
pub fn from_bytes(bytes: &[u8]) -> Result<PtexFile, PtexFileError> {
    let len = bytes.len() as u64;
    if !looks_like_ptex(bytes) {
        let found = bytes.get(..MAGIC.len()).unwrap_or(bytes);
        if MAGIC.starts_with(found) {
            return Err(PtexFileError::Truncated { what: "the magic".into(), end: 8, len });
        }
        return Err(PtexFileError::NotPtex { found: found.to_vec() });
    }
    let header_bytes = bytes.first_chunk::<HEADER_SIZE>().ok_or_else(|| PtexFileError::Truncated {
        what: "the header".into(),
        end: HEADER_SIZE as u64,
        len,
    })?;
    let header = Header::parse(header_bytes);
    if header.version != VERSION {
        return Err(PtexFileError::UnsupportedVersion(header.version));
    }
    if header.header_size as usize != HEADER_SIZE {
        return Err(PtexFileError::Header(format!("header size {}", header.header_size)));
    }
    check_sections(bytes, &header)?;
    let computed = checksum(bytes, CHECKSUM_OFFSET);
    if computed != header.checksum {
        return Err(PtexFileError::ChecksumMismatch { stored: header.checksum, computed });
    }
    if header.flags != 0 || header.reserved != 0 {
        return Err(PtexFileError::Header("flags and the reserved field must be 0".into()));
    }
    check_padding(bytes, &header)?;
    let format = ColorFormat::from_code(header.format_code)
        .ok_or_else(|| PtexFileError::Header(format!("unknown colour format {}", header.format_code)))?;
    let [vertices, faces, blocks] = header.counts.map(u64::from);
    // Sides are not checked yet (the content checks come later): saturate, never overflow.
    let texels = u64::from(header.width)
        .saturating_mul(u64::from(header.height))
        .saturating_mul(format.bytes_per_sample() as u64);
    let expected = [vertices * 16, faces * 12, faces * 4, TABLES_SIZE, texels];
    for ((section, name), want) in header.sections.iter().zip(SECTION_NAMES).zip(expected) {
        if section.length != want {
            return Err(PtexFileError::Header(format!("{name}: {} bytes, the counts say {want}", section.length)));
        }
    }
    let [s_pos, s_idx, s_rec, s_tab, s_tex] = header.sections;
    let (positions, density): (Vec<[f32; 3]>, Vec<f32>) = le_words::<4>(section_bytes(bytes, s_pos))
        .into_iter()
        .map(|[x, y, z, d]| ([x, y, z].map(f32::from_bits), f32::from_bits(d)))
        .unzip();
    let indices = le_words::<3>(section_bytes(bytes, s_idx));
    let records: Vec<PtexFaceRecord> =
        le_words::<1>(section_bytes(bytes, s_rec)).into_iter().map(|[w]| PtexFaceRecord(w)).collect();
    let mut tables = PtexTables::default();
    for (k, [n_res, n_row, per_row]) in le_words::<3>(section_bytes(bytes, s_tab)).into_iter().enumerate().take(SLICES)
    {
        (tables.n_res[k], tables.n_row[k], tables.per_row[k]) = (n_res, n_row, per_row);
    }
    let blocks = u32::try_from(blocks).unwrap_or(u32::MAX);
    if block_count(&records) != blocks {
        let named = block_count(&records);
        return Err(content(
            "face records",
            format!("the largest block named is {named} − 1, the header says {blocks} blocks"),
        ));
    }
    let fields = (header.width, header.height, header.levels);
    check_content(&positions, &density, &indices, &records, &tables, blocks, fields)?;
    let layout = PtexLayout {
        records,
        blocks: Vec::new(),
        tables,
        width: header.width,
        height: header.height,
        levels: header.levels,
    };
    let texels = section_bytes(bytes, s_tex).to_vec();
    let ptex = PackedPtex { layout, format, texels, stats: PtexStats::default(), vertex_density: density };
    Ok(PtexFile { positions, indices, ptex })
}

/// Writes the packed Ptex file of `positions`, `indices` and `ptex` to `path` atomically.
pub fn write_ptex(
    path: &Path,
    positions: &[[f32; 3]],
    indices: &[[u32; 3]],
    ptex: &PackedPtex,
) -> Result<(), PtexFileError> {
    let bytes = to_bytes(positions, indices, ptex)
        .map_err(|source| PtexFileError::File { path: path.to_path_buf(), source: Box::new(source) })?;
    crate::atomic_write::write_atomically(path, &bytes).map_err(|error| PtexFileError::Io {
        path: error.path,
        action: error.action,
        source: error.source,
    })
}

/// Reads and decodes the packed Ptex file at `path`. Errors name the path.
pub fn read_ptex(path: &Path) -> Result<PtexFile, PtexFileError> {
    let bytes = std::fs::read(path).map_err(|source| PtexFileError::Io {
        path: path.to_path_buf(),
        action: "read the file",
        source,
    })?;
    from_bytes(&bytes).map_err(|source| PtexFileError::File { path: path.to_path_buf(), source: Box::new(source) })
}
