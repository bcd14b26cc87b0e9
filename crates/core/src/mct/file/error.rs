//! The errors of reading and writing MCT files; each names the problem (and, through
//! [`MctFileError::File`] and [`MctFileError::Io`], the file).

use std::path::PathBuf;

use super::{HEADER_SIZE, MAGIC, MAX_ATLAS_SIDE, MAX_LEVELS, SECTION_ALIGN, VERSION};
use crate::packing::file::Expected;

/// Everything that can go wrong writing or reading an MCT file.
#[derive(Debug, thiserror::Error)]
pub enum MctFileError {
    /// An I/O operation on `path` failed.
    #[error("{}: cannot {action}: {source}", path.display())]
    Io {
        /// The file (or temporary file) concerned.
        path: PathBuf,
        /// What was being done, e.g. "read the file".
        action: &'static str,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The content of the file at `path` is refused.
    #[error("{}: {source}", path.display())]
    File {
        /// The file that was read or written.
        path: PathBuf,
        /// What is wrong.
        source: Box<MctFileError>,
    },
    /// The file does not start with [`MAGIC`].
    #[error("not a meshpaint MCT file: starts with {found:02x?}, expected {MAGIC:02x?} (\"MESHMCT\\0\")")]
    NotMct {
        /// The first (up to 8) bytes of the file.
        found: Vec<u8>,
    },
    /// The file ends before something the header (or the format) says is there.
    #[error("truncated: {what} at byte {end} but the file has {len} bytes")]
    Truncated {
        /// What ends past the end of file, e.g. "header says texels end".
        what: String,
        /// Where it ends.
        end: u64,
        /// The file's actual length.
        len: u64,
    },
    /// The file has bytes after its end (as the header's file size or last section say).
    #[error("{extra} unexpected bytes after the end of the {what} at byte {end}")]
    TrailingBytes {
        /// What ends there ("file" by the header's size field, or "last section").
        what: &'static str,
        /// Where the file should end.
        end: u64,
        /// How many bytes follow.
        extra: u64,
    },
    /// The file's version is not [`VERSION`].
    #[error("unsupported MCT file version {0} (this build reads version {VERSION})")]
    UnsupportedVersion(u32),
    /// A version-1 or -2 file: written before squares were laid out in strips (1) or before
    /// files held the vertices' level-of-detail density (2).
    #[error(
        "MCT file version {0} was written by an older meshpaint (version 1: squares without strips; 2: no level-of-detail density per vertex); this build reads version {VERSION}: export it again from its source with `meshpaint export SOURCE -o OUT.mct --representation mct`"
    )]
    OldVersion(u32),
    /// A vertex's level-of-detail density is negative, NaN or infinite.
    #[error("vertex {vertex}: level-of-detail density {density} is not a finite number ≥ 0")]
    BadDensity {
        /// The vertex.
        vertex: u64,
        /// Its density.
        density: f32,
    },
    /// The texture's per-vertex densities do not match the vertices.
    #[error("{densities} level-of-detail densities for {vertices} vertices")]
    DensityCount {
        /// Densities.
        densities: u64,
        /// Vertices.
        vertices: u64,
    },
    /// The strip-row fields of a group's band entry are out of range.
    #[error(
        "band table, block resolution {resolution}: strip rows of 2^{log2_row} pairs with at most {pieces} pieces and masks from {mask_base} (rows of at most 32 pairs, 1..=rows+1 pieces, masks inside the {masks} stored)"
    )]
    StripRows {
        /// The block resolution.
        resolution: u32,
        /// `log2 S`.
        log2_row: u32,
        /// Most pieces per strip row.
        pieces: u32,
        /// Index of the group's first mask.
        mask_base: u32,
        /// Masks in the file.
        masks: u64,
    },
    /// A strip-row mask is not what the group's rows allow.
    #[error(
        "strip-row mask {index} ({mask:#010x}) of block resolution {resolution}: bit 0 and bits past the row's {per_row} pairs must be 0, and it may start at most {pieces} pieces"
    )]
    StripMask {
        /// Index of the mask.
        index: u64,
        /// Its value.
        mask: u32,
        /// The block resolution.
        resolution: u32,
        /// Pairs per strip row.
        per_row: u32,
        /// Most pieces per row.
        pieces: u32,
    },
    /// The number of strip-row masks is not the one the records and band table imply.
    #[error("{stored} strip-row masks follow the face records, the band table and records need {expected}")]
    MaskCount {
        /// Masks stored.
        stored: u64,
        /// Masks needed.
        expected: u64,
    },
    /// The header size field is not [`HEADER_SIZE`].
    #[error("header size is {0} bytes, version {VERSION} headers are {HEADER_SIZE} bytes")]
    HeaderSize(u32),
    /// The stored CRC-32 does not match the file content.
    #[error("checksum mismatch: stored CRC-32 {stored:#010x}, content has {computed:#010x} (file corrupt)")]
    ChecksumMismatch {
        /// The CRC-32 in the header.
        stored: u32,
        /// The CRC-32 of the content.
        computed: u32,
    },
    /// Flag bits this version does not define are set.
    #[error("unknown flag bits {0:#010x} (version {VERSION} defines none)")]
    UnknownFlags(u32),
    /// A reserved header field is not zero.
    #[error("reserved header field at byte {offset} is {value:#x}, must be 0")]
    ReservedNotZero {
        /// Byte offset of the field in the header.
        offset: usize,
        /// Its value.
        value: u32,
    },
    /// A padding byte (after the header or between sections) is not zero.
    #[error("padding byte at offset {offset} is {value:#04x}, must be 0")]
    NonZeroPadding {
        /// Offset of the first non-zero padding byte.
        offset: u64,
        /// Its value.
        value: u8,
    },
    /// The colour format code is unknown.
    #[error("unknown colour format code {0} (known: 0 = rgba8, 1 = rgba16f, 2 = rgba32f)")]
    UnknownColorFormat(u32),
    /// A section offset is not a multiple of [`SECTION_ALIGN`].
    #[error("{section} section offset {offset} is not a multiple of {SECTION_ALIGN}")]
    SectionMisaligned {
        /// The section.
        section: &'static str,
        /// Its offset.
        offset: u64,
    },
    /// A section starts before the previous section (or the header) ends.
    #[error("{section} section starts at byte {offset}, before the end of the {previous} at byte {previous_end}")]
    SectionOverlap {
        /// The section.
        section: &'static str,
        /// Its offset.
        offset: u64,
        /// What precedes it ("header" or a section name).
        previous: &'static str,
        /// Where that ends.
        previous_end: u64,
    },
    /// A section's offset plus length does not fit in 64 bits.
    #[error("{section} section: offset {offset} + length {length} overflows")]
    SectionOverflow {
        /// The section.
        section: &'static str,
        /// Its offset.
        offset: u64,
        /// Its length.
        length: u64,
    },
    /// A section's length disagrees with the header's counts.
    #[error("{section} section is {length} bytes but {count} {unit} need {expected} bytes")]
    SectionLength {
        /// The section.
        section: &'static str,
        /// Its length in the table.
        length: u64,
        /// The header count.
        count: u64,
        /// What is counted ("vertices", "faces", "band tables", "texels").
        unit: &'static str,
        /// `count × element size`, or `None` when that overflows 64 bits.
        expected: Expected,
    },
    /// The atlas is empty or larger than [`MAX_ATLAS_SIDE`] on a side.
    #[error("the atlas is {width}×{height} texels: each side must be 1..={MAX_ATLAS_SIDE}")]
    AtlasSize {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
    /// The level count is 0 or above [`MAX_LEVELS`].
    #[error("levels is {0}: must be 1..={MAX_LEVELS} (1 + log2 of the largest resolution)")]
    Levels(u32),
    /// More vertices or faces than a 32-bit count holds (writer only).
    #[error("{count} {what} exceed the format's 32-bit count")]
    TooMany {
        /// What ("vertices", "faces").
        what: &'static str,
        /// How many.
        count: u64,
    },
    /// The index buffer and the face records disagree about the face count (writer only).
    #[error("{indices} triangles in the index buffer but {records} MCT face records")]
    FaceCountMismatch {
        /// Triangles.
        indices: u64,
        /// Face records.
        records: u64,
    },
    /// The texel buffer is not the atlas's size (writer only).
    #[error("the atlas holds {len} bytes but {width}×{height} texels of {format} need {expected}")]
    TexelBytes {
        /// Bytes in the texel buffer.
        len: u64,
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// The colour format's name.
        format: &'static str,
        /// Bytes needed.
        expected: u64,
    },
    /// The layout's pair lists are not the ones its records describe (writer only: the file
    /// stores the records and the reader rebuilds the pairs from them).
    #[error(
        "the layout's pair lists disagree with its face records at block resolution {resolution}, pair {pair}: {stored:?} listed, {rebuilt:?} recorded"
    )]
    PairsMismatch {
        /// The block resolution of the first disagreeing group.
        resolution: u32,
        /// The first disagreeing pair (or the list length when only the lengths differ).
        pair: u64,
        /// The layout's entry (`None` past the end of its list).
        stored: Option<[u32; 2]>,
        /// The entry the records give (`None` past the end of that list).
        rebuilt: Option<[u32; 2]>,
    },
    /// A position coordinate is NaN or infinite.
    #[error("position of vertex {vertex} is not finite: {position:?}")]
    NonFinitePosition {
        /// The vertex.
        vertex: u64,
        /// Its position.
        position: [f32; 3],
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("index {corner} of triangle {triangle} is {index} but there are {vertex_count} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: u64,
        /// The corner (0, 1, 2).
        corner: usize,
        /// The index stored.
        index: u32,
        /// The number of vertices.
        vertex_count: u64,
    },
    /// A face record names a corner 3 as `p`.
    #[error("face {face}: its MCT record {record:#010x} names corner {corner} as p (corners are 0, 1, 2)")]
    RecordCorner {
        /// The face.
        face: u64,
        /// The record's bits.
        record: u32,
        /// The corner stored.
        corner: u32,
    },
    /// A face record's block resolution is above 4096.
    #[error("face {face}: its MCT record {record:#010x} has log2 R_b = {log2}, at most 12 (R_b ≤ 4096)")]
    RecordResolution {
        /// The face.
        face: u64,
        /// The record's bits.
        record: u32,
        /// The stored `log2 R_b`.
        log2: u32,
    },
    /// A face's block resolution needs more levels than the file has.
    #[error(
        "face {face}: block resolution {resolution} needs at least {needed} levels (down to one texel step) but the file has {levels}"
    )]
    RecordLevels {
        /// The face.
        face: u64,
        /// Its block resolution.
        resolution: u32,
        /// `1 + log2 R_b`.
        needed: u32,
        /// The header's levels.
        levels: u32,
    },
    /// A face record's pair index is past the faces of its group.
    #[error(
        "face {face}: pair {pair} of block resolution {resolution}, but only {faces} faces have that block resolution (pairs are numbered from 0 without gaps)"
    )]
    PairIndex {
        /// The face.
        face: u64,
        /// The pair index stored.
        pair: u32,
        /// The block resolution.
        resolution: u32,
        /// Faces of that block resolution.
        faces: u64,
    },
    /// A reserved word of the band table is not zero, or a band skips a whole row.
    #[error(
        "band table entry of block resolution {resolution} at level {level}: word {word} is {value:#x}, must be 0 (word 2 of a band in use: fewer than its blocks per row)"
    )]
    BandReserved {
        /// The block resolution.
        resolution: u32,
        /// The level.
        level: u32,
        /// The word (2 or 3).
        word: usize,
        /// Its value.
        value: u32,
    },
    /// A band that faces read holds no block per row.
    #[error(
        "band of block resolution {resolution} at level {level} holds 0 blocks per row, but {faces} faces are placed in it"
    )]
    EmptyBand {
        /// The block resolution.
        resolution: u32,
        /// The level.
        level: u32,
        /// Faces of that block resolution.
        faces: u64,
    },
    /// Two faces claim the same side of the same pair.
    #[error("faces {other} and {face} both claim side {side} of pair {pair} of block resolution {resolution}")]
    DuplicateSlot {
        /// The later face.
        face: u64,
        /// The earlier face.
        other: u64,
        /// The block resolution.
        resolution: u32,
        /// The pair.
        pair: u32,
        /// 0 (first) or 1 (second).
        side: u32,
    },
    /// A pair below the group's last has no first face (a gap, or a lone second face).
    #[error(
        "pair {pair} of block resolution {resolution} has no first face (pairs are numbered from 0 without gaps, each with a first face)"
    )]
    MissingFirst {
        /// The block resolution.
        resolution: u32,
        /// The pair.
        pair: u64,
    },
    /// The two faces of a pair do not share the edge `p → q` their records name.
    #[error(
        "faces {first} and {second} (pair {pair} of block resolution {resolution}) do not share their edge p → q: vertices {first_edge:?} and {second_edge:?}"
    )]
    PairEdge {
        /// The first face.
        first: u64,
        /// The second face.
        second: u64,
        /// The block resolution.
        resolution: u32,
        /// The pair.
        pair: u64,
        /// `(p, q)` vertices of the first face.
        first_edge: [u32; 2],
        /// `(p, q)` vertices of the second face.
        second_edge: [u32; 2],
    },
    /// A face's block (or ring) at some level reaches outside the atlas.
    #[error("face {face}: its block at level {level} reaches texel {texel:?}, outside the {width}×{height} atlas")]
    OutsideAtlas {
        /// The face.
        face: u64,
        /// The level.
        level: u32,
        /// The first texel found outside.
        texel: [i64; 2],
        /// Atlas width.
        width: u32,
        /// Atlas height.
        height: u32,
    },
}
