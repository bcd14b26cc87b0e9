//! The CPU evaluation of Htex filtering (paper, Algorithm 3) on the atlas pages: what the
//! shader computes with hardware bilinear lookups, in `f32` — the truth the GPU is tested
//! against (keep in sync with crates/render/shaders/htex.wgsl).
//!
//! A point of face `f` lies in the intrinsic triangle of one of its halfedges `h` at
//! `(u, v)` ([`intrinsic_point`]); its colour is `Σ c / Σ a` over three fetches — `h`'s quad
//! at `(u, v)`, `Next(h)`'s at `(v, −u)` and `Prev(h)`'s at `(−v, u)`, each through
//! Algorithm 2 — where `c` is the bilinear colour of the block (zero border) and `a` the
//! bilinear border-normalisation weight at the same point.

use crate::colors::format::Rgba;
use crate::colors::layout::sanitize_barycentric;
use crate::htex::HtexTexture;
use crate::htex::halfedge::{intrinsic_point, next, prev, triangle_to_quad};
use crate::htex::layout::{decode_record, weight_block_x};

impl HtexTexture {
    /// The decoded texel at `(x, y)` of `page` (clamped to the page).
    pub fn texel(&self, page: u32, x: i64, y: i64) -> Rgba {
        let (w, h) = (i64::from(self.layout.page_size), i64::from(self.layout.page_height));
        let (x, y) = (x.clamp(0, w - 1) as u64, y.clamp(0, h - 1) as u64);
        let bpp = self.format.bytes_per_sample() as u64;
        let at = (((u64::from(page) * h as u64 + y) * w as u64 + x) * bpp) as usize;
        self.format.decode(&self.texels[at..at + bpp as usize])
    }

    fn weight_texel(&self, x: i64, y: i64) -> f32 {
        let [w, h] = self.layout.weight_size;
        let (x, y) = (x.clamp(0, i64::from(w) - 1), y.clamp(0, i64::from(h) - 1));
        f32::from(self.weights[(y * i64::from(w) + x) as usize]) / 255.0
    }

    /// One fetch of halfedge `h`'s quad at intrinsic point `uv` and `level`: the bilinear
    /// colour (zero border) and the bilinear normalisation weight.
    pub fn fetch(&self, h: u32, uv: [f32; 2], level: u32) -> (Rgba, f32) {
        let (q, lower, _) = decode_record(self.layout.face_records[(h / 3) as usize][(h % 3) as usize]);
        let p = triangle_to_quad(lower, uv);
        let level = level.min(self.layout.levels - 1);
        let n = self.layout.size(q, level);
        let o = self.layout.origin(q, level);
        let nf = n as f32;
        // In-block texel coordinate, clamped to the border texels' centres.
        let t = [(p[0] * nf).clamp(-0.5, nf + 0.5), (p[1] * nf).clamp(-0.5, nf + 0.5)];
        let split = |v: f32| {
            let f = v.floor();
            (f as i64, v - f)
        };
        let (x0, fx) = split(o.x as f32 + 1.0 + t[0] - 0.5);
        let (y0, fy) = split(o.y as f32 + 1.0 + t[1] - 0.5);
        let c = |dx: i64, dy: i64| self.texel(o.page, x0 + dx, y0 + dy);
        let (c00, c10, c01, c11) = (c(0, 0), c(1, 0), c(0, 1), c(1, 1));
        let color = std::array::from_fn(|k| {
            let bottom = c00[k] + (c10[k] - c00[k]) * fx;
            let top = c01[k] + (c11[k] - c01[k]) * fx;
            bottom + (top - bottom) * fy
        });
        let (wx, wfx) = split(weight_block_x(n.trailing_zeros()) as f32 + 1.0 + t[0] - 0.5);
        let (wy, wfy) = split(1.0 + t[1] - 0.5);
        let a = |dx: i64, dy: i64| self.weight_texel(wx + dx, wy + dy);
        let bottom = a(0, 0) + (a(1, 0) - a(0, 0)) * wfx;
        let top = a(0, 1) + (a(1, 1) - a(0, 1)) * wfx;
        (color, bottom + (top - bottom) * wfy)
    }

    /// Algorithm 3 at intrinsic point `uv` of halfedge `h`'s triangle and `level`.
    pub fn sample_halfedge(&self, h: u32, uv: [f32; 2], level: u32) -> Rgba {
        let [u, v] = uv;
        let (c0, a0) = self.fetch(h, [u, v], level);
        let (c1, a1) = self.fetch(next(h), [v, -u], level);
        let (c2, a2) = self.fetch(prev(h), [-v, u], level);
        let a = a0 + a1 + a2;
        if a <= 0.0 {
            return [0.0; 4];
        }
        std::array::from_fn(|k| (c0[k] + c1[k] + c2[k]) / a)
    }

    /// `face` at barycentric `w` and MIP `level` (clamped to the last level).
    pub fn sample_level(&self, face: u32, w: [f32; 3], level: u32) -> Option<Rgba> {
        self.layout.face_records.get(face as usize)?;
        let (k, uv) = intrinsic_point(sanitize_barycentric(w));
        Some(self.sample_halfedge(3 * face + k, uv, level))
    }

    /// Trilinear filtering at level of detail `lod` (clamped to `[0, levels − 1]`, NaN as
    /// 0): levels `⌊lod⌋` and `⌊lod⌋ + 1` blended, as `packing::sampler::sample_trilinear`.
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
