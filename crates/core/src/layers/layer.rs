//! One layer of the stack: its properties, its content store and its optional mask, each
//! store with its own undo history (docs/LAYERS.md, "Layers").

use thiserror::Error;

use crate::colors::budget::BudgetError;
use crate::colors::format::Rgba;
use crate::colors::store::ColorStore;
use crate::paint::undo::{UndoError, UndoHistory};

use super::blend::BlendMode;

/// The longest layer name, in bytes of UTF-8.
pub const MAX_NAME_BYTES: usize = 256;

/// A layer's id: stable across reorders, never reused within a stack.
pub type LayerId = u64;

/// Errors of layer operations.
#[derive(Debug, Error)]
pub enum LayerError {
    /// A layer index past the stack.
    #[error("layer {index} does not exist (the stack has {count} layers)")]
    NoSuchLayer {
        /// The index asked for.
        index: usize,
        /// Layers in the stack.
        count: usize,
    },
    /// Deleting the only layer.
    #[error("the last layer cannot be deleted")]
    LastLayer,
    /// A layer operation, undo or redo while a paint step is open.
    #[error("a paint step is open (end the stroke first)")]
    Busy,
    /// No paint step is open, or the one open is on a layer that no longer exists.
    #[error("no paint step is open")]
    NotPainting,
    /// The layer has no mask to paint.
    #[error("layer {index} has no mask")]
    NoMask {
        /// The layer.
        index: usize,
    },
    /// A name longer than [`MAX_NAME_BYTES`].
    #[error("a layer name has at most {MAX_NAME_BYTES} bytes, this one has {0}")]
    NameTooLong(usize),
    /// A store whose per-face resolutions differ from the stack's.
    #[error("layer stores must share the channel's face resolutions ({0})")]
    Resolutions(String),
    /// A saved layers section does not fit the document.
    #[error("saved layers: {0}")]
    Section(String),
    /// A layer store's undo failed.
    #[error(transparent)]
    Undo(#[from] UndoError),
    /// Another store would take the document past the budget.
    #[error(transparent)]
    Budget(#[from] BudgetError),
}

/// A store painted through its own undo history ([`crate::paint::undo::StoreWriter`]).
#[derive(Debug, Clone)]
pub struct Painted {
    pub(super) store: ColorStore,
    pub(super) history: UndoHistory,
}

impl Painted {
    /// `store` with an empty history.
    pub fn new(store: ColorStore) -> Self {
        Painted { store, history: UndoHistory::default() }
    }

    /// A store like `like` (same topology and resolutions, sharing its topology) with every
    /// sample `color`.
    pub(super) fn filled_like(like: &ColorStore, color: Rgba) -> Self {
        let mut store = like.clone();
        store.fill_with(|_| color);
        store.take_dirty();
        Painted::new(store)
    }

    /// The store.
    pub fn store(&self) -> &ColorStore {
        &self.store
    }
}

/// What a paint step writes: a layer's content or its mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PaintTarget {
    /// The layer's colours (alpha is the coverage).
    Content,
    /// The layer's mask (R is the mask value).
    Mask,
}

/// One layer (docs/LAYERS.md, "Layers").
#[derive(Debug, Clone)]
pub struct Layer {
    pub(super) id: LayerId,
    pub(super) name: String,
    pub(super) visible: bool,
    pub(super) opacity: f32,
    pub(super) blend: BlendMode,
    pub(super) content: Painted,
    pub(super) mask: Option<Painted>,
}

impl Layer {
    /// A visible normal layer at opacity 1 without a mask holding `content`.
    pub fn new(id: LayerId, name: &str, content: ColorStore) -> Result<Self, LayerError> {
        check_name(name)?;
        Ok(Self::named(id, name.to_owned(), content))
    }

    /// [`Layer::new`] for a name already checked.
    pub(super) fn named(id: LayerId, name: String, content: ColorStore) -> Self {
        Layer {
            id,
            name,
            visible: true,
            opacity: 1.0,
            blend: BlendMode::Normal,
            content: Painted::new(content),
            mask: None,
        }
    }

    /// The layer's stable id.
    pub fn id(&self) -> LayerId {
        self.id
    }

    /// Its name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether it is composited.
    pub fn visible(&self) -> bool {
        self.visible
    }

    /// Its opacity in `[0, 1]`.
    pub fn opacity(&self) -> f32 {
        self.opacity
    }

    /// Its blend mode.
    pub fn blend(&self) -> BlendMode {
        self.blend
    }

    /// Its colours (base-colour channel; alpha is the coverage).
    pub fn content(&self) -> &ColorStore {
        &self.content.store
    }

    /// Its mask (R is the mask value), if it has one.
    pub fn mask(&self) -> Option<&ColorStore> {
        self.mask.as_ref().map(Painted::store)
    }

    /// The painted store of `target` (`None`: a mask the layer does not have).
    pub(super) fn painted_mut(&mut self, target: PaintTarget) -> Option<&mut Painted> {
        match target {
            PaintTarget::Content => Some(&mut self.content),
            PaintTarget::Mask => self.mask.as_mut(),
        }
    }

    /// The stores this layer holds (content, then the mask if any).
    pub(super) fn stores_mut(&mut self) -> impl Iterator<Item = &mut ColorStore> {
        std::iter::once(&mut self.content.store).chain(self.mask.as_mut().map(|mask| &mut mask.store))
    }
}

/// Refuses a name longer than [`MAX_NAME_BYTES`].
pub(super) fn check_name(name: &str) -> Result<(), LayerError> {
    if name.len() > MAX_NAME_BYTES {
        return Err(LayerError::NameTooLong(name.len()));
    }
    Ok(())
}

/// `opacity` made valid: clamped to `[0, 1]`, NaN becomes 0.
pub(super) fn valid_opacity(opacity: f32) -> f32 {
    if opacity.is_nan() { 0.0 } else { opacity.clamp(0.0, 1.0) }
}
