//! Resampling when a resolution changes: 2× refinement and its exact inverse.
//!
//! **Refinement** (going up) interpolates the current signal linearly: on the finer
//! lattice, even points keep their colour and every odd point is the midpoint of the two
//! coarse samples it lies between, `0.5·a + 0.5·b`. Repeating 2× steps is the same
//! piecewise-linear signal as interpolating once at the final resolution, and colours at
//! the old sample positions are unchanged.
//!
//! **Reduction** (going down) filters with a lifting update (the update step of the
//! CDF 5/3 wavelet, generalised to the triangular lattice):
//!
//! ```text
//! coarse(c) = fine(c) + β · Σ_dir ( fine(c + dir) − (0.5·fine(c) + 0.5·fine(c + 2·dir)) )
//! ```
//!
//! over the lattice directions around `c` (two on an edge, six inside a face), with
//! `β = 1/4` on edges and `β = 1/12` inside faces. Each term is the detail the coarse
//! signal cannot represent; β is chosen so that the highest-frequency pattern
//! (alternating ±1) is removed, which is what makes it a low-pass filter. On a signal
//! that a refinement produced every detail is *exactly* zero in floating point (the
//! midpoint is recomputed from the same two operands, and `+` is commutative), so
//! refine-then-reduce restores the original samples bit for bit. The MIP chains use the
//! thesis' averaging filters instead (eq. 2.5/2.6, `packer.rs`): they must never ring.

use crate::colors::format::Rgba;

/// Per-channel `0.5·a + 0.5·b`; symmetric in `a` and `b` bit for bit.
pub fn midpoint(a: Rgba, b: Rgba) -> Rgba {
    std::array::from_fn(|c| 0.5 * a[c] + 0.5 * b[c])
}

/// The lifting detail of `odd` between `a` and `b`: `odd − midpoint(a, b)`.
fn detail(odd: Rgba, a: Rgba, b: Rgba) -> Rgba {
    let m = midpoint(a, b);
    std::array::from_fn(|c| odd[c] - m[c])
}

/// Lifting weight on edges (two neighbours).
pub const EDGE_BETA: f32 = 0.25;
/// Lifting weight inside faces (six neighbours).
pub const FACE_BETA: f32 = 1.0 / 12.0;

/// Refines a polyline of `R + 1` samples (endpoints included) to `2R + 1`.
pub fn refine_polyline(coarse: &[Rgba]) -> Vec<Rgba> {
    let mut fine = Vec::with_capacity(coarse.len() * 2);
    for (k, &sample) in coarse.iter().enumerate() {
        fine.push(sample);
        if let Some(&next) = coarse.get(k + 1) {
            fine.push(midpoint(sample, next));
        }
    }
    fine
}

/// Reduces a polyline of `2R + 1` samples to `R + 1` (endpoints copied). An input of
/// even length or shorter than 3 is returned unchanged.
pub fn reduce_polyline(fine: &[Rgba]) -> Vec<Rgba> {
    if fine.len() < 3 || fine.len().is_multiple_of(2) {
        return fine.to_vec();
    }
    let last = fine.len() - 1;
    (0..=last / 2)
        .map(|k| {
            let c = 2 * k;
            if c == 0 || c == last {
                return fine[c];
            }
            let left = detail(fine[c - 1], fine[c], fine[c - 2]);
            let right = detail(fine[c + 1], fine[c], fine[c + 2]);
            std::array::from_fn(|ch| fine[c][ch] + EDGE_BETA * (left[ch] + right[ch]))
        })
        .collect()
}

/// The six lattice directions `(di, dj)` around a sample.
pub const LATTICE_DIRECTIONS: [(i32, i32); 6] = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)];

/// A dense triangular lattice of colours at resolution `r` (all `(i, j)` with
/// `i + j <= r`), rows of constant `i`.
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice {
    r: u32,
    samples: Vec<Rgba>,
}

impl Lattice {
    /// A lattice of resolution `r` filled with `color`.
    pub fn new(r: u32, color: Rgba) -> Self {
        let count = (r as usize + 1) * (r as usize + 2) / 2;
        Lattice { r, samples: vec![color; count] }
    }

    /// The lattice resolution.
    pub fn resolution(&self) -> u32 {
        self.r
    }

    fn index(&self, i: u32, j: u32) -> Option<usize> {
        if i + j > self.r {
            return None;
        }
        let (i, j, r) = (i as usize, j as usize, self.r as usize);
        Some(i * (r + 1) - i * i.saturating_sub(1) / 2 + j)
    }

    /// The colour at `(i, j)`, or `None` outside the lattice.
    pub fn get(&self, i: u32, j: u32) -> Option<Rgba> {
        self.samples.get(self.index(i, j)?).copied()
    }

    /// Sets the colour at `(i, j)`; ignored outside the lattice.
    pub fn set(&mut self, i: u32, j: u32, color: Rgba) {
        if let Some(slot) = self.index(i, j).and_then(|k| self.samples.get_mut(k)) {
            *slot = color;
        }
    }

    fn at(&self, i: u32, j: u32) -> Rgba {
        self.get(i, j).unwrap_or([0.0; 4])
    }

    /// The 2× finer lattice interpolating this one (see the module docs).
    pub fn refine(&self) -> Lattice {
        let r = self.r * 2;
        let mut fine = Lattice::new(r, [0.0; 4]);
        for a in 0..=r {
            for b in 0..=r - a {
                let color = match (a % 2, b % 2) {
                    (0, 0) => self.at(a / 2, b / 2),
                    (1, 0) => midpoint(self.at(a / 2, b / 2), self.at(a / 2 + 1, b / 2)),
                    (0, _) => midpoint(self.at(a / 2, b / 2), self.at(a / 2, b / 2 + 1)),
                    _ => midpoint(self.at(a / 2 + 1, b / 2), self.at(a / 2, b / 2 + 1)),
                };
                fine.set(a, b, color);
            }
        }
        fine
    }

    /// The 2× coarser lattice. Interior points are filtered by the face lifting update;
    /// boundary points are copied (their edges are reduced as polylines by the caller).
    pub fn reduce(&self) -> Lattice {
        let r = self.r / 2;
        let mut coarse = Lattice::new(r, [0.0; 4]);
        for i in 0..=r {
            for j in 0..=r - i {
                let (ci, cj) = (2 * i, 2 * j);
                let center = self.at(ci, cj);
                let interior = i >= 1 && j >= 1 && i + j < r;
                if !interior {
                    coarse.set(i, j, center);
                    continue;
                }
                let mut sum = [0.0f32; 4];
                for (di, dj) in LATTICE_DIRECTIONS {
                    let step = |k: i32| ((ci as i32 + k * di) as u32, (cj as i32 + k * dj) as u32);
                    let (oi, oj) = step(1);
                    let (fi, fj) = step(2);
                    let d = detail(self.at(oi, oj), center, self.at(fi, fj));
                    for c in 0..4 {
                        sum[c] += d[c];
                    }
                }
                coarse.set(i, j, std::array::from_fn(|c| center[c] + FACE_BETA * sum[c]));
            }
        }
        coarse
    }
}
