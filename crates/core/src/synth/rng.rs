//! Deterministic random sources (no `rand` dependency). Two algorithms, kept apart because
//! tests, benchmarks and fuzz campaigns were written against their exact sequences:
//! [`SplitMix64`] and [`XorShift64`]. Never change either: seeds would draw other inputs.

use crate::colors::format::Rgba;

/// SplitMix64 (Steele, Lea and Flood 2014): small, fast, deterministic, every seed usable.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// An integer in `0..n` (modulo: the bias is below 2^-32 for `n` < 2^32; 0 when `n == 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        if n == 0 { 0 } else { self.next_u64() % n }
    }

    /// A float in `[0, 1)` with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A double in `[0, 1)` with 53 random bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A random colour, alpha included ([`SplitMix64::unit`] per channel).
    pub fn color(&mut self) -> Rgba {
        [self.unit(), self.unit(), self.unit(), self.unit()]
    }
}

/// xorshift64 (Marsaglia 2003): deterministic and seedable; the seed must not be 0.
#[derive(Debug, Clone)]
pub struct XorShift64(pub u64);

impl XorShift64 {
    /// The next 64 random bits (named as the tests written against this sequence call it;
    /// not an `Iterator`: the sequence never ends).
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A float in `[0, 1)` with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A double in `[0, 1)` with 53 random bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A random colour, alpha included.
    pub fn color(&mut self) -> Rgba {
        [self.unit(), self.unit(), self.unit(), self.unit()]
    }

    /// A random opaque colour (three draws; alpha 1).
    pub fn opaque_color(&mut self) -> Rgba {
        [self.unit(), self.unit(), self.unit(), 1.0]
    }

    /// Uniform on the unit sphere (rejection sampling from the cube, [`XorShift64::unit_f64`]).
    pub fn direction(&mut self) -> glam::DVec3 {
        loop {
            let v =
                glam::DVec3::new(self.unit_f64() * 2.0 - 1.0, self.unit_f64() * 2.0 - 1.0, self.unit_f64() * 2.0 - 1.0);
            let len = v.length();
            if len > 1e-3 && len <= 1.0 {
                return v / len;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first outputs of SplitMix64 from seed 0, as published with the algorithm
    /// (Vigna's reference `splitmix64.c`).
    #[test]
    fn splitmix64_matches_the_reference_sequence() {
        let mut rng = SplitMix64(0);
        assert_eq!(rng.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(rng.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(rng.next_u64(), 0x06C4_5D18_8009_454F);
    }

    /// xorshift64 with shifts 13, 7, 17 from seed 1: the first output by hand
    /// (1 ^ 1<<13 = 0x2001; ^ >>7 = 0x2041; ^ <<17 = 0x4082_2041).
    #[test]
    fn xorshift64_matches_the_hand_computed_first_output() {
        assert_eq!(XorShift64(1).next(), 0x4082_2041);
    }
}
