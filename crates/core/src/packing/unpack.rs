//! Packed buffers back to an editable store (level 0 of the canonical layout), and a
//! store's MIP chains in full `f32` for reference sampling.

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::Resolution;
use crate::colors::store::{ColorStore, SampleRef};
use crate::mesh::topology::Topology;
use crate::packing::linear::PackedMesh;
use crate::packing::packer::{PackError, PackLayout, pack};
use crate::packing::sampler::MeshColorSource;

/// Unpacks level 0 of a packed mesh into an editable store. The packed data must be in
/// the canonical layout [`pack`] writes (checked record by record).
pub fn unpack(packed: &PackedMesh) -> Result<ColorStore, PackError> {
    unpack_within(packed, &crate::colors::budget::Budget::from_environment())
}

/// [`unpack`] within `budget`: the store's samples are counted from the face records and
/// checked before the store is allocated.
pub fn unpack_within(packed: &PackedMesh, budget: &crate::colors::budget::Budget) -> Result<ColorStore, PackError> {
    let topology = Topology::build(packed.positions.len() as u32, &packed.indices)?;
    if packed.face_records.len() != topology.face_count() as usize {
        return Err(PackError::NotCanonical(format!(
            "{} face records for {} faces",
            packed.face_records.len(),
            topology.face_count()
        )));
    }
    let resolutions = packed
        .face_records
        .iter()
        .enumerate()
        .map(|(face, record)| {
            record.resolution().ok_or_else(|| PackError::NotCanonical(format!("face {face} has an invalid resolution")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let counts = crate::colors::budget::SampleCounts::of_resolutions(&topology, |face| {
        resolutions.get(face as usize).copied().unwrap_or(Resolution::ONE)
    });
    budget.check("the packed mesh", &counts, packed.format)?;
    let mut store = ColorStore::with_resolutions(topology, resolutions, [0.0; 4])
        .map_err(|error| PackError::NotCanonical(error.to_string()))?;
    let layout = PackLayout::of(&store)?;
    if layout.vertex_levels != packed.vertex_levels || layout.sample_count != packed.sample_count() {
        return Err(PackError::NotCanonical(format!(
            "expected {} vertex levels and {} samples, found {} and {}",
            layout.vertex_levels,
            layout.sample_count,
            packed.vertex_levels,
            packed.sample_count()
        )));
    }
    for (face, record) in packed.face_records.iter().enumerate() {
        let expected = layout.face_record(&store, face as u32);
        if *record != expected {
            return Err(PackError::NotCanonical(format!(
                "face {face} record {record:?} differs from the canonical {expected:?}"
            )));
        }
    }
    let read = |index: u64| packed.color(index).unwrap_or([0.0; 4]);
    let topology = store.topology().clone();
    for v in 0..topology.vertex_count {
        store.set(SampleRef::Vertex(v), read(u64::from(v) * u64::from(layout.vertex_levels)));
    }
    for edge in 0..topology.edge_count() {
        let count = store.edge_samples(edge).len() as u32;
        for offset in 0..count {
            let color = read(u64::from(layout.edge_base[edge as usize] + offset));
            store.set(SampleRef::Edge { edge, offset }, color);
        }
    }
    for face in 0..topology.face_count() {
        let count = store.interior_samples(face).len() as u32;
        for offset in 0..count {
            let color = read(u64::from(layout.interior_base[face as usize] + offset));
            store.set(SampleRef::Interior { face, offset }, color);
        }
    }
    store.take_dirty();
    Ok(store)
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

    fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution> {
        self.chains.edge_resolution(face, k)
    }

    fn edge_color(&self, face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
        self.chains.edge_color(face, k, level, p)
    }
}
