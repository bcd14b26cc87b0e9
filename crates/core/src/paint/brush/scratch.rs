//! Per-mesh scratch reused across dabs (no allocation per sample): the faces of the dab and
//! their sphere masks, per-element stamps that visit each shared vertex and edge once, the
//! blur accumulators, and the resolution brush's per-stroke face marks.

use glam::DVec3;

use crate::colors::format::Rgba;
use crate::colors::layout::Resolution;
use crate::colors::store::ColorStore;

/// Per-element scratch, sized to the mesh, reused across dabs (no allocation per sample).
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    pub(super) faces: Vec<u32>,
    pub(super) face_masks: Vec<u8>,
    pub(super) vertex_stamp: Vec<u32>,
    pub(super) vertex_mask: Vec<u8>,
    pub(super) edge_stamp: Vec<u32>,
    pub(super) edge_mask: Vec<u8>,
    /// Even; `stamp` marks "mask accumulated in this dab", `stamp + 1` "processed".
    stamp: u32,
    /// Blur: accumulator slots of the dab's edge samples and vertices, the element → first
    /// slot tables (valid for the elements listed in `blur_edges` / `blur_vertices`).
    pub(super) blur_acc: Vec<BlurAcc>,
    pub(super) edge_slot: Vec<u32>,
    pub(super) vertex_slot: Vec<u32>,
    pub(super) blur_edges: Vec<u32>,
    pub(super) blur_vertices: Vec<u32>,
    /// Resolution tool: the stroke number in which each face was last changed.
    pub(super) face_stroke: Vec<u32>,
    pub(super) stroke: u32,
    /// Backface culling: per face, whether its winding is read reversed to agree with its
    /// component ([`crate::mesh::orientation::face_flips`]); built on first use.
    pub(super) face_flipped: Vec<bool>,
    /// Blur: the lattice stencils by resolution (built on first use, kept across dabs).
    pub(super) stencils: super::stencil::Stencils,
}

impl Scratch {
    pub(super) fn fit(&mut self, store: &ColorStore) {
        let topology = store.topology();
        let (v, e, f) =
            (topology.vertex_count as usize, topology.edge_count() as usize, topology.face_count() as usize);
        if self.vertex_stamp.len() != v || self.edge_stamp.len() != e || self.face_stroke.len() != f {
            self.vertex_stamp = vec![0; v];
            self.vertex_mask = vec![0; v];
            self.edge_stamp = vec![0; e];
            self.edge_mask = vec![0; e];
            self.vertex_slot = vec![0; v];
            self.edge_slot = vec![0; e];
            self.face_stroke = vec![0; f];
            self.face_flipped = Vec::new();
            self.stamp = 0;
            self.stroke = 0;
        }
    }

    /// The per-face flips of `store`'s mesh (computed once per mesh).
    pub(super) fn face_flips(&mut self, store: &ColorStore) -> &[bool] {
        let faces = store.topology().face_count() as usize;
        if self.face_flipped.len() != faces {
            let flips = crate::mesh::orientation::face_flips(store.topology());
            self.face_flipped = flips.into_iter().map(|(_, flipped)| flipped).collect();
        }
        &self.face_flipped
    }

    fn next_stamp(&mut self) -> u32 {
        self.stamp = self.stamp.wrapping_add(2);
        if self.stamp == 0 {
            self.vertex_stamp.fill(0);
            self.edge_stamp.fill(0);
            self.stamp = 2;
        }
        self.stamp
    }

    pub(super) fn next_stroke(&mut self) -> u32 {
        self.stroke = self.stroke.wrapping_add(1);
        if self.stroke == 0 {
            self.face_stroke.fill(0);
            self.stroke = 1;
        }
        self.stroke
    }
}

/// The blur sums of one shared sample over the faces of a dab: neighbour colours, their
/// count, and the largest weight.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BlurAcc {
    pub(super) sum: Rgba,
    pub(super) count: u32,
    pub(super) weight: f32,
}

/// Pass 1 of a dab: ORs the face masks into the faces' vertices and edges. Returns the stamp.
pub(super) fn accumulate_masks(store: &ColorStore, scratch: &mut Scratch) -> u32 {
    let stamp = scratch.next_stamp();
    let topology = store.topology();
    for (&face, &mask) in scratch.faces.iter().zip(&scratch.face_masks) {
        let (Some(edges), Some(corners)) =
            (topology.face_edges.get(face as usize), topology.face_vertices.get(face as usize))
        else {
            continue;
        };
        for &edge in edges {
            or_mask(&mut scratch.edge_stamp, &mut scratch.edge_mask, edge, stamp, mask);
        }
        for &v in corners {
            or_mask(&mut scratch.vertex_stamp, &mut scratch.vertex_mask, v, stamp, mask);
        }
    }
    stamp
}

/// ORs `mask` into element `id`'s mask, first resetting it when not yet stamped in this dab.
#[inline(always)]
fn or_mask(stamps: &mut [u32], masks: &mut [u8], id: u32, stamp: u32, mask: u8) {
    let i = id as usize;
    if stamps[i] != stamp {
        stamps[i] = stamp;
        masks[i] = mask;
    } else {
        masks[i] |= mask;
    }
}

/// Element `id`'s accumulated mask the first time it is visited in this dab (marking it
/// visited), else 0.
#[inline(always)]
pub(super) fn visit_mask(stamps: &mut [u32], masks: &[u8], id: u32, stamp: u32) -> u8 {
    let i = id as usize;
    if stamps[i] != stamp {
        return 0;
    }
    stamps[i] = stamp + 1;
    masks[i]
}

/// The resolution, corner vertices and edges of `face`.
pub(super) fn face_elements(store: &ColorStore, face: u32) -> Option<(Resolution, [u32; 3], [u32; 3])> {
    let topology = store.topology();
    Some((
        store.face_resolution(face)?,
        *topology.face_vertices.get(face as usize)?,
        *topology.face_edges.get(face as usize)?,
    ))
}

/// The position of vertex `v` in `f64` (the origin past the end).
pub(super) fn position(positions: &[[f32; 3]], v: u32) -> DVec3 {
    positions.get(v as usize).map_or(DVec3::ZERO, |p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
}
