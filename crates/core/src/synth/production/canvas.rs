//! Textures drawn in code: an RGBA8 canvas filled texel by texel (rows in parallel), smooth
//! value noise for low-detail surfaces, and the box-filter anti-aliasing that keeps sharp
//! edges (text, logos) free of jaggies.

use rayon::prelude::*;

use crate::mesh::scene::Texture;

/// An sRGB colour, channels in `[0, 1]`.
pub type Srgb = [f32; 3];

/// Fills a `width × height` texture with `colour(x, y)` of each texel's centre (texel units,
/// rows top to bottom), rows in parallel; alpha is 1.
pub fn paint(width: u32, height: u32, colour: impl Fn(f64, f64) -> Srgb + Sync) -> Texture {
    let mut rgba8_srgb = vec![0u8; width as usize * height as usize * 4];
    rgba8_srgb.par_chunks_mut(width as usize * 4).enumerate().for_each(|(y, row)| {
        for (x, texel) in row.chunks_exact_mut(4).enumerate() {
            let c = colour(x as f64 + 0.5, y as f64 + 0.5);
            for k in 0..3 {
                texel[k] = (c[k].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            }
            texel[3] = 255;
        }
    });
    Texture { width, height, rgba8_srgb }
}

/// The mean of `colour` over the texel centred at `(x, y)`, from `n × n` point samples (a
/// box filter: edges anti-aliased by the area each side covers).
pub fn supersample(x: f64, y: f64, n: u32, colour: impl Fn(f64, f64) -> Srgb) -> Srgb {
    let mut sum = [0.0f32; 3];
    for j in 0..n {
        for i in 0..n {
            let dx = (f64::from(i) + 0.5) / f64::from(n) - 0.5;
            let dy = (f64::from(j) + 0.5) / f64::from(n) - 0.5;
            let c = colour(x + dx, y + dy);
            for k in 0..3 {
                sum[k] += c[k];
            }
        }
    }
    sum.map(|s| s / (n * n) as f32)
}

/// `a` blended towards `b` by `t`.
pub fn mix(a: Srgb, b: Srgb, t: f32) -> Srgb {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t]
}

/// `colour` scaled by `k`.
pub fn scale(colour: Srgb, k: f32) -> Srgb {
    colour.map(|c| c * k)
}

/// An integer hash of a lattice point and a seed, in `[0, 1)`.
fn hash3(x: i64, y: i64, z: i64, seed: u64) -> f64 {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for v in [x, y, z] {
        h = (h ^ v as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 29;
    }
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^= h >> 32;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth 3D value noise in `[0, 1)`: a lattice of hashed values with smoothstep weights.
pub fn value_noise(p: [f64; 3], seed: u64) -> f64 {
    let cell = p.map(f64::floor);
    let f = [p[0] - cell[0], p[1] - cell[1], p[2] - cell[2]];
    let w = f.map(|t| t * t * (3.0 - 2.0 * t));
    let c = cell.map(|v| v as i64);
    let mut sum = 0.0;
    for corner in 0..8 {
        let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let weight: f64 = (0..3).map(|a| if o[a] == 1 { w[a] } else { 1.0 - w[a] }).product();
        sum += weight * hash3(c[0] + o[0] as i64, c[1] + o[1] as i64, c[2] + o[2] as i64, seed);
    }
    sum
}

/// `octaves` of [`value_noise`], each at twice the frequency and half the amplitude,
/// normalised to `[0, 1)`.
pub fn fractal_noise(p: [f64; 3], octaves: u32, seed: u64) -> f64 {
    let (mut sum, mut amplitude, mut total, mut frequency) = (0.0, 1.0, 0.0, 1.0);
    for octave in 0..octaves {
        sum += amplitude * value_noise(p.map(|c| c * frequency), seed.wrapping_add(u64::from(octave)));
        total += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    sum / total
}

/// Coverage in `[0, 1]` of a shape whose signed distance (negative inside) is `d`, with
/// `footprint` the size of one texel in the same units: a linear ramp one texel wide.
pub fn coverage(d: f64, footprint: f64) -> f32 {
    (0.5 - d / footprint.max(1e-12)).clamp(0.0, 1.0) as f32
}
