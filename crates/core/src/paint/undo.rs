//! Undo and redo, one step per stroke (or per fill, per "set resolution"), storing only
//! what changed.
//!
//! # What a step holds
//!
//! A step is a sequence of changes, recorded in the order they happened:
//!
//! - **sample writes**: `(sample, old colour)` for every sample the step changed, the
//!   *first* write in the step winning (later writes to the same sample add nothing), so a
//!   step costs `changed samples × 28 bytes` however many dabs overlapped;
//! - **resolution changes**: for a face whose resolution changes, its old resolution and the
//!   old samples of the face's interior and of its three edges *before* the change (the
//!   store resamples exactly these four elements, [`ColorStore::set_face_resolution`]).
//!
//! Undo walks the changes backwards: a resolution change is undone by setting the old
//! resolution back and overwriting the four elements with the saved samples, so undo is
//! bit-exact whatever the resampling filters do. While undoing, the current values of the
//! same samples and faces are captured, which gives the redo step (the same walk again,
//! forwards); redo after undo restores the state after the step bit for bit.
//!
//! # First-write tracking without hashing
//!
//! Whether a sample was already recorded in the open step is a bit in a per-element bitset:
//! one bitset over all vertices, and one per touched edge or face interior, found through a
//! dense element → slot table. A tool asks the [`StoreWriter`] for an element's
//! [`ElementWriter`] once per element, which records each write with a bit test and a push.
//! Tools that write many elements in parallel [`StoreWriter::split`] the writer into one
//! [`ElementSlice`] per element (its samples and its bitset, disjoint borrows); each parallel
//! task records into its own [`UndoLog`], and [`StoreWriter::commit`] appends the logs to
//! the open step and marks the changed elements dirty.
//!
//! # One write path
//!
//! Every tool changes the store through a [`StoreWriter`] (`&mut ColorStore` and
//! `&mut UndoHistory` borrowed together for a dab, a fill, …): [`StoreWriter::set`], the
//! per-element fast path [`StoreWriter::element`] and [`StoreWriter::set_face_resolution`]
//! record the old state in the open step, then write through the store's setters, which mark
//! the element dirty for the GPU upload. Undo, dirty tracking and GPU sync cannot diverge.
//!
//! # Memory
//!
//! [`UndoHistory::bytes_used`] counts the payload of every kept step (undo and redo). When a
//! step is closed and the total exceeds the cap, the oldest undo steps are dropped first (a
//! step larger than the cap on its own cannot be kept either). A new non-empty step clears
//! the redo steps.
//!
//! The store must only change through recorded steps between [`UndoHistory::begin_step`]
//! calls; a store that no longer matches a step makes undo fail with
//! [`UndoError::Mismatch`] (and the history is cleared, since it cannot be trusted).

use std::collections::VecDeque;

use crate::colors::budget::{Budget, BudgetError};
use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::Resolution;
use crate::colors::store::{ColorStore, SampleRef, StoreError};

use super::face_state::FaceState;
pub use super::face_state::UndoError;

/// The default memory cap of an [`UndoHistory`]: 512 MiB.
pub const DEFAULT_CAP_BYTES: usize = 512 << 20;

/// Bytes of one recorded sample write.
pub const SAMPLE_RECORD_BYTES: usize = std::mem::size_of::<(SampleRef, Rgba)>();

/// One recorded change.
#[derive(Debug, Clone, PartialEq)]
enum Change {
    /// Old colours of samples (each sample at most once).
    Samples(Vec<(SampleRef, Rgba)>),
    /// A face and its edges before a resolution change.
    Resolution(Box<FaceState>),
}

impl Change {
    fn bytes(&self) -> usize {
        match self {
            Change::Samples(list) => list.len() * SAMPLE_RECORD_BYTES,
            Change::Resolution(state) => state.bytes(),
        }
    }
}

/// One undoable step.
#[derive(Debug, Clone, PartialEq)]
struct Step {
    label: String,
    changes: Vec<Change>,
    bytes: usize,
}

impl Step {
    fn is_empty(&self) -> bool {
        self.changes.iter().all(|change| matches!(change, Change::Samples(list) if list.is_empty()))
    }

    fn recount(&mut self) {
        self.bytes = self.changes.iter().map(Change::bytes).sum();
    }

    /// Checks that applying the step backwards to `store` stays within `budget`, counting the
    /// face resolutions it leaves (walking backwards, a face's first recorded state wins).
    fn check_budget(&self, store: &ColorStore, budget: &Budget, format: ColorFormat) -> Result<(), BudgetError> {
        if !self.changes.iter().any(|change| matches!(change, Change::Resolution(_))) {
            return Ok(());
        }
        let mut resolutions = store.face_resolutions().to_vec();
        for change in self.changes.iter().rev() {
            if let Change::Resolution(state) = change
                && let Some(slot) = resolutions.get_mut(state.face as usize)
            {
                *slot = state.resolution;
            }
        }
        budget.check_resolutions(&format!("\"{}\"", self.label), store, &resolutions, format)
    }

    /// Applies the step backwards and returns the step that reverses it.
    fn apply_backwards(&self, store: &mut ColorStore) -> Result<Step, UndoError> {
        let mut inverse = Vec::with_capacity(self.changes.len());
        for change in self.changes.iter().rev() {
            match change {
                Change::Samples(list) => {
                    let mut current = Vec::with_capacity(list.len());
                    for &(sample, old) in list {
                        let now = store
                            .get(sample)
                            .ok_or_else(|| UndoError::Mismatch(format!("sample {sample:?} does not exist")))?;
                        current.push((sample, now));
                        store.set(sample, old);
                    }
                    inverse.push(Change::Samples(current));
                }
                Change::Resolution(state) => {
                    let current = FaceState::capture(store, state.face)?;
                    state.restore(store)?;
                    inverse.push(Change::Resolution(Box::new(current)));
                }
            }
        }
        let mut step = Step { label: self.label.clone(), changes: inverse, bytes: 0 };
        step.recount();
        Ok(step)
    }
}

/// What a closed step recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StepSummary {
    /// The step's label.
    pub label: String,
    /// Samples whose old colour was recorded.
    pub samples: u64,
    /// Faces whose resolution changed.
    pub resolution_changes: u64,
    /// Bytes the step takes.
    pub bytes: usize,
    /// Whether the step was kept (`false` when it was empty, or alone larger than the cap).
    pub kept: bool,
    /// Older steps dropped to stay within the cap.
    pub dropped_steps: usize,
}

/// Slot marker: the element has no bitset in the open step.
const NO_SLOT: u32 = u32::MAX;

/// First-write bitsets of the open step.
#[derive(Debug, Clone, Default)]
struct SeenSamples {
    vertex_bits: Vec<u64>,
    edge_slot: Vec<u32>,
    face_slot: Vec<u32>,
    /// Bitsets; the first `used` are live, the rest are kept for reuse.
    slots: Vec<Vec<u64>>,
    used: usize,
    touched_edges: Vec<u32>,
    touched_faces: Vec<u32>,
}

impl SeenSamples {
    fn fit(&mut self, store: &ColorStore) {
        let topology = store.topology();
        let words = (topology.vertex_count as usize).div_ceil(64);
        if self.vertex_bits.len() != words {
            self.vertex_bits = vec![0; words];
        }
        if self.edge_slot.len() != topology.edge_count() as usize {
            self.edge_slot = vec![NO_SLOT; topology.edge_count() as usize];
        }
        if self.face_slot.len() != topology.face_count() as usize {
            self.face_slot = vec![NO_SLOT; topology.face_count() as usize];
        }
    }

    fn clear(&mut self) {
        self.vertex_bits.fill(0);
        for &edge in &self.touched_edges {
            self.edge_slot[edge as usize] = NO_SLOT;
        }
        for &face in &self.touched_faces {
            self.face_slot[face as usize] = NO_SLOT;
        }
        self.touched_edges.clear();
        self.touched_faces.clear();
        self.used = 0;
    }

    /// A zeroed bitset of `bits` bits; returns its slot.
    fn new_slot(&mut self, bits: usize) -> u32 {
        let words = bits.div_ceil(64);
        if self.used == self.slots.len() {
            self.slots.push(Vec::new());
        }
        let slot = &mut self.slots[self.used];
        slot.clear();
        slot.resize(words, 0);
        self.used += 1;
        (self.used - 1) as u32
    }

    /// The slot of an element (`table[id]`), created for `bits` bits when missing.
    fn slot(&mut self, is_edge: bool, id: u32, bits: usize) -> usize {
        let current = if is_edge { self.edge_slot[id as usize] } else { self.face_slot[id as usize] };
        if current != NO_SLOT {
            return current as usize;
        }
        let slot = self.new_slot(bits);
        if is_edge {
            self.edge_slot[id as usize] = slot;
            self.touched_edges.push(id);
        } else {
            self.face_slot[id as usize] = slot;
            self.touched_faces.push(id);
        }
        slot as usize
    }

    /// Forgets an element's bitset (its sample count is about to change).
    fn forget(&mut self, is_edge: bool, id: u32) {
        let table = if is_edge { &mut self.edge_slot } else { &mut self.face_slot };
        if let Some(slot) = table.get_mut(id as usize) {
            *slot = NO_SLOT;
        }
    }
}

/// One element's samples, as [`StoreWriter::element`] writes them (the store's element).
pub use crate::colors::store::StoreElement as Element;

/// Records first writes to the samples of one element (or to vertices) in the open step;
/// recording is a bit test and, the first time, a push. Only [`ElementWriter`] records
/// through it ([`ElementSlice`] borrows its element's bitset directly).
#[derive(Debug)]
struct SampleLog<'a> {
    element: Element,
    bits: &'a mut [u64],
    /// `None`: no step is open, nothing is recorded.
    list: Option<&'a mut Vec<(SampleRef, Rgba)>>,
}

impl SampleLog<'_> {
    /// A log that records nothing (no step is open).
    fn off(element: Element) -> Self {
        SampleLog { element, bits: &mut [], list: None }
    }

    /// Records that sample `index` of the element had colour `old` before its first write
    /// in the step.
    #[inline(always)]
    fn record(&mut self, index: u32, old: Rgba) {
        let Some(list) = self.list.as_deref_mut() else {
            return;
        };
        let (word, bit) = ((index / 64) as usize, 1u64 << (index % 64));
        let Some(bits) = self.bits.get_mut(word) else {
            return;
        };
        if *bits & bit != 0 {
            return;
        }
        *bits |= bit;
        list.push((self.element.sample(index), old));
    }
}
/// The open step's current block of sample writes (started after the last resolution
/// change), or `None` without an open step.
fn current_samples(open: &mut Option<Step>) -> Option<&mut Vec<(SampleRef, Rgba)>> {
    let step = open.as_mut()?;
    if !matches!(step.changes.last(), Some(Change::Samples(_))) {
        step.changes.push(Change::Samples(Vec::new()));
    }
    match step.changes.last_mut() {
        Some(Change::Samples(list)) => Some(list),
        _ => None,
    }
}

/// The undo and redo stacks with the open step being recorded.
#[derive(Debug, Clone)]
pub struct UndoHistory {
    undo: VecDeque<Step>,
    redo: Vec<Step>,
    open: Option<Step>,
    seen: SeenSamples,
    cap_bytes: usize,
    generation: u64,
    dropped_steps: u64,
    /// The budget undo and redo check resolution changes against, with the document's format.
    budget: Option<(Budget, ColorFormat)>,
}

impl Default for UndoHistory {
    fn default() -> Self {
        Self::new(DEFAULT_CAP_BYTES)
    }
}

impl UndoHistory {
    /// An empty history keeping at most `cap_bytes` of undo data.
    pub fn new(cap_bytes: usize) -> Self {
        UndoHistory {
            undo: VecDeque::new(),
            redo: Vec::new(),
            open: None,
            seen: SeenSamples::default(),
            cap_bytes,
            generation: 0,
            dropped_steps: 0,
            budget: None,
        }
    }

    /// The budget that undo and redo of resolution changes are checked against before they
    /// change anything (`None`: no check), with the document's colour format.
    pub fn set_budget(&mut self, budget: Option<(Budget, ColorFormat)>) {
        self.budget = budget;
    }

    /// The memory cap in bytes.
    pub fn cap_bytes(&self) -> usize {
        self.cap_bytes
    }

    /// Changes the memory cap; the oldest steps are dropped at once if needed.
    pub fn set_cap_bytes(&mut self, cap_bytes: usize) {
        self.cap_bytes = cap_bytes;
        self.enforce_cap();
    }

    /// Bytes taken by the kept undo and redo steps (the open step not included).
    pub fn bytes_used(&self) -> usize {
        self.undo.iter().chain(&self.redo).map(|step| step.bytes).sum()
    }

    /// Bytes recorded so far in the open step (0 when none is open).
    pub fn open_step_bytes(&self) -> usize {
        self.open.as_ref().map_or(0, |step| step.changes.iter().map(Change::bytes).sum())
    }

    /// Number of steps that can be undone.
    pub fn undo_len(&self) -> usize {
        self.undo.len()
    }

    /// Number of steps that can be redone.
    pub fn redo_len(&self) -> usize {
        self.redo.len()
    }

    /// The label of the step [`UndoHistory::undo`] would undo.
    pub fn undo_label(&self) -> Option<&str> {
        self.undo.back().map(|step| step.label.as_str())
    }

    /// The label of the step [`UndoHistory::redo`] would redo.
    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|step| step.label.as_str())
    }

    /// Steps dropped so far to stay within the cap.
    pub fn dropped_steps(&self) -> u64 {
        self.dropped_steps
    }

    /// A counter that changes whenever the colours change through the history (a step
    /// closed, undone or redone): compare it to decide whether to autosave.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Whether a step is open.
    pub fn is_recording(&self) -> bool {
        self.open.is_some()
    }

    /// Forgets every step (e.g. when another document is opened).
    pub fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
        self.open = None;
        self.seen.clear();
    }

    /// Opens a step labelled `label` for edits of `store`.
    pub fn begin_step(&mut self, store: &ColorStore, label: &str) -> Result<(), UndoError> {
        if self.open.is_some() {
            return Err(UndoError::StepOpen);
        }
        self.seen.fit(store);
        self.seen.clear();
        self.open = Some(Step { label: label.to_owned(), changes: Vec::new(), bytes: 0 });
        Ok(())
    }

    /// Closes the open step: keeps it when it changed anything (clearing redo), then drops the
    /// oldest steps while over the cap. `None` when no step was open.
    pub fn end_step(&mut self) -> Option<StepSummary> {
        let mut step = self.open.take()?;
        self.seen.clear();
        step.changes.retain(|change| !matches!(change, Change::Samples(list) if list.is_empty()));
        for change in &mut step.changes {
            if let Change::Samples(list) = change {
                list.shrink_to_fit();
            }
        }
        step.recount();
        let samples = step
            .changes
            .iter()
            .map(|change| match change {
                Change::Samples(list) => list.len() as u64,
                Change::Resolution(_) => 0,
            })
            .sum();
        let resolution_changes =
            step.changes.iter().filter(|change| matches!(change, Change::Resolution(_))).count() as u64;
        let mut summary = StepSummary {
            label: step.label.clone(),
            samples,
            resolution_changes,
            bytes: step.bytes,
            kept: false,
            dropped_steps: 0,
        };
        if step.is_empty() {
            return Some(summary);
        }
        self.generation += 1;
        self.redo.clear();
        self.undo.push_back(step);
        let before = self.undo.len();
        self.enforce_cap();
        // Steps go oldest first, so the new step is dropped only when it alone is over the cap.
        summary.kept = !self.undo.is_empty();
        summary.dropped_steps = before - self.undo.len() - usize::from(!summary.kept);
        Some(summary)
    }

    fn enforce_cap(&mut self) {
        // Redo steps are the most recently undone work: drop the oldest undo steps first,
        // then (only if still over) the redo step farthest from the present.
        let mut used = self.bytes_used();
        while used > self.cap_bytes {
            let dropped = match self.undo.pop_front() {
                Some(step) => step,
                None if !self.redo.is_empty() => self.redo.remove(0),
                None => break,
            };
            used -= dropped.bytes;
            self.dropped_steps += 1;
        }
    }

    /// The log of `element`, which currently has `sample_count` samples (ignored for
    /// vertices).
    fn element_log(&mut self, element: Element, sample_count: usize) -> SampleLog<'_> {
        let (is_edge, id) = match element {
            Element::Vertices => {
                return match current_samples(&mut self.open) {
                    Some(list) => SampleLog { element, bits: &mut self.seen.vertex_bits, list: Some(list) },
                    None => SampleLog::off(element),
                };
            }
            Element::Edge(edge) => (true, edge),
            Element::Interior(face) => (false, face),
        };
        let table_len = if is_edge { self.seen.edge_slot.len() } else { self.seen.face_slot.len() };
        if self.open.is_none() || id as usize >= table_len {
            return SampleLog::off(element);
        }
        let slot = self.seen.slot(is_edge, id, sample_count);
        match current_samples(&mut self.open) {
            Some(list) => SampleLog { element, bits: &mut self.seen.slots[slot], list: Some(list) },
            None => SampleLog::off(element),
        }
    }

    /// The first-write bitset slot of an edge (`is_edge`) or face interior `id` of `count`
    /// samples in the open step, made when missing; `None` without an open step or past the
    /// end of the tables.
    pub(super) fn bitset_slot(&mut self, is_edge: bool, id: u32, count: usize) -> Option<usize> {
        let table_len = if is_edge { self.seen.edge_slot.len() } else { self.seen.face_slot.len() };
        (self.open.is_some() && (id as usize) < table_len).then(|| self.seen.slot(is_edge, id, count))
    }

    /// The bitsets of `slots` (from [`UndoHistory::bitset_slot`], each listed once), all
    /// writable at once.
    pub(super) fn bitsets(&mut self, slots: &[usize]) -> Option<Vec<&mut [u64]>> {
        let used = self.seen.used.min(self.seen.slots.len());
        let picked = pick_mut(&mut self.seen.slots[..used], slots)?;
        Some(picked.into_iter().map(Vec::as_mut_slice).collect())
    }

    /// Appends recorded sample writes to the open step: `small` lists join its current block,
    /// each of `large` becomes a block of its own (moved, not copied). Blocks may come in any
    /// order: each sample is recorded once per step.
    pub(super) fn append_records(&mut self, small: Vec<Vec<(SampleRef, Rgba)>>, large: Vec<Vec<(SampleRef, Rgba)>>) {
        if !small.is_empty()
            && let Some(list) = current_samples(&mut self.open)
        {
            list.reserve(small.iter().map(Vec::len).sum());
            for records in small {
                list.extend(records);
            }
        }
        if let Some(step) = self.open.as_mut() {
            step.changes.extend(large.into_iter().map(Change::Samples));
        }
    }

    /// Records the state of `face` and its edges before a resolution change in the open step
    /// (no-op without one).
    fn record_resolution_change(&mut self, store: &ColorStore, face: u32) -> Result<(), UndoError> {
        if self.open.is_none() {
            return Ok(());
        }
        let state = FaceState::capture(store, face)?;
        // Offsets recorded from now on refer to the new sizes.
        self.seen.forget(false, face);
        for (edge, _, _) in &state.edges {
            self.seen.forget(true, *edge);
        }
        if let Some(step) = self.open.as_mut() {
            step.changes.push(Change::Resolution(Box::new(state)));
        }
        Ok(())
    }

    /// Writes `color` to `sample` through a [`StoreWriter`] (recording the old colour in the
    /// open step). Returns whether the sample exists.
    pub fn set_sample(&mut self, store: &mut ColorStore, sample: SampleRef, color: Rgba) -> bool {
        let exists = store.get(sample).is_some();
        StoreWriter::new(store, self).set(sample, color);
        exists
    }

    /// Changes the resolution of `face` through a [`StoreWriter`] (see
    /// [`StoreWriter::set_face_resolution`]). Returns whether the resolution changed.
    pub fn set_face_resolution(
        &mut self,
        store: &mut ColorStore,
        face: u32,
        resolution: Resolution,
    ) -> Result<bool, UndoError> {
        StoreWriter::new(store, self).set_face_resolution(face, resolution)
    }

    /// Undoes the newest step. Returns `false` when there is nothing to undo.
    pub fn undo(&mut self, store: &mut ColorStore) -> Result<bool, UndoError> {
        if self.open.is_some() {
            return Err(UndoError::Busy);
        }
        let Some(step) = self.undo.pop_back() else {
            return Ok(false);
        };
        if let Some((budget, format)) = &self.budget
            && let Err(error) = step.check_budget(store, budget, *format)
        {
            self.undo.push_back(step);
            return Err(error.into());
        }
        match step.apply_backwards(store) {
            Ok(inverse) => {
                self.redo.push(inverse);
                self.generation += 1;
                Ok(true)
            }
            Err(error) => {
                self.clear();
                self.generation += 1;
                Err(error)
            }
        }
    }

    /// Redoes the step undone last. Returns `false` when there is nothing to redo.
    pub fn redo(&mut self, store: &mut ColorStore) -> Result<bool, UndoError> {
        if self.open.is_some() {
            return Err(UndoError::Busy);
        }
        let Some(step) = self.redo.pop() else {
            return Ok(false);
        };
        if let Some((budget, format)) = &self.budget
            && let Err(error) = step.check_budget(store, budget, *format)
        {
            self.redo.push(step);
            return Err(error.into());
        }
        match step.apply_backwards(store) {
            Ok(inverse) => {
                self.undo.push_back(inverse);
                self.generation += 1;
                self.enforce_cap();
                Ok(true)
            }
            Err(error) => {
                self.clear();
                self.generation += 1;
                Err(error)
            }
        }
    }
}

/// Whether two colours differ in any bit (compiles to one vector comparison).
#[inline(always)]
pub(super) fn differs(a: Rgba, b: Rgba) -> bool {
    let (x, y) = (a.map(f32::to_bits), b.map(f32::to_bits));
    // Lane by lane (`x != y` on the arrays becomes a byte comparison through integer registers).
    (x[0] ^ y[0]) | (x[1] ^ y[1]) | (x[2] ^ y[2]) | (x[3] ^ y[3]) != 0
}

/// The one way tools change a store: every write records the old value in the history's
/// open step (when one is open) and goes through the store's own setters, which mark the
/// element dirty for the GPU upload. Borrow one for the duration of a dab, a fill, …
#[derive(Debug)]
pub struct StoreWriter<'a> {
    pub(super) store: &'a mut ColorStore,
    pub(super) history: &'a mut UndoHistory,
}

impl<'a> StoreWriter<'a> {
    /// A writer of `store` recording into `history`.
    pub fn new(store: &'a mut ColorStore, history: &'a mut UndoHistory) -> Self {
        StoreWriter { store, history }
    }

    /// The store, to read.
    #[inline(always)]
    pub fn store(&self) -> &ColorStore {
        self.store
    }

    /// Writes `color` to `sample`, recording the old colour first. Returns whether the
    /// colour changed (`false` when it is bit-identical or the sample does not exist).
    pub fn set(&mut self, sample: SampleRef, color: Rgba) -> bool {
        // Unchanged samples do not touch the history (no log slot is made for them).
        let Some(old) = self.store.get(sample).filter(|&old| differs(color, old)) else {
            return false;
        };
        let (element, index) = match sample {
            SampleRef::Vertex(v) => (Element::Vertices, v),
            SampleRef::Edge { edge, offset } => (Element::Edge(edge), offset),
            SampleRef::Interior { face, offset } => (Element::Interior(face), offset),
        };
        self.element(element).write(index, old, color)
    }

    /// Makes room in the open step for `samples` more first writes (a dab that knows how
    /// many samples it writes grows the log once instead of doubling it repeatedly).
    pub fn reserve(&mut self, samples: usize) {
        if let Some(list) = current_samples(&mut self.history.open) {
            list.reserve(samples);
        }
    }

    /// The writer of one element's samples: the fast path for many writes to one element
    /// (one slot look-up, then a bit test per write).
    #[inline]
    pub fn element(&mut self, element: Element) -> ElementWriter<'_> {
        let count = match element {
            Element::Vertices => 0,
            Element::Edge(edge) => self.store.edge_samples(edge).len(),
            Element::Interior(face) => self.store.interior_samples(face).len(),
        };
        ElementWriter { store: self.store, log: self.history.element_log(element, count) }
    }

    /// Sets every sample to `color_at(site)` (sites in [`ColorStore::for_each_site`]'s
    /// order), each written as [`StoreWriter::set`] writes it. Returns the samples changed.
    pub fn fill_with(&mut self, mut color_at: impl FnMut(crate::colors::store::SampleSite) -> Rgba) -> u64 {
        let mut sites = Vec::new();
        self.store.for_each_site(|site| sites.push(site));
        sites.into_iter().map(|site| u64::from(self.set(site.sample, color_at(site)))).sum()
    }

    /// Changes the resolution of `face` (resampling as [`ColorStore::set_face_resolution`]
    /// defines), recording the face's old resolution and the old samples of the face and its
    /// three edges in the open step. Returns whether the resolution changed.
    pub fn set_face_resolution(&mut self, face: u32, resolution: Resolution) -> Result<bool, UndoError> {
        let Some(current) = self.store.face_resolution(face) else {
            return Err(StoreError::NoSuchFace { face, face_count: self.store.topology().face_count() }.into());
        };
        if current == resolution {
            return Ok(false);
        }
        self.history.record_resolution_change(self.store, face)?;
        self.store.set_face_resolution(face, resolution)?;
        Ok(true)
    }
}

/// Writes the samples of one [`Element`], from [`StoreWriter::element`].
#[derive(Debug)]
pub struct ElementWriter<'w> {
    store: &'w mut ColorStore,
    log: SampleLog<'w>,
}

impl ElementWriter<'_> {
    /// The store, to read.
    #[inline(always)]
    pub fn store(&self) -> &ColorStore {
        self.store
    }

    /// The colour of sample `index` of the element.
    #[inline(always)]
    pub fn get(&self, index: u32) -> Option<Rgba> {
        self.store.get(self.log.element.sample(index))
    }

    /// Writes `new` to sample `index`, whose colour is `old` (as [`ElementWriter::get`] returned
    /// it), recording `old` on the first write in the step. Returns whether the colour changed
    /// (nothing is written or recorded when `new` is bit-identical to `old`).
    #[inline(always)]
    pub fn write(&mut self, index: u32, old: Rgba, new: Rgba) -> bool {
        if !differs(new, old) {
            return false;
        }
        self.log.record(index, old);
        self.store.set(self.log.element.sample(index), new)
    }

    /// Updates the run of `len` samples from `first` in place ([`ColorStore::update_run`]):
    /// `update(index, old)` gives the new (clamped) colour or `None`; a bit-identical one is
    /// not written; old colours are recorded on first write. Returns the samples changed.
    #[inline(always)]
    pub fn update_run(&mut self, first: u32, len: u32, mut update: impl FnMut(u32, Rgba) -> Option<Rgba>) -> u64 {
        let log = &mut self.log;
        self.store.update_run(log.element, first, len, |index, old| {
            let new = update(index, old)?;
            if !differs(new, old) {
                return None;
            }
            log.record(index, old);
            Some(new)
        })
    }
}

/// Disjoint `&mut` to the items of `items` at `indices` (each listed once; `None` when one is
/// repeated or past the end), in the order of `indices`.
fn pick_mut<'a, T>(items: &'a mut [T], indices: &[usize]) -> Option<Vec<&'a mut T>> {
    let mut order: Vec<(usize, usize)> = indices.iter().copied().zip(0..).collect();
    if !order.is_sorted() {
        order.sort_unstable();
    }
    let mut out: Vec<Option<&'a mut T>> = Vec::with_capacity(indices.len());
    out.resize_with(indices.len(), || None);
    let mut iter = items.iter_mut().enumerate();
    for (index, position) in order {
        let item = loop {
            let (at, item) = iter.next()?;
            if at == index {
                break item;
            }
            if at > index {
                return None;
            }
        };
        *out.get_mut(position)? = Some(item);
    }
    out.into_iter().collect()
}
