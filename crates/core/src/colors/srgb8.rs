//! Exact RGBA8 sRGB encoding and decoding by table (the `Rgba8Srgb` format's codec).
//!
//! A linear channel encodes to the 8-bit code whose exact (f64) sRGB value is nearest:
//! code `b + 1` or above from the smallest f32 at or above the f64 boundary
//! `srgb_to_linear((b + ½) / 255)`. The encoder finds it with one bucket of the f32 bit
//! patterns (`bits >> 15`: the exponent and the top 8 mantissa bits) and one compare:
//! `code = base[k] + (x >= threshold[k])`, where `base[k]` is the code of the bucket's
//! smallest value and `threshold[k]` the one boundary that may fall inside the bucket (a
//! bucket spans < 0.4 % of its values, one sRGB code at least 0.89 %, so at most one does).
//! Both are read from one 8-byte entry, so a value costs one load and no dependent one;
//! where the CPU has AVX2 a slice is encoded two samples (eight channels) a step with two
//! gathers. crates/core/tests/core/repack.rs checks every f32 in `[0, 1]` against the f64
//! formula, through the dispatched slice encoder and the scalar one.

/// A linear RGBA colour (the format module's `Rgba`, spelled out so that this codec, which the
/// format module uses, does not depend on it).
type Color = [f32; 4];

/// Buckets of `bits >> BUCKET_SHIFT`.
const BUCKET_SHIFT: u32 = 15;

/// Tables for exact, fast RGBA8 sRGB conversion, built once in `f64`.
pub(crate) struct SrgbTables {
    /// Linear value of each 8-bit code.
    pub(crate) decode: [f32; 256],
    /// Each alpha code's value, `code / 255` (a lookup in place of a division).
    pub(crate) alpha: [f32; 256],
    /// Per bucket of f32 bit patterns from `first_bucket` up to the bucket of 1.0 (the last
    /// entry): `[threshold bits, base code]`. Every f32 in the bucket encodes to `base`, or
    /// `base + 1` from `threshold` on (+∞ when no boundary falls in the bucket).
    entries: Vec<[u32; 2]>,
    /// The bucket holding the first boundary: every f32 below its start encodes to 0, so
    /// the table (3.3 k entries, 26 KiB) stays in the L1 cache. Buckets below it read entry 0.
    first_bucket: u32,
}

/// The tables, built on first use.
pub(crate) fn srgb_tables() -> &'static SrgbTables {
    static TABLES: std::sync::OnceLock<SrgbTables> = std::sync::OnceLock::new();
    TABLES.get_or_init(SrgbTables::build)
}

/// The exact sRGB decode of an encoded value in `[0, 1]`, in f64.
fn to_linear(encoded: f64) -> f64 {
    if encoded <= 0.040_45 { encoded / 12.92 } else { ((encoded + 0.055) / 1.055).powf(2.4) }
}

/// `x * 255` rounded half away from zero, for `x` in `[0, 1]` (linear alpha): `v − trunc(v)`
/// is exact here, so no libm call.
#[inline(always)]
fn unorm8(x: f32) -> u8 {
    let v = x * 255.0;
    let t = v as u32;
    (t + u32::from(v - t as f32 >= 0.5)) as u8
}

/// `x` clamped to `[0, 1]`, NaN and −0 to +0 (`f32::max` returns the other operand for NaN;
/// the sign bit is cleared for −0, which `max` may return).
#[inline(always)]
#[allow(clippy::manual_clamp)] // `clamp` keeps NaN; `max` turns it into 0
fn unit(x: f32) -> f32 {
    f32::from_bits(x.max(0.0).min(1.0).to_bits() & 0x7fff_ffff)
}

impl SrgbTables {
    fn build() -> Self {
        // Each threshold is the smallest f32 at or above the exact (f64) boundary, so
        // "reaches the threshold" is exactly "the f64 formula rounds up" for every f32.
        let thresholds: [f32; 255] = std::array::from_fn(|b| {
            let exact = to_linear((b as f64 + 0.5) / 255.0);
            let mut t = exact as f32;
            while f64::from(t) < exact {
                t = t.next_up();
            }
            while f64::from(t.next_down()) >= exact {
                t = t.next_down();
            }
            t
        });
        let first_bucket = thresholds[0].to_bits() >> BUCKET_SHIFT;
        let entries = (first_bucket..=1.0f32.to_bits() >> BUCKET_SHIFT)
            .map(|k| {
                let start = f32::from_bits(k << BUCKET_SHIFT);
                let base = thresholds.partition_point(|&t| t <= start);
                let threshold = thresholds.get(base).copied().unwrap_or(f32::INFINITY);
                [threshold.to_bits(), base as u32]
            })
            .collect();
        SrgbTables {
            decode: std::array::from_fn(|b| to_linear(b as f64 / 255.0) as f32),
            alpha: std::array::from_fn(|b| b as f32 / 255.0),
            entries,
            first_bucket,
        }
    }

    /// The 8-bit sRGB code of one linear channel (clamped to `[0, 1]`, NaN as 0).
    #[inline(always)]
    pub(crate) fn encode(&self, linear: f32) -> u8 {
        let x = unit(linear);
        let k = ((x.to_bits() >> BUCKET_SHIFT).max(self.first_bucket) - self.first_bucket) as usize;
        // `k` is at most the bucket of 1.0, the last entry (`x ≤ 1`).
        let [threshold, base] = self.entries.get(k).copied().unwrap_or([0, 255]);
        base as u8 + u8::from(x >= f32::from_bits(threshold))
    }

    /// A colour's RGBA8 bytes: RGB sRGB-encoded, alpha linear (clamped, rounded half away
    /// from zero).
    #[inline(always)]
    pub(crate) fn encode_rgba8(&self, color: Color) -> [u8; 4] {
        [self.encode(color[0]), self.encode(color[1]), self.encode(color[2]), unorm8(unit(color[3]))]
    }

    #[inline(always)]
    pub(crate) fn decode_rgba8(&self, bytes: [u8; 4]) -> Color {
        [
            self.decode[usize::from(bytes[0])],
            self.decode[usize::from(bytes[1])],
            self.decode[usize::from(bytes[2])],
            self.alpha[usize::from(bytes[3])],
        ]
    }

    /// Encodes `colors` into `out` (4 bytes each) and, when given, writes what decoding
    /// gives to `quantized`, as far as all of them reach: with AVX2 where the CPU has it,
    /// else [`SrgbTables::encode_slice_portable`]; the same bytes either way.
    pub(crate) fn encode_slice(&self, colors: &[Color], out: &mut [u8], quantized: Option<&mut [Color]>) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { avx2::encode(self, colors, out, quantized) };
            return;
        }
        self.encode_slice_portable(colors, out, quantized);
    }

    /// [`SrgbTables::encode_slice`] one channel at a time.
    pub(crate) fn encode_slice_portable(&self, colors: &[Color], out: &mut [u8], quantized: Option<&mut [Color]>) {
        let out = out.chunks_exact_mut(4).zip(colors);
        match quantized {
            Some(quantized) => {
                for ((bytes, &color), slot) in out.zip(quantized.iter_mut()) {
                    let code = self.encode_rgba8(color);
                    bytes.copy_from_slice(&code);
                    *slot = self.decode_rgba8(code);
                }
            }
            None => {
                for (bytes, &color) in out {
                    bytes.copy_from_slice(&self.encode_rgba8(color));
                }
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::{BUCKET_SHIFT, Color, SrgbTables};

    /// Two samples (eight channels) a step: clamped to `[0, 1]` (`max` with zero first
    /// returns zero for NaN and for −0), each RGB channel's entry gathered (threshold and
    /// base) and compared, alpha rounded as [`super::unorm8`] does, the codes' low bytes
    /// stored; the decoded copy gathered from the decode table (alpha `code / 255`, the
    /// alpha table's correctly rounded division). An odd last sample goes the scalar way.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn encode(
        tables: &SrgbTables,
        colors: &[Color],
        out: &mut [u8],
        quantized: Option<&mut [Color]>,
    ) {
        let n = colors.len().min(out.len() / 4).min(quantized.as_ref().map_or(usize::MAX, |q| q.len()));
        let src = colors.as_ptr().cast::<f32>();
        let dst = out.as_mut_ptr();
        let decoded = quantized.map(|q| q.as_mut_ptr().cast::<f32>());
        let entries = tables.entries.as_ptr().cast::<u8>();
        let zero = _mm256_setzero_ps();
        let one = _mm256_set1_ps(1.0);
        let first = _mm256_set1_epi32(tables.first_bucket as i32);
        let last = _mm256_set1_epi32((tables.entries.len() - 1) as i32);
        // The low byte of each 32-bit code to the low 4 bytes of its 128-bit lane, then
        // the two lanes' dwords together.
        let bytes_of = _mm256_setr_epi8(
            0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1,
            -1, -1, -1, -1,
        );
        let together = _mm256_setr_epi32(0, 4, 1, 1, 1, 1, 1, 1);
        for p in 0..n / 2 {
            // SAFETY: samples 2p and 2p + 1 are below `n`, within all three slices; every
            // gather index is within the tables (`k` in `0..entries.len()`, codes ≤ 255).
            unsafe {
                let x = _mm256_min_ps(_mm256_max_ps(_mm256_loadu_ps(src.add(8 * p)), zero), one);
                let bucket = _mm256_srli_epi32::<{ BUCKET_SHIFT as i32 }>(_mm256_castps_si256(x));
                let k = _mm256_min_epi32(_mm256_sub_epi32(_mm256_max_epi32(bucket, first), first), last);
                let threshold = _mm256_i32gather_ps::<8>(entries.cast(), k);
                let base = _mm256_i32gather_epi32::<8>(entries.add(4).cast(), k);
                let reached = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(x, threshold));
                let rgb = _mm256_sub_epi32(base, reached);
                let scaled = _mm256_mul_ps(x, _mm256_set1_ps(255.0));
                let whole = _mm256_cvttps_epi32(scaled);
                let fraction = _mm256_sub_ps(scaled, _mm256_cvtepi32_ps(whole));
                let up = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(fraction, _mm256_set1_ps(0.5)));
                let alpha = _mm256_sub_epi32(whole, up);
                let codes = _mm256_blend_epi32::<0b1000_1000>(rgb, alpha);
                let packed = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(codes, bytes_of), together);
                _mm_storel_epi64(dst.add(8 * p).cast(), _mm256_castsi256_si128(packed));
                if let Some(decoded) = decoded {
                    let linear = _mm256_i32gather_ps::<4>(tables.decode.as_ptr(), codes);
                    let alpha = _mm256_div_ps(_mm256_cvtepi32_ps(codes), _mm256_set1_ps(255.0));
                    _mm256_storeu_ps(decoded.add(8 * p), _mm256_blend_ps::<0b1000_1000>(linear, alpha));
                }
            }
        }
        if n % 2 == 1 {
            let last = n - 1;
            let code = tables.encode_rgba8(colors[last]);
            out[4 * last..4 * last + 4].copy_from_slice(&code);
            if let Some(decoded) = decoded {
                // SAFETY: sample `last` is below `n`, within `quantized`.
                unsafe { decoded.add(4 * last).cast::<Color>().write_unaligned(tables.decode_rgba8(code)) };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Color, srgb_tables};

    /// The dispatched slice encoder (AVX2 on this CPU, if it has it) equals the portable
    /// one bit for bit, bytes and decoded copy, on runs of every length around its step
    /// and on the values where clamping and rounding could differ.
    #[test]
    fn dispatched_rgba8_encoder_equals_the_portable_one() {
        let values = [
            0.0,
            -0.0,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -1.0,
            1e-30,
            1.5e-4,
            0.003_130_8,
            0.5 / 255.0,
            1.5 / 255.0,
            0.214_041_14,
            0.5,
            254.5 / 255.0,
            0.999_999_94,
            1.0,
            1.000_000_1,
            65_504.0,
        ];
        let tables = srgb_tables();
        for len in [0, 1, 2, 3, 7, 8, 31, 33] {
            let colors: Vec<Color> =
                (0..len).map(|i| std::array::from_fn(|c| values[(4 * i + c + len) % values.len()])).collect();
            let (mut portable, mut dispatched) = (vec![0u8; 4 * len], vec![0u8; 4 * len]);
            let (mut portable_q, mut dispatched_q) = (vec![[0.0f32; 4]; len], vec![[0.0f32; 4]; len]);
            tables.encode_slice_portable(&colors, &mut portable, Some(&mut portable_q));
            tables.encode_slice(&colors, &mut dispatched, Some(&mut dispatched_q));
            assert_eq!(portable, dispatched, "length {len}");
            let bits = |q: &[Color]| q.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&portable_q), bits(&dispatched_q), "length {len}");
            let mut bytes_only = vec![0u8; 4 * len];
            tables.encode_slice(&colors, &mut bytes_only, None);
            assert_eq!(bytes_only, portable, "length {len}");
        }
    }
}
