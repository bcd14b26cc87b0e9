//! The CPU reference sampler: the truth the WGSL shaders are tested against.
//!
//! `sample(source, face, barycentric, filter, level)` evaluates mesh colors on one face:
//! nearest (the highest-weight sample, thesis 2.2.3) or linear (three samples, eq. 2.4)
//! at MIP level `level` (clamped to the face's last level, where only vertex colours
//! remain), through [`MeshColorSource`], implemented by
//! - [`ColorStore`]: level 0, read straight from the editable maps;
//! - [`StoreMips`]: every level of a store, its MIP chains evaluated in full `f32`
//!   (the packer's filters with RGBA32F, whose quantisation is the identity);
//! - [`PackedMesh`]: every level of packed buffers in any colour format.
//!
//! The arithmetic is `f32` in the order the shaders use.

use crate::colors::format::ColorFormat;
use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution, SampleLocation};
use crate::colors::store::ColorStore;
use crate::packing::linear::PackedMesh;
use crate::packing::packer::{PackError, pack};

/// How colours between samples are reconstructed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest sample (hexagonal cells).
    Nearest,
    /// Linear interpolation of the three samples of the sub-triangle.
    Linear,
}

/// Anything that can return a face's lattice samples at a MIP level.
pub trait MeshColorSource {
    /// Resolution of `face` (level 0), or `None` for a face that does not exist.
    fn face_resolution(&self, face: u32) -> Option<Resolution>;
    /// The colour at lattice point `(i, j)` of `face` at `level` (whose resolution is
    /// `R_f >> level`); `None` when the point, face or level is not available.
    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba>;
}

impl MeshColorSource for ColorStore {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        ColorStore::face_resolution(self, face)
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        if level != 0 {
            return None;
        }
        self.face_sample(face, i, j)
    }
}

/// A store with its MIP chains evaluated in `f32`, for level-`l` reference sampling.
#[derive(Debug, Clone)]
pub struct StoreMips {
    chains: PackedMesh,
}

impl StoreMips {
    /// Evaluates every MIP chain of `store` (no quantisation).
    pub fn new(store: &ColorStore) -> Result<Self, PackError> {
        let positions = vec![[0.0f32; 3]; store.topology().vertex_count as usize];
        Ok(StoreMips { chains: pack(store, &positions, ColorFormat::Rgba32F)? })
    }
}

impl MeshColorSource for StoreMips {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        self.chains.face_resolution(face)
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        self.chains.lattice_color(face, level, i, j)
    }
}

impl MeshColorSource for PackedMesh {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        self.face_records.get(face as usize)?.resolution()
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        self.color(packed_sample_index(self, face, level, i, j)?)
    }
}

/// Index in the colour buffer of lattice point `(i, j)` of `face` at `level` — the
/// addressing the shaders implement (keep in sync with shaders/mesh_colors.wgsl).
pub fn packed_sample_index(packed: &PackedMesh, face: u32, level: u32, i: u32, j: u32) -> Option<u64> {
    let record = packed.face_records.get(face as usize)?;
    let corners = packed.indices.get(face as usize)?;
    let r_face = record.resolution()?;
    let level = level.min(r_face.log2());
    let r = r_face.at_level(level).ok()?;
    Some(match layout::classify_sample(r, i, j, [false; 3])? {
        SampleLocation::Vertex { corner } => {
            let vertex = u64::from(corners[usize::from(corner)]);
            let last = packed.vertex_levels.checked_sub(1)?;
            vertex * u64::from(packed.vertex_levels) + u64::from(level.min(last))
        }
        SampleLocation::Edge { face_edge, offset } => {
            let k = usize::from(face_edge);
            let (base, r_edge) = record.edge(k)?;
            let stride_log2 = r_edge.log2().checked_sub(r_face.log2())?;
            let r_edge_level = r_edge.at_level(level).ok()?;
            let position = (offset + 1) << stride_log2;
            let reversed = corners[k] > corners[(k + 1) % 3];
            let in_level = layout::edge_storage_offset(r_edge_level, position, reversed);
            u64::from(base) + u64::from(layout::edge_level_offset(r_edge, level).ok()?) + u64::from(in_level)
        }
        SampleLocation::Interior { offset } => {
            let level_offset = layout::interior_level_offset(r_face, level).ok()?;
            u64::from(record.interior_base()) + u64::from(level_offset) + u64::from(offset)
        }
    })
}

/// Samples `face` at `barycentric` with `filter` at MIP `level`. Returns `None` when the
/// source cannot provide the samples (unknown face, or a level the source lacks).
pub fn sample<S: MeshColorSource + ?Sized>(
    source: &S,
    face: u32,
    barycentric: [f32; 3],
    filter: Filter,
    level: u32,
) -> Option<Rgba> {
    let r_face = source.face_resolution(face)?;
    let level = level.min(r_face.log2());
    let r = r_face.at_level(level).ok()?;
    match filter {
        Filter::Nearest => {
            let (i, j) = layout::nearest_sample(r, barycentric);
            source.lattice_color(face, level, i, j)
        }
        Filter::Linear => {
            let mut out = [0.0f32; 4];
            for s in layout::linear_samples(r, barycentric) {
                let color = source.lattice_color(face, level, s.i, s.j)?;
                for c in 0..4 {
                    out[c] += s.weight * color[c];
                }
            }
            Some(out)
        }
    }
}
