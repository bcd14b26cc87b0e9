//! The colour buffer read through the sampler's addressing while the edge and vertex
//! chains are built (what coarser faces show next to an edge, the seam rule).

use crate::colors::format::Rgba;
use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;
use crate::packing::edges::EdgeReader;
use crate::packing::interiors::InteriorReader;
use crate::packing::linear::FaceRecord;
use crate::packing::sampler::{self, MeshColorSource};

/// The colour buffer while the edge and vertex chains are being built, read through the
/// sampler's addressing (every level below the one being built is final).
pub(crate) struct ChainsView<'a> {
    pub(crate) store: &'a ColorStore,
    pub(crate) records: &'a [FaceRecord],
    pub(crate) vertex_levels: u32,
    pub(crate) vertex_colors: &'a [Rgba],
    pub(crate) edges: EdgeReader<'a>,
    pub(crate) interiors: InteriorReader<'a>,
    pub(crate) vertex_section: usize,
    pub(crate) interior_start: usize,
}

impl ChainsView<'_> {
    /// Sample `index` of the colour buffer, read for `face` (an interior index is always one
    /// of `face`'s own interior samples).
    fn at(&self, face: u32, index: u64) -> Option<Rgba> {
        let index = usize::try_from(index).ok()?;
        if index < self.vertex_section {
            self.vertex_colors.get(index).copied()
        } else if index < self.interior_start {
            let local = index - self.vertex_section;
            let edge = self.edges.edge_at(local)?;
            self.edges.get(edge, local - *self.edges.prefix.chain.get(edge as usize)? as usize)
        } else {
            let base = self.records.get(face as usize)?.interior_base() as usize;
            self.interiors.get(face, index.checked_sub(base)?)
        }
    }
}

impl MeshColorSource for ChainsView<'_> {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        self.store.face_resolution(face)
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        let record = self.records.get(face as usize)?;
        let corners = self.store.topology().face_vertices.get(face as usize)?;
        self.at(face, sampler::record_sample_index(record, corners, self.vertex_levels, level, i, j)?)
    }

    fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution> {
        Some(self.records.get(face as usize)?.edge(usize::from(k))?.1)
    }

    fn edge_color(&self, face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
        let record = self.records.get(face as usize)?;
        let corners = self.store.topology().face_vertices.get(face as usize)?;
        self.at(face, sampler::record_edge_index(record, corners, k, level, p)?)
    }
}
