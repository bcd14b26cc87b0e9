//! Per-face resolution chosen by the content when a textured mesh is converted.
//!
//! # Rules ([`ResolutionRule`])
//!
//! - **Uniform** `R` on every face (the first round's behaviour).
//! - **Texel density**: about one sample per texel the face covers: of the two powers of
//!   two around `√(2A)` (`A` the face's UV area in texels of the base-colour texture's
//!   level 0; a face at `R` holds about `R²/2` samples), the one whose `R²/2` is nearer `A`,
//!   at most `max`. Faces without a texture get `R = 1` (their colour is one constant).
//! - **Error bound** `E`: `R_f` = the lowest power of two (up to the face's content cap)
//!   whose reconstruction stays within `E` of the texture on the face.
//! - **Budget** `N`: the resolutions with the least area-weighted squared error that hold at
//!   most `N` samples (below).
//!
//! # The content cap
//!
//! No rule tries a face past its *content cap*: two samples a texel along its longest UV
//! edge (`2·T`, `T` the smallest power of two ≥ that edge in texels), at least 8, at most
//! `max`. Finer, a sample spacing is under half a texel of a bilinear texture and the error
//! cannot fall by more than rounding. So `max` defaults to the layout's largest
//! ([`Resolution::MAX`]): a logo on a large face gets the `R` its texels need (within a
//! budget), a small face stops where its texels do, and every face's trials grow with the
//! texels it covers rather than with `max²`.
//!
//! # The error of a face at `R` (the metric behind `--error E`)
//!
//! The face's lattice at `R` is baked as [`crate::convert::bake::bake_texture`] bakes it (the
//! texture read trilinearly at the level matched to the sample spacing, in linear light,
//! times the base-colour factor), and reconstructed with the linear filter (eq. 2.4) at
//! the centroids of the `D²` sub-triangles of a denser lattice `D` — the *test points*,
//! `D` = the smallest power of two ≥ the face's longest UV edge in texels, at least
//! 8, at least `2R` and at most `2·max`, so every texel the face covers holds two or more
//! points (twice that `D`, eight or more a texel, cost four times as much; the Duck's and
//! the Fox's rows moved by under 0.1 dB, docs/ADAPTIVE.md) and so does every strip one sample spacing
//! wide along an edge (where a UV seam's
//! foreign colours fade out: with `D` from the texture alone, faces under a texel were
//! tested on a lattice of 8 at every `R`, and at `R ≥ 32` the strip held no point). The truth
//! at a test point is the texture's level 0 read bilinearly there (what a magnified UV
//! render shows) times the factor. The error is the **root mean square** of the
//! differences over the test points and the four channels, the colour channels compared
//! **sRGB-encoded** (as a display and the PSNR of 8-bit images see them; alpha as is;
//! colour units: full range = 1, RMS 0.01 ≈ 40 dB PSNR of 8-bit images). RMS, not the maximum, because a
//! single texel spike should not force a whole face to the finest `R`; the PSNR the
//! measurements report is an RMS measure too.
//!
//! Errors at or below [`ROUNDING`] count as zero (the float rounding of the bake and of
//! the reconstruction), so `E = 0` means lossless within rounding, as for `optimize`, and a
//! constant colour (a 1 × 1 texture, a face whose UVs have no area) needs only `R = 1`.
//!
//! The fit treats each face alone (its edges at its own `R`). In the mesh an edge takes
//! the larger `R` of its two faces, which only adds texture samples along it. Faces are
//! fitted in parallel (rayon).
//!
//! The errors the texel-density and error-bound rules predict are the point bake's. The
//! conversion then refines the bake to the least-squares fit ([`crate::convert::least_squares`],
//! [`BakeFit::LeastSquares`], the default), which shows most faces closer to the texture; an
//! error bound is verified on the store as fitted ([`bake_and_verify`]).
//!
//! A **budget** allocation for the least-squares bake measures what the fit shows instead:
//! the whole mesh is baked and fitted at the three finest uniform `R` whose sample count is
//! at most [`CALIBRATION_FACTOR`] × the budget (counted before the store is allocated), and
//! each face's error at that `R` is measured on that store (its neighbours at the same `R`,
//! as the fit balances shared samples between them). At the other levels, a face's
//! point-bake error is scaled by the gain its fit made at the nearest calibrated level.
//! (Every level was calibrated before: on a 50k-triangle asset, one fit each was most of
//! the time; the finest level alone missed the coarse levels' gains where small budgets put
//! faces, and the Fox at a third of uniform R = 4's samples fell below it.) (A face fitted alone, every sample free,
//! predicts far too little error at low `R`, where the global fit cannot give each face its
//! own vertices: Fox's budget rows fell from 26.6–51.0 dB to 22.2–31.8 dB with it.)
//!
//! Those predictions come from uniform stores, where a face's neighbours share its `R`. In
//! the allocated store a coarse face fans towards finer edges and the fit balances shared
//! samples between faces of different `R`, so a face can show more or less error than
//! predicted. [`REFINEMENT_ROUNDS`] times, the allocation is baked, fitted and measured as
//! shown, each face's predicted distortions are scaled by measured / predicted at its `R`,
//! and the budget is allocated again; the allocation whose store showed the least
//! area-weighted squared error is kept (the first one included).

use std::time::{Duration, Instant};

use rayon::prelude::*;

mod face_fit;
mod measure;

pub use measure::texture_psnr;

use face_fit::{FaceFit, SharedUvs, TestPoint, dense_lattice, shared_uvs};

use crate::colors::budget::SampleCounts;
use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;
use crate::convert::bake::{FaceMaterial, bake_texture, face_materials, world_area};
use crate::convert::least_squares::{self, BakeFit};
use crate::mesh::scene::Scene;
use crate::mesh::topology::Topology;
use crate::mesh::weld::WeldedMesh;
use crate::progress::{Cancelled, Progress, Reporter};

/// Errors (RMS, sRGB-encoded colour units) at or below this are float rounding and count as
/// zero: a constant colour baked and reconstructed differs from its texel by a few ulps.
/// The same value as [`crate::paint::optimize::LOSSLESS_TOLERANCE`].
pub const ROUNDING: f32 = 1e-6;

/// How faces get their resolution when a glTF mesh is converted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ResolutionRule {
    /// The same `R` on every face.
    Uniform(Resolution),
    /// `R` on faces whose material has a base-colour texture, `R = 1` (the lowest) on the
    /// others: what the editor opens a mesh at by default. A face without a texture shows
    /// one colour, or its vertex colours, which `R = 1` holds exactly; painting raises it
    /// (resolution follows the brush), so memory grows only where the artist paints.
    WhereTextured(Resolution),
    /// One sample per texel along each face's longest UV edge, up to `max`.
    TexelDensity {
        /// The largest `R` given.
        max: Resolution,
    },
    /// The face resolutions that minimise the area-weighted squared error over the mesh
    /// with at most `samples` level-0 samples (rate–distortion allocation, module docs).
    Budget {
        /// The level-0 sample budget.
        samples: u64,
        /// The largest `R` given.
        max: Resolution,
    },
    /// The lowest `R` whose reconstruction error (RMS of sRGB-encoded differences) is at most `bound`.
    ErrorBound {
        /// `E`, colour units (full range = 1).
        bound: f32,
        /// The largest `R` given.
        max: Resolution,
    },
}

impl From<Resolution> for ResolutionRule {
    fn from(r: Resolution) -> Self {
        ResolutionRule::Uniform(r)
    }
}

impl ResolutionRule {
    /// A short description for reports (`R = 8`, `texel density ≤ 64`, `error ≤ 0.01, R ≤ 64`).
    pub fn describe(&self) -> String {
        match self {
            ResolutionRule::Uniform(r) => format!("R = {}", r.get()),
            ResolutionRule::WhereTextured(r) => format!("R = {} where textured, 1 elsewhere", r.get()),
            ResolutionRule::TexelDensity { max } => format!("texel density, R ≤ {}", max.get()),
            ResolutionRule::ErrorBound { bound, max } => format!("error ≤ {bound}, R ≤ {}", max.get()),
            ResolutionRule::Budget { samples, max } => format!("≤ {samples} samples, R ≤ {}", max.get()),
        }
    }
}

/// How long the phases of choosing the face resolutions took ([`face_resolutions_phased`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RulePhases {
    /// A budget's calibration: the whole mesh baked and fitted at each uniform `R` it measures.
    pub calibrate: Duration,
    /// Each face's error at each `R` (the predictions; for an error bound or texel density,
    /// the whole choice).
    pub predict: Duration,
    /// A budget's allocations, and its refinement rounds (bake, fit and measure each).
    pub allocate: Duration,
    /// Faces a budget held below what their texels could use: a finer `R` (up to the
    /// face's content cap, two samples a texel) was predicted to show less error, but the
    /// samples went where they removed more. Zero for the other rules.
    pub faces_held_by_budget: u64,
}

/// Each face's resolution under `rule` (`face_count` faces of `mesh`).
/// A budget's allocation predicts the error of the bake `fit` will make (module docs).
pub fn face_resolutions(
    mesh: &WeldedMesh,
    scene: &Scene,
    face_count: usize,
    rule: ResolutionRule,
    fit: BakeFit,
) -> Vec<Resolution> {
    let reporter = Reporter::silent();
    face_resolutions_phased(mesh, scene, face_count, rule, fit, &mut RulePhases::default(), reporter.progress())
        .unwrap_or_else(|Cancelled| vec![Resolution::ONE; face_count])
}

/// [`face_resolutions`], recording how long each phase took in `phases` and reporting to
/// `progress`; [`Cancelled`] as soon as it is cancelled.
pub fn face_resolutions_phased(
    mesh: &WeldedMesh,
    scene: &Scene,
    face_count: usize,
    rule: ResolutionRule,
    fit: BakeFit,
    phases: &mut RulePhases,
    progress: Progress<'_>,
) -> Result<Vec<Resolution>, Cancelled> {
    let started = Instant::now();
    let resolutions = choose_resolutions(mesh, scene, face_count, rule, fit, phases, progress);
    phases.predict += started.elapsed().saturating_sub(phases.calibrate + phases.allocate);
    progress.check()?;
    progress.report(1.0, "face resolutions chosen");
    resolutions
}

/// Long: one arm per rule.
fn choose_resolutions(
    mesh: &WeldedMesh,
    scene: &Scene,
    face_count: usize,
    rule: ResolutionRule,
    fit: BakeFit,
    phases: &mut RulePhases,
    progress: Progress<'_>,
) -> Result<Vec<Resolution>, Cancelled> {
    if let ResolutionRule::Uniform(r) = rule {
        return Ok(vec![r; face_count]);
    }
    let (materials, pyramids) = face_materials(mesh, scene, face_count);
    let shared = shared_uvs(mesh);
    if shared.len() != face_count {
        return Ok(vec![Resolution::ONE; face_count]);
    }
    if let ResolutionRule::Budget { samples, max } = rule {
        let faces = Faces::new(mesh, &materials, &shared, &pyramids, max, progress.part(0.0, 0.1))?;
        // The calibration stores are dropped before the refinement allocates its own.
        let started = Instant::now();
        let calibration = calibration_stores(mesh, scene, samples, max, fit, progress.part(0.1, 0.4))?;
        phases.calibrate = started.elapsed();
        let mut distortion = faces.predicted_distortions(&calibration, progress.part(0.4, 0.6))?;
        drop(calibration);
        let started = Instant::now();
        let first = allocate_budget(mesh, &distortion, samples, max);
        let resolutions =
            refine_allocation(&faces, scene, &mut distortion, first, samples, fit, progress.part(0.6, 1.0))?;
        phases.allocate = started.elapsed();
        phases.faces_held_by_budget = (distortion.iter().zip(&resolutions))
            .filter(|(row, r)| {
                let at = row.get(r.log2() as usize).copied().unwrap_or(0.0);
                row.last().is_some_and(|&finest| finest < at * (1.0 - 1e-6))
            })
            .count() as u64;
        return Ok(resolutions);
    }
    if let ResolutionRule::TexelDensity { max } = rule {
        return Ok(texel_density(&materials, max));
    }
    let material_boundary = if matches!(rule, ResolutionRule::WhereTextured(_)) {
        faces_on_material_boundaries(mesh, face_count)
    } else {
        Vec::new()
    };
    let counter = progress.counter("choosing face resolutions", "faces", face_count);
    let resolutions = (0..face_count)
        .into_par_iter()
        .map(|face| {
            counter.add(1);
            if counter.is_cancelled() {
                return Resolution::ONE;
            }
            let material = &materials[face];
            if material.texture.is_none() {
                // Shared vertices hold one colour: a face touching another material keeps
                // `R` so the blend between the two colours stays within one sample spacing.
                return match rule {
                    ResolutionRule::WhereTextured(r) if material_boundary.get(face).copied().unwrap_or(false) => r,
                    _ => Resolution::ONE,
                };
            }
            let uvs = mesh.corner_uvs.get(face).copied().unwrap_or([[0.0; 2]; 3]);
            match rule {
                ResolutionRule::Uniform(r)
                | ResolutionRule::WhereTextured(r)
                | ResolutionRule::Budget { max: r, .. } => r,
                ResolutionRule::TexelDensity { max } => max,
                ResolutionRule::ErrorBound { bound, max } => {
                    let fit = FaceFit::new(&materials, face, shared[face], &pyramids, uvs, max, None);
                    let cap = face_fit::content_cap(material, max);
                    (0..=cap.log2())
                        .filter_map(|log2| Resolution::from_log2(log2).ok())
                        .find(|&r| fit.error(r) <= bound.max(ROUNDING))
                        .unwrap_or(cap)
                }
            }
        })
        .collect();
    progress.check()?;
    Ok(resolutions)
}

/// The texel-density rule: about one sample per texel a face covers. A face at `R` holds
/// about `R²/2` samples (its interior, half of each edge's, a share of its vertices), so
/// `√(2·A)` for `A` texels of UV area; of the two powers of two around it, each face takes
/// the one whose `R²/2` is nearer `A` (each face on its own: a whole-period shift of its
/// UVs, which moves `A` by float rounding only, changes nothing). Faces without a texture
/// get `R = 1`; at most `max`.
fn texel_density(materials: &[FaceMaterial], max: Resolution) -> Vec<Resolution> {
    materials
        .iter()
        .map(|material| {
            if material.texture.is_none() {
                return Resolution::ONE;
            }
            let texels = f64::from(material.uv_area_texels);
            let ideal = (2.0 * texels).sqrt().max(1.0);
            let log2 = (ideal.log2().floor() as u32).min(max.log2());
            let low = Resolution::from_log2(log2).unwrap_or(max);
            let high = Resolution::from_log2(log2 + 1).unwrap_or(max).min(max);
            let off = |r: Resolution| (f64::from(r.get()).powi(2) / 2.0 - texels).abs();
            if off(low) <= off(high) { low } else { high }
        })
        .collect()
}

/// For each face, whether one of its vertices is shared with a face of another material.
fn faces_on_material_boundaries(mesh: &WeldedMesh, face_count: usize) -> Vec<bool> {
    const NONE: u32 = u32::MAX;
    const MIXED: u32 = u32::MAX - 1;
    let material = |f: usize| mesh.triangle_materials.get(f).copied().flatten().unwrap_or(NONE - 2);
    let mut vertex_material = vec![NONE; mesh.positions_world.len()];
    for (f, triangle) in mesh.triangles.iter().enumerate().take(face_count) {
        for &v in triangle {
            if let Some(slot) = vertex_material.get_mut(v as usize) {
                *slot = match *slot {
                    NONE => material(f),
                    m if m == material(f) => m,
                    _ => MIXED,
                };
            }
        }
    }
    (0..face_count)
        .map(|f| {
            mesh.triangles.get(f).is_some_and(|t| t.iter().any(|&v| vertex_material.get(v as usize) == Some(&MIXED)))
        })
        .collect()
}

/// A mesh's faces as a budget allocation sees them: materials, where each face's shared
/// samples are baked, the texture pyramids, and the largest `R` given.
struct Faces<'a> {
    mesh: &'a WeldedMesh,
    materials: &'a [FaceMaterial],
    shared: &'a [SharedUvs],
    pyramids: &'a [Option<crate::convert::bake::TexturePyramid>],
    max: Resolution,
    /// Each face's test points at its `dense` lattice, kept between the rounds that measure
    /// every face again when they fit in [`FIT_CACHE_BYTES`] (else empty: each round computes
    /// them again).
    cache: Vec<Option<Vec<TestPoint>>>,
}

/// Bytes of test points [`Faces`] keeps between rounds, counted before they are computed.
const FIT_CACHE_BYTES: u64 = 512 << 20;

impl<'a> Faces<'a> {
    fn new(
        mesh: &'a WeldedMesh,
        materials: &'a [FaceMaterial],
        shared: &'a [SharedUvs],
        pyramids: &'a [Option<crate::convert::bake::TexturePyramid>],
        max: Resolution,
        progress: Progress<'_>,
    ) -> Result<Self, Cancelled> {
        let mut faces = Faces { mesh, materials, shared, pyramids, max, cache: Vec::new() };
        let bytes: u64 = materials
            .iter()
            .filter(|material| material.texture.is_some())
            .map(|material| u64::from(dense_lattice(material, max)).pow(2) * std::mem::size_of::<TestPoint>() as u64)
            .sum();
        if bytes <= FIT_CACHE_BYTES {
            let counter = progress.counter("reading the texture under each face", "faces", materials.len());
            let cache = (0..materials.len())
                .into_par_iter()
                .map(|face| {
                    counter.add(1);
                    if counter.is_cancelled() { None } else { faces.fit(face).map(FaceFit::into_points) }
                })
                .collect();
            progress.check()?;
            faces.cache = cache;
        }
        Ok(faces)
    }

    /// Face `face`'s test points and texture; `None` for a face without a texture.
    fn fit(&self, face: usize) -> Option<FaceFit<'_>> {
        self.materials.get(face)?.texture?;
        let uvs = self.mesh.corner_uvs.get(face).copied().unwrap_or([[0.0; 2]; 3]);
        let cached = self.cache.get(face).and_then(Option::as_deref);
        Some(FaceFit::new(self.materials, face, *self.shared.get(face)?, self.pyramids, uvs, self.max, cached))
    }

    /// The distortion the allocation weighs: error² × the face's world area (zero at or
    /// below [`ROUNDING`]).
    fn distortion(&self, face: usize, error: f32) -> f64 {
        if error <= ROUNDING { 0.0 } else { f64::from(error).powi(2) * world_area(self.mesh, face) }
    }

    /// Each face's predicted distortion at each level `R = 2^l` up to `max` (module docs).
    fn predicted_distortions(
        &self,
        calibration: &[Option<ColorStore>],
        progress: Progress<'_>,
    ) -> Result<Vec<Vec<f64>>, Cancelled> {
        let levels = self.max.log2() as usize + 1;
        let counter = progress.counter("predicting each face's error", "faces", self.materials.len());
        let distortions = (0..self.materials.len())
            .into_par_iter()
            .map(|face| {
                counter.add(1);
                match self.fit(face).filter(|_| !counter.is_cancelled()) {
                    None => vec![0.0; levels],
                    Some(fit) => fit
                        .predicted_errors(face as u32, self.max, calibration)
                        .into_iter()
                        .map(|error| self.distortion(face, error))
                        .collect(),
                }
            })
            .collect();
        progress.check()?;
        Ok(distortions)
    }

    /// The error (module docs) of face `face` as `store` shows it, at the face's own `R`
    /// there; `None` for a face without a texture.
    fn shown_error(&self, store: &ColorStore, face: usize) -> Option<f32> {
        let (fit, r) = (self.fit(face)?, store.face_resolution(face as u32)?);
        Some(fit.error_in(store, face as u32, r))
    }

    /// Each face's distortion as `store` shows it ([`Faces::shown_error`]).
    fn shown_distortions(&self, store: &ColorStore, progress: Progress<'_>) -> Result<Vec<f64>, Cancelled> {
        let counter = progress.counter("measuring each face as fitted", "faces", self.materials.len());
        let shown = (0..self.materials.len())
            .into_par_iter()
            .map(|face| {
                counter.add(1);
                if counter.is_cancelled() {
                    return 0.0;
                }
                self.shown_error(store, face).map_or(0.0, |error| self.distortion(face, error))
            })
            .collect();
        progress.check()?;
        Ok(shown)
    }
}

/// Rounds of [`refine_allocation`] after the first allocation.
pub const REFINEMENT_ROUNDS: usize = 2;

/// Measures an allocation on the store the conversion makes of it and corrects the
/// predictions (module docs): the predictions come from uniform stores, where every face's
/// neighbours share its `R`; in the allocated store a coarse face fans towards finer edges
/// and the least-squares fit balances shared samples between faces of different `R`, so a
/// face can show more or less error than predicted. Each round bakes and fits the allocated
/// store (counted first: it holds at most `budget` samples), measures each face's error as
/// shown, scales that face's predicted distortions at every level by measured / predicted at
/// its level, and allocates again. Returns the allocation whose store showed the least
/// area-weighted squared error, the first one included, so a round never makes it worse by
/// that measure. The point bake's predictions are its own errors: nothing to correct.
fn refine_allocation(
    faces: &Faces,
    scene: &Scene,
    distortion: &mut [Vec<f64>],
    first: Vec<Resolution>,
    budget: u64,
    fit: BakeFit,
    progress: Progress<'_>,
) -> Result<Vec<Resolution>, Cancelled> {
    let mesh = faces.mesh;
    let topology = Topology::build(mesh.positions_world.len() as u32, &mesh.triangles).ok();
    let (Some(topology), BakeFit::LeastSquares) = (topology, fit) else {
        return Ok(first);
    };
    let rounds = (REFINEMENT_ROUNDS + 1) as f32;
    let measure = |resolutions: &[Resolution], round: usize| -> Result<Option<Vec<f64>>, Cancelled> {
        let progress = progress.part(round as f32 / rounds, (round + 1) as f32 / rounds);
        let counts = SampleCounts::of_resolutions(&topology, |f| resolutions[f as usize]);
        if counts.samples > budget.min(least_squares::MAX_SAMPLES) {
            return Ok(None);
        }
        let Ok(mut store) = ColorStore::with_resolutions(topology.clone(), resolutions.to_vec(), [1.0; 4]) else {
            return Ok(None);
        };
        progress.report(0.0, "baking the allocation");
        bake_texture(&mut store, mesh, scene);
        if least_squares::refine_with(&mut store, mesh, scene, progress.part(0.05, 0.6))?.is_none() {
            return Ok(None);
        }
        faces.shown_distortions(&store, progress.part(0.6, 1.0)).map(Some)
    };
    let mut current = first;
    let Some(mut shown) = measure(&current, 0)? else { return Ok(current) };
    let mut best = (shown.iter().sum::<f64>(), current.clone());
    for round in 1..=REFINEMENT_ROUNDS {
        for (face, row) in distortion.iter_mut().enumerate() {
            let level = current[face].log2() as usize;
            let predicted = row.get(level).copied().unwrap_or(0.0);
            if predicted > 0.0 && shown[face] > 0.0 {
                let scale = shown[face] / predicted;
                row.iter_mut().for_each(|d| *d *= scale);
            }
        }
        current = allocate_budget(mesh, distortion, budget, faces.max);
        let Some(measured) = measure(&current, round)? else { break };
        shown = measured;
        let total = shown.iter().sum::<f64>();
        if total < best.0 {
            best = (total, current.clone());
        }
    }
    Ok(best.1)
}

/// Rate–distortion allocation (module docs): every face starts at `R = 1`; raises are taken
/// in order of distortion removed per sample added, each face's best raise among those that
/// still fit `budget`, until none fits. `distortion[face][l]` is the face's predicted
/// distortion at `R = 2^l`.
/// Sample counts are exact as the store counts them (an edge holds the larger `R` of its
/// faces), so the result never exceeds the budget (nor goes below the `R = 1` count, the
/// least any mesh needs).
fn allocate_budget(mesh: &WeldedMesh, distortion: &[Vec<f64>], budget: u64, max: Resolution) -> Vec<Resolution> {
    let face_count = distortion.len();
    let levels = max.log2() as usize + 1;
    // Topology: the three edges of each face, as vertex pairs.
    let mut edge_ids = std::collections::HashMap::new();
    let face_edges: Vec<[usize; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            [0, 1, 2].map(|k| {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                let next = edge_ids.len();
                *edge_ids.entry((a, b)).or_insert(next)
            })
        })
        .collect();
    let mut edge_faces: Vec<Vec<usize>> = vec![Vec::new(); edge_ids.len()];
    for (face, edges) in face_edges.iter().enumerate() {
        for &e in edges {
            edge_faces[e].push(face);
        }
    }
    let mut level = vec![0usize; face_count];
    let edge_level = |level: &[usize], e: usize| edge_faces[e].iter().map(|&f| level[f]).max().unwrap_or(0);
    // Samples added by raising `face` from its level to `to`.
    let added = |level: &[usize], face: usize, to: usize| -> u64 {
        let interior = |l: usize| {
            let r = 1u64 << l;
            (r.saturating_sub(1)) * (r.saturating_sub(2)) / 2
        };
        let mut added = interior(to) - interior(level[face]);
        for &e in &face_edges[face] {
            let current = edge_level(level, e);
            if to > current {
                added += (1u64 << to) - (1u64 << current);
            }
        }
        added
    };
    let mut used: u64 = mesh.positions_world.len() as u64;
    // The best raise of a face that adds at most `limit` samples: the level with the most
    // distortion removed per sample. (A face whose best raise no longer fits the budget
    // still takes a smaller one that does.)
    let best = |level: &[usize], face: usize, limit: u64| -> Option<(f64, usize)> {
        ((level[face] + 1)..levels)
            .filter_map(|to| {
                let gain = distortion[face][level[face]] - distortion[face][to];
                let cost = added(level, face, to);
                (gain > 0.0 && cost <= limit).then_some((gain / cost.max(1) as f64, to))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
    };
    let mut heap: std::collections::BinaryHeap<(OrderedRatio, usize, usize)> = (0..face_count)
        .filter_map(|face| {
            best(&level, face, budget.saturating_sub(used)).map(|(ratio, to)| (OrderedRatio(ratio), face, to))
        })
        .collect();
    while let Some((_, face, to)) = heap.pop() {
        // Stale entries (the face or a neighbour moved, or the budget left shrank): recompute.
        let Some((ratio, now_to)) = best(&level, face, budget.saturating_sub(used)) else { continue };
        if now_to != to {
            heap.push((OrderedRatio(ratio), face, now_to));
            continue;
        }
        used += added(&level, face, to);
        level[face] = to;
        if let Some((ratio, to)) = best(&level, face, budget.saturating_sub(used)) {
            heap.push((OrderedRatio(ratio), face, to));
        }
    }
    level.iter().map(|&l| Resolution::from_log2(l as u32).unwrap_or(max)).collect()
}

/// Level-0 samples a calibration store may hold, as a multiple of the budget (module docs).
pub const CALIBRATION_FACTOR: u64 = 4;

/// The least-squares bake of the whole mesh at each uniform `R = 2^l` (`l` up to
/// `log2 max`) whose sample count is at most [`CALIBRATION_FACTOR`] × `budget` (and at most
/// what [`least_squares::refine`] fits), for a budget allocation to measure each face's
/// fitted error on; `None` at the other levels and for the point bake (module docs).
fn calibration_stores(
    mesh: &WeldedMesh,
    scene: &Scene,
    budget: u64,
    max: Resolution,
    bake: BakeFit,
    progress: Progress<'_>,
) -> Result<Vec<Option<ColorStore>>, Cancelled> {
    let levels = max.log2() + 1;
    let topology = Topology::build(mesh.positions_world.len() as u32, &mesh.triangles).ok();
    let (Some(topology), BakeFit::LeastSquares) = (topology, bake) else {
        return Ok((0..levels).map(|_| None).collect());
    };
    let limit = budget.saturating_mul(CALIBRATION_FACTOR).min(least_squares::MAX_SAMPLES);
    // The three finest levels within the limit only (about the budget's own `R`, the next
    // coarser and the next finer): a fit of the whole mesh each, their gains carried to the
    // other levels (module docs). Every level took one before, most of a budget's time on
    // large meshes; the finest alone or two missed the gains of the coarse levels where
    // small budgets put faces (Fox at a third of R = 4's samples fell below uniform R = 4).
    let within: Vec<Resolution> = (0..levels)
        .filter_map(|l| Resolution::from_log2(l).ok())
        .filter(|&r| {
            r.get() <= least_squares::MAX_RESOLUTION && SampleCounts::uniform_on(&topology, r).samples <= limit
        })
        .collect();
    let measured = within[within.len().saturating_sub(3)..].to_vec();
    // Each level's share of the progress: its samples' share of all the levels' samples.
    let weight = |r: Resolution| SampleCounts::uniform_on(&topology, r).samples as f32;
    let total: f32 = measured.iter().map(|&r| weight(r)).sum::<f32>().max(1.0);
    let mut done = 0.0;
    let mut stores: Vec<Option<ColorStore>> = (0..levels).map(|_| None).collect();
    for r in measured {
        let part = progress.part(done / total, (done + weight(r)) / total);
        done += weight(r);
        part.report(0.0, &format!("calibrating: baking at R = {r}"));
        // Counted above, before the store is allocated.
        let mut store = ColorStore::uniform(topology.clone(), r, [1.0; 4]);
        bake_texture(&mut store, mesh, scene);
        if least_squares::refine_with(&mut store, mesh, scene, part.part(0.1, 1.0))?.is_some() {
            stores[r.log2() as usize] = Some(store);
        }
    }
    Ok(stores)
}

/// A ratio ordered by `f64::total_cmp` (for the allocation's heap).
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrderedRatio(f64);

impl Eq for OrderedRatio {}

impl PartialOrd for OrderedRatio {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrderedRatio {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Bakes `store` (the store of `mesh`, at the resolutions [`face_resolutions`] chose for
/// `rule`) with `fit` and, for an error bound, checks every face as the mesh shows it —
/// shared vertices and edges baked from their owner face (or, fitted, balanced between the
/// faces that show them), and coarse faces fanned towards finer edges — raising `R` (up to
/// `max`) of every face still over the bound and baking again, until none is. Returns the
/// rounds.
pub fn bake_and_verify(
    store: &mut ColorStore,
    mesh: &WeldedMesh,
    scene: &Scene,
    rule: ResolutionRule,
    fit: BakeFit,
) -> u32 {
    let reporter = Reporter::silent();
    bake_and_verify_with(store, mesh, scene, rule, fit, reporter.progress()).unwrap_or(0)
}

/// [`bake_and_verify`], reporting to `progress`; [`Cancelled`] (the store part-baked) as soon
/// as it is cancelled. Each verification round takes half of what is left of `progress`.
/// Long: the bake, then the verification loop.
pub fn bake_and_verify_with(
    store: &mut ColorStore,
    mesh: &WeldedMesh,
    scene: &Scene,
    rule: ResolutionRule,
    fit: BakeFit,
    progress: Progress<'_>,
) -> Result<u32, Cancelled> {
    let bake = |store: &mut ColorStore, progress: Progress<'_>| -> Result<(), Cancelled> {
        progress.report(0.0, "baking the texture");
        bake_texture(store, mesh, scene);
        progress.check()?;
        if fit == BakeFit::LeastSquares {
            least_squares::refine_with(store, mesh, scene, progress.part(0.1, 1.0))?;
        }
        Ok(())
    };
    let ResolutionRule::ErrorBound { bound, max } = rule else {
        bake(store, progress)?;
        return Ok(0);
    };
    bake(store, progress.part(0.0, 0.5))?;
    let face_count = store.topology().face_count() as usize;
    let (materials, pyramids) = face_materials(mesh, scene, face_count);
    let shared = shared_uvs(mesh);
    if shared.len() != face_count {
        return Ok(0);
    }
    let faces = Faces::new(mesh, &materials, &shared, &pyramids, max, progress.part(0.5, 0.55))?;
    let mut rounds = 0;
    // Round k verifies in [1 − 2^-k, 1 − 2^-(k+1)] of the whole (the bake had the first half).
    let round_part = |k: i32| progress.part(1.0 - 0.5f32.powi(k), 1.0 - 0.5f32.powi(k + 1));
    loop {
        rounds += 1;
        let part = round_part(rounds as i32);
        let shown: &ColorStore = store;
        let counter = part.part(0.0, 0.2).counter("verifying the error bound", "faces", face_count);
        let cap = |face: usize| materials.get(face).map_or(max, |m| face_fit::content_cap(m, max));
        let over: Vec<u32> = (0..face_count)
            .into_par_iter()
            .filter(|&face| {
                counter.add(1);
                let r = shown.face_resolution(face as u32).unwrap_or(max);
                !counter.is_cancelled()
                    && r < cap(face)
                    && faces.shown_error(shown, face).is_some_and(|error| error > bound.max(ROUNDING))
            })
            .map(|face| face as u32)
            .collect();
        progress.check()?;
        if over.is_empty() {
            return Ok(rounds);
        }
        for face in over {
            let r = store.face_resolution(face).unwrap_or(max);
            let raised = Resolution::from_log2(r.log2() + 1).unwrap_or(max).min(max);
            // The face exists and `raised` is a valid resolution, so this cannot fail.
            let _ = store.set_face_resolution(face, raised);
        }
        bake(store, part.part(0.2, 1.0))?;
    }
}

/// The smallest power of two `≥ x` (at least 1), capped at `max`.
fn power_of_two_at_least(x: f32, max: Resolution) -> Resolution {
    let wanted = if x.is_finite() && x > 1.0 { x.ceil() as u64 } else { 1 };
    let log2 = wanted.next_power_of_two().trailing_zeros().min(max.log2());
    Resolution::from_log2(log2).unwrap_or(max)
}
