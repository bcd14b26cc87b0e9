//! Colours: linear-light RGBA in the store, and the three packed colour formats.
//!
//! The store keeps every sample as linear-light RGBA `f32`. Packing encodes samples in
//! one of three formats, the precision trade we measure:
//!
//! | format | bytes | encoding |
//! |---|---|---|
//! | `Rgba8Srgb` (default) | 4 | RGB sRGB-encoded, A linear, 8-bit unorm each |
//! | `Rgba16F` | 8 | IEEE binary16 per channel, linear |
//! | `Rgba32F` | 16 | IEEE binary32 per channel, linear (bit-exact) |

use half::f16;

/// A linear-light RGBA colour, straight (not premultiplied) alpha.
pub type Rgba = [f32; 4];

/// Opaque black.
pub const BLACK: Rgba = [0.0, 0.0, 0.0, 1.0];

/// How packed colour samples are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ColorFormat {
    /// 8-bit unorm, RGB sRGB-encoded, alpha linear. 4 bytes per sample.
    #[default]
    Rgba8Srgb,
    /// binary16 floats, linear. 8 bytes per sample.
    Rgba16F,
    /// binary32 floats, linear. 16 bytes per sample.
    Rgba32F,
}

impl ColorFormat {
    /// Every format, in file-code order.
    pub const ALL: [ColorFormat; 3] = [ColorFormat::Rgba8Srgb, ColorFormat::Rgba16F, ColorFormat::Rgba32F];

    /// Bytes one sample takes.
    pub fn bytes_per_sample(self) -> usize {
        match self {
            ColorFormat::Rgba8Srgb => 4,
            ColorFormat::Rgba16F => 8,
            ColorFormat::Rgba32F => 16,
        }
    }

    /// The code stored in packed files (see docs/FORMAT.md) and passed to shaders.
    pub fn code(self) -> u32 {
        match self {
            ColorFormat::Rgba8Srgb => 0,
            ColorFormat::Rgba16F => 1,
            ColorFormat::Rgba32F => 2,
        }
    }

    /// The format of a file code, if known.
    pub fn from_code(code: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|format| format.code() == code)
    }

    /// The command-line name (`rgba8`, `rgba16f`, `rgba32f`).
    pub fn name(self) -> &'static str {
        match self {
            ColorFormat::Rgba8Srgb => "rgba8",
            ColorFormat::Rgba16F => "rgba16f",
            ColorFormat::Rgba32F => "rgba32f",
        }
    }

    /// Parses a command-line name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|format| format.name() == name)
    }

    /// Appends the encoding of `color` to `out`.
    pub fn encode_into(self, color: Rgba, out: &mut Vec<u8>) {
        match self {
            ColorFormat::Rgba8Srgb => out.extend_from_slice(&encode_rgba8_srgb(color)),
            ColorFormat::Rgba16F => {
                for channel in color {
                    out.extend_from_slice(&f16::from_f32(channel).to_bits().to_le_bytes());
                }
            }
            ColorFormat::Rgba32F => {
                for channel in color {
                    out.extend_from_slice(&channel.to_le_bytes());
                }
            }
        }
    }

    /// Decodes one sample from `bytes` (exactly `bytes_per_sample` long; shorter input
    /// decodes missing bytes as zero).
    pub fn decode(self, bytes: &[u8]) -> Rgba {
        let byte = |k: usize| bytes.get(k).copied().unwrap_or(0);
        match self {
            ColorFormat::Rgba8Srgb => decode_rgba8_srgb([byte(0), byte(1), byte(2), byte(3)]),
            ColorFormat::Rgba16F => {
                std::array::from_fn(|c| f16::from_bits(u16::from_le_bytes([byte(2 * c), byte(2 * c + 1)])).to_f32())
            }
            ColorFormat::Rgba32F => std::array::from_fn(|c| {
                f32::from_le_bytes([byte(4 * c), byte(4 * c + 1), byte(4 * c + 2), byte(4 * c + 3)])
            }),
        }
    }

    /// The colour after an encode/decode round trip (what the GPU will see).
    pub fn quantize(self, color: Rgba) -> Rgba {
        let mut bytes = Vec::with_capacity(16);
        self.encode_into(color, &mut bytes);
        self.decode(&bytes)
    }
}

/// Linear → sRGB transfer function (IEC 61966-2-1), input clamped to `[0, 1]`.
pub fn linear_to_srgb(linear: f32) -> f32 {
    let x = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

/// sRGB → linear transfer function (IEC 61966-2-1).
pub fn srgb_to_linear(encoded: f32) -> f32 {
    let x = encoded.clamp(0.0, 1.0);
    if x <= 0.040_45 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

fn unorm8(x: f32) -> u8 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    (x * 255.0).round() as u8
}

/// Encodes a linear colour as RGBA8 with sRGB-encoded RGB and linear alpha.
pub fn encode_rgba8_srgb(color: Rgba) -> [u8; 4] {
    [
        unorm8(linear_to_srgb(color[0])),
        unorm8(linear_to_srgb(color[1])),
        unorm8(linear_to_srgb(color[2])),
        unorm8(color[3]),
    ]
}

/// Decodes RGBA8 with sRGB-encoded RGB and linear alpha to a linear colour.
pub fn decode_rgba8_srgb(bytes: [u8; 4]) -> Rgba {
    let channel = |b: u8| srgb_to_linear(f32::from(b) / 255.0);
    [channel(bytes[0]), channel(bytes[1]), channel(bytes[2]), f32::from(bytes[3]) / 255.0]
}

/// `a * (1 - t) + b * t` per channel.
pub fn lerp(a: Rgba, b: Rgba, t: f32) -> Rgba {
    std::array::from_fn(|c| a[c] * (1.0 - t) + b[c] * t)
}

/// `Σ weight_k · color_k` per channel.
pub fn weighted_sum<const N: usize>(terms: [(f32, Rgba); N]) -> Rgba {
    let mut out = [0.0; 4];
    for (weight, color) in terms {
        for c in 0..4 {
            out[c] += weight * color[c];
        }
    }
    out
}
