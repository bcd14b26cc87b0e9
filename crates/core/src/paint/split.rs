//! Writes to many elements from parallel tasks: [`StoreWriter::split`] gives each edge and
//! face interior its own [`ElementSlice`] (its samples and its first-write bitset, disjoint
//! borrows of the store and of the open undo step); each task records old colours into its
//! own [`UndoLog`]; [`StoreWriter::commit`] marks the changed elements dirty and appends the
//! logs to the step. Still the one write path: the undo step and the dirty sets see every
//! write, as through [`StoreWriter::element`].

use crate::colors::format::Rgba;
use crate::colors::store::SampleRef;
use crate::mesh::topology::Topology;

use super::undo::{Element, StoreWriter, differs};

/// Records from which an [`UndoLog`] is kept as its own block of the step.
const OWN_BLOCK_RECORDS: usize = 256;

impl StoreWriter<'_> {
    /// Splits the writer into one [`ElementSlice`] per element of `elements` (edges and face
    /// interiors, each listed once), for writes from parallel tasks. `None` when an element is
    /// listed twice, does not exist or is `Vertices` (write vertices through
    /// [`StoreWriter::element`]). After the writes, hand the changed elements and the tasks'
    /// logs to [`StoreWriter::commit`].
    pub fn split(&mut self, elements: &[Element]) -> Option<Split<'_>> {
        let recording = self.history.is_recording();
        // Every element's bitset slot, made before anything is borrowed.
        let mut slots = Vec::with_capacity(if recording { elements.len() } else { 0 });
        if recording {
            for element in elements {
                let (is_edge, id, count) = match *element {
                    Element::Vertices => return None,
                    Element::Edge(edge) => (true, edge, self.store.edge_samples(edge).len()),
                    Element::Interior(face) => (false, face, self.store.interior_samples(face).len()),
                };
                slots.push(self.history.bitset_slot(is_edge, id, count)?);
            }
        }
        let (topology, runs) = self.store.elements_mut(elements)?;
        let mut bits: Vec<Option<&mut [u64]>> =
            if recording { self.history.bitsets(&slots)?.into_iter().map(Some).collect() } else { Vec::new() };
        bits.resize_with(elements.len(), || None);
        let elements = elements
            .iter()
            .zip(runs)
            .zip(bits)
            .map(|((&element, samples), bits)| ElementSlice { element, samples, bits, changed: 0 })
            .collect();
        Some(Split { topology, elements })
    }

    /// Ends writes through a [`Split`]: marks `changed` elements dirty for the GPU upload and
    /// appends the tasks' `logs` to the open step (small logs join its current block, a large
    /// one becomes a block of its own, moved rather than copied).
    pub fn commit(&mut self, changed: impl IntoIterator<Item = Element>, logs: impl IntoIterator<Item = UndoLog>) {
        for element in changed {
            self.store.mark_written(element);
        }
        let (small, large): (Vec<UndoLog>, Vec<UndoLog>) =
            logs.into_iter().filter(|log| !log.is_empty()).partition(|log| log.len() < OWN_BLOCK_RECORDS);
        self.history.append_records(
            small.into_iter().map(|log| log.list).collect(),
            large.into_iter().map(|log| log.list).collect(),
        );
    }
}

/// A [`StoreWriter`] split into one writer per element, from [`StoreWriter::split`].
#[derive(Debug)]
pub struct Split<'a> {
    /// The mesh's topology, to read while the elements are borrowed.
    pub topology: &'a Topology,
    /// One writer per element, in the order asked for.
    pub elements: Vec<ElementSlice<'a>>,
}

/// Old colours recorded by one parallel task of a [`Split`] (handed to [`StoreWriter::commit`]).
#[derive(Debug, Default)]
pub struct UndoLog {
    list: Vec<(SampleRef, Rgba)>,
    /// Entries reserved at the first record (the samples the task may write).
    hint: usize,
}

impl UndoLog {
    /// A log that reserves room for `samples` records when it records its first.
    pub fn with_hint(samples: usize) -> Self {
        UndoLog { list: Vec::new(), hint: samples }
    }

    #[inline(always)]
    fn push(&mut self, record: (SampleRef, Rgba)) {
        if self.list.capacity() == 0 {
            self.list.reserve(self.hint);
        }
        self.list.push(record);
    }

    /// Samples recorded.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}

/// The samples of one element and its first-write bitset, writable from a parallel task.
#[derive(Debug)]
pub struct ElementSlice<'a> {
    element: Element,
    samples: &'a mut [Rgba],
    /// `None`: no step is open, nothing is recorded.
    bits: Option<&'a mut [u64]>,
    changed: u32,
}

impl ElementSlice<'_> {
    /// The element.
    #[inline(always)]
    pub fn element(&self) -> Element {
        self.element
    }

    /// Its samples, to read (storage order).
    #[inline(always)]
    pub fn samples(&self) -> &[Rgba] {
        self.samples
    }

    /// Writes `new` (clamped as the store holds colours) to sample `index`, recording the old
    /// colour into `log` on the sample's first write in the step. Returns whether the colour
    /// changed (`false` when bit-identical or the sample does not exist).
    #[inline(always)]
    pub fn write(&mut self, index: u32, new: Rgba, log: &mut UndoLog) -> bool {
        let Some(slot) = self.samples.get_mut(index as usize) else {
            return false;
        };
        let new = crate::colors::format::clamp_color(new);
        if !differs(new, *slot) {
            return false;
        }
        if let Some(bits) = self.bits.as_deref_mut() {
            let (word, bit) = ((index / 64) as usize, 1u64 << (index % 64));
            if let Some(bits) = bits.get_mut(word)
                && *bits & bit == 0
            {
                *bits |= bit;
                log.push((self.element.sample(index), *slot));
            }
        }
        *slot = new;
        self.changed += 1;
        true
    }

    /// Writes `blend(old, w)` to each sample `start + i` whose weight `w = weights[i]` is
    /// positive, as [`ElementSlice::write`] does; returns how many had a positive weight.
    #[inline(always)]
    pub fn blend_run(
        &mut self,
        start: u32,
        weights: &[f32],
        log: &mut UndoLog,
        blend: impl Fn(Rgba, f32) -> Rgba,
    ) -> u64 {
        let mut covered = 0;
        for (index, &w) in (start..).zip(weights) {
            if w <= 0.0 {
                continue;
            }
            let Some(&old) = self.samples.get(index as usize) else {
                break;
            };
            covered += 1;
            self.write(index, blend(old, w), log);
        }
        covered
    }

    /// Samples whose colour [`ElementSlice::write`] changed.
    pub fn changed(&self) -> u32 {
        self.changed
    }
}
