//! Deterministic random sources (no `rand` dependency). Two algorithms, kept apart because
//! tests were written against their exact sequences: [`Rng`] (xorshift64) and
//! [`SplitMix64`]. Never change either: seeds in the tests would draw other inputs.

use glam::DVec3;
use meshpaint::colors::format::Rgba;

/// xorshift64: deterministic, seedable, good enough to scatter test inputs.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
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

    /// Uniform on the unit sphere (rejection sampling from the cube, [`Rng::unit_f64`]).
    pub fn direction(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.unit_f64() * 2.0 - 1.0, self.unit_f64() * 2.0 - 1.0, self.unit_f64() * 2.0 - 1.0);
            let len = v.length();
            if len > 1e-3 && len <= 1.0 {
                return v / len;
            }
        }
    }
}

/// SplitMix64: a small deterministic generator with a different sequence from [`Rng`].
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

    /// An integer in `0..n` (modulo; the bias does not matter for tests).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// A float in `[0, 1)` with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A random colour, alpha included.
    pub fn color(&mut self) -> Rgba {
        [self.unit(), self.unit(), self.unit(), self.unit()]
    }
}
