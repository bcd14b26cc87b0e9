//! The least-squares bake: the samples whose reconstruction is closest to the texture.
//!
//! [`crate::convert::bake::bake_texture`] reads each sample from the texture prefiltered to the
//! sample spacing. The linear filter then interpolates those values, a second blur on top
//! of the prefilter, and each shared sample takes its owner face's mapping across a UV
//! seam. [`refine`] starts from that bake and moves every sample to the values that
//! minimise
//!
//! ```text
//! Σ_faces  area_f · ∫_f | shown(p) − texture(p) |² dp   (linear light, all four channels)
//! ```
//!
//! where `shown` is the CPU reference sampler's linear filter at level 0
//! ([`crate::packing::sampler::sample`], seam fans included: its weights are read off the
//! sampler itself, see below) and `area_f` the face's world area.
//!
//! # Discretisation
//!
//! - **Quadrature.** On each face, the centroids of the `D²` sub-triangles of a lattice
//!   `D`, each weighted `area_f / D²`: `D = max(2 · max(R_f, R_e of its edges),
//!   min(T, MAX_DENSE))` with `T` the face's longest UV edge in texels rounded up to a
//!   power of two (so every texel the face covers holds at least two points, as the fit's
//!   test points in [`crate::convert::adaptive`]; `2·T`, eight or more a texel, cost four
//!   times the reads for a fit within 0.1 dB, docs/ADAPTIVE.md). The texture at a quadrature point is read as the bake reads a
//!   sample of resolution `D`: level 0 bilinear once `D` resolves the texels, prefiltered to
//!   the spacing where [`MAX_DENSE`] caps it, so the integral does not alias. (A quadrature
//!   from the resolution alone read the texture prefiltered to a coarse face's spacing,
//!   which blurs in colours from outside the face's UV triangle: measured on the Duck, the
//!   budget rows fell from 64.6 to 54.7 dB.)
//! - **Weights.** The reconstruction is linear in the stored samples, and which samples it
//!   reads depends on the point and the resolutions only. A probe source
//!   (a [`MeshColorSource`]) first records the samples one lookup reads, then answers with
//!   one-hot colours, four samples a lookup: channel `c` of the result is the weight of
//!   sample `c`. So the fit uses the sampler's own formula, fans included, and a face's
//!   weights depend on its resolution and its edges' only: they are computed once per such
//!   configuration (a *template*: the local mass matrix `Σ_q w_i(q) w_j(q) / D²`).
//! - **Solve.** The normal equations `(A + Λ) x = b + Λ x₀`, assembled into one sparse
//!   matrix, by conjugate gradients with a Jacobi preconditioner, per channel, from the
//!   point bake `x₀`. `Λ = ε · diag(A)` ([`REGULARISATION`]) keeps samples that no quadrature
//!   point sees (faces of zero area, faces without a texture: those show one colour, which
//!   the point bake holds) at `x₀`; a constant texture is reproduced exactly (the weights sum
//!   to 1, so `x₀` already solves the system). Results are clamped to `[0, 1]`, the range of
//!   texels and factors (a fit overshoots next to hard edges). Every sum runs in a fixed order, so a file converts to the same
//!   samples on every run.
//!
//! Faces whose `max(R_f, R_e)` exceeds [`MAX_RESOLUTION`] keep the point bake and do not
//! take part (their quadrature would hold millions of points a face).

use std::cell::RefCell;
use std::collections::HashMap;

use rayon::prelude::*;

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution};
use crate::colors::store::{ColorStore, SampleRef};
use crate::convert::bake::{face_materials, interpolate_uv, material_color, world_area};
use crate::mesh::scene::Scene;
use crate::mesh::weld::WeldedMesh;
use crate::packing::sampler::{Filter, MeshColorSource, sample};
use crate::progress::{Cancelled, Progress, Reporter};

/// `ε` of the regularisation `Λ = ε · diag(A)` (module docs).
pub const REGULARISATION: f64 = 1e-4;

/// Faces finer than this (or with an edge finer than this) keep the point bake.
pub const MAX_RESOLUTION: u32 = 128;

/// The quadrature lattice at most, from the texture (`2·MAX_RESOLUTION` from the resolution).
pub const MAX_DENSE: u32 = 256;

/// Conjugate-gradient iterations at most.
pub const MAX_ITERATIONS: u32 = 64;

/// The solve stops once every channel's residual norm is below this fraction of its start.
pub const TOLERANCE: f64 = 1e-4;

/// Level-0 samples a document may have for [`refine`] to run; larger ones keep the point
/// bake. The solve's working memory is about 250 bytes a sample (the assembled matrix
/// holds about ten entries a sample), so this bounds it near 1 GB.
pub const MAX_SAMPLES: u64 = 1 << 22;

/// How a conversion turns a texture into samples (`--bake`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BakeFit {
    /// Each sample reads the texture prefiltered to the sample spacing, in its owner face
    /// ([`crate::convert::bake::bake_texture`]).
    Point,
    /// The point bake refined to the least-squares fit of the module docs ([`refine`]), on
    /// documents of at most [`MAX_SAMPLES`] samples.
    #[default]
    LeastSquares,
}

/// What [`refine`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RefineReport {
    /// Samples solved for.
    pub samples: u64,
    /// Faces that took part (textured, of non-zero area, within [`MAX_RESOLUTION`]).
    pub faces: u64,
    /// Conjugate-gradient iterations run.
    pub iterations: u32,
    /// The objective (module docs) of the point bake and of the result, before clamping.
    pub objective: (f64, f64),
}

/// A face-local sample: a lattice point of the face, or an edge's own sample at position
/// `p` (from the face edge's start corner) of a finer edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Local {
    Lattice(u32, u32),
    Edge(u8, u32),
}

/// The weights of one face configuration (resolution and its edges' resolutions).
struct Template {
    /// The quadrature lattice `D`.
    dense: u32,
    /// The local samples the reconstruction reads.
    locals: Vec<Local>,
    /// Per quadrature point: its barycentrics and its entries `start..end` in `weights`.
    points: Vec<([f32; 3], u32, u32)>,
    /// `(local sample, weight)` of every point.
    weights: Vec<(u32, f32)>,
    /// The local mass matrix `Σ_q w_i w_j / D²`, as `(row, column, value)`.
    mass: Vec<(u32, u32, f64)>,
}

/// The probe source of the module docs: one face (id 0) of resolution `r` with edges `edges`.
struct Probe {
    r: Resolution,
    edges: [Resolution; 3],
    /// Recording: every local sample read, in order. Probing: the distinct ones.
    reads: RefCell<Vec<Local>>,
    /// `None` while recording; `Some(base)`: sample `base + c` answers one-hot in channel `c`.
    base: RefCell<Option<usize>>,
}

impl Probe {
    fn value(&self, local: Local) -> Rgba {
        let base = *self.base.borrow();
        let mut reads = self.reads.borrow_mut();
        match base {
            None => {
                if !reads.contains(&local) {
                    reads.push(local);
                }
                [0.0; 4]
            }
            Some(base) => {
                let mut out = [0.0; 4];
                if let Some(c) = reads.iter().position(|&l| l == local).and_then(|k| k.checked_sub(base))
                    && c < 4
                {
                    out[c] = 1.0;
                }
                out
            }
        }
    }

    /// The samples the linear filter reads at `bary` and their weights.
    fn weights(&self, bary: [f32; 3]) -> Vec<(Local, f32)> {
        self.reads.borrow_mut().clear();
        *self.base.borrow_mut() = None;
        if sample(self, 0, bary, Filter::Linear, 0).is_none() {
            return Vec::new();
        }
        let count = self.reads.borrow().len();
        let mut out = Vec::with_capacity(count);
        for base in (0..count).step_by(4) {
            *self.base.borrow_mut() = Some(base);
            let Some(color) = sample(self, 0, bary, Filter::Linear, 0) else { return Vec::new() };
            let reads = self.reads.borrow();
            for (c, &local) in reads.iter().enumerate().skip(base).take(4) {
                if color[c - base] != 0.0 {
                    out.push((local, color[c - base]));
                }
            }
        }
        out
    }
}

impl MeshColorSource for Probe {
    fn face_resolution(&self, face: u32) -> Option<Resolution> {
        (face == 0).then_some(self.r)
    }

    fn lattice_color(&self, _face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
        (level == 0 && i + j <= self.r.get()).then(|| self.value(Local::Lattice(i, j)))
    }

    fn edge_resolution(&self, _face: u32, k: u8) -> Option<Resolution> {
        self.edges.get(usize::from(k)).copied()
    }

    fn edge_color(&self, _face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
        let r_edge = self.edges.get(usize::from(k))?;
        (level == 0 && p > 0 && p < r_edge.get()).then(|| self.value(Local::Edge(k, p)))
    }
}

impl Template {
    /// Long: one configuration's quadrature, weights (by probing the sampler) and mass matrix.
    fn new(r: Resolution, edges: [Resolution; 3], dense: u32) -> Self {
        let probe = Probe { r, edges, reads: RefCell::new(Vec::new()), base: RefCell::new(None) };
        let mut index: HashMap<Local, u32> = HashMap::new();
        let mut locals = Vec::new();
        let mut points = Vec::with_capacity((dense * dense) as usize);
        let mut weights = Vec::new();
        for bary in layout::sub_triangle_centroids(dense) {
            let start = weights.len() as u32;
            for (local, w) in probe.weights(bary) {
                let next = locals.len() as u32;
                let id = *index.entry(local).or_insert_with(|| {
                    locals.push(local);
                    next
                });
                weights.push((id, w));
            }
            points.push((bary, start, weights.len() as u32));
        }
        let mut mass: HashMap<(u32, u32), f64> = HashMap::new();
        let area = 1.0 / f64::from(dense * dense);
        for &(_, start, end) in &points {
            let entries = &weights[start as usize..end as usize];
            for &(a, wa) in entries {
                for &(b, wb) in entries {
                    *mass.entry((a, b)).or_insert(0.0) += f64::from(wa) * f64::from(wb) * area;
                }
            }
        }
        let mut mass: Vec<(u32, u32, f64)> = mass.into_iter().map(|((a, b), v)| (a, b, v)).collect();
        mass.sort_unstable_by_key(|&(a, b, _)| (a, b));
        Template { dense, locals, points, weights, mass }
    }
}

/// Global sample numbering: vertices, then every edge's samples, then every face's interior.
struct Numbering {
    vertices: usize,
    edge_base: Vec<usize>,
    face_base: Vec<usize>,
    total: usize,
}

impl Numbering {
    fn new(store: &ColorStore) -> Self {
        let topology = store.topology();
        let vertices = topology.vertex_count as usize;
        let mut next = vertices;
        let edge_base = (0..topology.edge_count())
            .map(|e| {
                let base = next;
                next += store.edge_samples(e).len();
                base
            })
            .collect();
        let face_base = (0..topology.face_count())
            .map(|f| {
                let base = next;
                next += store.interior_samples(f).len();
                base
            })
            .collect();
        Numbering { vertices, edge_base, face_base, total: next }
    }

    fn index(&self, sample: SampleRef) -> Option<usize> {
        match sample {
            SampleRef::Vertex(v) => ((v as usize) < self.vertices).then_some(v as usize),
            SampleRef::Edge { edge, offset } => self.edge_base.get(edge as usize).map(|b| b + offset as usize),
            SampleRef::Interior { face, offset } => self.face_base.get(face as usize).map(|b| b + offset as usize),
        }
    }
}

/// Moves every sample of `store` (the store of `mesh`, already point-baked by
/// [`crate::convert::bake::bake_texture`]) to the least-squares fit of the module docs.
/// `None` (and the store untouched) when it holds more than [`MAX_SAMPLES`] samples.
pub fn refine(store: &mut ColorStore, mesh: &WeldedMesh, scene: &Scene) -> Option<RefineReport> {
    let reporter = Reporter::silent();
    refine_with(store, mesh, scene, reporter.progress()).ok().flatten()
}

/// [`refine`], reporting to `progress` (faces assembled, then the solve's iterations);
/// [`Cancelled`], the store untouched, as soon as it is cancelled.
/// Long: numbering, templates, assembly, the solve and the write-back.
pub fn refine_with(
    store: &mut ColorStore,
    mesh: &WeldedMesh,
    scene: &Scene,
    progress: Progress<'_>,
) -> Result<Option<RefineReport>, Cancelled> {
    if store.sample_count() > MAX_SAMPLES {
        return Ok(None);
    }
    let face_count = store.topology().face_count() as usize;
    let (materials, pyramids) = face_materials(mesh, scene, face_count);
    let numbering = Numbering::new(store);
    let n = numbering.total;
    // Configurations, and each face's template and global sample indices.
    let config = |face: u32| -> Option<(Resolution, [Resolution; 3], u32)> {
        let r = store.face_resolution(face)?;
        let edges = store.topology().face_edges.get(face as usize)?;
        let edges = edges.map(|e| store.edge_resolution(e).unwrap_or(r));
        let finest = edges.iter().map(|e| e.get()).max().unwrap_or(1).max(r.get());
        let texels = materials.get(face as usize).map_or(0.0, |m| m.longest_uv_edge_texels);
        let texels = if texels.is_finite() && texels > 1.0 { (texels.ceil() as u32).next_power_of_two() } else { 1 };
        let dense = (2 * finest).max(texels.min(MAX_DENSE));
        (finest <= MAX_RESOLUTION).then_some((r, edges, dense))
    };
    let mut templates: HashMap<(Resolution, [Resolution; 3], u32), usize> = HashMap::new();
    let mut configs = Vec::new();
    let face_template: Vec<Option<usize>> = (0..face_count as u32)
        .map(|face| {
            let key = config(face)?;
            let next = configs.len();
            Some(*templates.entry(key).or_insert_with(|| {
                configs.push(key);
                next
            }))
        })
        .collect();
    let templates: Vec<Template> =
        configs.par_iter().map(|&(r, edges, dense)| Template::new(r, edges, dense)).collect();
    let global = |face: u32, local: Local| -> Option<usize> {
        let sample = match local {
            Local::Lattice(i, j) => store.face_sample_ref(face, i, j)?,
            Local::Edge(k, p) => {
                let edge = *store.topology().face_edges.get(face as usize)?.get(usize::from(k))?;
                let r_edge = store.edge_resolution(edge)?;
                let reversed = store.topology().is_reversed(face, usize::from(k));
                SampleRef::Edge { edge, offset: layout::edge_storage_offset(r_edge, p, reversed) }
            }
        };
        numbering.index(sample)
    };
    // Per face: its template, world area, global indices and the right-hand side.
    struct FaceSystem {
        template: usize,
        area: f64,
        indices: Vec<usize>,
        rhs: Vec<[f64; 4]>,
    }
    let counter = progress.part(0.0, 0.5).counter("fitting: reading the texture", "faces", face_count);
    let faces: Vec<FaceSystem> = (0..face_count)
        .into_par_iter()
        .filter_map(|face| {
            counter.add(1);
            if counter.is_cancelled() {
                return None;
            }
            let template = face_template[face]?;
            let t = &templates[template];
            let area = world_area(mesh, face);
            let material = materials.get(face)?;
            // A face without a texture shows one colour (its factor), which the point bake
            // holds; it takes no part, so material boundaries stay where the owner rule puts them.
            if area.is_nan() || area <= 0.0 || material.texture.is_none() {
                return None;
            }
            let indices: Option<Vec<usize>> = t.locals.iter().map(|&l| global(face as u32, l)).collect();
            let indices = indices?;
            let uvs = mesh.corner_uvs.get(face).copied().unwrap_or([[0.0; 2]; 3]);
            let weight = area / f64::from(t.dense * t.dense);
            let mut rhs = vec![[0.0f64; 4]; t.locals.len()];
            for &(bary, start, end) in &t.points {
                let truth = material_color(material, &pyramids, interpolate_uv(uvs, bary), t.dense);
                for &(local, w) in &t.weights[start as usize..end as usize] {
                    for c in 0..4 {
                        rhs[local as usize][c] += weight * f64::from(w) * f64::from(truth[c]);
                    }
                }
            }
            Some(FaceSystem { template, area, indices, rhs })
        })
        .collect();
    progress.check()?;
    let mut b = vec![[0.0f64; 4]; n];
    let mut triplets: Vec<(u32, u32, f64)> = Vec::new();
    for face in &faces {
        let t = &templates[face.template];
        for (&g, rhs) in face.indices.iter().zip(&face.rhs) {
            for c in 0..4 {
                b[g][c] += rhs[c];
            }
        }
        triplets.extend(
            t.mass
                .iter()
                .map(|&(r, c, v)| (face.indices[r as usize] as u32, face.indices[c as usize] as u32, v * face.area)),
        );
    }
    let taking_part = faces.len() as u64;
    drop(faces);
    let matrix = Csr::from_triplets(n, triplets);
    // The point bake, the starting point and the regularisation's anchor.
    let mut x0 = vec![[0.0f64; 4]; n];
    store.for_each_site(|site| {
        if let (Some(g), Some(color)) = (numbering.index(site.sample), store.get(site.sample)) {
            x0[g] = color.map(f64::from);
        }
    });
    let (x, iterations, objective) = solve(&matrix, &b, &x0, progress.part(0.55, 1.0))?;
    // Clamped to the range of what is fitted (texels and factors lie in [0, 1]): a fit
    // overshoots next to hard edges, and a texture never shows more than full range.
    let solved =
        |sample: SampleRef| numbering.index(sample).and_then(|g| x.get(g)).map(|c| c.map(|v| v.clamp(0.0, 1.0) as f32));
    store.fill_with(|site| solved(site.sample).unwrap_or([0.0; 4]));
    Ok(Some(RefineReport { samples: n as u64, faces: taking_part, iterations, objective }))
}

/// A symmetric sparse matrix in compressed rows.
struct Csr {
    offsets: Vec<usize>,
    columns: Vec<u32>,
    values: Vec<f64>,
    diagonal: Vec<f64>,
}

impl Csr {
    fn from_triplets(n: usize, mut triplets: Vec<(u32, u32, f64)>) -> Self {
        // Stable: equal entries are summed in face order, so the result is deterministic.
        triplets.par_sort_by_key(|&(r, c, _)| (r, c));
        let mut offsets = vec![0usize; n + 1];
        let mut columns = Vec::with_capacity(triplets.len() / 2);
        let mut values: Vec<f64> = Vec::with_capacity(triplets.len() / 2);
        let mut diagonal = vec![0.0; n];
        let mut last: Option<(u32, u32)> = None;
        for (r, c, v) in triplets {
            if last == Some((r, c)) {
                if let Some(slot) = values.last_mut() {
                    *slot += v;
                }
            } else {
                columns.push(c);
                values.push(v);
                offsets[r as usize + 1] += 1;
                last = Some((r, c));
            }
            if r == c {
                diagonal[r as usize] += v;
            }
        }
        for k in 0..n {
            offsets[k + 1] += offsets[k];
        }
        Csr { offsets, columns, values, diagonal }
    }

    /// `y = (A + Λ) x`.
    fn apply(&self, x: &[[f64; 4]], lambda: &[f64], y: &mut [[f64; 4]]) {
        y.par_iter_mut().enumerate().for_each(|(row, out)| {
            let mut sum = x[row].map(|v| v * lambda[row]);
            for k in self.offsets[row]..self.offsets[row + 1] {
                let (column, value) = (self.columns[k] as usize, self.values[k]);
                for c in 0..4 {
                    sum[c] += value * x[column][c];
                }
            }
            *out = sum;
        });
    }
}

/// Preconditioned conjugate gradients on `(A + Λ) x = b + Λ x₀` from `x₀`, each channel on
/// its own; returns the solution, the iterations and the objective before and after.
/// `progress` sees the iterations against [`MAX_ITERATIONS`] (most solves stop earlier).
/// Long: the textbook loop, four channels at once.
type Solution = (Vec<[f64; 4]>, u32, (f64, f64));
fn solve(a: &Csr, b: &[[f64; 4]], x0: &[[f64; 4]], progress: Progress<'_>) -> Result<Solution, Cancelled> {
    let n = b.len();
    let lambda: Vec<f64> = a.diagonal.iter().map(|&d| if d > 0.0 { REGULARISATION * d } else { 1.0 }).collect();
    let inverse: Vec<f64> = a.diagonal.iter().zip(&lambda).map(|(&d, &l)| 1.0 / (d + l)).collect();
    let rhs: Vec<[f64; 4]> = (0..n).map(|k| std::array::from_fn(|c| b[k][c] + lambda[k] * x0[k][c])).collect();
    // Fixed chunks summed in order: the same result on every run and thread count.
    let dot = |u: &[[f64; 4]], v: &[[f64; 4]]| -> [f64; 4] {
        let partial: Vec<[f64; 4]> = u
            .par_chunks(4096)
            .zip(v.par_chunks(4096))
            .map(|(u, v)| u.iter().zip(v).fold([0.0; 4], |sum, (p, q)| add4(sum, std::array::from_fn(|c| p[c] * q[c]))))
            .collect();
        partial.into_iter().fold([0.0; 4], add4)
    };
    // The quadratic part of the objective, ½xᵀAx − bᵀx (the constant ∫t² omitted).
    let objective = |x: &[[f64; 4]], ax: &[[f64; 4]]| -> f64 {
        let xax = dot(x, ax).iter().sum::<f64>();
        let bx = dot(b, x).iter().sum::<f64>();
        0.5 * xax - bx
    };
    let mut x = x0.to_vec();
    let mut ax = vec![[0.0; 4]; n];
    a.apply(&x, &lambda, &mut ax);
    let start = objective(&x, &ax);
    let mut r: Vec<[f64; 4]> = (0..n).map(|k| std::array::from_fn(|c| rhs[k][c] - ax[k][c])).collect();
    let mut z: Vec<[f64; 4]> = (0..n).map(|k| r[k].map(|v| v * inverse[k])).collect();
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let initial = dot(&r, &r).map(f64::sqrt);
    let mut iterations = 0;
    let mut ap = vec![[0.0; 4]; n];
    while iterations < MAX_ITERATIONS {
        let norm = dot(&r, &r).map(f64::sqrt);
        if (0..4).all(|c| norm[c] <= TOLERANCE * initial[c] || norm[c] == 0.0) {
            break;
        }
        iterations += 1;
        progress.check()?;
        progress.report(
            iterations as f32 / MAX_ITERATIONS as f32,
            &format!("fitting: solving for {n} samples, iteration {iterations}"),
        );
        a.apply(&p, &lambda, &mut ap);
        let pap = dot(&p, &ap);
        let alpha: [f64; 4] = std::array::from_fn(|c| if pap[c] > 0.0 { rz[c] / pap[c] } else { 0.0 });
        x.par_iter_mut().zip(&p).for_each(|(x, p)| (0..4).for_each(|c| x[c] += alpha[c] * p[c]));
        r.par_iter_mut().zip(&ap).for_each(|(r, ap)| (0..4).for_each(|c| r[c] -= alpha[c] * ap[c]));
        z.par_iter_mut().zip(&r).zip(&inverse).for_each(|((z, r), &m)| *z = r.map(|v| v * m));
        let next = dot(&r, &z);
        let beta: [f64; 4] = std::array::from_fn(|c| if rz[c] > 0.0 { next[c] / rz[c] } else { 0.0 });
        rz = next;
        p.par_iter_mut().zip(&z).for_each(|(p, z)| (0..4).for_each(|c| p[c] = z[c] + beta[c] * p[c]));
    }
    a.apply(&x, &lambda, &mut ax);
    let end = objective(&x, &ax);
    Ok((x, iterations, (start, end)))
}

fn add4(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    std::array::from_fn(|c| a[c] + b[c])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A source with a distinct pseudo-random colour for every local sample.
    struct Random(Probe);

    fn value(local: Local) -> Rgba {
        let (a, b): (u64, u64) = match local {
            Local::Lattice(i, j) => (u64::from(i) * 7919 + u64::from(j), 1),
            Local::Edge(k, p) => (u64::from(k) * 104_729 + u64::from(p), 2),
        };
        let mut x = a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        std::array::from_fn(|_| {
            x ^= x >> 29;
            x = x.wrapping_mul(0x94D0_49BB_1331_11EB);
            (x >> 40) as f32 / (1u64 << 24) as f32
        })
    }

    impl MeshColorSource for Random {
        fn face_resolution(&self, face: u32) -> Option<Resolution> {
            self.0.face_resolution(face)
        }
        fn lattice_color(&self, _face: u32, level: u32, i: u32, j: u32) -> Option<Rgba> {
            (level == 0 && i + j <= self.0.r.get()).then(|| value(Local::Lattice(i, j)))
        }
        fn edge_resolution(&self, face: u32, k: u8) -> Option<Resolution> {
            self.0.edge_resolution(face, k)
        }
        fn edge_color(&self, _face: u32, k: u8, level: u32, p: u32) -> Option<Rgba> {
            let r_edge = self.0.edges.get(usize::from(k))?;
            (level == 0 && p > 0 && p < r_edge.get()).then(|| value(Local::Edge(k, p)))
        }
    }

    /// The probed weights, applied to random colours, give what the reference sampler gives
    /// on those colours, at points of every sub-triangle of faces with fine sides (fans) and
    /// without; every point's weights sum to 1.
    #[test]
    fn probed_weights_reproduce_the_sampler() {
        let res = |v: u32| Resolution::from_log2(v).unwrap();
        for (r, edges) in [(0, [0, 0, 0]), (0, [3, 0, 2]), (1, [1, 4, 1]), (2, [5, 3, 2]), (3, [3, 3, 3])] {
            let probe =
                Probe { r: res(r), edges: edges.map(res), reads: RefCell::new(Vec::new()), base: RefCell::new(None) };
            let random = Random(Probe {
                r: res(r),
                edges: edges.map(res),
                reads: RefCell::new(Vec::new()),
                base: RefCell::new(None),
            });
            let dense = 2 * (1 << edges.iter().copied().max().unwrap_or(0).max(r));
            let n = dense as f32;
            for j in 0..dense {
                for i in 0..dense - j {
                    let bary = [
                        (n - i as f32 - j as f32 - 2.0 / 3.0) / n,
                        (i as f32 + 1.0 / 3.0) / n,
                        (j as f32 + 1.0 / 3.0) / n,
                    ];
                    let weights = probe.weights(bary);
                    let truth = sample(&random, 0, bary, Filter::Linear, 0).unwrap();
                    let total: f32 = weights.iter().map(|&(_, w)| w).sum();
                    assert!((total - 1.0).abs() < 1e-5, "R 2^{r} edges {edges:?} {bary:?}: weights sum {total}");
                    for (c, expected) in truth.iter().enumerate() {
                        let got: f32 = weights.iter().map(|&(l, w)| w * value(l)[c]).sum();
                        assert!(
                            (got - expected).abs() < 1e-5,
                            "R 2^{r} edges {edges:?} {bary:?} channel {c}: {got} vs {expected}"
                        );
                    }
                }
            }
        }
    }
}
