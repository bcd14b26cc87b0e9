//! Per-element sample slots in a few large chunks: the store's edge and interior samples.
//!
//! Each element (an edge, a face's interior) owns one slot: a run of samples inside one
//! chunk. Opening a mesh allocates a handful of chunks (filled in parallel) instead of one
//! allocation per element. Changing one element's sample count moves only that element: the
//! new run goes to the end of the last chunk (or a new one), the old one becomes dead space,
//! and a chunk more than half dead is compacted (its live runs move down, nothing else), so
//! no global array shifts and dead space stays under half of each chunk.
//!
//! Chunks are shared between clones and copied on their first write (`Arc::make_mut`): a
//! snapshot of the store (paint mode's base colours, a document handed to autosave) costs
//! one pointer per chunk, and the first dab that writes into a chunk copies that chunk only.

use std::sync::Arc;

use rayon::prelude::*;

use crate::colors::format::Rgba;

/// Bytes of `v`'s allocation.
pub(crate) fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}

/// Samples per chunk (16 MiB of `f32` RGBA); a longer element gets a chunk of its own.
const CHUNK: usize = 1 << 20;

/// Where one element's samples are.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Slot {
    chunk: u32,
    start: u32,
    len: u32,
}

/// The samples of `slots.len()` elements, each a contiguous run.
#[derive(Debug, Clone, Default)]
pub(crate) struct Slab {
    chunks: Vec<Arc<Vec<Rgba>>>,
    /// Dead samples per chunk.
    dead: Vec<usize>,
    slots: Vec<Slot>,
    live: u64,
}

impl Slab {
    /// Elements of `lens` samples each, every sample `color`.
    pub(crate) fn filled(lens: impl Iterator<Item = u32>, color: Rgba) -> Self {
        let mut slots = Vec::with_capacity(lens.size_hint().0);
        let mut chunk_lens: Vec<usize> = Vec::new();
        let mut live = 0u64;
        for len in lens {
            let n = len as usize;
            let fits = chunk_lens.last().is_some_and(|&used| used + n <= CHUNK);
            if !fits && n > 0 {
                chunk_lens.push(0);
            }
            let chunk = chunk_lens.len().saturating_sub(1);
            let start = chunk_lens.get(chunk).copied().unwrap_or(0);
            if let Some(used) = chunk_lens.get_mut(chunk) {
                *used += n;
            }
            slots.push(Slot { chunk: chunk as u32, start: start as u32, len });
            live += u64::from(len);
        }
        let chunks: Vec<Arc<Vec<Rgba>>> =
            chunk_lens.par_iter().map(|&n| Arc::new(crate::memory::filled(n, color))).collect();
        Slab { dead: vec![0; chunks.len()], chunks, slots, live }
    }

    /// Heap bytes `(chunks, index)`: the chunks' allocations (counted whole, shared or not),
    /// then the slots and dead counts.
    pub(crate) fn heap_bytes(&self) -> (u64, u64) {
        let chunks: usize = self.chunks.iter().map(|c| c.capacity() * std::mem::size_of::<Rgba>()).sum();
        (chunks as u64, (vec_bytes(&self.dead) + vec_bytes(&self.slots)) as u64)
    }

    /// Bytes of the chunks this slab shares with `other` (the same allocation, not yet copied
    /// on a write).
    pub(crate) fn shared_bytes(&self, other: &Slab) -> u64 {
        let shared = |chunk: &Arc<Vec<Rgba>>| other.chunks.iter().any(|o| Arc::ptr_eq(o, chunk));
        let bytes: usize =
            self.chunks.iter().filter(|c| shared(c)).map(|c| c.capacity() * std::mem::size_of::<Rgba>()).sum();
        bytes as u64
    }

    /// Samples held by all elements.
    pub(crate) fn live_samples(&self) -> u64 {
        self.live
    }

    /// The samples of element `id` (`None` past the end).
    #[inline]
    pub(crate) fn get(&self, id: usize) -> Option<&[Rgba]> {
        let slot = *self.slots.get(id)?;
        let start = slot.start as usize;
        self.chunks.get(slot.chunk as usize)?.get(start..start + slot.len as usize)
    }

    /// The samples of element `id`, writable (`None` past the end).
    #[inline]
    pub(crate) fn get_mut(&mut self, id: usize) -> Option<&mut [Rgba]> {
        let slot = *self.slots.get(id)?;
        let start = slot.start as usize;
        Arc::make_mut(self.chunks.get_mut(slot.chunk as usize)?).get_mut(start..start + slot.len as usize)
    }

    /// The samples of each element of `ids`, all writable at once (for writers that work on
    /// many elements in parallel). `None` when an id is past the end or listed twice.
    pub(crate) fn many_mut(&mut self, ids: &[u32]) -> Option<Vec<&mut [Rgba]>> {
        // Each run as (chunk · 2³² + start, len, position in `ids`): sorting by the one key
        // puts the runs in storage order (16-byte entries, one comparison each).
        let mut order: Vec<(u64, u32, u32)> = Vec::with_capacity(ids.len());
        for (position, &id) in (0u32..).zip(ids) {
            let slot = *self.slots.get(id as usize)?;
            // Empty runs share `Slot::default()`; they need no storage.
            if slot.len > 0 {
                order.push(((u64::from(slot.chunk) << 32) | u64::from(slot.start), slot.len, position));
            }
        }
        // Often already in order (faces by id, a stroke's elements in their first dab's order).
        if !order.is_sorted_by_key(|run| run.0) {
            order.sort_unstable_by_key(|run| run.0);
        }
        let mut out: Vec<&mut [Rgba]> = Vec::with_capacity(ids.len());
        out.resize_with(ids.len(), || &mut []);
        let mut chunks = self.chunks.iter_mut().enumerate();
        // The chunk being split: its index, the part after the last run taken, and where that
        // part starts.
        let mut current: Option<(usize, &mut [Rgba], usize)> = None;
        for (key, len, position) in order {
            let (chunk, start, len) = ((key >> 32) as usize, (key & u64::from(u32::MAX)) as usize, len as usize);
            if current.as_ref().is_none_or(|(index, _, _)| *index != chunk) {
                // Only the chunks written into are made unique (copied if shared).
                let (index, data) = chunks.find(|(index, _)| *index >= chunk)?;
                if index != chunk {
                    return None;
                }
                current = Some((index, Arc::make_mut(data).as_mut_slice(), 0));
            }
            let (_, rest, offset) = current.as_mut()?;
            // A run starting before the end of the previous one: an id listed twice.
            let skip = start.checked_sub(*offset)?;
            let tail = std::mem::take(rest);
            if skip + len > tail.len() {
                return None;
            }
            let (piece, tail) = tail[skip..].split_at_mut(len);
            *rest = tail;
            *offset = start + len;
            *out.get_mut(position as usize)? = piece;
        }
        Some(out)
    }

    /// Replaces element `id`'s samples by `samples` (a different count moves the element).
    pub(crate) fn set(&mut self, id: usize, samples: &[Rgba]) {
        let Some(&slot) = self.slots.get(id) else {
            return;
        };
        if slot.len as usize == samples.len() {
            if let Some(run) = self.get_mut(id) {
                run.copy_from_slice(samples);
            }
            return;
        }
        let old_chunk = slot.chunk as usize;
        if slot.len > 0
            && let Some(dead) = self.dead.get_mut(old_chunk)
        {
            *dead += slot.len as usize;
        }
        self.live = self.live - u64::from(slot.len) + samples.len() as u64;
        let n = samples.len();
        let new_slot = if n == 0 {
            Slot::default()
        } else {
            let fits = self.chunks.last().is_some_and(|last| last.len() + n <= CHUNK.max(last.capacity()));
            if !fits {
                self.chunks.push(Arc::new(Vec::with_capacity(CHUNK.max(n))));
                self.dead.push(0);
            }
            let chunk = self.chunks.len() - 1;
            let last = Arc::make_mut(&mut self.chunks[chunk]);
            if last.capacity() < CHUNK {
                last.reserve_exact(CHUNK - last.len());
            }
            let start = last.len();
            last.extend_from_slice(samples);
            Slot { chunk: chunk as u32, start: start as u32, len: n as u32 }
        };
        self.slots[id] = new_slot;
        if slot.len > 0 {
            self.compact_if_mostly_dead(old_chunk);
        }
    }

    /// Moves the live runs of `chunk` down over its dead space when more than half of it
    /// is dead (each element keeps its chunk; only slots of this chunk change).
    fn compact_if_mostly_dead(&mut self, chunk: usize) {
        let (Some(&dead), Some(data)) = (self.dead.get(chunk), self.chunks.get(chunk)) else {
            return;
        };
        if dead == 0 || 2 * dead <= data.len() {
            return;
        }
        let mut members: Vec<(u32, usize)> = (0..self.slots.len())
            .filter(|&id| self.slots[id].chunk as usize == chunk && self.slots[id].len > 0)
            .map(|id| (self.slots[id].start, id))
            .collect();
        members.sort_unstable();
        let data = Arc::make_mut(&mut self.chunks[chunk]);
        let mut next = 0usize;
        for (start, id) in members {
            let len = self.slots[id].len as usize;
            data.copy_within(start as usize..start as usize + len, next);
            self.slots[id].start = next as u32;
            next += len;
        }
        data.truncate(next);
        self.dead[chunk] = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clone shares every chunk until one side writes: then only the chunks written are
    /// copied, and neither side sees the other's writes (get_mut, many_mut, resizes).
    #[test]
    fn clones_share_chunks_until_written() {
        let lens = vec![1000u32; 3 * CHUNK / 1000];
        let original = Slab::filled(lens.iter().copied(), [0.25; 4]);
        assert!(original.chunks.len() >= 3);
        let mut copy = original.clone();
        assert!(original.chunks.iter().zip(&copy.chunks).all(|(a, b)| Arc::ptr_eq(a, b)));
        copy.get_mut(0).unwrap()[0] = [1.0; 4];
        let last = lens.len() - 1;
        copy.many_mut(&[last as u32]).unwrap()[0][999] = [2.0; 4];
        copy.set(1, &[[3.0; 4]; 7]);
        assert_eq!(original.get(0).unwrap()[0], [0.25; 4]);
        assert_eq!(original.get(last).unwrap()[999], [0.25; 4]);
        assert_eq!(original.get(1).unwrap(), &[[0.25; 4]; 1000][..]);
        assert_eq!(copy.get(0).unwrap()[0], [1.0; 4]);
        assert_eq!(copy.get(last).unwrap()[999], [2.0; 4]);
        assert_eq!(copy.get(1).unwrap(), &[[3.0; 4]; 7][..]);
        // The first chunk and the last were written (and the one the resize appended to);
        // a chunk in between nobody wrote is still shared.
        assert!(!Arc::ptr_eq(&original.chunks[0], &copy.chunks[0]));
        let middle = copy.slots[lens.len() / 2].chunk as usize;
        assert!(middle != 0 && middle + 1 < original.chunks.len());
        assert!(Arc::ptr_eq(&original.chunks[middle], &copy.chunks[middle]));
        // Writing the original afterwards leaves the copy as it was.
        let mut original = original;
        original.get_mut(lens.len() / 2).unwrap()[0] = [4.0; 4];
        assert_eq!(copy.get(lens.len() / 2).unwrap()[0], [0.25; 4]);
    }

    /// The slab against a `Vec<Vec<_>>` (the obvious map), through many resizes that move,
    /// kill and compact runs.
    #[test]
    fn slab_holds_what_a_vec_of_vecs_holds() {
        let lens: Vec<u32> = (0..3000u32).map(|i| (i * 7919) % 700).collect();
        let mut truth: Vec<Vec<Rgba>> = lens.iter().map(|&n| vec![[0.5; 4]; n as usize]).collect();
        let mut slab = Slab::filled(lens.iter().copied(), [0.5; 4]);
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        for step in 0..20_000 {
            let id = next() % truth.len();
            let n = if step % 3 == 0 { truth[id].len() } else { next() % 2000 };
            let samples: Vec<Rgba> = (0..n).map(|k| [step as f32, k as f32, id as f32, 1.0]).collect();
            slab.set(id, &samples);
            truth[id] = samples;
            if step % 97 == 0
                && let Some(run) = slab.get_mut(id)
                && let Some(first) = run.first_mut()
            {
                *first = [9.0; 4];
                truth[id][0] = [9.0; 4];
            }
        }
        assert_eq!(slab.slots.len(), truth.len());
        for (id, want) in truth.iter().enumerate() {
            assert_eq!(slab.get(id).unwrap(), want.as_slice(), "element {id}");
        }
        assert_eq!(slab.live_samples(), truth.iter().map(|t| t.len() as u64).sum::<u64>());
        let held: usize = slab.chunks.iter().map(|chunk| chunk.len()).sum();
        assert!(held as u64 <= 2 * slab.live_samples() + 2 * CHUNK as u64, "dead space bounded");
        assert!(slab.get(truth.len()).is_none());
        // Many runs at once, in any order, are the runs `get` returns; a repeat is refused.
        let mut ids: Vec<u32> = (0..truth.len() as u32).filter(|id| id % 3 != 1).collect();
        ids.reverse();
        let runs = slab.many_mut(&ids).unwrap();
        for (run, &id) in runs.into_iter().zip(&ids) {
            assert_eq!(&*run, truth[id as usize].as_slice(), "element {id}");
            if let Some(first) = run.first_mut() {
                *first = [id as f32; 4];
            }
        }
        for &id in &ids {
            if let Some(first) = truth[id as usize].first_mut() {
                *first = [id as f32; 4];
            }
        }
        for (id, want) in truth.iter().enumerate() {
            assert_eq!(slab.get(id).unwrap(), want.as_slice(), "element {id} after many_mut");
        }
        let repeated = truth.iter().position(|t| !t.is_empty()).unwrap() as u32;
        assert!(slab.many_mut(&[repeated, 0, repeated]).is_none());
        assert!(slab.many_mut(&[truth.len() as u32]).is_none());
    }
}
