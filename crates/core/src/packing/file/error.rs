//! The errors of reading and writing packed files; each names the file and the problem.

use std::path::PathBuf;

use super::{HEADER_SIZE, MAGIC, SECTION_ALIGN, VERSION};
use crate::colors::layout::MAX_LOG2_RESOLUTION;
use crate::packing::linear::MAX_SAMPLES;

/// Everything that can go wrong writing or reading a packed file.
#[derive(Debug, thiserror::Error)]
pub enum PackedFileError {
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
        source: Box<PackedFileError>,
    },
    /// The layers section (version 2) is malformed.
    #[error("layers section: {0}")]
    BadLayers(String),
    /// The file does not start with [`MAGIC`].
    #[error("not a meshpaint packed file: starts with {found:02x?}, expected {MAGIC:02x?} (\"MESHPAK\\0\")")]
    NotPacked {
        /// The first (up to 8) bytes of the file.
        found: Vec<u8>,
    },
    /// The file ends before something the header (or the format) says is there.
    #[error("truncated: {what} at byte {end} but the file has {len} bytes")]
    Truncated {
        /// What ends past the end of file, e.g. "header says colors end".
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
    /// The file's version is not 1 or [`VERSION`].
    #[error("unsupported packed file version {0} (this build reads versions 1 to {VERSION})")]
    UnsupportedVersion(u32),
    /// The header size field is not [`HEADER_SIZE`].
    #[error("header size is {0} bytes, packed-file headers are {HEADER_SIZE} bytes")]
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
    #[error("unknown flag bits {0:#010x} (version 1 defines none, version 2 only bit 0: a layers section)")]
    UnknownFlags(u32),
    /// A reserved header field is not zero.
    #[error("reserved header field at byte {offset} is {value:#x}, must be 0")]
    ReservedNotZero {
        /// Byte offset of the field in the header.
        offset: usize,
        /// Its value.
        value: u32,
    },
    /// A padding byte (between the header and a section, or between sections) is not zero.
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
    /// A section's length disagrees with the header counts.
    #[error("{section} section is {length} bytes but {count} {unit} need {expected} bytes")]
    SectionLength {
        /// The section.
        section: &'static str,
        /// Its length in the table.
        length: u64,
        /// The header count.
        count: u64,
        /// What is counted ("vertices", "faces", "samples").
        unit: &'static str,
        /// `count × element size`, or `None` when that overflows 64 bits.
        expected: Expected,
    },
    /// More samples than face-record bases can address.
    #[error("sample count {0} exceeds the limit of {MAX_SAMPLES} (2^28) samples")]
    TooManySamples(u64),
    /// More vertices or faces than a 32-bit count holds (writer only).
    #[error("{count} {what} exceed the format's 32-bit count")]
    TooMany {
        /// What ("vertices", "faces").
        what: &'static str,
        /// How many.
        count: u64,
    },
    /// The mesh's buffers disagree about the face count (writer only).
    #[error("{indices} triangles in the index buffer but {records} face records")]
    FaceCountMismatch {
        /// Triangles.
        indices: u64,
        /// Face records.
        records: u64,
    },
    /// The colour buffer is not a whole number of samples (writer only).
    #[error("colour buffer of {len} bytes is not a whole number of {bytes_per_sample}-byte samples")]
    PartialSample {
        /// Bytes in the colour buffer.
        len: u64,
        /// Bytes per sample of the format.
        bytes_per_sample: usize,
    },
    /// `vertex_levels` exceeds `1 + MAX_LOG2_RESOLUTION`.
    #[error("vertex_levels is {0}, the most is {max} (1 + log2 of the largest resolution)", max = MAX_LOG2_RESOLUTION + 1)]
    TooManyVertexLevels(u32),
    /// The vertex section does not fit in the colour buffer.
    #[error("{vertices} vertices × {levels} levels need {needed} samples but there are {samples}")]
    VertexSamples {
        /// Vertex count.
        vertices: u64,
        /// `vertex_levels`.
        levels: u32,
        /// Their product.
        needed: u64,
        /// The colour buffer's sample count.
        samples: u64,
    },
    /// A position coordinate is NaN or infinite.
    #[error("position of vertex {vertex} is not finite: {position:?}")]
    NonFinitePosition {
        /// The vertex.
        vertex: u64,
        /// Its position.
        position: [f32; 3],
    },
    /// A colour the formats cannot hold: NaN, infinite, negative, above
    /// [`crate::colors::format::MAX_CHANNEL`], or an alpha outside `[0, 1]`.
    #[error(
        "sample {sample} has colour {color:?}: colours must be finite, R, G, B in [0, 65504] and alpha in [0, 1] (docs/FORMAT.md, \"Colour values\")"
    )]
    BadColor {
        /// Index of the sample in the colour buffer.
        sample: u64,
        /// Its decoded colour.
        color: [f32; 4],
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
    /// A triangle uses the same vertex twice.
    #[error("triangle {triangle} repeats a corner: {corners:?}")]
    RepeatedCorner {
        /// The triangle.
        triangle: u64,
        /// Its corners.
        corners: [u32; 3],
    },
    /// A face record's `log2 R_f` exceeds [`MAX_LOG2_RESOLUTION`].
    #[error("face record {face}: log2 R = {log2} exceeds {MAX_LOG2_RESOLUTION} (R ≤ 4096)")]
    FaceResolution {
        /// The face.
        face: u64,
        /// Its stored `log2 R_f`.
        log2: u32,
    },
    /// A face record's edge resolution is below the face's or above the limit.
    #[error(
        "face record {face}, edge {edge}: log2 R_e = {log2} must be in {face_log2}..={MAX_LOG2_RESOLUTION} (at least the face's log2 R)"
    )]
    EdgeResolution {
        /// The face.
        face: u64,
        /// The face edge (0, 1, 2).
        edge: usize,
        /// Its stored `log2 R_e`.
        log2: u32,
        /// The face's `log2 R_f`.
        face_log2: u32,
    },
    /// `vertex_levels` is too small for a face's resolution.
    #[error("face record {face}: log2 R = {log2} needs vertex_levels >= {needed} but it is {vertex_levels}")]
    VertexLevelsTooFew {
        /// The face.
        face: u64,
        /// Its `log2 R_f`.
        log2: u32,
        /// `1 + log2`.
        needed: u32,
        /// The mesh's `vertex_levels`.
        vertex_levels: u32,
    },
    /// A face record's MIP chain runs past the end of the colour buffer.
    #[error(
        "face record {face}: {chain} chain (R = {resolution}) at samples {base}..{end} runs past the {samples} samples of the colour buffer"
    )]
    ChainOutOfRange {
        /// The face.
        face: u64,
        /// "interior" or "edge 0/1/2".
        chain: &'static str,
        /// The chain's resolution.
        resolution: u32,
        /// Its first sample.
        base: u32,
        /// One past its last sample.
        end: u64,
        /// The colour buffer's sample count.
        samples: u64,
    },
}

/// An expected byte count that may have overflowed 64 bits (for error messages).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Expected(pub Option<u64>);

impl std::fmt::Display for Expected {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(bytes) => write!(f, "{bytes}"),
            None => write!(f, "more than 2^64"),
        }
    }
}
