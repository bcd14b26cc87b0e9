//! The layer stack: the layers bottom first, the active one, painting into it through the
//! one write path, and keeping a composite store up to date through dirty elements.

use crate::colors::store::ColorStore;
use crate::paint::undo::{StepSummary, StoreWriter};

use super::compose;
use super::history::{Entry, LayerHistory};
use super::layer::{Layer, LayerError, LayerId, PaintTarget};

/// The name of the layer a single-colour document becomes.
pub const BASE_LAYER_NAME: &str = "Base";

/// Layers, bottom first, with their undo record (docs/LAYERS.md).
#[derive(Debug, Clone)]
pub struct LayerStack {
    pub(super) layers: Vec<Layer>,
    pub(super) active: usize,
    pub(super) next_id: LayerId,
    pub(super) history: LayerHistory,
    /// The layer and store a paint step is open on.
    pub(super) painting: Option<(LayerId, PaintTarget)>,
    /// Whether the whole composite must be recomputed (a layer operation happened).
    pub(super) all_dirty: bool,
}

impl LayerStack {
    /// The stack of a single-colour document: one visible normal layer at opacity 1 without a
    /// mask holding `store` (a cheap clone: chunks are shared until written). Its composite
    /// is `store`, bit for bit.
    pub fn from_store(store: &ColorStore) -> Self {
        let mut content = store.clone();
        content.take_dirty();
        let layers = vec![Layer::named(0, BASE_LAYER_NAME.to_owned(), content)];
        LayerStack { layers, active: 0, next_id: 1, history: LayerHistory::default(), painting: None, all_dirty: true }
    }

    /// A stack of `layers` (bottom first, at least one, ids unique, every store at the same
    /// face resolutions) with `active` the active layer.
    pub fn from_layers(layers: Vec<Layer>, active: usize) -> Result<Self, LayerError> {
        let Some(first) = layers.first() else {
            return Err(LayerError::LastLayer);
        };
        if active >= layers.len() {
            return Err(LayerError::NoSuchLayer { index: active, count: layers.len() });
        }
        let resolutions = first.content().face_resolutions().to_vec();
        for (index, layer) in layers.iter().enumerate() {
            let stores = std::iter::once(layer.content()).chain(layer.mask());
            if stores.into_iter().any(|store| !compose::same_resolutions(store, &resolutions)) {
                return Err(LayerError::Resolutions(format!("layer {index} differs from layer 0")));
            }
        }
        let mut ids: Vec<LayerId> = layers.iter().map(Layer::id).collect();
        ids.sort_unstable();
        if ids.windows(2).any(|pair| pair[0] == pair[1]) {
            return Err(LayerError::Resolutions("two layers share an id".to_owned()));
        }
        let next_id = ids.last().map_or(0, |id| id.saturating_add(1));
        Ok(LayerStack { layers, active, next_id, history: LayerHistory::default(), painting: None, all_dirty: true })
    }

    /// The layers, bottom first.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// The active layer's index (what painting writes).
    pub fn active(&self) -> usize {
        self.active
    }

    /// Makes layer `index` the active one (not an undoable change).
    pub fn set_active(&mut self, index: usize) -> Result<(), LayerError> {
        self.check_index(index)?;
        if self.painting.is_some() {
            return Err(LayerError::Busy);
        }
        self.active = index;
        Ok(())
    }

    pub(super) fn check_index(&self, index: usize) -> Result<(), LayerError> {
        if index >= self.layers.len() {
            return Err(LayerError::NoSuchLayer { index, count: self.layers.len() });
        }
        Ok(())
    }

    /// Whether the stack is a single-colour document's: one visible normal layer at opacity
    /// 1 without a mask (its composite is the layer itself).
    pub fn is_single_layer(&self) -> bool {
        matches!(self.layers.as_slice(), [layer] if layer.visible && layer.opacity == 1.0
            && layer.blend == super::blend::BlendMode::Normal && layer.mask.is_none())
    }

    /// Opens a paint step labelled `label` on the active layer's `target` store.
    pub fn begin_paint(&mut self, target: PaintTarget, label: &str) -> Result<(), LayerError> {
        if self.painting.is_some() {
            return Err(LayerError::Busy);
        }
        let index = self.active;
        let layer = self.layers.get_mut(index).ok_or(LayerError::NoSuchLayer { index, count: 0 })?;
        let id = layer.id;
        let painted = layer.painted_mut(target).ok_or(LayerError::NoMask { index })?;
        painted.history.begin_step(&painted.store, label)?;
        self.painting = Some((id, target));
        Ok(())
    }

    /// The writer of the open paint step: the one write path
    /// ([`crate::paint::undo::StoreWriter`]) into the active layer's content or mask.
    pub fn writer(&mut self) -> Result<StoreWriter<'_>, LayerError> {
        let (id, target) = self.painting.ok_or(LayerError::NotPainting)?;
        let layer = self.layers.iter_mut().find(|layer| layer.id == id).ok_or(LayerError::NotPainting)?;
        let painted = layer.painted_mut(target).ok_or(LayerError::NotPainting)?;
        Ok(StoreWriter::new(&mut painted.store, &mut painted.history))
    }

    /// Closes the open paint step; a kept step becomes an undo entry (and drops the redo
    /// entries). `None` when no step was open.
    pub fn end_paint(&mut self) -> Option<StepSummary> {
        let (id, target) = self.painting.take()?;
        let layer = self.layers.iter_mut().find(|layer| layer.id == id)?;
        let summary = layer.painted_mut(target)?.history.end_step()?;
        if summary.kept {
            self.history.push(Entry::Paint { layer: id, target, label: summary.label.clone() });
        }
        Some(summary)
    }

    /// Brings `composite` (a store at the layers' face resolutions) up to date: after a
    /// layer operation every sample, else the samples of the elements painted or undone
    /// since the last call. Returns the samples written (bit-identical ones are not).
    pub fn sync(&mut self, composite: &mut ColorStore) -> u64 {
        let mut vertices = Vec::new();
        let mut edges = Vec::new();
        let mut faces = Vec::new();
        for layer in &mut self.layers {
            for store in layer.stores_mut() {
                let dirty = store.take_dirty();
                vertices.extend(dirty.vertices);
                edges.extend(dirty.edges);
                faces.extend(dirty.faces);
            }
        }
        if std::mem::take(&mut self.all_dirty) {
            return compose::composite_all(&self.layers, composite);
        }
        for list in [&mut vertices, &mut edges, &mut faces] {
            list.sort_unstable();
            list.dedup();
        }
        use crate::colors::store::StoreElement;
        let elements: Vec<StoreElement> =
            edges.into_iter().map(StoreElement::Edge).chain(faces.into_iter().map(StoreElement::Interior)).collect();
        compose::composite_vertices(&self.layers, composite, &vertices)
            + compose::composite_elements(&self.layers, composite, &elements)
    }

    /// Writes the whole composite into `target` (a store at the layers' face resolutions),
    /// whatever changed. Returns the samples written.
    pub fn composite_into(&self, target: &mut ColorStore) -> u64 {
        compose::composite_all(&self.layers, target)
    }

    /// Number of entries undo can walk back.
    pub fn undo_len(&self) -> usize {
        self.history.undo.len()
    }

    /// Number of entries redo can walk forward.
    pub fn redo_len(&self) -> usize {
        self.history.redo.len()
    }

    /// The label of the entry undo would undo.
    pub fn undo_label(&self) -> Option<&str> {
        self.history.undo.last().map(Entry::label)
    }

    /// The label of the entry redo would redo.
    pub fn redo_label(&self) -> Option<&str> {
        self.history.redo.last().map(Entry::label)
    }
}
