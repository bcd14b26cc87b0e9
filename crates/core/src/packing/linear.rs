//! Packed mesh colors: the compact linear buffers the GPU renders and export writes.
//!
//! # Colour buffer
//!
//! One array of samples (encoded in a [`ColorFormat`]) in three sections:
//!
//! 1. **Vertices**: `vertex_levels` colours per vertex, vertex `v` level `l` at
//!    `v · vertex_levels + l`. `vertex_levels = 1 + log2(max face R)` over the mesh, so a
//!    shader finds any vertex colour without a table; a vertex whose faces are all coarser
//!    repeats its last level.
//! 2. **Edges**: each edge with `R_e > 1` owns its MIP chain (levels `0..log2 R_e`, level
//!    `l` holding `(R_e >> l) − 1` samples in canonical direction, at offset
//!    [`crate::colors::layout::edge_level_offset`]), chains in edge-id order.
//! 3. **Interiors**: each face with `R >= 4` owns its interior MIP chain (level offsets
//!    [`crate::colors::layout::interior_level_offset`]), chains in face order.
//!
//! # Face records (16 bytes)
//!
//! Four `u32` words, each `base | log2 << 28`:
//!
//! | word | low 28 bits | high 4 bits |
//! |---|---|---|
//! | 0 | first sample of the face's interior chain | `log2 R_f` |
//! | 1..=3 | first sample of face edge `k`'s chain (k = 0: c0→c1, 1: c1→c2, 2: c2→c0) | `log2 R_e` of that edge |
//!
//! The edge direction needs no bit: an edge's canonical direction runs from the lower to
//! the higher vertex id, and the shader has both ids from the index buffer. A face with
//! `R_f < R_e` reads the edge with stride `R_e / R_f` at the same level, so both faces see
//! identical values at shared sample positions; between them the seam rule of
//! [`crate::packing::sampler`] interpolates the edge's own samples. Bases must stay below `2^28` samples
//! ([`MAX_SAMPLES`]), 1 GiB of RGBA8.

use bytemuck::{Pod, Zeroable};

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::Resolution;

/// Largest colour-buffer size in samples: bases are 28-bit.
pub const MAX_SAMPLES: u64 = 1 << 28;
/// Mask of the base bits of a face-record word.
pub const BASE_MASK: u32 = (1 << 28) - 1;
/// Position of the `log2 R` nibble in a face-record word.
pub const LOG2_SHIFT: u32 = 28;

/// One face's entry in the face-record buffer.
///
/// Keep in sync with `struct FaceRecord` in shaders/mesh_colors.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Pod, Zeroable)]
pub struct FaceRecord {
    /// `interior base | log2 R_f << 28`.
    pub interior: u32,
    /// Per face edge: `edge chain base | log2 R_e << 28`.
    pub edges: [u32; 3],
}

const _: () = assert!(std::mem::size_of::<FaceRecord>() == 16);

/// Packs a base and a `log2` resolution into one word.
pub fn pack_word(base: u32, log2: u32) -> u32 {
    (base & BASE_MASK) | (log2 << LOG2_SHIFT)
}

/// Splits a face-record word into `(base, log2)`.
pub fn unpack_word(word: u32) -> (u32, u32) {
    (word & BASE_MASK, word >> LOG2_SHIFT)
}

impl FaceRecord {
    /// The face's resolution, or `None` when the stored `log2` is out of range.
    pub fn resolution(&self) -> Option<Resolution> {
        Resolution::from_log2(unpack_word(self.interior).1).ok()
    }

    /// First sample of the face's interior chain.
    pub fn interior_base(&self) -> u32 {
        unpack_word(self.interior).0
    }

    /// Chain base and resolution of face edge `k`.
    pub fn edge(&self, k: usize) -> Option<(u32, Resolution)> {
        let (base, log2) = unpack_word(*self.edges.get(k)?);
        Some((base, Resolution::from_log2(log2).ok()?))
    }
}

/// A mesh with packed mesh colors: geometry, face records and the colour buffer.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PackedMesh {
    /// World-space positions of the welded vertices.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as vertex ids (also the GPU index buffer).
    pub indices: Vec<[u32; 3]>,
    /// Colours per vertex (MIP levels of every vertex), `1 + log2(max R)`.
    pub vertex_levels: u32,
    /// One record per triangle.
    pub face_records: Vec<FaceRecord>,
    /// Encoding of [`PackedMesh::colors`].
    pub format: ColorFormat,
    /// Encoded samples, `sample_count · format.bytes_per_sample()` bytes.
    pub colors: Vec<u8>,
}

impl PackedMesh {
    /// Number of samples in the colour buffer.
    pub fn sample_count(&self) -> u64 {
        (self.colors.len() / self.format.bytes_per_sample()) as u64
    }

    /// Decodes sample `index`, or `None` past the end.
    pub fn color(&self, index: u64) -> Option<Rgba> {
        let size = self.format.bytes_per_sample();
        let start = usize::try_from(index).ok()?.checked_mul(size)?;
        let bytes = self.colors.get(start..start.checked_add(size)?)?;
        Some(self.format.decode(bytes))
    }

    /// Bytes of the face-record buffer.
    pub fn face_record_bytes(&self) -> u64 {
        (self.face_records.len() * std::mem::size_of::<FaceRecord>()) as u64
    }

    /// Bytes of the colour buffer.
    pub fn color_bytes(&self) -> u64 {
        self.colors.len() as u64
    }
}
