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

use super::srgb8::srgb_tables;

/// A linear-light RGBA colour, straight (not premultiplied) alpha.
pub type Rgba = [f32; 4];

/// Opaque black.
pub const BLACK: Rgba = [0.0, 0.0, 0.0, 1.0];

/// The largest colour channel any format holds: RGBA16F's largest finite value. Every
/// stored colour has R, G, B in `[0, MAX_CHANNEL]` and alpha in `[0, 1]` (docs/FORMAT.md,
/// "Colour values"); writes into the store and encoders clamp to it, the packed reader
/// refuses anything else.
pub const MAX_CHANNEL: f32 = 65504.0;

/// `color` clamped to what every format holds: R, G, B to `[0, MAX_CHANNEL]`, alpha to
/// `[0, 1]`; NaN becomes 0 (so no NaN or infinity is ever stored, encoded or uploaded).
#[inline(always)]
pub fn clamp_color(color: Rgba) -> Rgba {
    // `f32::max` returns the other operand for NaN: NaN becomes 0, with no branch.
    let channel = |x: f32, max: f32| x.max(0.0).min(max);
    [
        channel(color[0], MAX_CHANNEL),
        channel(color[1], MAX_CHANNEL),
        channel(color[2], MAX_CHANNEL),
        channel(color[3], 1.0),
    ]
}

/// Whether `color` is a storable colour (what [`clamp_color`] leaves unchanged).
pub fn is_storable(color: Rgba) -> bool {
    color[..3].iter().all(|c| (0.0..=MAX_CHANNEL).contains(c)) && (0.0..=1.0).contains(&color[3])
}

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

    /// Appends the encoding of `color` (clamped by [`clamp_color`]) to `out`.
    pub fn encode_into(self, color: Rgba, out: &mut Vec<u8>) {
        let color = clamp_color(color);
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
    #[inline(always)]
    pub fn decode(self, bytes: &[u8]) -> Rgba {
        // Whole samples (the usual case) without per-byte checks.
        match self {
            ColorFormat::Rgba8Srgb => {
                if let Some(b) = bytes.first_chunk::<4>() {
                    return decode_rgba8_srgb(*b);
                }
            }
            ColorFormat::Rgba16F => {
                if let Some(b) = bytes.first_chunk::<8>() {
                    return f16x4_to_vec4(b).to_array();
                }
            }
            ColorFormat::Rgba32F => {
                if let Some(b) = bytes.first_chunk::<16>() {
                    return std::array::from_fn(|c| {
                        f32::from_le_bytes([b[4 * c], b[4 * c + 1], b[4 * c + 2], b[4 * c + 3]])
                    });
                }
            }
        }
        self.decode_short(bytes)
    }

    /// [`ColorFormat::decode`] of a short slice (kept out of line: the hot path inlines).
    #[cold]
    fn decode_short(self, bytes: &[u8]) -> Rgba {
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

    /// [`ColorFormat::decode`] into a SIMD register (the same values), for loops that add
    /// decoded samples as vectors.
    #[inline(always)]
    pub fn decode_vec4(self, bytes: &[u8]) -> glam::Vec4 {
        match self {
            ColorFormat::Rgba8Srgb => {
                if let Some(b) = bytes.first_chunk::<4>() {
                    let t = srgb_tables();
                    let d = |k: usize| t.decode[usize::from(b[k])];
                    return glam::Vec4::new(d(0), d(1), d(2), t.alpha[usize::from(b[3])]);
                }
            }
            ColorFormat::Rgba32F => {
                if let Some(b) = bytes.first_chunk::<16>() {
                    let c = |k: usize| f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]);
                    return glam::Vec4::new(c(0), c(1), c(2), c(3));
                }
            }
            ColorFormat::Rgba16F => {
                if let Some(b) = bytes.first_chunk::<8>() {
                    return f16x4_to_vec4(b);
                }
            }
        }
        glam::Vec4::from_array(self.decode(bytes))
    }

    /// The colour after an encode/decode round trip (what the GPU will see), clamped first.
    pub fn quantize(self, color: Rgba) -> Rgba {
        let color = clamp_color(color);
        match self {
            ColorFormat::Rgba8Srgb => decode_rgba8_srgb(encode_rgba8_srgb(color)),
            ColorFormat::Rgba16F => color.map(|c| f16::from_f32(c).to_f32()),
            ColorFormat::Rgba32F => color,
        }
    }

    /// Encodes `color` (clamped) into `out` (`bytes_per_sample` long) and returns what
    /// decoding those bytes gives, i.e. [`ColorFormat::quantize`] with the encoding done once.
    #[inline]
    pub fn encode_quantized(self, color: Rgba, out: &mut [u8]) -> Rgba {
        let color = clamp_color(color);
        match self {
            ColorFormat::Rgba8Srgb => {
                let tables = srgb_tables();
                let bytes = tables.encode_rgba8(color);
                out.copy_from_slice(&bytes);
                tables.decode_rgba8(bytes)
            }
            ColorFormat::Rgba16F => {
                let halves = color.map(f16::from_f32);
                for (pair, half) in out.chunks_exact_mut(2).zip(halves) {
                    pair.copy_from_slice(&half.to_bits().to_le_bytes());
                }
                halves.map(f16::to_f32)
            }
            ColorFormat::Rgba32F => {
                for (quad, channel) in out.chunks_exact_mut(4).zip(color) {
                    quad.copy_from_slice(&channel.to_le_bytes());
                }
                color
            }
        }
    }

    /// [`ColorFormat::encode_quantized`] over a slice: encodes `colors` into `out` and
    /// writes what decoding gives to `quantized` (as far as all three reach), the format
    /// chosen once for the run.
    pub fn encode_quantized_slice(self, colors: &[Rgba], out: &mut [u8], quantized: &mut [Rgba]) {
        // Each arm splits `out` at its format's constant sample size, so every copy is a
        // fixed-size store, not a call.
        match self {
            ColorFormat::Rgba8Srgb => srgb_tables().encode_slice(colors, out, Some(quantized)),
            ColorFormat::Rgba16F => {
                let n = colors.len().min(out.len() / 8).min(quantized.len());
                encode_f16_runs(&colors[..n], &mut out[..n * 8], Some(&mut quantized[..n]));
            }
            ColorFormat::Rgba32F => {
                for ((&color, out), slot) in colors.iter().zip(out.chunks_exact_mut(16)).zip(quantized.iter_mut()) {
                    *slot = self.encode_quantized(color, out);
                }
            }
        }
    }

    /// Encodes `colors` (each clamped by [`clamp_color`]) into `out`, which must be exactly
    /// `colors.len() * bytes_per_sample()` long (extra input or output is ignored).
    pub fn encode_slice(self, colors: &[Rgba], out: &mut [u8]) {
        // One loop per format, each at its constant sample size (fixed-size stores).
        match self {
            ColorFormat::Rgba8Srgb => srgb_tables().encode_slice(colors, out, None),
            ColorFormat::Rgba16F => {
                let n = colors.len().min(out.len() / 8);
                encode_f16_runs(&colors[..n], &mut out[..n * 8], None);
            }
            ColorFormat::Rgba32F => {
                for (color, bytes) in colors.iter().zip(out.chunks_exact_mut(16)) {
                    let color = clamp_color(*color);
                    for (c, quad) in bytes.chunks_exact_mut(4).enumerate() {
                        quad.copy_from_slice(&color[c].to_le_bytes());
                    }
                }
            }
        }
    }
}

/// A binary16 value (its bits) as `f32`, exactly: the bits `half`'s `to_f32` gives (F16C's
/// `vcvtph2ps` or its software path; a NaN comes out quiet with its payload), in integer
/// operations the compiler keeps in registers, not a call per sample (F. Giesen's
/// `half_to_float_fast4`: the exponent rebiased, subnormals renormalised by one float
/// subtraction). crates/core/tests/core/packer.rs checks all 65,536 bit patterns against `half`.
#[inline(always)]
pub fn f16_bits_to_f32(h: u16) -> f32 {
    const SHIFTED_EXPONENT: u32 = 0x7c00 << 13;
    let magic = f32::from_bits(113 << 23);
    let mut o = u32::from(h & 0x7fff) << 13;
    let exponent = o & SHIFTED_EXPONENT;
    o += (127 - 15) << 23;
    if exponent == SHIFTED_EXPONENT {
        // Infinity or NaN: the largest exponent; a NaN made quiet as the hardware does.
        o += (128 - 16) << 23;
        if o & 0x007f_ffff != 0 {
            o |= 0x0040_0000;
        }
    } else if exponent == 0 {
        // Zero or subnormal: one more exponent step, then the implicit 1 taken away.
        o += 1 << 23;
        o = (f32::from_bits(o) - magic).to_bits();
    }
    f32::from_bits(o | (u32::from(h & 0x8000) << 16))
}

/// Four binary16 values (little-endian bits, one sample's RGBA16F bytes) as `f32`, exactly
/// [`f16_bits_to_f32`] of each, in one SSE2 register: the four channels at once in about
/// fifteen vector operations (F. Giesen's `half_to_float_SSE2`: the exponent and mantissa
/// shifted into place and rebiased by one multiplication by 2¹¹², exact also for subnormals,
/// whose product has a subnormal `f32` operand, exact as long as the thread does not set
/// "denormals are zero", which Rust never does; infinities and NaNs given the largest
/// exponent, a NaN made quiet). SSE2 is part of x86-64, so no CPU check; elsewhere channel
/// by channel. crates/core/tests/core/packer.rs checks all 65,536 bit patterns in every channel against
/// `half`.
#[inline(always)]
fn f16x4_to_vec4(bytes: &[u8; 8]) -> glam::Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is baseline on x86-64, and `bytes` is 8 readable bytes (the load
        // reads exactly 8, unaligned).
        unsafe {
            let h = _mm_unpacklo_epi16(_mm_loadl_epi64(bytes.as_ptr().cast()), _mm_setzero_si128());
            let exponent_mantissa = _mm_and_si128(h, _mm_set1_epi32(0x7fff));
            let sign = _mm_slli_epi32(_mm_xor_si128(h, exponent_mantissa), 16);
            let rebias = _mm_castsi128_ps(_mm_set1_epi32((254 - 15) << 23));
            let scaled = _mm_mul_ps(_mm_castsi128_ps(_mm_slli_epi32(exponent_mantissa, 13)), rebias);
            let inf_nan = _mm_cmpgt_epi32(exponent_mantissa, _mm_set1_epi32(0x7bff));
            let nan = _mm_cmpgt_epi32(exponent_mantissa, _mm_set1_epi32(0x7c00));
            let top = _mm_or_si128(
                _mm_and_si128(inf_nan, _mm_set1_epi32(255 << 23)),
                _mm_and_si128(nan, _mm_set1_epi32(0x0040_0000)),
            );
            glam::Vec4::from(_mm_or_ps(scaled, _mm_castsi128_ps(_mm_or_si128(sign, top))))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let c = |k: usize| f16_bits_to_f32(u16::from_le_bytes([bytes[2 * k], bytes[2 * k + 1]]));
        glam::Vec4::new(c(0), c(1), c(2), c(3))
    }
}

/// Encodes `colors` (clamped) as RGBA16F into `out` (8 bytes each) and, when given, writes
/// what decoding gives to `quantized` (all three the same length). Where the CPU has F16C,
/// two samples an instruction straight from the colours to the bytes
/// ([`f16c::encode`]); elsewhere runs of samples through `half`'s slice conversions. The
/// rounding is IEEE round-to-nearest-even either way, [`f16::from_f32`]'s.
fn encode_f16_runs(colors: &[Rgba], out: &mut [u8], quantized: Option<&mut [Rgba]>) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("f16c") && std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has F16C and AVX (checked above).
        unsafe { f16c::encode(colors, out, quantized) };
        return;
    }
    encode_f16_portable(colors, out, quantized);
}

/// [`encode_f16_runs`] through `half`'s slice conversions.
fn encode_f16_portable(colors: &[Rgba], out: &mut [u8], mut quantized: Option<&mut [Rgba]>) {
    use half::slice::HalfFloatSliceExt;
    const RUN: usize = 32;
    let mut clamped = [0.0f32; RUN * 4];
    let mut halves = [f16::ZERO; RUN * 4];
    let mut decoded = [0.0f32; RUN * 4];
    for (run, (colors, out)) in colors.chunks(RUN).zip(out.chunks_mut(RUN * 8)).enumerate() {
        let n = colors.len() * 4;
        for (slot, &color) in clamped.chunks_exact_mut(4).zip(colors) {
            slot.copy_from_slice(&clamp_color(color));
        }
        halves[..n].convert_from_f32_slice(&clamped[..n]);
        for (pair, half) in out.chunks_exact_mut(2).zip(&halves[..n]) {
            pair.copy_from_slice(&half.to_bits().to_le_bytes());
        }
        if let Some(quantized) = quantized.as_deref_mut() {
            halves[..n].convert_to_f32_slice(&mut decoded[..n]);
            let slots = quantized.iter_mut().skip(run * RUN).take(colors.len());
            for (slot, value) in slots.zip(decoded.chunks_exact(4)) {
                *slot = [value[0], value[1], value[2], value[3]];
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod f16c {
    use std::arch::x86_64::*;

    use super::{MAX_CHANNEL, Rgba};

    /// Two samples (eight channels) a step: clamped as [`super::clamp_color`] does (NaN and
    /// every zero or negative to +0: `max` returns its second operand for NaN and for two
    /// zeros), converted with `vcvtps2ph` (round to nearest even), stored; the decoded copy
    /// converted back with `vcvtph2ps`. An odd last sample takes the same steps at half width.
    ///
    /// # Safety
    /// The CPU must have F16C and AVX.
    #[target_feature(enable = "avx,f16c")]
    pub(super) unsafe fn encode(colors: &[Rgba], out: &mut [u8], quantized: Option<&mut [Rgba]>) {
        let n = colors.len().min(out.len() / 8).min(quantized.as_ref().map_or(usize::MAX, |q| q.len()));
        let pairs = n / 2;
        let zero = _mm256_setzero_ps();
        let max =
            _mm256_setr_ps(MAX_CHANNEL, MAX_CHANNEL, MAX_CHANNEL, 1.0, MAX_CHANNEL, MAX_CHANNEL, MAX_CHANNEL, 1.0);
        let src = colors.as_ptr().cast::<f32>();
        let dst = out.as_mut_ptr();
        let decoded = quantized.map(|q| q.as_mut_ptr().cast::<f32>());
        for p in 0..pairs {
            // SAFETY: samples 2p and 2p + 1 are below `n`, within all three slices.
            let x = unsafe { _mm256_loadu_ps(src.add(8 * p)) };
            let halves = _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm256_min_ps(_mm256_max_ps(x, zero), max));
            unsafe { _mm_storeu_si128(dst.add(16 * p).cast(), halves) };
            if let Some(decoded) = decoded {
                unsafe { _mm256_storeu_ps(decoded.add(8 * p), _mm256_cvtph_ps(halves)) };
            }
        }
        if n % 2 == 1 {
            // The odd last sample, four channels in a 128-bit register (the portable path's
            // fixed-size runs cost more than the sample for a chain of odd length).
            let last = n - 1;
            let max = _mm_setr_ps(MAX_CHANNEL, MAX_CHANNEL, MAX_CHANNEL, 1.0);
            // SAFETY: sample `last` is below `n`, within all three slices.
            let x = unsafe { _mm_loadu_ps(src.add(4 * last)) };
            let halves = _mm_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), max));
            unsafe { _mm_storel_epi64(dst.add(8 * last).cast(), halves) };
            if let Some(decoded) = decoded {
                unsafe { _mm_storeu_ps(decoded.add(4 * last), _mm_cvtph_ps(halves)) };
            }
        }
    }
}

/// Linear → sRGB transfer function (IEC 61966-2-1), input clamped to `[0, 1]`.
pub fn linear_to_srgb(linear: f32) -> f32 {
    let x = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

/// Mantissa bits below a [`linear_to_srgb_table`] interval: 9 of the 23 index it, so each
/// binade from 2⁻⁹ to 1 holds 512 intervals.
const SRGB_TABLE_FRACTION_BITS: u32 = 14;
/// Below this the transfer function is its linear segment (2⁻⁹ < 0.003 130 8).
const SRGB_TABLE_START: f32 = 1.0 / 512.0;

/// [`linear_to_srgb`] without a `powf`: a table of the f64 formula at the start of each of
/// 9 × 512 intervals (the binades 2⁻⁹…1, 512 intervals each, indexed by the float's
/// exponent and top 9 mantissa bits), read with linear interpolation; the linear segment
/// below 2⁻⁹ exactly. Within 2·10⁻⁷ of the exact value over `[0, 1]` (the curve's
/// curvature × interval² / 8 is below 1.3·10⁻⁷; tested against the f64 formula), monotonic,
/// and a function of its input alone, so equal colours still encode equal. For error
/// measures that encode millions of colours (`convert::adaptive`), not for 8-bit encoding.
pub fn linear_to_srgb_table(linear: f32) -> f32 {
    let x = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    if x < SRGB_TABLE_START {
        return 12.92 * x;
    }
    let table = srgb_table();
    let offset = x.to_bits() - SRGB_TABLE_START.to_bits();
    let index = (offset >> SRGB_TABLE_FRACTION_BITS) as usize;
    let fraction = (offset & ((1 << SRGB_TABLE_FRACTION_BITS) - 1)) as f32 / (1 << SRGB_TABLE_FRACTION_BITS) as f32;
    match (table.get(index), table.get(index + 1)) {
        (Some(&a), Some(&b)) => a + (b - a) * fraction,
        (Some(&a), None) => a,
        _ => 1.0,
    }
}

/// The values of [`linear_to_srgb_table`]'s interval starts, from the f64 formula.
fn srgb_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let start = SRGB_TABLE_START.to_bits();
        let end = 1.0f32.to_bits();
        (start..=end)
            .step_by(1 << SRGB_TABLE_FRACTION_BITS)
            .map(|bits| {
                let x = f64::from(f32::from_bits(bits));
                let y = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
                y as f32
            })
            .collect()
    })
}

/// sRGB → linear transfer function (IEC 61966-2-1).
pub fn srgb_to_linear(encoded: f32) -> f32 {
    let x = encoded.clamp(0.0, 1.0);
    if x <= 0.040_45 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

/// Encodes one linear channel as an 8-bit sRGB code: the code whose exact encoded value
/// is nearest (rounding in encoded space), from precomputed buckets and thresholds.
pub fn encode_srgb8(linear: f32) -> u8 {
    srgb_tables().encode(linear)
}

/// Decodes an 8-bit sRGB code to a linear channel value.
pub fn decode_srgb8(code: u8) -> f32 {
    srgb_tables().decode[usize::from(code)]
}

/// Encodes a linear colour as RGBA8 with sRGB-encoded RGB and linear alpha.
pub fn encode_rgba8_srgb(color: Rgba) -> [u8; 4] {
    srgb_tables().encode_rgba8(color)
}

/// Decodes RGBA8 with sRGB-encoded RGB and linear alpha to a linear colour.
#[inline]
pub fn decode_rgba8_srgb(bytes: [u8; 4]) -> Rgba {
    srgb_tables().decode_rgba8(bytes)
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

#[cfg(test)]
mod tests {
    use half::f16;

    use super::{Rgba, encode_f16_portable, encode_f16_runs};

    /// The portable RGBA16F encoder (CPUs without F16C) against `half`, value by value, and
    /// against the encoder this CPU runs, bit for bit, on runs of every length around its
    /// batch sizes: on a CPU with F16C nothing else runs the portable path.
    #[test]
    fn portable_rgba16f_encoder_equals_half_and_the_dispatched_one() {
        let values = [
            0.0,
            -0.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -1.0,
            1e-8,
            6.0e-8,
            6.1e-5,
            0.333_333_34,
            0.5,
            1.0,
            1.5,
            65_519.996,
            65_520.0,
            1e9,
        ];
        for len in [1, 2, 7, 31, 32, 33, 65] {
            let colors: Vec<Rgba> =
                (0..len).map(|i| std::array::from_fn(|c| values[(4 * i + c) % values.len()])).collect();
            let (mut portable, mut dispatched) = (vec![0u8; 8 * len], vec![0u8; 8 * len]);
            let (mut portable_q, mut dispatched_q) = (vec![[0.0f32; 4]; len], vec![[0.0f32; 4]; len]);
            encode_f16_portable(&colors, &mut portable, Some(&mut portable_q));
            encode_f16_runs(&colors, &mut dispatched, Some(&mut dispatched_q));
            assert_eq!(portable, dispatched, "length {len}");
            for (i, color) in colors.iter().enumerate() {
                for c in 0..4 {
                    // NaN, negatives and both zeros to +0; then at most the channel's top.
                    let top = if c == 3 { 1.0 } else { 65504.0 };
                    let clamped = if color[c] > 0.0 { color[c].min(top) } else { 0.0 };
                    let want = f16::from_f32(clamped);
                    let got = u16::from_le_bytes([portable[8 * i + 2 * c], portable[8 * i + 2 * c + 1]]);
                    assert_eq!(got, want.to_bits(), "length {len}, sample {i}, channel {c}: {}", color[c]);
                    assert_eq!(portable_q[i][c].to_bits(), want.to_f32().to_bits());
                    assert_eq!(dispatched_q[i][c].to_bits(), want.to_f32().to_bits());
                }
            }
        }
    }
}
