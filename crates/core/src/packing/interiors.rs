//! The face-interior chains as the edge and vertex passes read them, without an `f32` copy
//! of level 0 (the bulk of the samples).
//!
//! Level 0 of a chain is the store's samples after quantisation, and quantising is exactly
//! decoding the bytes just written ([`ColorFormat::encode_quantized`] returns what
//! [`ColorFormat::decode`] gives), so level 0 is read back from the output bytes. Levels
//! ≥ 1 are filtered in `f32` and not representable in the output format: they are kept in
//! a compact buffer, face after face ([`InteriorPrefix::upper`]). Each face's chain is built
//! in a small scratch buffer (cache-resident) and written straight to both.

use glam::Vec4;

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout::{self, Resolution};
use crate::colors::store::ColorStore;

/// Per face, where its interior chain starts among the interior samples (`chain`) and where
/// its levels ≥ 1 start in the upper buffer (`upper`); both `F + 1` long (prefix sums).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct InteriorPrefix {
    pub(crate) chain: Vec<u32>,
    pub(crate) upper: Vec<u32>,
}

impl InteriorPrefix {
    /// The prefixes of `store`'s face resolutions (the canonical layout's interior order).
    pub(crate) fn of(store: &ColorStore) -> Self {
        let lengths =
            store.face_resolutions().iter().map(|&r| (layout::interior_chain_len(r), layout::interior_sample_count(r)));
        let (chain, upper) = prefix_sums(lengths);
        InteriorPrefix { chain, upper }
    }

    /// Samples of every face's levels ≥ 1.
    pub(crate) fn upper_len(&self) -> usize {
        self.upper.last().copied().unwrap_or(0) as usize
    }
}

/// Prefix sums of chain lengths and of their levels ≥ 1, from `(chain length, level-0
/// length)` per element: `(chain, upper)`, each one longer than the elements.
pub(crate) fn prefix_sums(lengths: impl ExactSizeIterator<Item = (u32, u32)>) -> (Vec<u32>, Vec<u32>) {
    let mut chain = Vec::with_capacity(lengths.len() + 1);
    let mut upper = Vec::with_capacity(lengths.len() + 1);
    let (mut c, mut u) = (0u32, 0u32);
    for (len, level0) in lengths {
        chain.push(c);
        upper.push(u);
        c = c.saturating_add(len);
        u = u.saturating_add(len - level0.min(len));
    }
    chain.push(c);
    upper.push(u);
    (chain, upper)
}

/// The interior section as built so far: its bytes (level 0 decoded from them) and the
/// upper levels.
#[derive(Clone, Copy)]
pub(crate) struct InteriorReader<'a> {
    pub(crate) store: &'a ColorStore,
    pub(crate) prefix: &'a InteriorPrefix,
    /// The interior section of the colour bytes.
    pub(crate) bytes: &'a [u8],
    pub(crate) upper: &'a [Rgba],
    pub(crate) format: ColorFormat,
}

impl InteriorReader<'_> {
    /// Asks the CPU to start loading `face`'s whole interior chain (its level-0 bytes and
    /// its upper levels) into cache, so a pass that visits faces out of order overlaps
    /// those loads with work instead of waiting for each (a hint: no effect on results).
    #[inline]
    pub(crate) fn prefetch(&self, face: u32) {
        let f = face as usize;
        let size = self.format.bytes_per_sample();
        if let (Some(c), Some(u)) = (self.prefix.chain.get(f..f + 2), self.prefix.upper.get(f..f + 2)) {
            let r = self.store.face_resolution(face).unwrap_or(Resolution::ONE);
            let n0 = (layout::interior_sample_count(r) as usize).min((c[1] - c[0]) as usize);
            if let Some(bytes) = self.bytes.get(c[0] as usize * size..(c[0] as usize + n0) * size) {
                prefetch_lines(bytes);
            }
            if let Some(upper) = self.upper.get(u[0] as usize..u[1] as usize) {
                prefetch_lines(upper);
            }
        }
    }

    /// Sample `offset` of `face`'s interior chain, as the `f32` chain holds it.
    #[inline]
    pub(crate) fn get(&self, face: u32, offset: usize) -> Option<Rgba> {
        let r = self.store.face_resolution(face).unwrap_or(Resolution::ONE);
        let n0 = layout::interior_sample_count(r) as usize;
        let f = face as usize;
        if offset < n0 {
            let size = self.format.bytes_per_sample();
            let at = (*self.prefix.chain.get(f)? as usize + offset) * size;
            Some(self.format.decode(self.bytes.get(at..at + size)?))
        } else {
            self.upper.get(*self.prefix.upper.get(f)? as usize + offset - n0).copied()
        }
    }
}

/// Prefetches every 64-byte cache line `slice` touches into the L2 cache, not L1 (x86-64;
/// elsewhere nothing): a pass prefetches whole chains and reads only some of their samples,
/// so L1 keeps what is being worked on. `prefetcht1` rather than `prefetcht0`: with it the
/// Bunny's RGBA16F rebuild at R = 16 was faster in each of three interleaved runs, RGBA8 and
/// the 1M-triangle Duck unchanged (`bench pack`; the current figures: docs/BENCHMARKS.md).
#[inline]
pub(crate) fn prefetch_lines<T>(slice: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        // One item per 64 bytes from the first, and the last (whose line the steps may miss).
        let step = 64 / std::mem::size_of::<T>().clamp(1, 64);
        for item in slice.iter().step_by(step.max(1)).chain(slice.last()) {
            safe_arch::prefetch_t1(item);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = slice;
}

/// One face's interior chain at one level, as [`InteriorReader::level`] finds it.
#[derive(Clone, Copy)]
pub(crate) enum FaceLevel<'a> {
    /// Level 0: the encoded samples.
    Bytes(&'a [u8], ColorFormat),
    /// A level ≥ 1: the `f32` samples from that level's start on.
    Upper(&'a [Rgba]),
}

impl FaceLevel<'_> {
    /// Sample `offset` of the level, in a SIMD register (zero past the end).
    #[inline(always)]
    pub(crate) fn get_vec4(&self, offset: usize) -> Vec4 {
        match *self {
            FaceLevel::Bytes(bytes, format) => {
                let size = format.bytes_per_sample();
                bytes.get(offset * size..offset * size + size).map_or(Vec4::ZERO, |b| format.decode_vec4(b))
            }
            FaceLevel::Upper(upper) => upper.get(offset).map_or(Vec4::ZERO, |c| Vec4::from_array(*c)),
        }
    }
}

impl<'a> InteriorReader<'a> {
    /// `face`'s interior chain from offset `level_offset` on (the start of one level).
    #[inline]
    pub(crate) fn level(&self, face: u32, level_offset: usize) -> FaceLevel<'a> {
        let r = self.store.face_resolution(face).unwrap_or(Resolution::ONE);
        let n0 = layout::interior_sample_count(r) as usize;
        let f = face as usize;
        let empty = FaceLevel::Upper(&[]);
        if level_offset < n0 {
            let size = self.format.bytes_per_sample();
            let Some(&start) = self.prefix.chain.get(f) else {
                return empty;
            };
            let at = (start as usize + level_offset) * size;
            self.bytes.get(at..).map_or(empty, |bytes| FaceLevel::Bytes(bytes, self.format))
        } else {
            let Some(&start) = self.prefix.upper.get(f) else {
                return empty;
            };
            self.upper.get(start as usize + level_offset - n0..).map_or(empty, FaceLevel::Upper)
        }
    }
}

/// Splits `slice` into the pieces between consecutive `bounds` (increasing, relative to the
/// slice; bounds past the end are cut to it).
pub(crate) fn split_at_bounds<'a, T>(slice: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut pieces = Vec::with_capacity(bounds.len().saturating_sub(1));
    let mut rest = slice;
    let mut cursor = bounds.first().copied().unwrap_or(0).min(rest.len());
    rest = &mut rest[cursor..];
    for &end in bounds.iter().skip(1) {
        let len = end.saturating_sub(cursor).min(rest.len());
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(len);
        pieces.push(piece);
        rest = tail;
        cursor += len;
    }
    pieces
}

/// The interior bytes and upper levels of each face of `faces` (sorted, unique) that has an
/// interior chain, cut out of the interior section (`bytes`, `size` bytes a sample) and the
/// upper buffer.
pub(crate) fn dirty_pieces<'a>(
    prefix: &InteriorPrefix,
    faces: &[u32],
    size: usize,
    bytes: &'a mut [u8],
    upper: &'a mut [Rgba],
) -> Vec<(u32, &'a mut [u8], &'a mut [Rgba])> {
    let chain = |f: u32| prefix.chain.get(f as usize..f as usize + 2).map_or((0, 0), |c| (c[0], c[1]));
    let faces: Vec<u32> = faces.iter().copied().filter(|&f| chain(f).1 > chain(f).0).collect();
    // Bounds as [start, end] pairs: pieces alternate between a face's chain and the gap after it.
    let byte_bounds: Vec<usize> =
        faces.iter().flat_map(|&f| [chain(f).0 as usize * size, chain(f).1 as usize * size]).collect();
    let upper_of = |f: u32| prefix.upper.get(f as usize..f as usize + 2).map_or((0, 0), |u| (u[0], u[1]));
    let upper_bounds: Vec<usize> =
        faces.iter().flat_map(|&f| [upper_of(f).0 as usize, upper_of(f).1 as usize]).collect();
    let byte_pieces = split_at_bounds(bytes, &byte_bounds);
    let upper_pieces = split_at_bounds(upper, &upper_bounds);
    faces
        .into_iter()
        .zip(byte_pieces.into_iter().step_by(2))
        .zip(upper_pieces.into_iter().step_by(2))
        .map(|((f, out), up)| (f, out, up))
        .collect()
}
