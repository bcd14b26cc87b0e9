//! The fuzzer's deterministic random source and the mutation primitives shared by the
//! packed-file and glTF mutators. Input `i` of a campaign with seed `s` is drawn from
//! [`Rng::for_input`]`(s, i)` alone, so any input can be regenerated from its index.

use meshpaint_core::synth::SplitMix64;

/// The fuzzer's generator: [`SplitMix64`] (the one shared with the tests and benchmarks),
/// seeded per input.
pub struct Rng(SplitMix64);

impl Rng {
    /// The generator for input `index` of a campaign with `seed`.
    pub fn for_input(seed: u64, index: u64) -> Self {
        let mut rng = SplitMix64(seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03));
        rng.next_u64();
        Rng(rng)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// An integer in `0..n` (0 when `n == 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.0.below(n)
    }

    /// An index into a collection of `len` items (0 when empty).
    pub fn index(&mut self, len: usize) -> usize {
        self.below(len as u64) as usize
    }

    /// True with probability `numerator / denominator`.
    pub fn chance(&mut self, numerator: u64, denominator: u64) -> bool {
        self.below(denominator) < numerator
    }

    /// One of `items` (which must not be empty).
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.index(items.len())]
    }

    /// A 32-bit value that tends to hit boundaries: small numbers, powers of two and their
    /// neighbours, the extremes, `near ± small`, or random bits.
    pub fn interesting_u32(&mut self, near: u32) -> u32 {
        match self.below(8) {
            0 => self.below(17) as u32,
            1 => {
                let p = 1u32 << self.below(32);
                p.wrapping_add(self.pick(&[0u32, 1, u32::MAX]))
            }
            2 => self.pick(&[u32::MAX, u32::MAX - 1, i32::MAX as u32, 1 << 28, (1 << 28) - 1, (1 << 28) + 1]),
            3 | 4 => near.wrapping_add(self.below(9) as u32).wrapping_sub(4),
            5 => near.wrapping_mul(self.pick(&[2, 3, 16, 1000])),
            6 => near / self.pick(&[2, 3, 16]),
            _ => self.next_u64() as u32,
        }
    }

    /// A 64-bit value like [`Rng::interesting_u32`].
    pub fn interesting_u64(&mut self, near: u64) -> u64 {
        match self.below(6) {
            0 => u64::from(self.interesting_u32(near as u32)),
            1 => self.pick(&[u64::MAX, u64::MAX - 255, i64::MAX as u64, 1 << 32, 1 << 40, (1 << 32) - 1]),
            2 | 3 => near.wrapping_add(self.below(9)).wrapping_sub(4),
            4 => near.wrapping_add(256 * self.below(5)).wrapping_sub(512),
            _ => self.next_u64(),
        }
    }

    /// An `f32` bit pattern that tends to break arithmetic.
    pub fn interesting_f32(&mut self) -> f32 {
        match self.below(4) {
            0 => self.pick(&[f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -f32::NAN]),
            1 => self.pick(&[0.0, -0.0, 1.0, -1.0, f32::MAX, f32::MIN, f32::MIN_POSITIVE, 1e-45, 65504.0, 65520.0]),
            2 => (self.below(2001) as f32 - 1000.0) / 10.0,
            _ => f32::from_bits(self.next_u64() as u32),
        }
    }

    /// Applies one byte-level mutation to `bytes`: flip a bit, set a byte, overwrite a
    /// little-endian word with an interesting value, insert, delete, duplicate, truncate
    /// or append.
    pub fn mutate_bytes(&mut self, bytes: &mut Vec<u8>) {
        let len = bytes.len();
        match self.below(9) {
            0 if len > 0 => {
                let at = self.index(len);
                bytes[at] ^= 1 << self.below(8);
            }
            1 if len > 0 => {
                let at = self.index(len);
                let random = self.next_u64() as u8;
                bytes[at] = self.pick(&[0, 1, 0x7F, 0x80, 0xFF, random]);
            }
            2 if len >= 4 => {
                let at = self.index(len - 3);
                let old = u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
                let new = self.interesting_u32(old);
                bytes[at..at + 4].copy_from_slice(&new.to_le_bytes());
            }
            3 => {
                let at = self.index(len + 1);
                let count = 1 + self.index(16);
                let fill: Vec<u8> = (0..count).map(|_| self.next_u64() as u8).collect();
                bytes.splice(at..at, fill);
            }
            4 if len > 0 => {
                let at = self.index(len);
                let end = (at + 1 + self.index(64)).min(len);
                bytes.drain(at..end);
            }
            5 if len > 0 => {
                let at = self.index(len);
                let end = (at + 1 + self.index(256)).min(len);
                let copy = bytes[at..end].to_vec();
                let to = self.index(len + 1);
                bytes.splice(to..to, copy);
            }
            6 => bytes.truncate(self.index(len + 1)),
            7 => {
                let count = 1 + self.index(300);
                bytes.extend((0..count).map(|_| self.next_u64() as u8));
            }
            _ if len >= 4 => {
                let at = self.index(len - 3);
                bytes[at..at + 4].copy_from_slice(&self.interesting_f32().to_le_bytes());
            }
            _ => bytes.push(self.next_u64() as u8),
        }
    }
}
