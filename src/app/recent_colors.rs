//! The recent colours: the last distinct colours that strokes painted with, newest first
//! (the paint panel's row, remembered in the settings file). Colours count as the same
//! when their sRGB8 codes are equal (the swatches look alike whatever the alpha): the
//! newest alpha is kept.

use meshpaint_core::colors::format::{Rgba, decode_rgba8_srgb, encode_rgba8_srgb};

/// How many recent colours are kept.
pub const MAX_RECENT_COLORS: usize = 8;

/// The recent colours, newest first, as sRGB8 codes with 8-bit alpha.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RecentColors {
    colors: Vec<[u8; 4]>,
}

impl RecentColors {
    /// The list of `colors` (newest first): duplicates after the first dropped, at most
    /// [`MAX_RECENT_COLORS`] kept.
    pub fn from_srgba8(colors: impl IntoIterator<Item = [u8; 4]>) -> Self {
        let mut recent = RecentColors::default();
        for color in colors {
            if !recent.colors.iter().any(|c| c[..3] == color[..3]) && recent.colors.len() < MAX_RECENT_COLORS {
                recent.colors.push(color);
            }
        }
        recent
    }

    /// Puts `color` (linear, straight alpha) first, removing an earlier equal entry and the
    /// oldest past [`MAX_RECENT_COLORS`].
    pub fn push(&mut self, color: Rgba) {
        let code = encode_rgba8_srgb(color);
        self.colors.retain(|c| c[..3] != code[..3]);
        self.colors.insert(0, code);
        self.colors.truncate(MAX_RECENT_COLORS);
    }

    /// The colours as sRGB8 codes with 8-bit alpha, newest first.
    pub fn srgba8(&self) -> &[[u8; 4]] {
        &self.colors
    }

    /// The colour at `index` (0: newest) in linear light.
    pub fn linear(&self, index: usize) -> Option<Rgba> {
        self.colors.get(index).map(|&c| decode_rgba8_srgb(c))
    }

    /// No colour was used yet.
    pub fn is_empty(&self) -> bool {
        self.colors.is_empty()
    }
}

/// `#rrggbb` of an sRGB8 code (alpha left out).
pub fn hex_of(code: [u8; 4]) -> String {
    format!("#{:02x}{:02x}{:02x}", code[0], code[1], code[2])
}
