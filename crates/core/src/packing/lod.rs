//! The level of detail of trilinear filtering: one continuous function over the mesh, so
//! faces of different `R` agree along every shared edge.
//!
//! # Why not screen-space derivatives
//!
//! A texture picks its MIP level per pixel from the screen-space derivatives of its UVs.
//! Done per face on mesh colors (`log2` of the lattice footprint `|∂(u, v)/∂x| · R_f`), two
//! faces meeting at an edge pick different levels whenever their `R` differ (by
//! `log2(R_1 / R_2)`) or their screen-space shapes do, so they read the shared edge's chain
//! at different levels: a level-of-detail step along the edge even though every fixed
//! level is seamless (sampler module docs). The sampler's trilinear filter is continuous
//! across an edge exactly when both faces blend at the same `lod`, so the `lod` itself must
//! be a function of the surface point, not of the face.
//!
//! # The rule
//!
//! At a point `p = Σ bᵢ pᵢ` of a face (barycentrics `b`, corner vertices `pᵢ`):
//!
//! ```text
//! lod(p) = log2(depth(p)) + Σ bᵢ μᵢ
//! depth(p) = Σ bᵢ depthᵢ                       view-space depth (clip w), exact under perspective
//! μᵢ = clamp(log2(κ · ρᵢ / max(|nᵢ · v̂ᵢ|, MIN_COSINE)), −LOD_TERM_LIMIT, LOD_TERM_LIMIT)
//! ```
//!
//! - `κ` is the world size of one pixel at unit depth, `2 tan(fov_y / 2) / height`, so
//!   `depth · κ` is the pixel's footprint on a surface facing the camera, times
//!   `2^LOD_BIAS` ([`LOD_BIAS`]: the measured bias towards finer levels);
//! - `v̂ᵢ` the unit vector from `pᵢ` towards the eye and `nᵢ` the vertex normal (area-weighted
//!   face normals, rounded to `f16` as the GPU stores them): `1 / |n · v̂|` stretches the
//!   footprint on surfaces seen at a grazing angle (the major axis of the pixel's ellipse,
//!   as a texture's derivative LOD takes the larger footprint), at most by `1 / MIN_COSINE`;
//! - `ρᵢ` the vertex's **sample density**, samples per world unit: the largest
//!   `R_f / sqrt(2 A_f)` over the faces around it (a lattice of `R²` sub-triangles of area
//!   `A_f / R²` is one of squares of side `sqrt(2 A_f) / R`). Faces of zero or non-finite area
//!   are skipped; a vertex with none has density 0 (its term clamps to `−LOD_TERM_LIMIT`).
//!
//! Along a shared edge every term depends only on the edge's two vertices and on `p`, so
//! both faces compute the same `lod` there, and at a vertex every face computes the same
//! value: trilinear is seamless at any `R` pair (tests/app/gpu_render.rs renders it). Taking the
//! largest density around a vertex filters for the finest face there: a coarse face next to
//! a fine one blurs a little early near their shared vertices rather than the fine face
//! aliasing — and coarse faces hold smooth content once resolution follows the content.
//! The level is then clamped to `[0, vertex_levels − 1]` as before (sampler module docs).
//!
//! The GPU evaluates `depthᵢ` and `μᵢ` per vertex in the vertex stage and interpolates them
//! (two varyings); the fragment stage adds `log2(depth)`. Keep in sync with `vs_main` /
//! `fs_main` in shaders/mesh_colors.wgsl.

use half::f16;

use super::linear::PackedMesh;
use crate::mesh::normals::{face_cross, unit_or_zero};

/// The smallest `|n · v̂|` the footprint stretch uses: at most 4 levels coarser at grazing
/// angles. Keep in sync with `LOD_MIN_COSINE` in shaders/mesh_colors.wgsl.
pub const MIN_COSINE: f32 = 1.0 / 16.0;

/// Levels added to the level of detail (negative: finer): `κ` is scaled by `2^LOD_BIAS`, so
/// every `μᵢ` and therefore the level at every point moves by the same amount and stays
/// continuous across edges of any `R` pair. Chosen by measuring trilinear against the
/// supersampled reference at near, mid and far distances, biases 0, −0.5, −1, −1.5 and −2
/// (docs/BENCHMARKS.md, issue-46 section): without a bias trilinear lost 4–6 dB to linear at
/// mid distance; at −2 it is within 0.5 dB of linear or better there on the Duck and the Fox
/// and ahead of linear far away. The footprint this rule estimates (the larger axis, the
/// densest face at a vertex, a lattice of squares) is wider than the box the reference
/// averages over, most of all on long thin faces.
pub const LOD_BIAS: f32 = -2.0;

/// `μᵢ` is clamped to `±LOD_TERM_LIMIT`, so no `±∞` or NaN enters the interpolation.
/// Keep in sync with `LOD_TERM_LIMIT` in shaders/mesh_colors.wgsl.
pub const LOD_TERM_LIMIT: f32 = 64.0;

/// Per-vertex inputs of the level of detail, as the GPU stores them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VertexLod {
    /// Samples per world unit around each vertex (see the module docs).
    pub density: Vec<f32>,
    /// Unit vertex normals (area-weighted), each component rounded to `f16`; zero where the
    /// faces around a vertex have no area. Stored as `f16` bits `[x, y, z, 0]`.
    pub normal_bits: Vec<[u16; 4]>,
}

impl VertexLod {
    /// Densities and normals of `packed`'s vertices (computed in `f64`).
    pub fn of(packed: &PackedMesh) -> Self {
        let resolutions: Vec<Option<f64>> =
            packed.face_records.iter().map(|r| r.resolution().map(|r| r.get() as f64)).collect();
        Self::accumulate(&packed.positions, &packed.indices, &|face| resolutions.get(face).copied().flatten())
    }

    /// Normals of a mesh whose densities are known (an MCT file stores them): `density` as
    /// given (its length should be the vertex count), normals as [`VertexLod::of`] computes them.
    pub fn with_density(positions: &[[f32; 3]], indices: &[[u32; 3]], density: Vec<f32>) -> Self {
        let normal_bits = Self::accumulate(positions, indices, &|_| Some(1.0)).normal_bits;
        VertexLod { density, normal_bits }
    }

    /// Densities (from each face's resolution, `None` skips the face) and normals.
    fn accumulate(positions: &[[f32; 3]], indices: &[[u32; 3]], resolution: &dyn Fn(usize) -> Option<f64>) -> Self {
        let n = positions.len();
        let mut density = vec![0.0f64; n];
        let mut normal = vec![[0.0f64; 3]; n];
        for (face, corners) in indices.iter().enumerate() {
            let Some(p) = corners.iter().map(|&v| positions.get(v as usize).copied()).collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let cross = face_cross(p[0], p[1], p[2]);
            let twice_area = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
            let Some(resolution) = resolution(face) else { continue };
            if !(twice_area.is_finite() && twice_area > 0.0) {
                continue;
            }
            let face_density = resolution / twice_area.sqrt();
            for &v in corners {
                let v = v as usize;
                density[v] = density[v].max(face_density);
                for (sum, value) in normal[v].iter_mut().zip(cross) {
                    *sum += value;
                }
            }
        }
        let normal_bits = normal
            .into_iter()
            .map(|nv| {
                let bits = unit_or_zero(nv).map(|x| f16::from_f64(x).to_bits());
                [bits[0], bits[1], bits[2], 0]
            })
            .collect();
        let density = density.iter().map(|&d| if d.is_finite() { d as f32 } else { f32::MAX }).collect();
        VertexLod { density, normal_bits }
    }

    /// The normal of vertex `v` as the GPU reads it.
    pub fn normal(&self, v: usize) -> Option<[f32; 3]> {
        let bits = self.normal_bits.get(v)?;
        Some([0, 1, 2].map(|k| f16::from_bits(bits[k]).to_f32()))
    }
}
