//! A layer stack ⇄ the packed file's layers section ([`crate::packing::file::layers`]):
//! every store's level-0 samples in store order (vertices, edges in id order, face
//! interiors in face order), encoded in the file's colour format.

use crate::colors::budget::{Budget, BudgetError, STORE_BYTES_PER_SAMPLE, SampleCounts};
use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::store::{ColorStore, StoreElement};
use crate::packing::file::{LayerRecord, LayersSection};

use super::blend::BlendMode;
use super::layer::{Layer, LayerError, check_name, valid_opacity};
use super::stack::LayerStack;

/// The samples of `store` in store order, encoded in `format`.
fn encode_store(store: &ColorStore, format: ColorFormat) -> Vec<u8> {
    let samples = usize::try_from(store.sample_count()).unwrap_or(0);
    let mut out = Vec::with_capacity(samples * format.bytes_per_sample());
    let topology = store.topology();
    for v in 0..topology.vertex_count {
        format.encode_into(store.vertex_color(v).unwrap_or_default(), &mut out);
    }
    for edge in 0..topology.edge_count() {
        store.edge_samples(edge).iter().for_each(|&color| format.encode_into(color, &mut out));
    }
    for face in 0..topology.face_count() {
        store.interior_samples(face).iter().for_each(|&color| format.encode_into(color, &mut out));
    }
    out
}

/// A store like `like` (its topology and resolutions) holding `bytes` (store order, in
/// `format`; the caller checked the length).
fn decode_store(like: &ColorStore, bytes: &[u8], format: ColorFormat) -> ColorStore {
    let size = format.bytes_per_sample();
    let mut samples = bytes.chunks_exact(size).map(|chunk| format.decode(chunk));
    let mut store = like.clone();
    let topology = like.topology();
    let elements: Vec<(StoreElement, u32)> = std::iter::once((StoreElement::Vertices, topology.vertex_count))
        .chain((0..topology.edge_count()).map(|e| (StoreElement::Edge(e), like.edge_samples(e).len() as u32)))
        .chain((0..topology.face_count()).map(|f| (StoreElement::Interior(f), like.interior_samples(f).len() as u32)))
        .collect();
    for (element, len) in elements {
        let run: Vec<Rgba> = samples.by_ref().take(len as usize).collect();
        store.update_run(element, 0, len, |index, _| run.get(index as usize).copied());
    }
    store.take_dirty();
    store
}

/// The layers section of `stack` in `format`.
pub fn to_section(stack: &LayerStack, format: ColorFormat) -> LayersSection {
    let samples_per_store = stack.layers().first().map_or(0, |layer| layer.content().sample_count());
    LayersSection {
        active: stack.active() as u32,
        samples_per_store,
        layers: stack
            .layers()
            .iter()
            .map(|layer| LayerRecord {
                name: layer.name().to_owned(),
                visible: layer.visible(),
                opacity: layer.opacity(),
                blend: layer.blend().code(),
                content: encode_store(layer.content(), format),
                mask: layer.mask().map(|mask| encode_store(mask, format)),
            })
            .collect(),
    }
}

/// The stack a layers section holds, over `composite` (the document's store, whose
/// topology and face resolutions every layer shares), checked against `budget` before any
/// layer store is allocated.
pub fn from_section(
    section: &LayersSection,
    composite: &ColorStore,
    format: ColorFormat,
    budget: &Budget,
) -> Result<LayerStack, LayerError> {
    if section.samples_per_store != composite.sample_count() {
        return Err(LayerError::Section(format!(
            "{} samples per layer, the document has {}",
            section.samples_per_store,
            composite.sample_count()
        )));
    }
    let stores = section.layers.iter().map(|layer| 1 + u64::from(layer.mask.is_some())).sum::<u64>();
    let counts = SampleCounts::of_store(composite);
    let needed = counts
        .estimated_bytes(format)
        .saturating_add(stores.saturating_mul(counts.samples).saturating_mul(STORE_BYTES_PER_SAMPLE));
    if needed > budget.memory_bytes {
        return Err(BudgetError::Memory {
            what: format!("{} layers", section.layers.len()),
            needed,
            allowed: budget.memory_bytes,
            samples: counts.samples,
            samples_with_mips: counts.samples_with_mips,
            origin: budget.memory_source,
        }
        .into());
    }
    let mut layers = Vec::with_capacity(section.layers.len());
    for (id, record) in (0u64..).zip(&section.layers) {
        check_name(&record.name)?;
        let blend = BlendMode::from_code(record.blend)
            .ok_or_else(|| LayerError::Section(format!("layer {id}: unknown blend mode {}", record.blend)))?;
        let mut layer = Layer::named(id, record.name.clone(), decode_store(composite, &record.content, format));
        layer.visible = record.visible;
        layer.opacity = valid_opacity(record.opacity);
        layer.blend = blend;
        layer.mask = record.mask.as_ref().map(|mask| super::layer::Painted::new(decode_store(composite, mask, format)));
        layers.push(layer);
    }
    LayerStack::from_layers(layers, section.active as usize)
}
