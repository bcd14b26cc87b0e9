//! Layer operations with undo: add, delete, reorder, opacity, blend mode, visibility,
//! rename, mask; and undo / redo of the stack's history (paint steps and operations in the
//! order they happened).

use crate::colors::budget::{Budget, BudgetError, STORE_BYTES_PER_SAMPLE, SampleCounts};
use crate::colors::format::ColorFormat;

use super::blend::BlendMode;
use super::compose::TRANSPARENT;
use super::history::{Entry, Op};
use super::layer::{LayerError, Painted, check_name, valid_opacity};
use super::stack::LayerStack;

/// Layer `index` of `layers`, to change.
fn layer_mut(layers: &mut [super::layer::Layer], index: usize) -> Result<&mut super::layer::Layer, LayerError> {
    let count = layers.len();
    layers.get_mut(index).ok_or(LayerError::NoSuchLayer { index, count })
}

/// What a new store is checked against: the budget and the document's colour format
/// (`None`: no check).
pub type StoreBudget<'a> = Option<(&'a Budget, ColorFormat)>;

impl LayerStack {
    /// Refuses one more store when the document (its composite's counts in `format`) plus
    /// every layer store and the new one, at 16 bytes a sample, exceed the memory budget.
    fn check_new_store(&self, budget: StoreBudget<'_>) -> Result<(), LayerError> {
        let (Some((budget, format)), Some(first)) = (budget, self.layers.first()) else {
            return Ok(());
        };
        let counts = SampleCounts::of_store(first.content());
        let stores = self.layers.iter().map(|layer| 1 + u64::from(layer.mask.is_some())).sum::<u64>() + 1;
        let needed = counts
            .estimated_bytes(format)
            .saturating_add(stores.saturating_mul(counts.samples).saturating_mul(STORE_BYTES_PER_SAMPLE));
        if needed > budget.memory_bytes {
            return Err(BudgetError::Memory {
                what: format!("layer store {}", stores + 1),
                needed,
                allowed: budget.memory_bytes,
                samples: counts.samples,
                samples_with_mips: counts.samples_with_mips,
                origin: budget.memory_source,
            }
            .into());
        }
        Ok(())
    }

    /// Applies `op` and returns the operation that reverses it. The active layer stays the
    /// same layer when it is still in the stack (else the one now at its place, or the top one).
    fn apply(&mut self, op: Op) -> Result<Op, LayerError> {
        let active_id = self.layers.get(self.active).map(|layer| layer.id);
        let inverse = self.apply_op(op)?;
        let fallback = self.active.min(self.layers.len().saturating_sub(1));
        self.active = self.layers.iter().position(|layer| Some(layer.id) == active_id).unwrap_or(fallback);
        Ok(inverse)
    }

    /// [`LayerStack::apply`] without the active layer's bookkeeping.
    fn apply_op(&mut self, op: Op) -> Result<Op, LayerError> {
        if op.changes_composite() {
            self.all_dirty = true;
        }
        let count = self.layers.len();
        Ok(match op {
            Op::Insert { index, layer } => {
                if index > count {
                    return Err(LayerError::NoSuchLayer { index, count });
                }
                self.layers.insert(index, *layer);
                Op::Remove { index }
            }
            Op::Remove { index } => {
                self.check_index(index)?;
                if count == 1 {
                    return Err(LayerError::LastLayer);
                }
                let removed = self.layers.remove(index);
                Op::Insert { index, layer: Box::new(removed) }
            }
            Op::Move { from, to } => {
                self.check_index(from)?;
                self.check_index(to)?;
                let moved = self.layers.remove(from);
                self.layers.insert(to, moved);
                Op::Move { from: to, to: from }
            }
            Op::Opacity { index, opacity } => {
                let old = std::mem::replace(&mut layer_mut(&mut self.layers, index)?.opacity, valid_opacity(opacity));
                Op::Opacity { index, opacity: old }
            }
            Op::Blend { index, blend } => {
                Op::Blend { index, blend: std::mem::replace(&mut layer_mut(&mut self.layers, index)?.blend, blend) }
            }
            Op::Visible { index, visible } => Op::Visible {
                index,
                visible: std::mem::replace(&mut layer_mut(&mut self.layers, index)?.visible, visible),
            },
            Op::Rename { index, name } => {
                check_name(&name)?;
                Op::Rename { index, name: std::mem::replace(&mut layer_mut(&mut self.layers, index)?.name, name) }
            }
            Op::Mask { index, mask } => {
                let old = std::mem::replace(&mut layer_mut(&mut self.layers, index)?.mask, mask.map(|mask| *mask));
                Op::Mask { index, mask: old.map(Box::new) }
            }
        })
    }

    /// Applies `op` as a new undo entry labelled `label`.
    fn perform(&mut self, label: &str, op: Op) -> Result<(), LayerError> {
        if self.painting.is_some() {
            return Err(LayerError::Busy);
        }
        let inverse = self.apply(op)?;
        self.history.push(Entry::Op { label: label.to_owned(), op: inverse });
        Ok(())
    }

    /// Adds a transparent layer named `name` above the active one and makes it active
    /// (checked against `budget` first). Returns its index.
    pub fn add_layer(&mut self, name: &str, budget: StoreBudget<'_>) -> Result<usize, LayerError> {
        check_name(name)?;
        self.check_new_store(budget)?;
        let like = self.layers.first().ok_or(LayerError::LastLayer)?.content();
        let content = Painted::filled_like(like, TRANSPARENT).store;
        let layer = super::layer::Layer::named(self.next_id, name.to_owned(), content);
        let index = (self.active + 1).min(self.layers.len());
        self.perform("add layer", Op::Insert { index, layer: Box::new(layer) })?;
        self.next_id += 1;
        self.active = index;
        Ok(index)
    }

    /// Deletes layer `index` (not the last one).
    pub fn delete_layer(&mut self, index: usize) -> Result<(), LayerError> {
        self.perform("delete layer", Op::Remove { index })
    }

    /// Moves layer `from` to position `to` (bottom first).
    pub fn move_layer(&mut self, from: usize, to: usize) -> Result<(), LayerError> {
        if from == to {
            return self.check_index(from);
        }
        self.perform("reorder layers", Op::Move { from, to })
    }

    /// Sets layer `index`'s opacity (clamped to `[0, 1]`, NaN as 0).
    pub fn set_opacity(&mut self, index: usize, opacity: f32) -> Result<(), LayerError> {
        self.check_index(index)?;
        if self.layers[index].opacity.to_bits() == valid_opacity(opacity).to_bits() {
            return Ok(());
        }
        self.perform("layer opacity", Op::Opacity { index, opacity })
    }

    /// Sets layer `index`'s blend mode.
    pub fn set_blend(&mut self, index: usize, blend: BlendMode) -> Result<(), LayerError> {
        self.check_index(index)?;
        if self.layers[index].blend == blend {
            return Ok(());
        }
        self.perform("layer blend mode", Op::Blend { index, blend })
    }

    /// Shows or hides layer `index`.
    pub fn set_visible(&mut self, index: usize, visible: bool) -> Result<(), LayerError> {
        self.check_index(index)?;
        if self.layers[index].visible == visible {
            return Ok(());
        }
        self.perform(if visible { "show layer" } else { "hide layer" }, Op::Visible { index, visible })
    }

    /// Renames layer `index`.
    pub fn rename(&mut self, index: usize, name: &str) -> Result<(), LayerError> {
        self.check_index(index)?;
        if self.layers[index].name == name {
            return Ok(());
        }
        self.perform("rename layer", Op::Rename { index, name: name.to_owned() })
    }

    /// Gives layer `index` a mask of value `value` everywhere (1: the layer shows fully),
    /// checked against `budget` first; replaces a mask it has.
    pub fn add_mask(&mut self, index: usize, value: f32, budget: StoreBudget<'_>) -> Result<(), LayerError> {
        self.check_index(index)?;
        self.check_new_store(budget)?;
        let mask = Painted::filled_like(self.layers[index].content(), [value, value, value, 1.0]);
        self.perform("add mask", Op::Mask { index, mask: Some(Box::new(mask)) })
    }

    /// Removes layer `index`'s mask (no-op without one).
    pub fn remove_mask(&mut self, index: usize) -> Result<(), LayerError> {
        self.check_index(index)?;
        if self.layers[index].mask.is_none() {
            return Ok(());
        }
        self.perform("remove mask", Op::Mask { index, mask: None })
    }

    /// Undoes the newest entry. Returns `false` when there is nothing to undo.
    pub fn undo(&mut self) -> Result<bool, LayerError> {
        self.step(true)
    }

    /// Redoes the entry undone last. Returns `false` when there is nothing to redo.
    pub fn redo(&mut self) -> Result<bool, LayerError> {
        self.step(false)
    }

    /// Walks one entry back (`undo`) or forward, moving it to the other list.
    fn step(&mut self, undo: bool) -> Result<bool, LayerError> {
        if self.painting.is_some() {
            return Err(LayerError::Busy);
        }
        let popped = if undo { self.history.undo.pop() } else { self.history.redo.pop() };
        let Some(entry) = popped else {
            return Ok(false);
        };
        let result = match entry {
            Entry::Paint { layer, target, label } => {
                let painted = self.layers.iter_mut().find(|l| l.id == layer).and_then(|l| l.painted_mut(target));
                let done = match painted {
                    Some(p) if undo => p.history.undo(&mut p.store),
                    Some(p) => p.history.redo(&mut p.store),
                    None => Ok(false),
                };
                done.map(|_| Entry::Paint { layer, target, label }).map_err(LayerError::from)
            }
            Entry::Op { label, op } => self.apply(op).map(|inverse| Entry::Op { label, op: inverse }),
        };
        let reversed = result?;
        if undo {
            self.history.redo.push(reversed)
        } else {
            self.history.undo.push(reversed)
        }
        Ok(true)
    }
}
