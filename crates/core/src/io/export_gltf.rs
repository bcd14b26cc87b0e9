//! glTF export: the mesh tessellated at each face's resolution, one vertex per mesh-colors
//! sample, with the sample colours as `COLOR_0`.
//!
//! # What is written
//!
//! A binary glTF (`.glb`) with one scene, one node, one mesh and one triangle primitive:
//!
//! - **one vertex per sample** that a face reads. Samples shared between faces (mesh
//!   vertices, edge samples) become one shared glTF vertex, keyed by the store's
//!   [`SampleRef`]; a face coarser than its edge reads the edge with stride (exactly the
//!   samples [`ColorStore::face_sample_ref`] returns) at its lattice points, and
//!   - **seams**: every sub-triangle of a face with a side on a finer edge (`R_e > R_f`, a
//!     "fine side") is fanned from its centroid instead (the seam rule of
//!     [`crate::packing::sampler`]): one extra vertex at the centroid with the mean colour
//!     of the sub-triangle's three corners, and one triangle from it to each segment of the
//!     sub-triangle's boundary — a fine side contributes its `R_e / R_f` segments between
//!     consecutive edge samples (the same glTF vertices the finer face uses), any other
//!     side one segment. So no exported vertex lies inside another triangle's edge (no
//!     T-junctions) and the fan is exactly the sampler's linear filter;
//! - `POSITION` (float VEC3, with the `min`/`max` glTF requires): sample `(i, j)` of a face
//!   with corners `c0, c1, c2` at resolution `R` sits at
//!   `((R − i − j)/R)·c0 + (i/R)·c1 + (j/R)·c2`, computed in `f64` and rounded to `f32`;
//! - `COLOR_0` (float VEC4): the sample colour, linear RGBA as glTF defines COLOR_0, the
//!   store's `f32` values unchanged except that components outside `[0, 1]` (which glTF
//!   forbids; the store's exact-inverse reduction can overshoot) are clamped to it
//!   ([`tessellation_to_glb_encoded`] also writes normalized u16 or u8, see
//!   [`crate::io::export_fit`]);
//! - indices (unsigned short when every index fits, else unsigned int): for each face in
//!   face order, for `i` in `0..R`, for `j` in `0..R − i`, the sub-triangle
//!   `(i, j), (i+1, j), (i, j+1)` (or its fan, sides in the order (i,j)→(i+1,j)→(i,j+1)→(i,j),
//!   each triangle `(G, start, end)`) and then, when `i + j ≤ R − 2`, the sub-triangle
//!   `(i+1, j), (i+1, j+1), (i, j+1)` — `R²` triangles per face without fine sides, with the
//!   face's winding;
//! - `NORMAL` (float VEC3): smooth normals, so viewers do not shade each sub-triangle flat: the
//!   area-weighted normals of the welded mesh's vertices ([`vertex_normals`]) interpolated at
//!   the vertex's barycentric coordinates in its face and made unit (the face normal where
//!   they cancel). Shared samples get the same normal from either face (an edge sample's
//!   normal depends on the edge's two vertices only);
//! - a material with metallic factor 0 and roughness factor 1, so that viewers show the
//!   colours as diffuse colour.
//!
//! A glTF viewer interpolates `COLOR_0` linearly across each sub-triangle, which is exactly
//! meshpaint's linear filter ([`crate::packing::sampler`], thesis eq. 2.4).
//!
//! Vertices are numbered in order of first use along the index order above, so the same
//! store gives the same bytes.
//!
//! # Refused
//!
//! A store with no faces (a glTF primitive needs at least one vertex), positions that do
//! not match the store's vertex count or are non-finite, non-finite colours (glTF float
//! accessors must be finite), and output past the limits of the format: more than
//! `2^32 − 1` vertices (the largest index is reserved) or a GLB over `2^32 − 1` bytes. The
//! limits are checked from the counts before anything large is allocated.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gltf::json;
use gltf::json::validation::Checked::Valid;
use gltf::json::validation::USize64;
use thiserror::Error;

use crate::colors::layout::{self, Resolution};
use crate::colors::store::{ColorStore, SampleRef};
use crate::mesh::normals::{face_cross, interpolated_normal, unit_or_zero, vertex_normals};

/// The value of `asset.generator` in exported files.
pub const GENERATOR: &str = "meshpaint";

/// Errors of the glTF export.
#[derive(Debug, Error)]
pub enum ExportError {
    /// The store has no faces: there is nothing to tessellate.
    #[error("nothing to export: the mesh has no faces")]
    Empty,
    /// `positions` does not have one entry per store vertex.
    #[error("expected {expected} vertex positions (one per mesh vertex), got {got}")]
    PositionCount {
        /// The store's vertex count.
        expected: u64,
        /// The number of positions given.
        got: u64,
    },
    /// A vertex position is NaN or infinite.
    #[error("vertex {vertex} has a non-finite position")]
    NonFinitePosition {
        /// The vertex.
        vertex: u32,
    },
    /// A sample colour is NaN or infinite.
    #[error("face {face} sample ({i}, {j}) has a non-finite colour")]
    NonFiniteColor {
        /// The face reading the sample.
        face: u32,
        /// Lattice coordinate towards corner 1.
        i: u32,
        /// Lattice coordinate towards corner 2.
        j: u32,
    },
    /// The store could not return a sample its own layout names (an inconsistent store).
    #[error("face {face} sample ({i}, {j}) is missing from the store")]
    MissingSample {
        /// The face.
        face: u32,
        /// Lattice coordinate towards corner 1.
        i: u32,
        /// Lattice coordinate towards corner 2.
        j: u32,
    },
    /// The tessellation exceeds what glTF / GLB can hold.
    #[error(
        "the tessellation is too large for glTF: {vertices} vertices and {triangles} triangles \
         need {bytes} bytes ({limit})"
    )]
    TooLarge {
        /// Vertices the tessellation needs.
        vertices: u64,
        /// Triangles the tessellation needs.
        triangles: u64,
        /// Bytes of the GLB's binary chunk.
        bytes: u64,
        /// Which limit is exceeded.
        limit: &'static str,
    },
    /// Serialising the glTF JSON or assembling the GLB failed.
    #[error("cannot encode the glTF: {0}")]
    Encode(String),
    /// Writing the output file failed.
    #[error("{path}: cannot {action}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What was being done.
        action: &'static str,
        /// The cause.
        source: std::io::Error,
    },
}

/// A store tessellated at each face's resolution: one vertex per sample faces read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tessellation {
    /// Vertex positions (barycentric combinations of the face corners).
    pub positions: Vec<[f32; 3]>,
    /// Unit smooth normals (module documentation).
    pub normals: Vec<[f32; 3]>,
    /// Vertex colours: the sample colours, linear RGBA, clamped to `[0, 1]`.
    pub colors: Vec<[f32; 4]>,
    /// The sample each vertex shows (`None`: the centroid of a fanned sub-triangle).
    pub samples: Vec<Option<SampleRef>>,
    /// Triangles in face order (`R_f²` per face without fine sides; see the module
    /// documentation).
    pub triangles: Vec<[u32; 3]>,
}

/// Vertex and triangle counts of the tessellation of `store`, from the counts alone.
/// The vertex count assumes the store's rule that an edge's resolution is the finest of
/// its faces (every stored edge sample is read); it is exact for any consistent store.
pub fn tessellation_counts(store: &ColorStore) -> (u64, u64) {
    let topology = store.topology();
    let mut used = vec![false; topology.vertex_count as usize];
    for corners in &topology.face_vertices {
        for &v in corners {
            if let Some(flag) = used.get_mut(v as usize) {
                *flag = true;
            }
        }
    }
    let mut vertices = used.iter().filter(|&&u| u).count() as u64;
    let mut triangles = 0u64;
    for edge in 0..topology.edge_count() {
        vertices += store.edge_samples(edge).len() as u64;
    }
    for (face, &r) in store.face_resolutions().iter().enumerate() {
        vertices += u64::from(layout::interior_sample_count(r));
        let (fanned, fan_triangles) = fan_counts(&fine_ratios(store, face as u32), r.get());
        vertices += fanned;
        triangles += u64::from(r.get()) * u64::from(r.get()) - fanned + fan_triangles;
    }
    (vertices, triangles)
}

/// `R_e / R_f` of each face edge of `face` (1: not a fine side).
fn fine_ratios(store: &ColorStore, face: u32) -> [u32; 3] {
    let r_face = store.face_resolution(face).map_or(1, Resolution::get);
    let edges = store.topology().face_edges.get(face as usize).copied().unwrap_or([u32::MAX; 3]);
    edges.map(|edge| (store.edge_resolution(edge).map_or(1, Resolution::get) / r_face).max(1))
}

/// The face edge (if any) on which side `side` (0: (i,j)→(i+1,j), 1: (i+1,j)→(i,j+1),
/// 2: (i,j+1)→(i,j)) of the lower sub-triangle at `(i, j)` lies, at resolution `res`.
fn side_on_edge(res: u32, i: u32, j: u32, side: usize) -> bool {
    match side {
        0 => j == 0,
        1 => i + j + 1 == res,
        _ => i == 0,
    }
}

/// Segments of each side of the lower sub-triangle at `(i, j)`: `R_e / R_f` on a fine
/// side, else 1; `None` when the sub-triangle has no fine side (not fanned).
fn fan_segments(ratios: &[u32; 3], res: u32, i: u32, j: u32) -> Option<[u32; 3]> {
    let segments: [u32; 3] = std::array::from_fn(|side| if side_on_edge(res, i, j, side) { ratios[side] } else { 1 });
    segments.iter().any(|&m| m > 1).then_some(segments)
}

/// Fanned sub-triangles of a face and the triangles their fans have (only lower
/// sub-triangles along the boundary can be fanned).
fn fan_counts(ratios: &[u32; 3], res: u32) -> (u64, u64) {
    let mut boundary: Vec<(u32, u32)> = Vec::with_capacity(3 * res as usize);
    for q in 0..res {
        boundary.extend([(q, 0), (res - 1 - q, q), (0, q)]);
    }
    boundary.sort_unstable();
    boundary.dedup();
    let (mut fanned, mut triangles) = (0u64, 0u64);
    for (i, j) in boundary {
        if let Some(segments) = fan_segments(ratios, res, i, j) {
            fanned += 1;
            triangles += segments.iter().map(|&m| u64::from(m)).sum::<u64>();
        }
    }
    (fanned, triangles)
}

/// Marks a sample that has no glTF vertex yet.
const UNASSIGNED: u32 = u32::MAX;

/// Bytes per vertex in the binary chunk: POSITION (3 × f32) + COLOR_0 (4 × f32).
const VERTEX_BYTES: u64 = 12 + 12 + 16;

/// Room left in the GLB for its headers and JSON chunk (a few kilobytes at most).
const JSON_ALLOWANCE: u64 = 64 << 10;

/// Whether `vertices` vertices are indexed with unsigned shorts (the largest value of
/// the type is reserved, so at most 65 535 vertices).
fn use_u16_indices(vertices: u64) -> bool {
    vertices <= u64::from(u16::MAX)
}

/// Checks the GLB limits for the tessellation of a store with `counts` before the store
/// exists (vertices: the level-0 samples; triangles: `Σ R_f²`; exact for uniform
/// resolutions, which have no fans), as a [`crate::colors::budget::OutputCheck`].
pub fn check_tessellation_counts(counts: &crate::colors::budget::SampleCounts) -> Result<(), String> {
    check_limits(counts.samples, counts.tessellated_triangles).map_err(|error| error.to_string())
}

/// Checks the glTF / GLB limits for a tessellation of this size.
fn check_limits(vertices: u64, triangles: u64) -> Result<(), ExportError> {
    let index_bytes = if use_u16_indices(vertices) { 2 } else { 4 };
    let bytes = vertices
        .saturating_mul(VERTEX_BYTES)
        .saturating_add(triangles.saturating_mul(3 * index_bytes).next_multiple_of(4));
    let too_large = |limit| ExportError::TooLarge { vertices, triangles, bytes, limit };
    if vertices > u64::from(u32::MAX) {
        return Err(too_large("at most 2^32 - 1 vertices can be indexed"));
    }
    if bytes.saturating_add(JSON_ALLOWANCE) > u64::from(u32::MAX) {
        return Err(too_large("a GLB file holds at most 2^32 - 1 bytes"));
    }
    Ok(())
}

/// Tessellates `store` on `positions` (one per store vertex): see the module documentation.
/// Long: one pass over the faces that checks the limits, shares vertices through the slot
/// maps and writes lattice and fan triangles; the fans themselves are [`Fan::emit`].
pub fn tessellate(positions: &[[f32; 3]], store: &ColorStore) -> Result<Tessellation, ExportError> {
    let topology = store.topology();
    if topology.face_count() == 0 {
        return Err(ExportError::Empty);
    }
    if positions.len() as u64 != u64::from(topology.vertex_count) {
        return Err(ExportError::PositionCount {
            expected: u64::from(topology.vertex_count),
            got: positions.len() as u64,
        });
    }
    if let Some(vertex) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(ExportError::NonFinitePosition { vertex: vertex as u32 });
    }
    let (vertex_bound, triangle_count) = tessellation_counts(store);
    check_limits(vertex_bound, triangle_count)?;

    // Dense maps SampleRef → glTF vertex: one slot per mesh vertex and per stored edge
    // sample. Interior samples belong to one face and are never looked up again.
    let mut vertex_slots = vec![UNASSIGNED; topology.vertex_count as usize];
    let mut edge_base = Vec::with_capacity(topology.edge_count() as usize);
    let mut edge_total = 0usize;
    for edge in 0..topology.edge_count() {
        edge_base.push(edge_total);
        edge_total += store.edge_samples(edge).len();
    }
    let mut edge_slots = vec![UNASSIGNED; edge_total];

    let capacity = usize::try_from(vertex_bound).unwrap_or(0);
    let mut out = Tessellation {
        positions: Vec::with_capacity(capacity),
        normals: Vec::with_capacity(capacity),
        colors: Vec::with_capacity(capacity),
        samples: Vec::with_capacity(capacity),
        triangles: Vec::with_capacity(usize::try_from(triangle_count).unwrap_or(0)),
    };
    // Lattice point (i, j) of the current face → vertex, row by row (reused per face).
    let mut lattice: Vec<u32> = Vec::new();
    let smooth = vertex_normals(positions, &topology.face_vertices);
    for (face, corners) in topology.face_vertices.iter().enumerate() {
        let face = face as u32;
        let Some(r) = store.face_resolution(face) else {
            return Err(ExportError::MissingSample { face, i: 0, j: 0 });
        };
        let res = r.get();
        let corner_positions = corners.map(|v| positions.get(v as usize).copied().unwrap_or([0.0; 3]));
        let normals = FaceNormals {
            corners: corners.map(|v| smooth.get(v as usize).copied().unwrap_or([0.0; 3])),
            face: unit_or_zero(face_cross(corner_positions[0], corner_positions[1], corner_positions[2])),
        };
        lattice.clear();
        for i in 0..=res {
            for j in 0..=res - i {
                let missing = ExportError::MissingSample { face, i, j };
                let Some(sample) = store.face_sample_ref(face, i, j) else {
                    return Err(missing);
                };
                let slot = match sample {
                    SampleRef::Vertex(v) => vertex_slots.get_mut(v as usize),
                    SampleRef::Edge { edge, offset } => {
                        edge_base.get(edge as usize).and_then(|&base| edge_slots.get_mut(base + offset as usize))
                    }
                    SampleRef::Interior { .. } => None,
                };
                let known = slot.as_ref().map_or(UNASSIGNED, |s| **s);
                let index = if known != UNASSIGNED {
                    known
                } else {
                    let Some(color) = store.get(sample) else {
                        return Err(missing);
                    };
                    if !color.iter().all(|c| c.is_finite()) {
                        return Err(ExportError::NonFiniteColor { face, i, j });
                    }
                    let index = out.positions.len() as u32;
                    out.positions.push(lattice_position(&corner_positions, r, i, j));
                    out.normals.push(normals.at(layout::sample_barycentric(r, i, j)));
                    out.colors.push(color.map(|c| c.clamp(0.0, 1.0)));
                    out.samples.push(Some(sample));
                    if let Some(slot) = slot {
                        *slot = index;
                    }
                    index
                };
                lattice.push(index);
            }
        }
        // Row i starts at Σ_{k<i} (R + 1 − k) = i(2R + 3 − i)/2.
        let at = |i: u32, j: u32| {
            let row = (i as usize * (2 * res as usize + 3 - i as usize)) / 2;
            lattice.get(row + j as usize).copied().unwrap_or(0)
        };
        let ratios = fine_ratios(store, face);
        for i in 0..res {
            for j in 0..res - i {
                if let Some(segments) = fan_segments(&ratios, res, i, j) {
                    let ends = [at(i, j), at(i + 1, j), at(i, j + 1)];
                    let fan = Fan { face, res, i, j, ends, segments, corner_positions: &corner_positions, normals };
                    fan.emit(store, &edge_base, &mut edge_slots, &mut out)?;
                } else {
                    out.triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
                }
                if i + j + 2 <= res {
                    out.triangles.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    }
    Ok(out)
}

/// One fanned sub-triangle `(i, j), (i+1, j), (i, j+1)` of `face` (module documentation).
struct Fan<'a> {
    face: u32,
    res: u32,
    i: u32,
    j: u32,
    /// glTF vertices of the three corners.
    ends: [u32; 3],
    /// Segments of each side (`R_e / R_f` on a fine side, else 1).
    segments: [u32; 3],
    corner_positions: &'a [[f32; 3]; 3],
    normals: FaceNormals,
}

/// A face's corner vertex normals and its own normal (for [`interpolated_normal`]).
#[derive(Debug, Clone, Copy)]
struct FaceNormals {
    corners: [[f64; 3]; 3],
    face: [f64; 3],
}

impl FaceNormals {
    /// The smooth normal at barycentric `w`.
    fn at(&self, w: [f64; 3]) -> [f32; 3] {
        interpolated_normal(&self.corners, w, self.face)
    }
}

impl Fan<'_> {
    /// Appends the centroid vertex, the fan triangles and any edge-sample vertex not
    /// yet written (shared through `edge_slots` with the finer face).
    fn emit(
        &self,
        store: &ColorStore,
        edge_base: &[usize],
        edge_slots: &mut [u32],
        out: &mut Tessellation,
    ) -> Result<(), ExportError> {
        let Fan { face, res, i, j, ends, segments, corner_positions, normals } = *self;
        let topology = store.topology();
        let corner_colors = ends.map(|v| out.colors.get(v as usize).copied().unwrap_or([0.0; 4]));
        let centroid = out.positions.len() as u32;
        let w = [f64::from(3 * (res - i - j) - 2), f64::from(3 * i + 1), f64::from(3 * j + 1)]
            .map(|w| w / f64::from(3 * res));
        out.positions.push(std::array::from_fn(|a| {
            (w[0] * f64::from(corner_positions[0][a])
                + w[1] * f64::from(corner_positions[1][a])
                + w[2] * f64::from(corner_positions[2][a])) as f32
        }));
        out.normals.push(normals.at(w));
        out.colors
            .push(std::array::from_fn(|c| (corner_colors[0][c] + corner_colors[1][c] + corner_colors[2][c]) / 3.0));
        out.samples.push(None);
        for side in 0..3 {
            let (start, end) = (ends[side], ends[(side + 1) % 3]);
            let m = segments[side];
            if m == 1 {
                out.triangles.push([centroid, start, end]);
                continue;
            }
            // Side `side` lies on face edge `side`; its start corner sits at position q of
            // the face's lattice along that edge.
            let q = [i, j, res - j - 1][side];
            let edge = topology.face_edges.get(face as usize).map_or(u32::MAX, |e| e[side]);
            let Some(r_edge) = store.edge_resolution(edge) else {
                return Err(ExportError::MissingSample { face, i, j });
            };
            let reversed = topology.is_reversed(face, side);
            let mut previous = start;
            for n in 1..=m {
                let vertex = if n == m {
                    end
                } else {
                    let p = q * m + n;
                    let offset = layout::edge_storage_offset(r_edge, p, reversed);
                    let (fi, fj) = layout::edge_sample_coords(r_edge, side as u8, p);
                    let missing = ExportError::MissingSample { face, i: fi, j: fj };
                    let slot_index = edge_base.get(edge as usize).map(|&b| b + offset as usize);
                    let Some(slot) = slot_index.and_then(|k| edge_slots.get_mut(k)) else {
                        return Err(missing);
                    };
                    if *slot == UNASSIGNED {
                        let sample = SampleRef::Edge { edge, offset };
                        let Some(color) = store.get(sample) else {
                            return Err(missing);
                        };
                        if !color.iter().all(|c| c.is_finite()) {
                            return Err(ExportError::NonFiniteColor { face, i: fi, j: fj });
                        }
                        *slot = out.positions.len() as u32;
                        out.positions.push(lattice_position(corner_positions, r_edge, fi, fj));
                        out.normals.push(normals.at(layout::sample_barycentric(r_edge, fi, fj)));
                        out.colors.push(color.map(|c| c.clamp(0.0, 1.0)));
                        out.samples.push(Some(sample));
                    }
                    *slot
                };
                out.triangles.push([centroid, previous, vertex]);
                previous = vertex;
            }
        }
        Ok(())
    }
}

/// Position of lattice point `(i, j)` on the face with `corners` at resolution `r`:
/// the barycentric combination in `f64`, rounded to `f32`.
fn lattice_position(corners: &[[f32; 3]; 3], r: Resolution, i: u32, j: u32) -> [f32; 3] {
    let w = layout::sample_barycentric(r, i, j);
    std::array::from_fn(|a| {
        (w[0] * f64::from(corners[0][a]) + w[1] * f64::from(corners[1][a]) + w[2] * f64::from(corners[2][a])) as f32
    })
}

/// The tessellated mesh as a binary glTF (see the module documentation).
pub fn export_tessellated_glb(positions: &[[f32; 3]], store: &ColorStore) -> Result<Vec<u8>, ExportError> {
    tessellation_to_glb(tessellate(positions, store)?)
}

/// Encodes a tessellation as a binary glTF. The tessellation is consumed so that its
/// memory is released before the file's bytes are assembled.
pub fn tessellation_to_glb(tessellation: Tessellation) -> Result<Vec<u8>, ExportError> {
    tessellation_to_glb_encoded(tessellation, ColorEncoding::Float)
}

/// How `COLOR_0` is stored: float, or normalized unsigned shorts or bytes (glTF allows all
/// three for VEC4 colours; the values are linear in every case).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ColorEncoding {
    /// 4 × f32, 16 bytes per vertex.
    #[default]
    Float,
    /// 4 × normalized u16, 8 bytes per vertex.
    Unorm16,
    /// 4 × normalized u8, 4 bytes per vertex.
    Unorm8,
}

impl ColorEncoding {
    /// Bytes per vertex colour.
    pub fn bytes(self) -> usize {
        match self {
            ColorEncoding::Float => 16,
            ColorEncoding::Unorm16 => 8,
            ColorEncoding::Unorm8 => 4,
        }
    }

    /// The colour (clamped to `[0, 1]`) after storing it this way and reading it back.
    pub fn round_trip(self, color: [f32; 4]) -> [f32; 4] {
        let unit = |c: f32| if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
        match self {
            ColorEncoding::Float => color.map(unit),
            ColorEncoding::Unorm16 => color.map(|c| f32::from((unit(c) * 65535.0).round() as u16) / 65535.0),
            ColorEncoding::Unorm8 => color.map(|c| f32::from((unit(c) * 255.0).round() as u8) / 255.0),
        }
    }

    fn write(self, color: [f32; 4], out: &mut Vec<u8>) {
        let unit = |c: f32| if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
        for c in color {
            match self {
                ColorEncoding::Float => out.extend_from_slice(&c.to_le_bytes()),
                ColorEncoding::Unorm16 => out.extend_from_slice(&((unit(c) * 65535.0).round() as u16).to_le_bytes()),
                ColorEncoding::Unorm8 => out.push((unit(c) * 255.0).round() as u8),
            }
        }
    }
}

/// [`tessellation_to_glb`] with `COLOR_0` stored as `encoding`.
pub fn tessellation_to_glb_encoded(
    tessellation: Tessellation,
    encoding: ColorEncoding,
) -> Result<Vec<u8>, ExportError> {
    let vertices = tessellation.positions.len();
    let triangles = tessellation.triangles.len();
    check_limits(vertices as u64, triangles as u64)?;
    if vertices == 0 || triangles == 0 {
        return Err(ExportError::Empty);
    }
    if tessellation.colors.len() != vertices || tessellation.normals.len() != vertices {
        return Err(ExportError::Encode(format!(
            "{} colours and {} normals for {vertices} vertices",
            tessellation.colors.len(),
            tessellation.normals.len()
        )));
    }
    if let Some(&bad) = tessellation.triangles.iter().flatten().find(|&&index| index as usize >= vertices) {
        return Err(ExportError::Encode(format!("index {bad} out of range ({vertices} vertices)")));
    }

    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &tessellation.positions {
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }

    // Binary chunk, little-endian: positions, normals, colours, indices (each offset a
    // multiple of 4).
    let u16_indices = use_u16_indices(vertices as u64);
    let index_bytes = if u16_indices { 2 } else { 4 } * 3 * triangles;
    let mut bin: Vec<u8> = Vec::with_capacity(vertices * VERTEX_BYTES as usize + index_bytes + 3);
    for value in tessellation.positions.iter().flatten() {
        bin.extend_from_slice(&value.to_le_bytes());
    }
    let normals_offset = bin.len();
    for value in tessellation.normals.iter().flatten() {
        bin.extend_from_slice(&value.to_le_bytes());
    }
    let colors_offset = bin.len();
    for &color in &tessellation.colors {
        encoding.write(color, &mut bin);
    }
    let indices_offset = bin.len();
    for &index in tessellation.triangles.iter().flatten() {
        if u16_indices {
            bin.extend_from_slice(&(index as u16).to_le_bytes());
        } else {
            bin.extend_from_slice(&index.to_le_bytes());
        }
    }
    drop(tessellation);
    let buffer_length = bin.len();
    // The BIN chunk is padded to 4 bytes here (not left to the GLB writer).
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }

    let root = gltf_root(GltfLayout {
        vertices,
        triangles,
        buffer_length,
        normals_offset,
        colors_offset,
        indices_offset,
        u16_indices,
        min,
        max,
        encoding,
    });
    let json_string = json::serialize::to_string(&root).map_err(|err| ExportError::Encode(err.to_string()))?;
    let total = 12 + 8 + json_string.len().next_multiple_of(4) + 8 + bin.len();
    let Ok(length) = u32::try_from(total) else {
        return Err(ExportError::TooLarge {
            vertices: vertices as u64,
            triangles: triangles as u64,
            bytes: total as u64,
            limit: "a GLB file holds at most 2^32 - 1 bytes",
        });
    };
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length },
        json: Cow::Owned(json_string.into_bytes()),
        bin: Some(Cow::Owned(bin)),
    };
    glb.to_vec().map_err(|err| ExportError::Encode(err.to_string()))
}

/// Where things are in the binary chunk, for the JSON.
struct GltfLayout {
    vertices: usize,
    triangles: usize,
    buffer_length: usize,
    normals_offset: usize,
    colors_offset: usize,
    indices_offset: usize,
    u16_indices: bool,
    min: [f32; 3],
    max: [f32; 3],
    encoding: ColorEncoding,
}

/// The glTF JSON describing the binary chunk laid out as `layout` says.
fn gltf_root(layout: GltfLayout) -> json::Root {
    use json::accessor::{ComponentType, Type};
    use json::buffer::Target;

    let mut root = json::Root {
        asset: json::Asset { generator: Some(GENERATOR.to_owned()), ..json::Asset::default() },
        ..json::Root::default()
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(layout.buffer_length),
        extensions: None,
        extras: Default::default(),
        name: None,
        uri: None,
    });
    let view = |root: &mut json::Root, offset: usize, end: usize, target: Target| {
        root.push(json::buffer::View {
            buffer,
            byte_length: USize64::from(end - offset),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            extensions: None,
            extras: Default::default(),
            name: None,
            target: Some(Valid(target)),
        })
    };
    let positions_view = view(&mut root, 0, layout.normals_offset, Target::ArrayBuffer);
    let normals_view = view(&mut root, layout.normals_offset, layout.colors_offset, Target::ArrayBuffer);
    let colors_view = view(&mut root, layout.colors_offset, layout.indices_offset, Target::ArrayBuffer);
    let indices_view = view(&mut root, layout.indices_offset, layout.buffer_length, Target::ElementArrayBuffer);
    let positions = root.push(accessor(
        positions_view,
        layout.vertices,
        ComponentType::F32,
        Type::Vec3,
        Some((layout.min, layout.max)),
    ));
    let normals = root.push(accessor(normals_view, layout.vertices, ComponentType::F32, Type::Vec3, None));
    let (color_component, normalized) = match layout.encoding {
        ColorEncoding::Float => (ComponentType::F32, false),
        ColorEncoding::Unorm16 => (ComponentType::U16, true),
        ColorEncoding::Unorm8 => (ComponentType::U8, true),
    };
    let colors = root.push(json::Accessor {
        normalized,
        ..accessor(colors_view, layout.vertices, color_component, Type::Vec4, None)
    });
    let index_type = if layout.u16_indices { ComponentType::U16 } else { ComponentType::U32 };
    let indices = root.push(accessor(indices_view, 3 * layout.triangles, index_type, Type::Scalar, None));

    let material = root.push(json::Material {
        name: Some("meshpaint vertex colours".to_owned()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        ..Default::default()
    });
    let primitive = json::mesh::Primitive {
        attributes: BTreeMap::from([
            (Valid(json::mesh::Semantic::Positions), positions),
            (Valid(json::mesh::Semantic::Normals), normals),
            (Valid(json::mesh::Semantic::Colors(0)), colors),
        ]),
        extensions: None,
        extras: Default::default(),
        indices: Some(indices),
        material: Some(material),
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    };
    let mesh = root.push(json::Mesh {
        extensions: None,
        extras: Default::default(),
        name: Some("meshpaint".to_owned()),
        primitives: vec![primitive],
        weights: None,
    });
    let node = root.push(json::Node { mesh: Some(mesh), name: Some("meshpaint".to_owned()), ..Default::default() });
    let scene = root.push(json::Scene { extensions: None, extras: Default::default(), name: None, nodes: vec![node] });
    root.scene = Some(scene);
    root
}

/// What [`write_tessellated_glb`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExportSummary {
    /// glTF vertices: one per sample the faces read.
    pub vertices: u64,
    /// Triangles: `Σ R_f²`.
    pub triangles: u64,
    /// Size of the file in bytes.
    pub bytes: u64,
}

/// Tessellates `store` on `positions` and writes the binary glTF to `path` atomically:
/// the bytes go to a temporary file in the same directory, which is flushed to disk and
/// then renamed over `path`.
pub fn write_tessellated_glb(
    path: &Path,
    positions: &[[f32; 3]],
    store: &ColorStore,
) -> Result<ExportSummary, ExportError> {
    let tessellation = tessellate(positions, store)?;
    let (vertices, triangles) = (tessellation.positions.len() as u64, tessellation.triangles.len() as u64);
    let bytes = tessellation_to_glb(tessellation)?;
    write_atomically(path, &bytes)?;
    Ok(ExportSummary { vertices, triangles, bytes: bytes.len() as u64 })
}

/// Writes `bytes` to `path` atomically ([`crate::atomic_write`]).
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    crate::atomic_write::write_atomically(path, bytes).map_err(|error| ExportError::Io {
        path: error.path,
        action: error.action,
        source: error.source,
    })
}

/// The accessor of `count` `ty`s in `view` (min / max: `bounds`), for every glTF writer here.
pub(crate) fn accessor(
    view: json::Index<json::buffer::View>,
    count: usize,
    component: json::accessor::ComponentType,
    ty: json::accessor::Type,
    bounds: Option<([f32; 3], [f32; 3])>,
) -> json::Accessor {
    json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: Default::default(),
        type_: Valid(ty),
        min: bounds.map(|(min, _)| json::Value::from(min.to_vec())),
        max: bounds.map(|(_, max)| json::Value::from(max.to_vec())),
        name: None,
        normalized: false,
        sparse: None,
    }
}
