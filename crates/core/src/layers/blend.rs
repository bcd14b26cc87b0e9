//! Blend modes and the compositing of one sample over a backdrop (docs/LAYERS.md,
//! "Compositing": W3C Compositing and Blending Level 1, straight alpha).

use crate::colors::format::{Rgba, clamp_color};

/// How a layer's colour combines with the layers below it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BlendMode {
    /// The layer's colour.
    #[default]
    Normal,
    /// Backdrop × layer.
    Multiply,
    /// Backdrop + layer.
    Add,
    /// Multiply where the backdrop is dark, screen where it is light.
    Overlay,
}

impl BlendMode {
    /// Every mode, in file-code order.
    pub const ALL: [BlendMode; 4] = [BlendMode::Normal, BlendMode::Multiply, BlendMode::Add, BlendMode::Overlay];

    /// The code stored in packed files (docs/FORMAT.md, "Layers section").
    pub fn code(self) -> u32 {
        match self {
            BlendMode::Normal => 0,
            BlendMode::Multiply => 1,
            BlendMode::Add => 2,
            BlendMode::Overlay => 3,
        }
    }

    /// The mode of a file code.
    pub fn from_code(code: u32) -> Option<Self> {
        Self::ALL.get(code as usize).copied()
    }

    /// The name shown in the editor.
    pub fn name(self) -> &'static str {
        match self {
            BlendMode::Normal => "normal",
            BlendMode::Multiply => "multiply",
            BlendMode::Add => "add",
            BlendMode::Overlay => "overlay",
        }
    }

    /// `B(backdrop, source)` for one colour component.
    #[inline(always)]
    fn mix(self, backdrop: f32, source: f32) -> f32 {
        match self {
            BlendMode::Normal => source,
            BlendMode::Multiply => backdrop * source,
            BlendMode::Add => backdrop + source,
            BlendMode::Overlay if backdrop <= 0.5 => 2.0 * backdrop * source,
            BlendMode::Overlay => 1.0 - 2.0 * (1.0 - backdrop) * (1.0 - source),
        }
    }
}

/// `source` (straight alpha) with coverage `source[3] · weight` (`weight` = the layer's
/// opacity × its mask value) composited over `backdrop` in `mode`, clamped by the store's
/// value rule. Over a transparent backdrop the result is `(source RGB, coverage)` bit for bit
/// (also for a zero coverage: a transparent result keeps the upper colour); otherwise a zero
/// coverage leaves the backdrop bit for bit (both identities of the formula).
#[inline]
pub fn composite_over(backdrop: Rgba, source: Rgba, weight: f32, mode: BlendMode) -> Rgba {
    let alpha_s = source[3] * weight;
    let alpha_b = backdrop[3];
    if alpha_b <= 0.0 {
        // Also when `alpha_s` is 0: a fully transparent result keeps the upper colour, so a
        // single layer keeps the colours of its transparent samples.
        return clamp_color([source[0], source[1], source[2], alpha_s]);
    }
    if alpha_s <= 0.0 || alpha_s.is_nan() {
        return backdrop;
    }
    let alpha_o = alpha_s + alpha_b * (1.0 - alpha_s);
    let mut out = [0.0, 0.0, 0.0, alpha_o];
    for c in 0..3 {
        let (cb, cs) = (backdrop[c], source[c]);
        let cs_blended = (1.0 - alpha_b) * cs + alpha_b * mode.mix(cb, cs);
        out[c] = (alpha_s * cs_blended + (1.0 - alpha_s) * alpha_b * cb) / alpha_o;
    }
    clamp_color(out)
}
