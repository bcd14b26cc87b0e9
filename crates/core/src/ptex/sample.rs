//! The CPU evaluation of a packed Ptex: what hardware bilinear filtering of the packed
//! texture returns at a face's point and level, and the paper's trilinear filtering (two
//! levels blended at a per-pixel level of detail), in `f32` — the truth the Ptex shader is
//! tested against (keep in sync with crates/render/shaders/ptex.wgsl).

use crate::colors::format::Rgba;
use crate::colors::layout::sanitize_barycentric;
use crate::ptex::PackedPtex;

impl PackedPtex {
    /// The decoded texel at `(x, y)`, clamped to the texture (clamp-to-edge).
    pub fn texel(&self, x: i64, y: i64) -> Rgba {
        let x = x.clamp(0, i64::from(self.layout.width) - 1) as u64;
        let y = y.clamp(0, i64::from(self.layout.height) - 1) as u64;
        let bpp = self.format.bytes_per_sample() as u64;
        let at = ((y * u64::from(self.layout.width) + x) * bpp) as usize;
        match self.texels.get(at..at + bpp as usize) {
            Some(bytes) => self.format.decode(bytes),
            None => [0.0; 4],
        }
    }

    /// Hardware bilinear filtering at texel-space point `p` (texel centres at integers).
    pub fn bilinear(&self, p: [f32; 2]) -> Rgba {
        let (x0, y0) = (p[0].floor(), p[1].floor());
        let (fx, fy) = (p[0] - x0, p[1] - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let c00 = self.texel(x0, y0);
        let c10 = self.texel(x0 + 1, y0);
        let c01 = self.texel(x0, y0 + 1);
        let c11 = self.texel(x0 + 1, y0 + 1);
        std::array::from_fn(|c| {
            let bottom = c00[c] + (c10[c] - c00[c]) * fx;
            let top = c01[c] + (c11[c] - c01[c]) * fx;
            bottom + (top - bottom) * fy
        })
    }

    /// `face` at barycentric `w` and MIP `level` (relative to the face's block: slice
    /// `m − min(level, m)`): bilinear filtering of its block there.
    pub fn sample_level(&self, face: u32, w: [f32; 3], level: u32) -> Option<Rgba> {
        let frame = self.layout.frame(face, level)?;
        Some(self.bilinear(frame.point(sanitize_barycentric(w))))
    }

    /// Trilinear filtering at level of detail `lod` (clamped to `[0, levels − 1]`, NaN as 0):
    /// levels `⌊lod⌋` and `⌊lod⌋ + 1` blended, as `packing::sampler::sample_trilinear`.
    pub fn sample_trilinear(&self, face: u32, w: [f32; 3], lod: f32) -> Option<Rgba> {
        let last = (self.layout.levels - 1) as f32;
        let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, last) };
        let l0 = lod.floor() as u32;
        let t = lod - l0 as f32;
        let c0 = self.sample_level(face, w, l0)?;
        if t <= 0.0 {
            return Some(c0);
        }
        let c1 = self.sample_level(face, w, l0 + 1)?;
        Some(std::array::from_fn(|c| c0[c] + (c1[c] - c0[c]) * t))
    }
}
