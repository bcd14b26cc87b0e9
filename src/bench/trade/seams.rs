//! Seams: the largest colour jump between the two sides of an edge, both sides evaluated at
//! the same points along it — mesh colors with the CPU reference sampler, a Mesh Color
//! Texture with its CPU evaluation of the hardware filter.

use std::collections::HashMap;

use rayon::prelude::*;

use meshpaint_core::colors::format::Rgba;
use meshpaint_core::htex::HtexTexture;
use meshpaint_core::mct::MeshColorTexture;
use meshpaint_core::packing::linear::PackedMesh;
use meshpaint_core::packing::sampler::{Filter, sample, sample_trilinear};
use meshpaint_core::ptex::PackedPtex;

/// The fewest segments an edge is split into: points `t = k / segments`, `k = 0..=segments`.
const MIN_SEGMENTS: u32 = 32;

/// Segments per edge for `packed`: at least [`MIN_SEGMENTS`] and twice its largest R, so that
/// points fall between the lattice points of every level (at `t = k / R` alone the filters
/// would only ever be read at samples); a power of two, so every `t` is exact in `f32`.
fn segments(packed: &PackedMesh) -> u32 {
    let max_r = packed.face_records.iter().filter_map(|r| r.resolution()).map(|r| r.get()).max().unwrap_or(1);
    max_r.saturating_mul(2).max(MIN_SEGMENTS)
}

/// The largest jump across the compared edges for one filter at one level.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamJump {
    /// `nearest`, `linear` (MCT: hardware bilinear) or `trilinear` (at `level + 0.5`).
    pub filter: &'static str,
    /// The requested MIP level.
    pub level: u32,
    /// Edges compared (see [`SeamEdges`]).
    pub edges: u64,
    /// Of those, edges whose two faces have different R.
    pub mixed_edges: u64,
    /// Points compared (per edge, per face pair).
    pub points: u64,
    /// Points along each edge: `t = k / (points_per_edge − 1)`.
    pub points_per_edge: u32,
    /// Largest difference of a channel between the two sides, colour units (linear, 0..1).
    pub max_jump: f32,
    /// Mean over the points of the largest channel difference.
    pub mean_jump: f64,
}

impl SeamJump {
    /// As JSON.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "filter": self.filter, "level": self.level, "edges": self.edges, "mixed_edges": self.mixed_edges,
            "points": self.points, "points_per_edge": self.points_per_edge, "max_jump": self.max_jump, "mean_jump": self.mean_jump,
            "max_jump_8bit_steps": self.max_jump * 255.0,
        })
    }
}

/// Which edges a seam measurement compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeamEdges {
    /// Edges whose faces have different R (where mesh colors' seam rule acts).
    Mixed,
    /// Every edge with two or more faces.
    Every,
}

/// One side of an edge: a face and its local edge `k` (corner `k` → `k + 1`).
type Side = (u32, u8);

/// The face pairs of the selected edges, keyed by the edge's sorted vertex pair.
struct EdgePairs {
    pairs: Vec<((u32, u32), Side, Side)>,
    edges: u64,
    mixed_edges: u64,
    /// Points per pair: `t = k / segments`.
    segments: u32,
}

fn edge_pairs(packed: &PackedMesh, which: SeamEdges) -> EdgePairs {
    let mut edges: HashMap<(u32, u32), Vec<Side>> = HashMap::new();
    for (face, corners) in packed.indices.iter().enumerate() {
        for k in 0..3u8 {
            let (a, b) = (corners[usize::from(k)], corners[(usize::from(k) + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push((face as u32, k));
        }
    }
    let resolution = |face: u32| packed.face_records.get(face as usize).and_then(|r| r.resolution());
    let mut pairs = Vec::new();
    for (&key, sides) in &edges {
        for (x, &first) in sides.iter().enumerate() {
            for &second in &sides[x + 1..] {
                if which == SeamEdges::Every || resolution(first.0) != resolution(second.0) {
                    pairs.push((key, first, second));
                }
            }
        }
    }
    pairs.sort_unstable();
    let count = |mixed_only: bool| {
        let mut keys: Vec<(u32, u32)> =
            pairs.iter().filter(|(_, a, b)| !mixed_only || resolution(a.0) != resolution(b.0)).map(|p| p.0).collect();
        keys.dedup();
        keys.len() as u64
    };
    let (edges, mixed_edges) = (count(false), count(true));
    EdgePairs { pairs, edges, mixed_edges, segments: segments(packed) }
}

/// Barycentrics in `face` of the point at `t` from vertex `from` to the other end of its edge `k`.
fn barycentric(packed: &PackedMesh, (face, k): Side, from: u32, t: f32) -> [f32; 3] {
    let corners = packed.indices[face as usize];
    let (start, end) = (usize::from(k), (usize::from(k) + 1) % 3);
    let mut w = [0.0f32; 3];
    if corners[start] == from {
        w[start] = 1.0 - t;
        w[end] = t;
    } else {
        w[end] = 1.0 - t;
        w[start] = t;
    }
    w
}

/// The jump of `read` (a face and barycentrics → colour) across every pair, in parallel.
fn measure(
    packed: &PackedMesh,
    edges: &EdgePairs,
    filter: &'static str,
    level: u32,
    read: &(dyn Fn(u32, [f32; 3]) -> Option<Rgba> + Sync),
) -> SeamJump {
    let (max_jump, sum, points) = edges
        .pairs
        .par_iter()
        .map(|&((a, _), first, second)| {
            let (mut max_jump, mut sum, mut points) = (0.0f32, 0.0f64, 0u64);
            for step in 0..=edges.segments {
                let t = step as f32 / edges.segments as f32;
                let ca = read(first.0, barycentric(packed, first, a, t));
                let cb = read(second.0, barycentric(packed, second, a, t));
                let (Some(ca), Some(cb)) = (ca, cb) else {
                    continue;
                };
                let jump = (0..4).map(|c| (ca[c] - cb[c]).abs()).fold(0.0f32, f32::max);
                max_jump = max_jump.max(jump);
                sum += f64::from(jump);
                points += 1;
            }
            (max_jump, sum, points)
        })
        .reduce(|| (0.0, 0.0, 0), |x, y| (x.0.max(y.0), x.1 + y.1, x.2 + y.2));
    SeamJump {
        filter,
        level,
        edges: edges.edges,
        mixed_edges: edges.mixed_edges,
        points,
        points_per_edge: edges.segments + 1,
        max_jump,
        mean_jump: if points > 0 { sum / points as f64 } else { 0.0 },
    }
}

/// Mesh colors' seam measurement on `packed` over edges whose faces have different R (all
/// levels up to `log2` of its largest R); empty when there is no such edge.
pub fn seam_jumps(packed: &PackedMesh) -> Vec<SeamJump> {
    seam_jumps_over(packed, SeamEdges::Mixed)
}

/// Mesh colors' seam measurement on `packed` over the edges `which` selects: nearest and
/// linear at every level up to `log2` of the largest R, trilinear at `level + 0.5` below it,
/// with the CPU reference sampler. Empty when no edge is selected.
pub fn seam_jumps_over(packed: &PackedMesh, which: SeamEdges) -> Vec<SeamJump> {
    let edges = edge_pairs(packed, which);
    if edges.pairs.is_empty() {
        return Vec::new();
    }
    let max_level = packed.face_records.iter().filter_map(|r| r.resolution()).map(|r| r.log2()).max().unwrap_or(0);
    let mut out = Vec::new();
    for filter in ["nearest", "linear", "trilinear"] {
        for level in 0..=max_level {
            if filter == "trilinear" && level == max_level {
                continue;
            }
            let read = |face: u32, w: [f32; 3]| match filter {
                "nearest" => sample(packed, face, w, Filter::Nearest, level),
                "linear" => sample(packed, face, w, Filter::Linear, level),
                _ => sample_trilinear(packed, face, w, level as f32 + 0.5),
            };
            out.push(measure(packed, &edges, filter, level, &read));
        }
    }
    out
}

/// The Mesh Color Texture `texture` (built from `packed`) over every edge: hardware bilinear
/// (`linear`) at every level of the atlas, trilinear at `level + 0.5` below the last, with the
/// CPU evaluation of the sampler ([`MeshColorTexture::sample_level`],
/// [`MeshColorTexture::sample_trilinear`]). Empty when no edge has two faces.
pub fn mct_seam_jumps(packed: &PackedMesh, texture: &MeshColorTexture) -> Vec<SeamJump> {
    let edges = edge_pairs(packed, SeamEdges::Every);
    if edges.pairs.is_empty() {
        return Vec::new();
    }
    let last = texture.layout.levels.saturating_sub(1);
    let mut out = Vec::new();
    for filter in ["linear", "trilinear"] {
        for level in 0..=last {
            if filter == "trilinear" && level == last {
                continue;
            }
            let read = |face: u32, w: [f32; 3]| match filter {
                "linear" => texture.sample_level(face, w, level),
                _ => texture.sample_trilinear(face, w, level as f32 + 0.5),
            };
            out.push(measure(packed, &edges, filter, level, &read));
        }
    }
    out
}

/// The Htex `texture` (built from `packed`) over every mesh edge, as [`mct_seam_jumps`]:
/// its CPU evaluation of three bilinear fetches ([`HtexTexture::sample_level`],
/// [`HtexTexture::sample_trilinear`]) at every level, trilinear at `level + 0.5`.
pub fn htex_seam_jumps(packed: &PackedMesh, texture: &HtexTexture) -> Vec<SeamJump> {
    let edges = edge_pairs(packed, SeamEdges::Every);
    if edges.pairs.is_empty() {
        return Vec::new();
    }
    let last = texture.layout.levels.saturating_sub(1);
    let mut out = Vec::new();
    for filter in ["linear", "trilinear"] {
        for level in 0..=last {
            if filter == "trilinear" && level == last {
                continue;
            }
            let read = |face: u32, w: [f32; 3]| match filter {
                "linear" => texture.sample_level(face, w, level),
                _ => texture.sample_trilinear(face, w, level as f32 + 0.5),
            };
            out.push(measure(packed, &edges, filter, level, &read));
        }
    }
    out
}

/// The packed Ptex `texture` (built from `packed`) over every edge, as [`mct_seam_jumps`]:
/// hardware bilinear (`linear`) at every level, trilinear at `level + 0.5` below the last,
/// with its CPU evaluation ([`PackedPtex::sample_level`], [`PackedPtex::sample_trilinear`]).
pub fn ptex_seam_jumps(packed: &PackedMesh, texture: &PackedPtex) -> Vec<SeamJump> {
    let edges = edge_pairs(packed, SeamEdges::Every);
    if edges.pairs.is_empty() {
        return Vec::new();
    }
    let last = texture.layout.levels.saturating_sub(1);
    let mut out = Vec::new();
    for filter in ["linear", "trilinear"] {
        for level in 0..=last {
            if filter == "trilinear" && level == last {
                continue;
            }
            let read = |face: u32, w: [f32; 3]| match filter {
                "linear" => texture.sample_level(face, w, level),
                _ => texture.sample_trilinear(face, w, level as f32 + 0.5),
            };
            out.push(measure(packed, &edges, filter, level, &read));
        }
    }
    out
}
