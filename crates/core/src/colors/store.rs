//! The editable store: what paint mode edits.
//!
//! Colours are held per element, keyed by element id: one colour per vertex, one sample
//! run per edge (its `R_e − 1` samples in canonical direction) and one per face (its
//! interior samples). Each element owns its own slot in a slab of large chunks
//! ([`crate::colors::slab`]: a dense map from id to samples, allocated in a few pieces), so
//! changing one face's resolution moves only that face and its edges and never shifts any
//! global array. The linear GPU layout is produced from
//! this by the packer when paint mode ends.
//!
//! Rules:
//! - a face's resolution `R_f` is a power of two in `1..=MAX_RESOLUTION`;
//! - an edge's resolution `R_e` is the maximum over its faces; a face with `R_f < R_e`
//!   reads the edge with stride `R_e / R_f`, so every face sees the same colour at a
//!   shared sample position;
//! - raising `R_f` interpolates the current signal (old samples unchanged), lowering it
//!   filters ([`crate::colors::resample`]), and raising then lowering restores the samples exactly;
//! - every write and every resolution change is recorded as dirty until [`ColorStore::take_dirty`];
//! - a clone is cheap: it shares the topology and the sample chunks, and a chunk is copied
//!   on its first write (`colors/slab.rs`).

use std::sync::Arc;

use thiserror::Error;

use crate::colors::format::Rgba;
use crate::colors::layout::{self, Resolution, SampleLocation};
use crate::colors::resample::{Lattice, reduce_polyline, refine_polyline};
use crate::colors::slab::Slab;
use crate::mesh::topology::{Topology, VertexFaces};

/// Errors of store operations.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum StoreError {
    /// A face id past the face count.
    #[error("face {face} does not exist (the mesh has {face_count} faces)")]
    NoSuchFace {
        /// The id asked for.
        face: u32,
        /// Number of faces.
        face_count: u32,
    },
    /// A per-face array of the wrong length.
    #[error("expected {expected} face resolutions, got {got}")]
    WrongLength {
        /// Number of faces.
        expected: usize,
        /// Length given.
        got: usize,
    },
}

/// One stored sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SampleRef {
    /// The colour of a vertex.
    Vertex(u32),
    /// Sample `offset` (canonical direction) of an edge.
    Edge {
        /// Edge id.
        edge: u32,
        /// Offset in `0..R_e − 1`.
        offset: u32,
    },
    /// Interior sample `offset` of a face.
    Interior {
        /// Face id.
        face: u32,
        /// Offset in `0..(R−1)(R−2)/2` (thesis eq. 3.2 order).
        offset: u32,
    },
}

/// One element's sample storage, as [`ColorStore::update_run`] writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StoreElement {
    /// Every vertex colour (index = vertex id).
    Vertices,
    /// The samples of an edge (index = storage offset).
    Edge(u32),
    /// The interior samples of a face (index = storage offset).
    Interior(u32),
}

impl StoreElement {
    /// The sample at `index` of this element.
    #[inline(always)]
    pub fn sample(self, index: u32) -> SampleRef {
        match self {
            StoreElement::Vertices => SampleRef::Vertex(index),
            StoreElement::Edge(edge) => SampleRef::Edge { edge, offset: index },
            StoreElement::Interior(face) => SampleRef::Interior { face, offset: index },
        }
    }
}

/// A sample together with where it lies: barycentric coordinates in one face that
/// contains it. Shared samples are reported once, in their *owner* face: the lowest
/// face id among those containing them (the rule texture conversion uses across seams).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleSite {
    /// The sample.
    pub sample: SampleRef,
    /// The owner face.
    pub face: u32,
    /// Barycentric coordinates `(w0, w1, w2)` in the owner face.
    pub barycentric: [f32; 3],
}

/// Elements changed since the last [`ColorStore::take_dirty`], sorted and unique.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DirtyElements {
    /// Vertices whose colour changed.
    pub vertices: Vec<u32>,
    /// Edges whose samples changed (values or count).
    pub edges: Vec<u32>,
    /// Faces whose interior samples changed (values or count).
    pub faces: Vec<u32>,
    /// Faces whose resolution changed (their face records must be rewritten).
    pub resized_faces: Vec<u32>,
    /// Edges whose resolution changed (their storage was reallocated).
    pub resized_edges: Vec<u32>,
}

impl DirtyElements {
    /// Whether nothing changed.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty() && self.edges.is_empty() && self.faces.is_empty()
    }

    /// Every face whose rendering these changes reach, sorted and unique: faces whose
    /// interiors or resolutions changed, the faces of every changed edge and around every
    /// changed vertex (a face shows its own vertices', edges' and interior samples, nothing
    /// else).
    pub fn faces_shown(&self, topology: &Topology, vertex_faces: &VertexFaces) -> Vec<u32> {
        let mut faces: Vec<u32> = self.faces.iter().chain(&self.resized_faces).copied().collect();
        for &edge in self.edges.iter().chain(&self.resized_edges) {
            faces.extend(topology.faces_of_edge(edge).iter().map(|&(face, _)| face));
        }
        for &vertex in &self.vertices {
            faces.extend_from_slice(vertex_faces.faces(vertex));
        }
        faces.sort_unstable();
        faces.dedup();
        faces
    }
}

/// Dirty flags with a list, so marking is O(1) and collecting is O(changed).
#[derive(Debug, Clone, Default)]
struct DirtySet {
    flags: Vec<bool>,
    list: Vec<u32>,
}

impl DirtySet {
    fn new(len: usize) -> Self {
        DirtySet { flags: vec![false; len], list: Vec::new() }
    }

    fn mark(&mut self, id: u32) {
        if let Some(flag) = self.flags.get_mut(id as usize)
            && !*flag
        {
            *flag = true;
            self.list.push(id);
        }
    }

    fn take(&mut self) -> Vec<u32> {
        let mut list = std::mem::take(&mut self.list);
        for &id in &list {
            self.flags[id as usize] = false;
        }
        list.sort_unstable();
        list
    }
}

/// The union of several [`DirtyElements`] (e.g. every dab of a paint session): what an
/// incremental repack must redo. Adding is O(added), taking O(collected).
#[derive(Debug, Clone, Default)]
pub struct DirtyAccumulator {
    vertices: DirtySet,
    edges: DirtySet,
    faces: DirtySet,
    resized_faces: DirtySet,
    resized_edges: DirtySet,
}

impl DirtyAccumulator {
    /// An empty accumulator for `topology`'s elements.
    pub fn new(topology: &Topology) -> Self {
        let (v, e, f) =
            (topology.vertex_count as usize, topology.edge_count() as usize, topology.face_count() as usize);
        DirtyAccumulator {
            vertices: DirtySet::new(v),
            edges: DirtySet::new(e),
            faces: DirtySet::new(f),
            resized_faces: DirtySet::new(f),
            resized_edges: DirtySet::new(e),
        }
    }

    /// Adds `dirty` to the union.
    pub fn add(&mut self, dirty: &DirtyElements) {
        let pairs = [
            (&mut self.vertices, &dirty.vertices),
            (&mut self.edges, &dirty.edges),
            (&mut self.faces, &dirty.faces),
            (&mut self.resized_faces, &dirty.resized_faces),
            (&mut self.resized_edges, &dirty.resized_edges),
        ];
        for (set, ids) in pairs {
            for &id in ids {
                set.mark(id);
            }
        }
    }

    /// The union so far (sorted, unique), leaving the accumulator empty.
    pub fn take(&mut self) -> DirtyElements {
        DirtyElements {
            vertices: self.vertices.take(),
            edges: self.edges.take(),
            faces: self.faces.take(),
            resized_faces: self.resized_faces.take(),
            resized_edges: self.resized_edges.take(),
        }
    }
}

/// The editable mesh-colors store.
#[derive(Debug, Clone)]
pub struct ColorStore {
    /// Shared between clones (it never changes), like the slabs' chunks until written.
    topology: Arc<Topology>,
    face_resolution: Vec<Resolution>,
    edge_resolution: Vec<Resolution>,
    vertex_colors: Vec<Rgba>,
    edge_samples: Slab,
    interior_samples: Slab,
    /// For each vertex, the lowest face id that uses it (`INVALID` if none).
    vertex_owner_face: Vec<u32>,
    dirty_vertices: DirtySet,
    dirty_edges: DirtySet,
    dirty_faces: DirtySet,
    resized_faces: DirtySet,
    resized_edges: DirtySet,
}

impl ColorStore {
    /// A store with every face at `resolution` and every sample `color`.
    pub fn uniform(topology: Topology, resolution: Resolution, color: Rgba) -> Self {
        let faces = topology.face_count() as usize;
        Self::build(topology, vec![resolution; faces], color)
    }

    /// A store with per-face resolutions (one per face) and every sample `color`.
    pub fn with_resolutions(
        topology: Topology,
        face_resolution: Vec<Resolution>,
        color: Rgba,
    ) -> Result<Self, StoreError> {
        let faces = topology.face_count() as usize;
        if face_resolution.len() != faces {
            return Err(StoreError::WrongLength { expected: faces, got: face_resolution.len() });
        }
        Ok(Self::build(topology, face_resolution, color))
    }

    /// Builds the store; `face_resolution` has one entry per face.
    fn build(topology: Topology, face_resolution: Vec<Resolution>, color: Rgba) -> Self {
        let color = crate::colors::format::clamp_color(color);
        let faces = topology.face_count() as usize;
        let edge_resolution: Vec<Resolution> = (0..topology.edge_count())
            .map(|edge| {
                topology
                    .faces_of_edge(edge)
                    .iter()
                    .map(|&(face, _)| face_resolution[face as usize])
                    .max()
                    .unwrap_or(Resolution::ONE)
            })
            .collect();
        let mut vertex_owner_face = vec![crate::mesh::topology::INVALID; topology.vertex_count as usize];
        for (face, corners) in topology.face_vertices.iter().enumerate().rev() {
            for &v in corners {
                vertex_owner_face[v as usize] = face as u32;
            }
        }
        ColorStore {
            vertex_colors: vec![color; topology.vertex_count as usize],
            edge_samples: Slab::filled(edge_resolution.iter().map(|&r| layout::edge_sample_count(r)), color),
            interior_samples: Slab::filled(face_resolution.iter().map(|&r| layout::interior_sample_count(r)), color),
            dirty_vertices: DirtySet::new(topology.vertex_count as usize),
            dirty_edges: DirtySet::new(edge_resolution.len()),
            dirty_faces: DirtySet::new(faces),
            resized_faces: DirtySet::new(faces),
            resized_edges: DirtySet::new(edge_resolution.len()),
            vertex_owner_face,
            face_resolution,
            edge_resolution,
            topology: Arc::new(topology),
        }
    }

    /// Heap bytes of the store: `(samples, the rest)`: the slabs' chunks, then the
    /// resolutions, vertex colours, slots and dirty sets (the shared topology not counted).
    pub fn heap_bytes(&self) -> (u64, u64) {
        use crate::colors::slab::vec_bytes;
        let dirty =
            [&self.dirty_vertices, &self.dirty_edges, &self.dirty_faces, &self.resized_faces, &self.resized_edges]
                .iter()
                .map(|set| vec_bytes(&set.flags) + vec_bytes(&set.list))
                .sum::<usize>();
        let (edge_chunks, edge_index) = self.edge_samples.heap_bytes();
        let (interior_chunks, interior_index) = self.interior_samples.heap_bytes();
        let rest = vec_bytes(&self.face_resolution)
            + vec_bytes(&self.edge_resolution)
            + vec_bytes(&self.vertex_colors)
            + vec_bytes(&self.vertex_owner_face)
            + dirty;
        (edge_chunks + interior_chunks, rest as u64 + edge_index + interior_index)
    }

    /// Heap bytes of this store not shared with `other` (a snapshot's own cost: its sample
    /// chunks are shared until either writes into them).
    pub fn unshared_bytes(&self, other: &ColorStore) -> u64 {
        let (samples, rest) = self.heap_bytes();
        let shared = self.edge_samples.shared_bytes(&other.edge_samples)
            + self.interior_samples.shared_bytes(&other.interior_samples);
        samples - shared + rest
    }

    /// The mesh connectivity.
    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// Resolution of `face`.
    pub fn face_resolution(&self, face: u32) -> Option<Resolution> {
        self.face_resolution.get(face as usize).copied()
    }

    /// Resolutions of all faces.
    pub fn face_resolutions(&self) -> &[Resolution] {
        &self.face_resolution
    }

    /// Resolution of `edge` (the maximum over its faces).
    pub fn edge_resolution(&self, edge: u32) -> Option<Resolution> {
        self.edge_resolution.get(edge as usize).copied()
    }

    /// Colour of vertex `v`.
    pub fn vertex_color(&self, v: u32) -> Option<Rgba> {
        self.vertex_colors.get(v as usize).copied()
    }

    /// The samples of `edge`, canonical direction.
    pub fn edge_samples(&self, edge: u32) -> &[Rgba] {
        self.edge_samples.get(edge as usize).unwrap_or(&[])
    }

    /// The interior samples of `face`, thesis eq. 3.2 order.
    pub fn interior_samples(&self, face: u32) -> &[Rgba] {
        self.interior_samples.get(face as usize).unwrap_or(&[])
    }

    /// Number of level-0 samples stored.
    pub fn sample_count(&self) -> u64 {
        self.vertex_colors.len() as u64 + self.edge_samples.live_samples() + self.interior_samples.live_samples()
    }

    /// Reads one sample.
    pub fn get(&self, sample: SampleRef) -> Option<Rgba> {
        match sample {
            SampleRef::Vertex(v) => self.vertex_colors.get(v as usize).copied(),
            SampleRef::Edge { edge, offset } => self.edge_samples.get(edge as usize)?.get(offset as usize).copied(),
            SampleRef::Interior { face, offset } => {
                self.interior_samples.get(face as usize)?.get(offset as usize).copied()
            }
        }
    }

    /// Writes one sample, clamped by [`crate::colors::format::clamp_color`], and marks its
    /// element dirty. Returns `false` (and writes nothing) when the sample does not exist.
    ///
    /// Crate-private: outside the core, every write goes through
    /// [`crate::paint::undo::StoreWriter`], the one write path (it records undo).
    pub(crate) fn set(&mut self, sample: SampleRef, color: Rgba) -> bool {
        let slot = match sample {
            SampleRef::Vertex(v) => self.vertex_colors.get_mut(v as usize),
            SampleRef::Edge { edge, offset } => {
                self.edge_samples.get_mut(edge as usize).and_then(|s| s.get_mut(offset as usize))
            }
            SampleRef::Interior { face, offset } => {
                self.interior_samples.get_mut(face as usize).and_then(|s| s.get_mut(offset as usize))
            }
        };
        let Some(slot) = slot else {
            return false;
        };
        // The one rule for stored colours (docs/FORMAT.md): finite, within what the formats hold.
        *slot = crate::colors::format::clamp_color(color);
        match sample {
            SampleRef::Vertex(v) => self.dirty_vertices.mark(v),
            SampleRef::Edge { edge, .. } => self.dirty_edges.mark(edge),
            SampleRef::Interior { face, .. } => self.dirty_faces.mark(face),
        }
        true
    }

    /// Updates the run of `len` samples from `first` of one element in place: `update(index,
    /// old)` returns the new colour of sample `index` or `None` to keep it. New colours are
    /// clamped like [`ColorStore::set`]'s, and the element (for vertices: each vertex
    /// written, `index` being the vertex id) is marked dirty when anything was written.
    /// Returns the number of samples written; the indices past the element are skipped.
    /// The fast path of the brushes (one look-up per run instead of one per sample).
    ///
    /// Crate-private: outside the core, every write goes through
    /// [`crate::paint::undo::StoreWriter`], the one write path (it records undo).
    #[inline]
    pub(crate) fn update_run(
        &mut self,
        element: StoreElement,
        first: u32,
        len: u32,
        mut update: impl FnMut(u32, Rgba) -> Option<Rgba>,
    ) -> u64 {
        let slice = match element {
            StoreElement::Vertices => self.vertex_colors.as_mut_slice(),
            StoreElement::Edge(edge) => self.edge_samples.get_mut(edge as usize).unwrap_or(&mut []),
            StoreElement::Interior(face) => self.interior_samples.get_mut(face as usize).unwrap_or(&mut []),
        };
        let start = (first as usize).min(slice.len());
        let end = (first as usize).saturating_add(len as usize).min(slice.len());
        let mut written = 0;
        for (index, slot) in (first..).zip(&mut slice[start..end]) {
            if let Some(new) = update(index, *slot) {
                *slot = crate::colors::format::clamp_color(new);
                written += 1;
                if element == StoreElement::Vertices {
                    self.dirty_vertices.mark(index);
                }
            }
        }
        if written > 0 {
            match element {
                StoreElement::Vertices => {}
                StoreElement::Edge(edge) => self.dirty_edges.mark(edge),
                StoreElement::Interior(face) => self.dirty_faces.mark(face),
            }
        }
        written
    }

    /// The samples of each of `elements` (edges and face interiors, each listed once), all
    /// writable at once, with the topology to read: how a writer changes many elements in
    /// parallel. `None` when one is listed twice, does not exist, or is `Vertices`. Whoever
    /// writes through them reports each changed element with [`ColorStore::mark_written`].
    pub(crate) fn elements_mut(&mut self, elements: &[StoreElement]) -> Option<(&Topology, Vec<&mut [Rgba]>)> {
        let (mut edges, mut faces) = (Vec::new(), Vec::new());
        for element in elements {
            match *element {
                StoreElement::Vertices => return None,
                StoreElement::Edge(edge) => edges.push(edge),
                StoreElement::Interior(face) => faces.push(face),
            }
        }
        let mut edge_runs = self.edge_samples.many_mut(&edges)?.into_iter();
        let mut face_runs = self.interior_samples.many_mut(&faces)?.into_iter();
        let runs = elements
            .iter()
            .map(|element| match element {
                StoreElement::Edge(_) => edge_runs.next(),
                _ => face_runs.next(),
            })
            .collect::<Option<Vec<_>>>()?;
        Some((&self.topology, runs))
    }

    /// Marks `element` changed (for the GPU upload) after writes through
    /// [`ColorStore::elements_mut`]; `Vertices` marks nothing (vertices are written one by one).
    pub(crate) fn mark_written(&mut self, element: StoreElement) {
        match element {
            StoreElement::Vertices => {}
            StoreElement::Edge(edge) => self.dirty_edges.mark(edge),
            StoreElement::Interior(face) => self.dirty_faces.mark(face),
        }
    }

    /// The stored sample at face-local lattice point `(i, j)` of `face` at the face's
    /// resolution (edges read with stride when the edge is finer than the face).
    pub fn face_sample_ref(&self, face: u32, i: u32, j: u32) -> Option<SampleRef> {
        let r = self.face_resolution(face)?;
        let corners = self.topology.face_vertices.get(face as usize)?;
        Some(match layout::classify_sample(r, i, j, [false; 3])? {
            SampleLocation::Vertex { corner } => SampleRef::Vertex(corners[usize::from(corner)]),
            SampleLocation::Edge { face_edge, offset } => {
                let k = usize::from(face_edge);
                let edge = self.topology.face_edges[face as usize][k];
                let r_edge = self.edge_resolution(edge)?;
                let position = (offset + 1) << (r_edge.log2() - r.log2());
                SampleRef::Edge {
                    edge,
                    offset: layout::edge_storage_offset(r_edge, position, self.topology.is_reversed(face, k)),
                }
            }
            SampleLocation::Interior { offset } => SampleRef::Interior { face, offset },
        })
    }

    /// The colour at face-local lattice point `(i, j)` of `face`.
    pub fn face_sample(&self, face: u32, i: u32, j: u32) -> Option<Rgba> {
        self.get(self.face_sample_ref(face, i, j)?)
    }

    /// The face's whole lattice at its resolution (vertices, edges, interior).
    pub fn face_lattice(&self, face: u32) -> Option<Lattice> {
        let r = self.face_resolution(face)?.get();
        let mut lattice = Lattice::new(r, [0.0; 4]);
        for i in 0..=r {
            for j in 0..=r - i {
                lattice.set(i, j, self.face_sample(face, i, j)?);
            }
        }
        Some(lattice)
    }

    /// Calls `visit` once for every stored sample with its site in its owner face.
    pub fn for_each_site(&self, mut visit: impl FnMut(SampleSite)) {
        let bary = |r: Resolution, (i, j): (u32, u32)| layout::sample_barycentric(r, i, j).map(|w| w as f32);
        for (v, &face) in self.vertex_owner_face.iter().enumerate() {
            let Some(corners) = self.topology.face_vertices.get(face as usize) else {
                continue;
            };
            let corner = corners.iter().position(|&c| c == v as u32).unwrap_or(0);
            let mut barycentric = [0.0; 3];
            barycentric[corner] = 1.0;
            visit(SampleSite { sample: SampleRef::Vertex(v as u32), face, barycentric });
        }
        for edge in 0..self.topology.edge_count() {
            let Some(&(face, k)) = self.topology.faces_of_edge(edge).first() else {
                continue;
            };
            let r_edge = self.edge_resolution[edge as usize];
            let reversed = self.topology.is_reversed(face, usize::from(k));
            for offset in 0..layout::edge_sample_count(r_edge) {
                // Position along the face edge from its start corner, in the edge's lattice.
                let position = if reversed { r_edge.get() - 1 - offset } else { offset + 1 };
                visit(SampleSite {
                    sample: SampleRef::Edge { edge, offset },
                    face,
                    barycentric: bary(r_edge, layout::edge_sample_coords(r_edge, k, position)),
                });
            }
        }
        for face in 0..self.topology.face_count() {
            let r = self.face_resolution[face as usize];
            for offset in 0..layout::interior_sample_count(r) {
                let Some(ij) = layout::interior_sample_at(r, offset) else {
                    continue;
                };
                visit(SampleSite { sample: SampleRef::Interior { face, offset }, face, barycentric: bary(r, ij) });
            }
        }
    }

    /// Sets every sample to `color_at(site)`, marking everything dirty.
    ///
    /// `color_at` sees the sites in [`ColorStore::for_each_site`]'s order; each colour is
    /// written in place as [`ColorStore::set`] writes it (clamped, element marked dirty).
    ///
    /// Crate-private: outside the core, every write goes through
    /// [`crate::paint::undo::StoreWriter`], the one write path (it records undo).
    pub(crate) fn fill_with(&mut self, mut color_at: impl FnMut(SampleSite) -> Rgba) {
        use crate::colors::format::clamp_color;
        let bary = |r: Resolution, (i, j): (u32, u32)| layout::sample_barycentric(r, i, j).map(|w| w as f32);
        for (v, &face) in self.vertex_owner_face.iter().enumerate() {
            let Some(corners) = self.topology.face_vertices.get(face as usize) else {
                continue;
            };
            let corner = corners.iter().position(|&c| c == v as u32).unwrap_or(0);
            let mut barycentric = [0.0; 3];
            barycentric[corner] = 1.0;
            let color = color_at(SampleSite { sample: SampleRef::Vertex(v as u32), face, barycentric });
            self.vertex_colors[v] = clamp_color(color);
            self.dirty_vertices.mark(v as u32);
        }
        for edge in 0..self.topology.edge_count() {
            let Some(&(face, k)) = self.topology.faces_of_edge(edge).first() else {
                continue;
            };
            let r_edge = self.edge_resolution[edge as usize];
            let reversed = self.topology.is_reversed(face, usize::from(k));
            let samples = self.edge_samples.get_mut(edge as usize).unwrap_or(&mut []);
            for (offset, slot) in (0..layout::edge_sample_count(r_edge)).zip(samples.iter_mut()) {
                let position = if reversed { r_edge.get() - 1 - offset } else { offset + 1 };
                let site = SampleSite {
                    sample: SampleRef::Edge { edge, offset },
                    face,
                    barycentric: bary(r_edge, layout::edge_sample_coords(r_edge, k, position)),
                };
                *slot = clamp_color(color_at(site));
            }
            if !samples.is_empty() {
                self.dirty_edges.mark(edge);
            }
        }
        for face in 0..self.topology.face_count() {
            let r = self.face_resolution[face as usize];
            let samples = self.interior_samples.get_mut(face as usize).unwrap_or(&mut []);
            // Rows i ascending, then j ascending: the storage order (eq. 3.2).
            let res = r.get();
            let mut slots = samples.iter_mut();
            let mut offset = 0u32;
            for i in 1..res.saturating_sub(1) {
                for j in 1..res - i {
                    let Some(slot) = slots.next() else {
                        break;
                    };
                    let site =
                        SampleSite { sample: SampleRef::Interior { face, offset }, face, barycentric: bary(r, (i, j)) };
                    *slot = clamp_color(color_at(site));
                    offset += 1;
                }
            }
            if offset > 0 {
                self.dirty_faces.mark(face);
            }
        }
    }

    /// Changes the resolution of `face`, resampling its interior and any edge whose
    /// resolution (the maximum over its faces) changes as a result.
    ///
    /// Crate-private: outside the core, every write goes through
    /// [`crate::paint::undo::StoreWriter`], the one write path (it records undo).
    pub(crate) fn set_face_resolution(&mut self, face: u32, resolution: Resolution) -> Result<(), StoreError> {
        let Some(&old) = self.face_resolution.get(face as usize) else {
            return Err(StoreError::NoSuchFace { face, face_count: self.topology.face_count() });
        };
        if old == resolution {
            return Ok(());
        }
        // The face's signal at its old resolution, resampled in 2× steps.
        let Some(mut lattice) = self.face_lattice(face) else {
            return Ok(());
        };
        while lattice.resolution() < resolution.get() {
            lattice = lattice.refine();
            // Where an edge already holds finer samples (a finer neighbour), its true
            // colours replace the interpolated boundary, so the next refinement and any
            // later reduction see the same boundary (this keeps up-then-down exact).
            self.copy_finer_edges_into(face, &mut lattice);
        }
        while lattice.resolution() > resolution.get() {
            lattice = lattice.reduce();
        }
        self.face_resolution[face as usize] = resolution;
        self.resized_faces.mark(face);
        // Edges follow the maximum of their faces.
        for k in 0..3 {
            let edge = self.topology.face_edges[face as usize][k];
            let target = self
                .topology
                .faces_of_edge(edge)
                .iter()
                .map(|&(f, _)| self.face_resolution[f as usize])
                .max()
                .unwrap_or(Resolution::ONE);
            self.resample_edge(edge, target);
        }
        let interior: Vec<Rgba> = (0..layout::interior_sample_count(resolution))
            .filter_map(|offset| {
                let (i, j) = layout::interior_sample_at(resolution, offset)?;
                // Resampled colours obey the store's rule too (rounding can leave alpha an
                // ulp above 1), so a later `set` of a saved sample is bit-exact.
                lattice.get(i, j).map(crate::colors::format::clamp_color)
            })
            .collect();
        self.interior_samples.set(face as usize, &interior);
        self.dirty_faces.mark(face);
        Ok(())
    }

    /// Overwrites the boundary of `lattice` (a lattice of `face`) with the stored edge
    /// samples of every edge at least as fine as the lattice.
    fn copy_finer_edges_into(&self, face: u32, lattice: &mut Lattice) {
        let r = lattice.resolution();
        let Ok(r_lattice) = Resolution::new(u64::from(r)) else {
            return;
        };
        for k in 0..3u8 {
            let edge = self.topology.face_edges[face as usize][usize::from(k)];
            let r_edge = self.edge_resolution[edge as usize];
            if r_edge.get() < r {
                continue;
            }
            let stride = r_edge.get() / r;
            let reversed = self.topology.is_reversed(face, usize::from(k));
            for position in 1..r {
                let offset = layout::edge_storage_offset(r_edge, position * stride, reversed);
                if let Some(&color) = self.edge_samples(edge).get(offset as usize) {
                    let (i, j) = layout::edge_sample_coords(r_lattice, k, position);
                    lattice.set(i, j, color);
                }
            }
        }
    }

    /// Resamples `edge` to `target` as a polyline between its endpoint colours.
    fn resample_edge(&mut self, edge: u32, target: Resolution) {
        let current = self.edge_resolution[edge as usize];
        if current == target {
            return;
        }
        let [lower, higher] = self.topology.edge_vertices[edge as usize];
        let mut polyline = Vec::with_capacity(self.edge_samples(edge).len() + 2);
        polyline.push(self.vertex_colors[lower as usize]);
        polyline.extend_from_slice(self.edge_samples(edge));
        polyline.push(self.vertex_colors[higher as usize]);
        let mut r = current.get();
        while r < target.get() {
            polyline = refine_polyline(&polyline);
            r *= 2;
        }
        while r > target.get() {
            polyline = reduce_polyline(&polyline);
            r /= 2;
        }
        let inner = polyline.get(1..polyline.len().saturating_sub(1)).unwrap_or(&[]);
        let inner: Vec<Rgba> = inner.iter().map(|&c| crate::colors::format::clamp_color(c)).collect();
        self.edge_samples.set(edge as usize, &inner);
        self.edge_resolution[edge as usize] = target;
        self.resized_edges.mark(edge);
        self.dirty_edges.mark(edge);
    }

    /// Takes the set of elements changed since the last call.
    pub fn take_dirty(&mut self) -> DirtyElements {
        DirtyElements {
            vertices: self.dirty_vertices.take(),
            edges: self.dirty_edges.take(),
            faces: self.dirty_faces.take(),
            resized_faces: self.resized_faces.take(),
            resized_edges: self.resized_edges.take(),
        }
    }
}
