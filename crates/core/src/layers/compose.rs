//! The composite of a layer stack, sample by sample and face by face (docs/LAYERS.md,
//! "Compositing"): what renders, packs and exports.

use crate::colors::format::Rgba;
use crate::colors::layout;
use crate::colors::store::{ColorStore, SampleRef, StoreElement};

use super::blend::composite_over;
use super::layer::Layer;

/// A transparent black sample: the composite where no visible layer covers.
pub const TRANSPARENT: Rgba = [0.0, 0.0, 0.0, 0.0];

/// The composite of `layers` (bottom first) at `sample`: every visible layer over the ones
/// below, its coverage scaled by its opacity and mask value (the mask's R, clamped to
/// `[0, 1]`).
#[inline]
pub fn composite_sample(layers: &[Layer], sample: SampleRef) -> Rgba {
    let mut out = TRANSPARENT;
    for layer in layers.iter().filter(|layer| layer.visible) {
        let Some(source) = layer.content.store.get(sample) else {
            continue;
        };
        let mask = layer.mask.as_ref().map_or(1.0, |mask| mask.store.get(sample).map_or(0.0, |m| m[0].clamp(0.0, 1.0)));
        out = composite_over(out, source, layer.opacity * mask, layer.blend);
    }
    out
}

/// Writes the composite of `layers` into `target` for every sample of `elements` (each
/// element's samples at the target's resolution, which every layer shares). A sample whose
/// composite is bit-identical to the stored one is not written (nor marked dirty). Returns
/// the samples written.
pub fn composite_elements(layers: &[Layer], target: &mut ColorStore, elements: &[StoreElement]) -> u64 {
    let mut written = 0;
    for &element in elements {
        let (first, len) = match element {
            StoreElement::Vertices => (0, target.topology().vertex_count),
            StoreElement::Edge(edge) => (0, target.edge_samples(edge).len() as u32),
            StoreElement::Interior(face) => (0, target.interior_samples(face).len() as u32),
        };
        written += target.update_run(element, first, len, |index, old| {
            let new = composite_sample(layers, element.sample(index));
            differs(new, old).then_some(new)
        });
    }
    written
}

/// Writes the composite of `layers` into `target` for the vertices `vertices`. Returns the
/// samples written.
pub fn composite_vertices(layers: &[Layer], target: &mut ColorStore, vertices: &[u32]) -> u64 {
    let mut written = 0;
    for &v in vertices {
        written += target.update_run(StoreElement::Vertices, v, 1, |index, old| {
            let new = composite_sample(layers, SampleRef::Vertex(index));
            differs(new, old).then_some(new)
        });
    }
    written
}

/// Writes the composite of `layers` into `target` for the samples of `faces` (their
/// vertices, edges and interiors; shared elements once). Returns the samples written.
pub fn composite_faces(layers: &[Layer], target: &mut ColorStore, faces: &[u32]) -> u64 {
    let topology = target.topology();
    let mut edges: Vec<u32> = Vec::with_capacity(faces.len() * 3);
    let mut vertices: Vec<u32> = Vec::with_capacity(faces.len() * 3);
    for &face in faces {
        if let (Some(e), Some(v)) = (topology.face_edges.get(face as usize), topology.face_vertices.get(face as usize))
        {
            edges.extend_from_slice(e);
            vertices.extend_from_slice(v);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    vertices.sort_unstable();
    vertices.dedup();
    let written = composite_vertices(layers, target, &vertices);
    let elements: Vec<StoreElement> = edges
        .into_iter()
        .map(StoreElement::Edge)
        .chain(faces.iter().copied().filter(|&f| f < target.topology().face_count()).map(StoreElement::Interior))
        .collect();
    written + composite_elements(layers, target, &elements)
}

/// Writes the composite of `layers` into every sample of `target`. Returns the samples
/// written.
pub fn composite_all(layers: &[Layer], target: &mut ColorStore) -> u64 {
    let topology = target.topology();
    let elements: Vec<StoreElement> = std::iter::once(StoreElement::Vertices)
        .chain((0..topology.edge_count()).map(StoreElement::Edge))
        .chain((0..topology.face_count()).map(StoreElement::Interior))
        .collect();
    composite_elements(layers, target, &elements)
}

/// Whether two colours differ in any bit.
#[inline(always)]
fn differs(a: Rgba, b: Rgba) -> bool {
    a.map(f32::to_bits) != b.map(f32::to_bits)
}

/// Whether `store` has exactly the face resolutions `resolutions`.
pub(super) fn same_resolutions(store: &ColorStore, resolutions: &[layout::Resolution]) -> bool {
    store.face_resolutions() == resolutions
}
