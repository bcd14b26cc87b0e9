//! Mesh-colors layout math: pure integer and barycentric functions, no storage.
//!
//! # Conventions (derived here, tested against brute force in `crates/core/tests/core/layout.rs`)
//!
//! A face has corners `c0, c1, c2` and resolution `R = 2^k`, `1 <= R <= MAX_RESOLUTION`.
//! Its samples sit on a triangular lattice indexed by `(i, j)` with `i, j >= 0` and
//! `i + j <= R`. Sample `(i, j)` has barycentric coordinates (thesis eq. 2.3, with the
//! weights named per corner)
//!
//! ```text
//! (w0, w1, w2) = ((R - i - j) / R,  i / R,  j / R)
//! ```
//!
//! so `(0, 0)` is `c0`, `(R, 0)` is `c1` and `(0, R)` is `c2`. The face's edges are
//!
//! | face edge | from → to | samples | position from the start corner |
//! |---|---|---|---|
//! | 0 | c0 → c1 | `j = 0`, `0 < i < R` | `i` |
//! | 1 | c1 → c2 | `i + j = R`, `0 < j < R` | `j` |
//! | 2 | c2 → c0 | `i = 0`, `0 < j < R` | `R - j` |
//!
//! Every other sample (`i >= 1`, `j >= 1`, `i + j <= R - 1`) is an interior sample.
//! Interior samples are stored row by row (`i` ascending, then `j` ascending), which
//! gives the thesis' eq. 3.2: `offset = (i - 1)(2R - 2 - i) / 2 + (j - 1)`.
//!
//! An edge's samples are stored along the edge's *canonical* direction (the topology
//! decides it; `meshpaint` uses lower vertex id → higher vertex id). A face that walks
//! the edge the other way is `reversed`; position `p` along the face edge (1..R-1) is
//! stored at offset `p - 1` when not reversed and `R - 1 - p` when reversed.
//!
//! # MIP chains
//!
//! Level `l` of an element with resolution `R` has resolution `R >> l`; levels run from
//! 0 (finest) to `log2 R` (resolution 1, vertex colours only), so there are
//! `log2 R + 1` levels (thesis eq. 3.3 counts the `log2 R` reductions). Levels are
//! stored one after another, finest first, so a level's offset is the sum of the sizes
//! of the finer levels (thesis eq. 3.4a/b in closed form).
//!
//! # Limits
//!
//! `MAX_RESOLUTION = 2^12`. The largest per-face count is the interior chain of one
//! face, `≈ 2/3 · R²` ≈ 11.2 M samples at `R = 4096`, and every per-face quantity here
//! fits in `u32` with ample headroom (intermediate products are computed in `u64`).
//! Larger resolutions are refused by [`Resolution::new`].

use thiserror::Error;

/// log2 of the largest supported face resolution.
pub const MAX_LOG2_RESOLUTION: u32 = 12;
/// The largest supported face resolution, `2^12 = 4096`.
pub const MAX_RESOLUTION: u32 = 1 << MAX_LOG2_RESOLUTION;

/// Errors of the layout functions.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LayoutError {
    /// The resolution is zero or not a power of two.
    #[error("resolution {0} is not a power of two (allowed: 1, 2, 4, …, {MAX_RESOLUTION})")]
    NotPowerOfTwo(u64),
    /// The resolution exceeds [`MAX_RESOLUTION`].
    #[error("resolution {0} exceeds the largest supported resolution {MAX_RESOLUTION}")]
    TooLarge(u64),
    /// A MIP level beyond the element's chain was asked for.
    #[error("MIP level {level} does not exist for resolution {resolution} (last level {last})")]
    LevelOutOfRange {
        /// The requested level.
        level: u32,
        /// The element's resolution.
        resolution: u32,
        /// The last valid level, `log2 resolution`.
        last: u32,
    },
}

/// A validated face resolution: a power of two in `1..=MAX_RESOLUTION`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Resolution {
    log2: u8,
}

impl Resolution {
    /// Resolution 1: vertex colours only.
    pub const ONE: Resolution = Resolution { log2: 0 };
    /// `R = 64`.
    pub const SIXTY_FOUR: Resolution = Resolution { log2: 6 };
    /// The largest supported resolution.
    pub const MAX: Resolution = Resolution { log2: MAX_LOG2_RESOLUTION as u8 };

    /// Validates `value` as a resolution.
    pub fn new(value: u64) -> Result<Self, LayoutError> {
        if value == 0 || !value.is_power_of_two() {
            return Err(LayoutError::NotPowerOfTwo(value));
        }
        if value > u64::from(MAX_RESOLUTION) {
            return Err(LayoutError::TooLarge(value));
        }
        Ok(Resolution { log2: value.trailing_zeros() as u8 })
    }

    /// The resolution `2^log2`, or an error when `log2 > MAX_LOG2_RESOLUTION`.
    pub fn from_log2(log2: u32) -> Result<Self, LayoutError> {
        if log2 > MAX_LOG2_RESOLUTION {
            return Err(LayoutError::TooLarge(1u64 << log2.min(63)));
        }
        Ok(Resolution { log2: log2 as u8 })
    }

    /// The resolution as a number (`R`).
    pub fn get(self) -> u32 {
        1 << self.log2
    }

    /// `log2 R`, which is also the index of the last MIP level.
    pub fn log2(self) -> u32 {
        u32::from(self.log2)
    }

    /// Number of MIP levels, `log2 R + 1` (the last one has resolution 1).
    pub fn level_count(self) -> u32 {
        self.log2() + 1
    }

    /// The resolution of MIP level `level` (`R >> level`), or an error past the last level.
    pub fn at_level(self, level: u32) -> Result<Resolution, LayoutError> {
        if level > self.log2() {
            return Err(LayoutError::LevelOutOfRange { level, resolution: self.get(), last: self.log2() });
        }
        Ok(Resolution { log2: self.log2 - level as u8 })
    }

    /// The next finer resolution, if within the limit.
    pub fn doubled(self) -> Option<Resolution> {
        Resolution::from_log2(self.log2() + 1).ok()
    }

    /// The next coarser resolution, if above 1.
    pub fn halved(self) -> Option<Resolution> {
        self.log2.checked_sub(1).map(|log2| Resolution { log2 })
    }
}

impl std::fmt::Display for Resolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.get())
    }
}

/// Samples a vertex holds at any resolution (thesis eq. 2.1a).
pub const fn vertex_sample_count() -> u32 {
    1
}

/// Samples strictly inside an edge of resolution `r` (thesis eq. 2.1b): `R - 1`.
pub fn edge_sample_count(r: Resolution) -> u32 {
    r.get() - 1
}

/// Samples strictly inside a face of resolution `r` (thesis eq. 2.1c): `(R - 1)(R - 2) / 2`.
pub fn interior_sample_count(r: Resolution) -> u32 {
    let r = u64::from(r.get());
    // R = 1 gives (0)(-1)/2 = 0: computed as saturating to stay in unsigned arithmetic.
    ((r - 1) * r.saturating_sub(2) / 2) as u32
}

/// All lattice samples of one face, boundary included: `(R + 1)(R + 2) / 2`.
pub fn face_lattice_sample_count(r: Resolution) -> u32 {
    let r = u64::from(r.get());
    ((r + 1) * (r + 2) / 2) as u32
}

/// Where a face-local sample lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SampleLocation {
    /// The sample is corner `corner` (0, 1 or 2) of the face.
    Vertex {
        /// Face corner index.
        corner: u8,
    },
    /// The sample lies strictly inside face edge `face_edge`.
    Edge {
        /// Face edge index (0: c0→c1, 1: c1→c2, 2: c2→c0).
        face_edge: u8,
        /// Offset in the edge's storage (canonical direction), `0..R-1`.
        offset: u32,
    },
    /// The sample is strictly inside the face.
    Interior {
        /// Offset in the face's interior storage, `0..interior_sample_count`.
        offset: u32,
    },
}

/// Classifies the face-local sample `(i, j)` (thesis eq. 2.2, 3.1, 3.2 with the
/// conventions of this module). `reversed[e]` tells whether face edge `e` runs against
/// its edge's canonical direction. Returns `None` when `(i, j)` is outside the lattice.
pub fn classify_sample(r: Resolution, i: u32, j: u32, reversed: [bool; 3]) -> Option<SampleLocation> {
    let res = r.get();
    if i > res || j > res || i + j > res {
        return None;
    }
    let along = |face_edge: u8, position: u32| SampleLocation::Edge {
        face_edge,
        offset: edge_storage_offset(r, position, reversed[usize::from(face_edge)]),
    };
    Some(match (i, j) {
        (0, 0) => SampleLocation::Vertex { corner: 0 },
        (i, 0) if i == res => SampleLocation::Vertex { corner: 1 },
        (0, j) if j == res => SampleLocation::Vertex { corner: 2 },
        (i, 0) => along(0, i),
        (i, j) if i + j == res => along(1, j),
        (0, j) => along(2, res - j),
        (i, j) => SampleLocation::Interior { offset: interior_offset(r, i, j) },
    })
}

/// Storage offset of the sample at `position` (`1..R-1`, counted from the face edge's
/// start corner) on an edge of resolution `r` walked `reversed` or not.
pub fn edge_storage_offset(r: Resolution, position: u32, reversed: bool) -> u32 {
    if reversed { r.get() - 1 - position } else { position - 1 }
}

/// Offset of interior sample `(i, j)` (`i, j >= 1`, `i + j <= R - 1`), thesis eq. 3.2:
/// `(i - 1)(2R - 2 - i) / 2 + (j - 1)`.
pub fn interior_offset(r: Resolution, i: u32, j: u32) -> u32 {
    let (res, i64_, j64) = (u64::from(r.get()), u64::from(i), u64::from(j));
    ((i64_ - 1) * (2 * res - 2 - i64_) / 2 + (j64 - 1)) as u32
}

/// The interior sample `(i, j)` stored at `offset` (inverse of [`interior_offset`]),
/// or `None` when `offset >= interior_sample_count(r)`.
pub fn interior_sample_at(r: Resolution, offset: u32) -> Option<(u32, u32)> {
    if offset >= interior_sample_count(r) {
        return None;
    }
    let res = r.get();
    // Row i holds R - 1 - i samples; walk rows (at most R - 2 of them).
    let mut remaining = offset;
    for i in 1..res.saturating_sub(1) {
        let row = res - 1 - i;
        if remaining < row {
            return Some((i, remaining + 1));
        }
        remaining -= row;
    }
    None
}

/// The face-local lattice coordinates of the sample at `position` along face edge
/// `face_edge` (`position` counted from the face edge's start corner, `0..=R`).
pub fn edge_sample_coords(r: Resolution, face_edge: u8, position: u32) -> (u32, u32) {
    let res = r.get();
    match face_edge {
        0 => (position, 0),
        1 => (res - position, position),
        _ => (0, res - position),
    }
}

/// The barycentric coordinates `(w0, w1, w2)` of lattice sample `(i, j)` (eq. 2.3).
pub fn sample_barycentric(r: Resolution, i: u32, j: u32) -> [f64; 3] {
    let res = f64::from(r.get());
    let (wi, wj) = (f64::from(i) / res, f64::from(j) / res);
    [f64::from(r.get() - i - j) / res, wi, wj]
}

/// Offset of MIP level `level` in an edge chain of resolution `r` (thesis eq. 3.4a):
/// `Σ_{k<level} ((R >> k) - 1) = 2R - 2(R >> level) - level`.
pub fn edge_level_offset(r: Resolution, level: u32) -> Result<u32, LayoutError> {
    let at = r.at_level(level)?;
    Ok(2 * r.get() - 2 * at.get() - level)
}

/// Total samples of an edge's MIP chain, all levels: `2R - 2 - log2 R`.
pub fn edge_chain_len(r: Resolution) -> u32 {
    2 * r.get() - 2 - r.log2()
}

/// Offset of MIP level `level` in a face-interior chain of resolution `r` (thesis eq. 3.4b):
/// `Σ_{k<level} (r_k - 1)(r_k - 2)/2 = (2^(2m+1) - 2^(2(m-l)+1))/3 - 3(2^m - 2^(m-l)) + l`
/// with `m = log2 R`, `l = level`, `r_k = R >> k`.
pub fn interior_level_offset(r: Resolution, level: u32) -> Result<u32, LayoutError> {
    r.at_level(level)?;
    let (m, l) = (u64::from(r.log2()), u64::from(level));
    let squares = ((1u64 << (2 * m + 1)) - (1u64 << (2 * (m - l) + 1))) / 3;
    let linear = 3 * ((1u64 << m) - (1u64 << (m - l)));
    Ok((squares + l - linear) as u32)
}

/// Total samples of a face-interior MIP chain, all levels.
pub fn interior_chain_len(r: Resolution) -> u32 {
    // The last level (resolution 1) and the one before (2) have no interior samples.
    interior_level_offset(r, r.log2()).unwrap_or(0)
}

/// Total colours of a vertex's MIP chain: one per level, `log2 R + 1`.
pub fn vertex_chain_len(r: Resolution) -> u32 {
    r.level_count()
}

/// Sanitises barycentric coordinates for lookup: negatives and NaN become 0, the rest
/// is renormalised to sum 1; all-zero or non-finite input becomes corner 0.
pub fn sanitize_barycentric(bary: [f32; 3]) -> [f32; 3] {
    let clean = bary.map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 });
    let sum = clean[0] + clean[1] + clean[2];
    if !(sum.is_finite() && sum > 0.0) {
        return [1.0, 0.0, 0.0];
    }
    clean.map(|w| w / sum)
}

/// One lattice sample with its filter weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightedSample {
    /// Lattice coordinate `i` (towards corner 1).
    pub i: u32,
    /// Lattice coordinate `j` (towards corner 2).
    pub j: u32,
    /// Filter weight in `[0, 1]`; the three weights of a lookup sum to 1.
    pub weight: f32,
}

/// The three samples of the lattice sub-triangle containing `bary`, with linear weights
/// (thesis eq. 2.4): `B = ⌊R·P⌋`, `w = R·P − B`. When `w_i + w_j <= 1` the point lies in
/// the "lower" sub-triangle `(i,j), (i+1,j), (i,j+1)`, otherwise in the "upper" one
/// `(i+1,j+1), (i+1,j), (i,j+1)`.
///
/// Robust at the extremes: the floor is clamped so that every returned sample is inside
/// the lattice whatever the rounding (a point exactly on corner 1 or on edge 1 would
/// otherwise floor to `i + j = R` and reach outside), and weights are clamped to `[0, 1]`
/// and renormalised. Computed in `f32`, exactly as the WGSL shaders do.
pub fn linear_samples(r: Resolution, bary: [f32; 3]) -> [WeightedSample; 3] {
    let [_, b1, b2] = sanitize_barycentric(bary);
    let res_f = r.get() as f32;
    linear_samples_uv(r, res_f * b1, res_f * b2)
}

/// [`linear_samples`] for a point given in lattice units, `u = R·w1`, `v = R·w2`
/// (`u, v >= 0`, `u + v <= R`; values outside are clamped onto the lattice).
pub fn linear_samples_uv(r: Resolution, u: f32, v: f32) -> [WeightedSample; 3] {
    let res = r.get();
    let (u, v) = (if u.is_nan() { 0.0 } else { u }, if v.is_nan() { 0.0 } else { v });
    let max_index = (res - 1) as f32;
    let i = u.floor().clamp(0.0, max_index) as u32;
    let j = v.floor().clamp(0.0, (res - 1 - i) as f32) as u32;
    let (fu, fv) = (u - i as f32, v - j as f32);
    let upper = fu + fv > 1.0 && i + j + 2 <= res;
    let mut samples = if upper {
        [
            WeightedSample { i: i + 1, j: j + 1, weight: fu + fv - 1.0 },
            WeightedSample { i: i + 1, j, weight: 1.0 - fv },
            WeightedSample { i, j: j + 1, weight: 1.0 - fu },
        ]
    } else {
        [
            WeightedSample { i, j, weight: 1.0 - fu - fv },
            WeightedSample { i: i + 1, j, weight: fu },
            WeightedSample { i, j: j + 1, weight: fv },
        ]
    };
    for sample in &mut samples {
        sample.weight = sample.weight.clamp(0.0, 1.0);
    }
    let sum: f32 = samples.iter().map(|s| s.weight).sum();
    if sum > 0.0 {
        for sample in &mut samples {
            sample.weight /= sum;
        }
    } else {
        samples[0].weight = 1.0;
    }
    samples
}

/// The sample nearest to `bary` for nearest filtering: the sample with the highest linear
/// weight (thesis 2.2.3); ties go to the first of [`linear_samples`]' order.
pub fn nearest_sample(r: Resolution, bary: [f32; 3]) -> (u32, u32) {
    let samples = linear_samples(r, bary);
    let mut best = samples[0];
    for sample in &samples[1..] {
        if sample.weight > best.weight {
            best = *sample;
        }
    }
    (best.i, best.j)
}

/// Sample counts of a mesh colored at one uniform resolution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UniformCounts {
    /// Level-0 samples: `V + E(R−1) + F(R−1)(R−2)/2`.
    pub samples: u64,
    /// Samples of all MIP levels down to resolution 1.
    pub samples_with_mips: u64,
}

/// Sample counts for `vertices`, `edges` and `faces` all at resolution `r`.
pub fn uniform_counts(r: Resolution, vertices: u64, edges: u64, faces: u64) -> UniformCounts {
    UniformCounts {
        samples: vertices + edges * u64::from(edge_sample_count(r)) + faces * u64::from(interior_sample_count(r)),
        samples_with_mips: vertices * u64::from(vertex_chain_len(r))
            + edges * u64::from(edge_chain_len(r))
            + faces * u64::from(interior_chain_len(r)),
    }
}

/// The barycentrics of the centroids of the `dense²` sub-triangles of a lattice `dense`:
/// rows `j` ascending, `i` within, each lower sub-triangle's centroid followed by the upper
/// one's beside it (an even quadrature of the face: each stands for `1/dense²` of its area).
pub fn sub_triangle_centroids(dense: u32) -> impl Iterator<Item = [f32; 3]> {
    let n = dense as f32;
    (0..dense).flat_map(move |j| {
        (0..dense - j).flat_map(move |i| {
            let (u, v) = (i as f32, j as f32);
            let upper = (i + j + 2 <= dense).then_some((u + 2.0 / 3.0, v + 2.0 / 3.0));
            std::iter::once((u + 1.0 / 3.0, v + 1.0 / 3.0))
                .chain(upper)
                .map(move |(cu, cv)| [(n - cu - cv) / n, cu / n, cv / n])
        })
    })
}
