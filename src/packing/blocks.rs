//! Splitting a section of the chain buffers into runs of consecutive elements, so rayon
//! can hand each run's slices to one task.

use crate::colors::format::Rgba;

/// Elements per parallel task.
pub(crate) const BLOCK: usize = 1024;

/// A run of consecutive element ids and the part of the chain buffers that holds their
/// chains (`offset` is the global sample index of `chains[0]`).
pub(crate) struct Block<'a> {
    pub(crate) ids: std::ops::Range<u32>,
    pub(crate) offset: usize,
    pub(crate) chains: &'a mut [Rgba],
    pub(crate) bytes: &'a mut [u8],
}

/// Splits one section of the buffers (elements `0..count` laid out in id order from
/// `section_start`, element `id` at `base(id)` when it has a chain) into blocks of
/// `BLOCK` ids.
pub(crate) fn split_blocks<'a>(
    chains: &'a mut [Rgba],
    bytes: &'a mut [u8],
    size: usize,
    section_start: usize,
    count: u32,
    base: impl Fn(u32) -> Option<usize>,
) -> Vec<Block<'a>> {
    let block_count = (count as usize).div_ceil(BLOCK);
    let mut starts = vec![section_start + chains.len(); block_count + 1];
    let mut next = section_start + chains.len();
    for id in (0..count).rev() {
        if let Some(b) = base(id) {
            next = b;
        }
        if (id as usize).is_multiple_of(BLOCK) {
            starts[id as usize / BLOCK] = next;
        }
    }
    let mut blocks = Vec::with_capacity(block_count);
    let skip = starts.first().copied().unwrap_or(section_start).saturating_sub(section_start);
    let (_, mut rest_chains) = chains.split_at_mut(skip.min(chains.len()));
    let (_, mut rest_bytes) = bytes.split_at_mut((skip * size).min(bytes.len()));
    for b in 0..block_count {
        let len = starts[b + 1].saturating_sub(starts[b]).min(rest_chains.len());
        let byte_len = (len * size).min(rest_bytes.len());
        let (chain_part, chain_tail) = std::mem::take(&mut rest_chains).split_at_mut(len);
        let (byte_part, byte_tail) = std::mem::take(&mut rest_bytes).split_at_mut(byte_len);
        rest_chains = chain_tail;
        rest_bytes = byte_tail;
        let first = (b * BLOCK) as u32;
        let end = ((b + 1) * BLOCK).min(count as usize) as u32;
        blocks.push(Block { ids: first..end, offset: starts[b], chains: chain_part, bytes: byte_part });
    }
    blocks
}
