//! The edge chains as the passes read them, without an `f32` copy of level 0 (as
//! [`crate::packing::interiors`] does for faces).
//!
//! Level 0 of an edge chain is the store's samples after quantisation, which is exactly
//! decoding the bytes written for them, so it is read back from the output bytes. Levels
//! ≥ 1 are filtered in `f32`: they are kept in a compact buffer, edge after edge
//! ([`EdgePrefix::upper`]). An edge whose chain is being filtered is copied into a small
//! scratch chain (level 0 decoded, the levels above copied), filtered there and its levels
//! ≥ 1 copied back.

use crate::colors::format::{ColorFormat, Rgba};
use crate::colors::layout;
use crate::colors::store::ColorStore;
use crate::packing::interiors::{prefetch_lines, prefix_sums};

/// Per edge, where its chain starts in the edge section of the colour buffer (`chain`)
/// and where its levels ≥ 1 start in the upper buffer (`upper`); both `E + 1` long (prefix
/// sums, edges without samples take no room).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct EdgePrefix {
    pub(crate) chain: Vec<u32>,
    pub(crate) upper: Vec<u32>,
}

impl EdgePrefix {
    /// The prefixes of `store`'s edge resolutions (the canonical layout's edge order).
    pub(crate) fn of(store: &ColorStore) -> Self {
        let lengths = (0..store.topology().edge_count()).map(|e| {
            store.edge_resolution(e).map_or((0, 0), |r| (layout::edge_chain_len(r), layout::edge_sample_count(r)))
        });
        let (chain, upper) = prefix_sums(lengths);
        EdgePrefix { chain, upper }
    }

    /// Samples of every edge's levels ≥ 1.
    pub(crate) fn upper_len(&self) -> usize {
        self.upper.last().copied().unwrap_or(0) as usize
    }

    /// The chain and upper ranges of `edge` (relative to their sections).
    pub(crate) fn ranges(&self, edge: u32) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let e = edge as usize;
        let at = |v: &[u32], k: usize| v.get(k).copied().unwrap_or(0) as usize;
        (at(&self.chain, e)..at(&self.chain, e + 1), at(&self.upper, e)..at(&self.upper, e + 1))
    }
}

/// One edge's chain as [`EdgeReader::chain`] finds it.
#[derive(Clone, Copy)]
pub(crate) struct EdgeChain<'a> {
    /// Level 0's bytes.
    level0: &'a [u8],
    /// Levels ≥ 1 in `f32`.
    upper: &'a [Rgba],
    format: ColorFormat,
}

impl EdgeChain<'_> {
    /// Sample `offset` of the chain, as the `f32` chain holds it, in a SIMD register.
    #[inline(always)]
    pub(crate) fn get(&self, offset: usize) -> Option<glam::Vec4> {
        let size = self.format.bytes_per_sample();
        let n0 = self.level0.len() / size;
        if offset < n0 {
            Some(self.format.decode_vec4(self.level0.get(offset * size..offset * size + size)?))
        } else {
            self.upper.get(offset - n0).map(|c| glam::Vec4::from_array(*c))
        }
    }
}

/// The edge section as built so far: its bytes (level 0 decoded from them) and the levels
/// ≥ 1 in `f32`.
#[derive(Clone, Copy)]
pub(crate) struct EdgeReader<'a> {
    pub(crate) prefix: &'a EdgePrefix,
    /// The edge section of the colour bytes.
    pub(crate) bytes: &'a [u8],
    pub(crate) upper: &'a [Rgba],
    pub(crate) format: ColorFormat,
}

impl EdgeReader<'_> {
    /// Sample `offset` of `edge`'s chain, as the `f32` chain holds it.
    #[inline(always)]
    pub(crate) fn get(&self, edge: u32, offset: usize) -> Option<Rgba> {
        self.chain(edge)?.get(offset).map(|color| color.to_array())
    }

    /// `edge`'s chain: its level-0 bytes and its levels ≥ 1, looked up once for a loop
    /// that reads several of its samples.
    #[inline(always)]
    pub(crate) fn chain(&self, edge: u32) -> Option<EdgeChain<'_>> {
        let e = edge as usize;
        let (chain, chain_end) = (*self.prefix.chain.get(e)? as usize, *self.prefix.chain.get(e + 1)? as usize);
        let (upper, upper_end) = (*self.prefix.upper.get(e)? as usize, *self.prefix.upper.get(e + 1)? as usize);
        let size = self.format.bytes_per_sample();
        let n0 = chain_end.checked_sub(chain)?.checked_sub(upper_end.checked_sub(upper)?)?;
        Some(EdgeChain {
            level0: self.bytes.get(chain * size..(chain + n0) * size)?,
            upper: self.upper.get(upper..upper_end)?,
            format: self.format,
        })
    }

    /// Asks the CPU to start loading `edge`'s chain (its level-0 bytes and its levels ≥ 1)
    /// into cache, for a pass that visits edges out of order (a hint: no effect on results).
    #[inline]
    pub(crate) fn prefetch(&self, edge: u32) {
        let (chain, upper) = self.prefix.ranges(edge);
        let size = self.format.bytes_per_sample();
        if let Some(bytes) = self.bytes.get(chain.start * size..chain.end.saturating_sub(upper.len()) * size) {
            prefetch_lines(bytes);
        }
        if let Some(upper) = self.upper.get(upper) {
            prefetch_lines(upper);
        }
    }

    /// The edge whose chain holds sample `index` of the edge section.
    pub(crate) fn edge_at(&self, index: usize) -> Option<u32> {
        let after = self.prefix.chain.partition_point(|&start| start as usize <= index);
        let edge = after.checked_sub(1)?;
        (index < *self.prefix.chain.get(after)? as usize).then_some(edge as u32)
    }

    /// `edge`'s whole chain in `f32` into `scratch` (level 0 decoded from the bytes).
    pub(crate) fn chain_into(&self, edge: u32, scratch: &mut Vec<Rgba>) {
        let (chain, upper) = self.prefix.ranges(edge);
        let size = self.format.bytes_per_sample();
        scratch.clear();
        let level0 = self.bytes.get(chain.start * size..(chain.end - upper.len()) * size).unwrap_or(&[]);
        scratch.extend(level0.chunks_exact(size).map(|b| self.format.decode(b)));
        scratch.extend_from_slice(self.upper.get(upper).unwrap_or(&[]));
        scratch.resize(chain.len(), [0.0; 4]);
    }
}
