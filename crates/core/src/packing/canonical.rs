//! The canonical layout of the colour buffer: where every element's chain starts
//! (vertices, then edges in id order, then face interiors in id order) and each face's
//! 16-byte record; and the errors of packing. The packer writes this layout, the unpacker
//! checks a packed mesh against it.

use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;
use crate::packing::linear::{FaceRecord, MAX_SAMPLES, pack_word};
use thiserror::Error;

use crate::mesh::topology::TopologyError;

/// Errors of packing and unpacking.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PackError {
    /// The colour buffer would exceed the 28-bit sample addressing of face records.
    #[error("{samples} samples exceed the packed limit of {MAX_SAMPLES} (lower some face resolutions)")]
    TooManySamples {
        /// Samples the layout needs.
        samples: u64,
    },
    /// Positions and topology disagree.
    #[error("{positions} positions for a mesh with {vertices} vertices")]
    PositionCount {
        /// Positions given.
        positions: usize,
        /// Vertices in the topology.
        vertices: u32,
    },
    /// The packed mesh's triangles do not form a valid topology.
    #[error("packed mesh: {0}")]
    Topology(#[from] TopologyError),
    /// The store the packed data describes is past the budget (checked before unpacking).
    #[error(transparent)]
    Budget(#[from] crate::colors::budget::BudgetError),
    /// The packed data is not in the canonical layout this packer writes.
    #[error("packed mesh is not in the canonical layout: {0}")]
    NotCanonical(String),
}

/// Where every element's chain starts in the colour buffer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PackLayout {
    /// Colours per vertex (levels), `1 + log2(max R_f)`.
    pub vertex_levels: u32,
    /// First sample of each edge's chain (0 for edges without samples).
    pub edge_base: Vec<u32>,
    /// First sample of each face's interior chain (0 for faces without interior samples).
    pub interior_base: Vec<u32>,
    /// Total samples.
    pub sample_count: u64,
}

impl PackLayout {
    /// The canonical layout for the store's resolutions.
    pub fn of(store: &ColorStore) -> Result<Self, PackError> {
        let topology = store.topology();
        let max_log2 = store.face_resolutions().iter().map(|r| r.log2()).max().unwrap_or(0);
        let vertex_levels = max_log2 + 1;
        let mut next = u64::from(topology.vertex_count) * u64::from(vertex_levels);
        let mut place = |len: u32| -> u32 {
            if len == 0 {
                return 0;
            }
            let base = next;
            next += u64::from(len);
            // Bases past the limit are caught below, before anyone uses them.
            base.min(u64::from(u32::MAX)) as u32
        };
        let edge_base: Vec<u32> = (0..topology.edge_count())
            .map(|e| place(store.edge_resolution(e).map_or(0, layout::edge_chain_len)))
            .collect();
        let interior_base: Vec<u32> =
            store.face_resolutions().iter().map(|&r| place(layout::interior_chain_len(r))).collect();
        if next > MAX_SAMPLES {
            return Err(PackError::TooManySamples { samples: next });
        }
        Ok(PackLayout { vertex_levels, edge_base, interior_base, sample_count: next })
    }

    /// The 16-byte record of `face`.
    pub fn face_record(&self, store: &ColorStore, face: u32) -> FaceRecord {
        let topology = store.topology();
        let r = store.face_resolution(face).unwrap_or(Resolution::ONE);
        let edges = topology.face_edges[face as usize].map(|edge| {
            let r_edge = store.edge_resolution(edge).unwrap_or(Resolution::ONE);
            pack_word(self.edge_base[edge as usize], r_edge.log2())
        });
        FaceRecord { interior: pack_word(self.interior_base[face as usize], r.log2()), edges }
    }
}
