//! Material layers (docs/LAYERS.md): a stack of layers, bottom first, each with a name,
//! visibility, opacity, blend mode ([`blend`]), content and an optional paintable mask
//! ([`layer`]); the composite that renders, packs and exports, computed sample by sample and
//! kept up to date through dirty elements ([`compose`], [`stack`]); layer operations and
//! their undo in one history with the paint steps ([`ops`], `history`); the stack in the
//! packed file's layers section ([`file`]).
//!
//! Layers are *material layers spanning channels* (as Substance's fill and paint layers):
//! one mask, visibility and place in the stack for everything a material changes. Every
//! layer store shares its channel's face resolutions, so compositing is exact, sample by
//! sample. Today the base-colour channel is built; the other channels (roughness, metallic,
//! occlusion, height) join each layer as further stores of the same kind.

pub mod blend;
pub mod compose;
pub mod file;
mod history;
pub mod layer;
pub mod ops;
pub mod stack;

pub use blend::BlendMode;
pub use layer::{Layer, LayerError, LayerId, PaintTarget};
pub use stack::LayerStack;
