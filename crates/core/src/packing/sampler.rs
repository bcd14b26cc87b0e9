//! The CPU reference sampler: the truth the WGSL shaders are tested against.
//!
//! `sample(source, face, barycentric, filter, level)` evaluates mesh colors on one face:
//! nearest (the highest-weight sample, thesis 2.2.3) or linear (three samples, eq. 2.4,
//! with the seam rule below) at requested MIP level `level`; [`sample_trilinear`] blends
//! two levels. Sources ([`MeshColorSource`]):
//! - [`ColorStore`]: level 0, read straight from the editable maps;
//! - [`crate::packing::unpack::StoreMips`]: every level of a store, its MIP chains evaluated in full `f32`
//!   (the packer's filters with RGBA32F, whose quantisation is the identity);
//! - [`PackedMesh`]: every level of packed buffers in any colour format.
//!
//! The arithmetic is `f32` in the order the shaders use.
//!
//! # Seams between faces of different resolution
//!
//! An edge stores samples at `R_e = max R_f` of its faces. Eq. 2.4 on a coarser face only
//! interpolates every `R_e / R_f`-th of them, so before this rule the two faces showed
//! different colours along the same edge (random colours, two triangles, largest jump
//! 0.52–0.96 at level 0 and 0.13–0.77 at coarser levels over all pairs in 1..=64; the
//! issue measured 0.69 for 8|2, 0.80 for 16|1, 0.91 for 64|4). The rule:
//!
//! 1. **Levels per element.** At requested level `L` a face's own lattice is read at
//!    `min(L, log2 R_f)` (resolution `r`), every vertex at `min(L, vertex_levels − 1)` and
//!    edge `k` at `min(L, log2 R_e)` (resolution `r_e`). None of these depends on the face
//!    reading the element, so at any `L` both faces read the same stored values.
//!    (Before, vertices were read at the face's clamped level: a face past its last level
//!    and its finer neighbour read the shared vertex at different levels.) When the
//!    lattice has edge points (`r >= 2`) all three levels equal `L`, and the edge is read
//!    with stride `r_e / r = R_e / R_f` exactly as before.
//! 2. **Fine sides.** A face edge is a *fine side* at `L` when `r_e > r`. Only a "lower"
//!    sub-triangle `A = (i, j), B = (i+1, j), C = (i, j+1)` can have a side on the face
//!    boundary (AB on edge 0 when `j = 0`, BC on edge 1 when `i + j + 1 = r`, CA on edge 2
//!    when `i = 0`). Sub-triangles without a side on a fine side: eq. 2.4 unchanged.
//! 3. **Centroid fan.** Otherwise, with eq. 2.4's weights `(a, b, c)` of `A, B, C`, the
//!    sub-triangle is fanned from its centroid `G` (colour `(C_A + C_B + C_C)/3`); the
//!    point lies in the sector of the side opposite its smallest weight. For `c` smallest
//!    (sector `G A B`): `γ = 3c`, `t = (b − c)/(1 − 3c)` and
//!    `colour = γ·C_G + (1 − γ)·E_AB(t)`, where `E_AB` is the 1D linear interpolation of
//!    the edge's own `m = r_e / r` segments between `A` and `B` if AB is on a fine side,
//!    else `lerp(C_A, C_B, t)`; the sectors `G B C` (`a` smallest, `γ = 3a`,
//!    `t = (c − a)/(1 − 3a)`) and `G C A` (`b` smallest, `γ = 3b`, `t = (a − b)/(1 − 3b)`)
//!    likewise. Ties go to AB, then BC.
//!
//! Derivation. In sector `G A B` a point is `P = γG + αA + βB` with `γ + α + β = 1`,
//! `α, β >= 0`; since `G = (A + B + C)/3`, its weights in the sub-triangle are
//! `a = α + γ/3`, `b = β + γ/3`, `c = γ/3`, hence `γ = 3c`, `β = b − c`, `α = a − c`, the
//! sector condition is `c <= a, b`, and the parameter along AB is `β/(α + β) = (b−c)/(1−3c)`.
//! The colour is linear on each fan triangle `(G, x_n, x_{n+1})` (`x_n` the edge samples
//! on AB), so the rule is exactly piecewise linear on that triangulation. On AB itself
//! (`c = 0`, `γ = 0`) it is `E_AB`, i.e. the linear interpolation of consecutive edge
//! samples — what the finer face (`r = r_e` there) shows along its own sub-triangle
//! sides. On a side that is not fine it is `lerp`, what the neighbouring sub-triangle
//! shows, so the face stays continuous inside. At every level both faces therefore show
//! `E` along every shared edge (proved by measurement in crates/core/tests/core/seams.rs: zero difference
//! between faces, ≤ 6e-8 from the exact edge interpolation, every pair in 1..=64, pairs
//! with 4096, boundary and non-manifold edges, every level). On uniform-resolution
//! meshes no side is ever fine and `vertex_levels − 1 = log2 R`, so results are
//! bit-identical to eq. 2.4 as before (tested against a copy of the old function).
//!
//! **Trilinear** is the blend of two fixed levels, so it is continuous whenever both
//! faces use the same `lod` ([`sample_trilinear`]; tested). A per-face `lod` from
//! screen-space derivatives, `log2(footprint · R_f)`, does not: two faces of different `R`
//! seeing the same footprint pick levels `log2(R_1 / R_2)` apart (and faces of any `R`
//! with different screen-space shapes differ too), a level-of-detail step along the edge.
//! So the renderer's `lod` is one continuous function of the surface point, built from
//! per-vertex terms ([`crate::packing::lod`]: view depth, the vertex's sample density, the
//! view angle at the vertex), equal on both sides of every shared edge; tests/app/gpu_render.rs
//! renders mixed-resolution edges with trilinear against this sampler at that `lod`. Its
//! level is clamped to the mesh's last level (`vertex_levels − 1`, = `log2 R_f` on uniform
//! meshes) so coarse faces keep following their vertices' chains as far as their finer
//! neighbours do.
//!
//! **Nearest** stays discontinuous by nature: a face shows the value of its own nearest
//! lattice sample, so along a mixed edge the coarser face shows cells `R_e / R_f` times
//! longer than the finer face's, each holding the edge (or vertex) sample at its centre
//! — the two sides agree at the coarse face's lattice points and differ in between.
//!
//! **Alternatives measured** (random colours, the worst case for detail):
//! - *(A) edges at the coarser face's `R`*: zero sampling cost and fewer bytes
//!   (`R_max − R_min` level-0 samples per mixed edge, ≈ 2× with the chain), but the fine
//!   face loses its detail along the edge: RMS 0.27 (8→2), 0.32 (16→1), 0.32 (64→4), 0.20
//!   (64→32) colour units (test `alternative_min_resolution_edges_lose_the_fine_detail`);
//!   a stroke ending on an `R` boundary would be blurred along the boundary.
//! - *(B) additive correction* `L + (1 − c)·δ(t)`: similar cost for one fine side, but
//!   corner sub-triangles meet two fine sides and an `R = 1` face three, where the
//!   corrections overlap; and it is not piecewise linear on a triangulation, so the
//!   tessellated export could not reproduce it exactly.
//! - *The fan (chosen)*: no extra bytes (face records stay 16 B: the shader derives the
//!   fine sides from the `log2 R_e` it already decodes), detail kept exactly, one or two
//!   extra loads only in fanned sub-triangles; its frame time: docs/BENCHMARKS.md, "Render
//!   and GPU" (`meshpaint bench render`).

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution, SampleLocation};
use crate::colors::store::ColorStore;
use crate::packing::linear::{FaceRecord, PackedMesh};

/// How colours between samples are reconstructed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest sample (hexagonal cells).
    Nearest,
    /// Linear interpolation of the three samples of the sub-triangle.
    Linear,
}

/// Anything that can return a face's lattice samples at a MIP level.
pub trait MeshColorSource {
    /// Resolution of `face` (level 0), or `None` for a face that does not exist.
    fn face_resolution(&self, face: u32) -> Option<Resolution>;
    /// The colour at lattice point `(i, j)` of `face` at the requested level `level`: the
    /// face's lattice is that of its own level `min(level, log2 R_f)` (resolution
    /// `R_f >> min(level, log2 R_f)`), its corners are the vertex colours at
    /// `min(level, last vertex level)` (see the module docs: every shared element is read
    /// at a level that does not depend on the face reading it); `None` when the point,
    /// face or level is not available.
    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba>;
    /// Resolution `R_e` (level 0) of face edge `k` of `face`.
    fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution>;
    /// The edge's own sample at position `p` (`1..r_e`, counted from the face edge's start
    /// corner) of face edge `k` at the edge's level `min(level, log2 R_e)`, whose
    /// resolution is `r_e = R_e >> min(level, log2 R_e)`.
    fn edge_color(&self, face: u32, k: u8, level: u32, p: u32) -> Option<Rgba>;
}

impl MeshColorSource for ColorStore {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        ColorStore::face_resolution(self, face)
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        // The store holds level 0 only: a face whose own level is 0 (level 0, or R_f = 1)
        // reads it, vertices included.
        if level.min(ColorStore::face_resolution(self, face)?.log2()) != 0 {
            return None;
        }
        self.face_sample(face, i, j)
    }

    fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution> {
        let edge = *self.topology().face_edges.get(face as usize)?.get(usize::from(k))?;
        ColorStore::edge_resolution(self, edge)
    }

    fn edge_color(&self, face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
        let edge = *self.topology().face_edges.get(face as usize)?.get(usize::from(k))?;
        let r_edge = ColorStore::edge_resolution(self, edge)?;
        if level.min(r_edge.log2()) != 0 || p == 0 || p >= r_edge.get() {
            return None;
        }
        let reversed = self.topology().is_reversed(face, usize::from(k));
        self.edge_samples(edge).get(layout::edge_storage_offset(r_edge, p, reversed) as usize).copied()
    }
}

impl MeshColorSource for PackedMesh {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        self.face_records.get(face as usize)?.resolution()
    }

    fn lattice_color(&self, face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        self.color(packed_sample_index(self, face, level, i, j)?)
    }

    fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution> {
        Some(self.face_records.get(face as usize)?.edge(usize::from(k))?.1)
    }

    fn edge_color(&self, face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
        self.color(packed_edge_index(self, face, k, level, p)?)
    }
}

/// Index in the colour buffer of lattice point `(i, j)` of `face` at the requested level
/// `requested` — the addressing the shaders implement (keep in sync with
/// shaders/mesh_colors.wgsl). The lattice is the face's own level
/// `min(requested, log2 R_f)`; corners are vertex level `min(requested, vertex_levels − 1)`.
pub fn packed_sample_index(packed: &PackedMesh, face: u32, requested: u32, i: u32, j: u32) -> Option<u64> {
    let record = packed.face_records.get(face as usize)?;
    let corners = packed.indices.get(face as usize)?;
    record_sample_index(record, corners, packed.vertex_levels, requested, i, j)
}

/// [`packed_sample_index`] from one face's record and corners.
pub(crate) fn record_sample_index(
    record: &FaceRecord,
    corners: &[u32; 3],
    vertex_levels: u32,
    requested: u32,
    i: u32,
    j: u32,
) -> Option<u64> {
    let r_face = record.resolution()?;
    let level = requested.min(r_face.log2());
    let r = r_face.at_level(level).ok()?;
    Some(match layout::classify_sample(r, i, j, [false; 3])? {
        SampleLocation::Vertex { corner } => {
            let vertex = u64::from(corners[usize::from(corner)]);
            let last = vertex_levels.checked_sub(1)?;
            vertex * u64::from(vertex_levels) + u64::from(requested.min(last))
        }
        SampleLocation::Edge { face_edge, offset } => {
            let k = usize::from(face_edge);
            let (base, r_edge) = record.edge(k)?;
            let stride_log2 = r_edge.log2().checked_sub(r_face.log2())?;
            let r_edge_level = r_edge.at_level(level).ok()?;
            let position = (offset + 1) << stride_log2;
            let reversed = corners[k] > corners[(k + 1) % 3];
            let in_level = layout::edge_storage_offset(r_edge_level, position, reversed);
            u64::from(base) + u64::from(layout::edge_level_offset(r_edge, level).ok()?) + u64::from(in_level)
        }
        SampleLocation::Interior { offset } => {
            let level_offset = layout::interior_level_offset(r_face, level).ok()?;
            u64::from(record.interior_base()) + u64::from(level_offset) + u64::from(offset)
        }
    })
}

/// Index in the colour buffer of the edge's own sample at position `p` (`1..r_e`, from
/// the face edge's start corner) of face edge `k` of `face`, at the edge's level
/// `min(requested, log2 R_e)` (`r_e = R_e >> min(requested, log2 R_e)`).
pub fn packed_edge_index(packed: &PackedMesh, face: u32, k: u8, requested: u32, p: u32) -> Option<u64> {
    let record = packed.face_records.get(face as usize)?;
    let corners = packed.indices.get(face as usize)?;
    record_edge_index(record, corners, k, requested, p)
}

/// [`packed_edge_index`] from one face's record and corners.
pub(crate) fn record_edge_index(record: &FaceRecord, corners: &[u32; 3], k: u8, requested: u32, p: u32) -> Option<u64> {
    let k = usize::from(k);
    let (base, r_edge) = record.edge(k)?;
    let level = requested.min(r_edge.log2());
    let r_level = r_edge.at_level(level).ok()?;
    if p == 0 || p >= r_level.get() {
        return None;
    }
    let reversed = corners[k] > corners[(k + 1) % 3];
    let in_level = layout::edge_storage_offset(r_level, p, reversed);
    Some(u64::from(base) + u64::from(layout::edge_level_offset(r_edge, level).ok()?) + u64::from(in_level))
}

/// Samples `face` at `barycentric` with `filter` at MIP `level`. Returns `None` when the
/// source cannot provide the samples (unknown face, or a level the source lacks).
///
/// `level` is the requested level `L`: the face's lattice is read at `min(L, log2 R_f)`,
/// its vertices at `min(L, last vertex level)` and its edges at `min(L, log2 R_e)`; linear
/// filtering applies the seam rule of the module docs on sub-triangles with a fine side.
pub fn sample<S: MeshColorSource + ?Sized>(
    source: &S,
    face: u32,
    barycentric: [f32; 3],
    filter: Filter,
    level: u32,
) -> Option<Rgba> {
    let r_face = source.face_resolution(face)?;
    let r = r_face.at_level(level.min(r_face.log2())).ok()?;
    match filter {
        Filter::Nearest => {
            let (i, j) = layout::nearest_sample(r, barycentric);
            source.lattice_color(face, level, i, j)
        }
        Filter::Linear => sample_linear(source, face, barycentric, level, r),
    }
}

/// Trilinear filtering at a continuous level of detail `lod` (as the shader's automatic
/// level): the blend `c0 + (c1 − c0)·t` of linear levels `⌊lod⌋` and `⌊lod⌋ + 1`,
/// `t = lod − ⌊lod⌋` (level `⌊lod⌋` alone when `t = 0`). `lod` is clamped below at 0 (NaN
/// reads as 0); levels past an element's last read its last level.
pub fn sample_trilinear<S: MeshColorSource + ?Sized>(
    source: &S,
    face: u32,
    barycentric: [f32; 3],
    lod: f32,
) -> Option<Rgba> {
    let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, crate::colors::layout::MAX_LOG2_RESOLUTION as f32) };
    let l0 = lod.floor() as u32;
    let t = lod - l0 as f32;
    let c0 = sample(source, face, barycentric, Filter::Linear, l0)?;
    if t <= 0.0 {
        return Some(c0);
    }
    let c1 = sample(source, face, barycentric, Filter::Linear, l0 + 1)?;
    Some(std::array::from_fn(|c| c0[c] + (c1[c] - c0[c]) * t))
}

/// Linear filtering at requested level `level` on the face's lattice of resolution `r`
/// (its own level), with the seam rule on sub-triangles that have a side on a fine edge.
fn sample_linear<S: MeshColorSource + ?Sized>(
    source: &S,
    face: u32,
    barycentric: [f32; 3],
    level: u32,
    r: Resolution,
) -> Option<Rgba> {
    let samples = layout::linear_samples(r, barycentric);
    let res = r.get();
    // A "lower" sub-triangle (i, j), (i+1, j), (i, j+1) is the only kind with a side on the
    // face's boundary; `linear_samples` lists it in that order (an "upper" one starts at
    // (i+1, j+1), so its first two samples differ in j).
    let (i, j) = (samples[0].i, samples[0].j);
    let lower = samples[0].j == samples[1].j;
    // Ratio r_e / r of each face edge at this level (1: no finer samples on it).
    let mut ratio = [1u32; 3];
    for k in 0..3u8 {
        let r_edge = source.edge_resolution(face, k)?;
        let r_edge_level = r_edge.get() >> level.min(r_edge.log2());
        ratio[usize::from(k)] = (r_edge_level / res).max(1);
    }
    let on_side = [lower && j == 0, lower && i + j + 1 == res, lower && i == 0];
    let fine = |k: usize| on_side[k] && ratio[k] > 1;
    let mut colors = [[0.0f32; 4]; 3];
    for (slot, s) in colors.iter_mut().zip(&samples) {
        *slot = source.lattice_color(face, level, s.i, s.j)?;
    }
    if !(fine(0) || fine(1) || fine(2)) {
        // No fine side: eq. 2.4, bit-identical to the formula without the seam rule.
        let mut out = [0.0f32; 4];
        for (s, color) in samples.iter().zip(&colors) {
            for c in 0..4 {
                out[c] += s.weight * color[c];
            }
        }
        return Some(out);
    }
    // The fan from the centroid G: the sector of the side opposite the smallest weight.
    let [a, b, c] = [samples[0].weight, samples[1].weight, samples[2].weight];
    let [ca, cb, cc] = colors;
    // (k, γ, numerator of t, start P, end Q, lattice position of P along face edge k)
    let (k, gamma, num, from, to, q) = if c <= a && c <= b {
        (0usize, 3.0 * c, b - c, ca, cb, i)
    } else if a <= b {
        (1usize, 3.0 * a, c - a, cb, cc, j)
    } else {
        (2usize, 3.0 * b, a - b, cc, ca, res.wrapping_sub(j + 1))
    };
    let den = 1.0 - gamma;
    let t = if den > 0.0 { (num / den).clamp(0.0, 1.0) } else { 0.0 };
    let (e0, e1, f) = if fine(k) {
        // The edge's own samples between P and Q: m of them per sub-triangle side.
        let m = ratio[k];
        let x = t * m as f32;
        let n = x.floor().clamp(0.0, (m - 1) as f32) as u32;
        let f = x - n as f32;
        let p0 = q * m + n;
        let e0 = if n == 0 { from } else { source.edge_color(face, k as u8, level, p0)? };
        let e1 = if n + 1 == m { to } else { source.edge_color(face, k as u8, level, p0 + 1)? };
        (e0, e1, f)
    } else {
        (from, to, t)
    };
    Some(std::array::from_fn(|ch| {
        let centroid = (ca[ch] + cb[ch] + cc[ch]) / 3.0;
        let edge = (1.0 - f) * e0[ch] + f * e1[ch];
        gamma * centroid + (1.0 - gamma) * edge
    }))
}
