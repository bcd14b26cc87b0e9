//! The stack's undo record: one ordered history of paint steps (each kept by the painted
//! store's own [`crate::paint::undo::UndoHistory`]) and layer operations (each kept as the
//! operation that reverses it), so undo and redo walk both in the order they happened.

use super::blend::BlendMode;
use super::layer::{Layer, LayerId, PaintTarget, Painted};

/// A change to the stack's structure or a layer's properties. Applying one returns the
/// operation that reverses it.
#[derive(Debug, Clone)]
pub(super) enum Op {
    /// Insert `layer` at `index` (the reverse of a delete; the layer keeps its stores and
    /// their histories).
    Insert { index: usize, layer: Box<Layer> },
    /// Remove the layer at `index`.
    Remove { index: usize },
    /// Move the layer at `from` to `to`.
    Move { from: usize, to: usize },
    /// Set a layer's opacity.
    Opacity { index: usize, opacity: f32 },
    /// Set a layer's blend mode.
    Blend { index: usize, blend: BlendMode },
    /// Show or hide a layer.
    Visible { index: usize, visible: bool },
    /// Rename a layer.
    Rename { index: usize, name: String },
    /// Give a layer this mask (or none).
    Mask { index: usize, mask: Option<Box<Painted>> },
}

impl Op {
    /// Whether applying it changes the composite.
    pub(super) fn changes_composite(&self) -> bool {
        !matches!(self, Op::Rename { .. })
    }
}

/// One undoable entry.
#[derive(Debug, Clone)]
pub(super) enum Entry {
    /// A paint step kept by the history of layer `layer`'s `target` store.
    Paint { layer: LayerId, target: PaintTarget, label: String },
    /// A layer operation: `op` reverses it.
    Op { label: String, op: Op },
}

impl Entry {
    pub(super) fn label(&self) -> &str {
        match self {
            Entry::Paint { label, .. } | Entry::Op { label, .. } => label,
        }
    }
}

/// The undo and redo entries of a stack.
#[derive(Debug, Clone, Default)]
pub(super) struct LayerHistory {
    pub(super) undo: Vec<Entry>,
    pub(super) redo: Vec<Entry>,
}

impl LayerHistory {
    /// Records a new entry: the redo entries are dropped.
    pub(super) fn push(&mut self, entry: Entry) {
        self.redo.clear();
        self.undo.push(entry);
    }
}
