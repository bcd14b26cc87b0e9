//! The byte-level pieces both sectioned little-endian file formats share (the packed file,
//! docs/FORMAT.md, and the MCT file, docs/MCT_FORMAT.md): a section-table entry, a
//! panic-free header field reader, the CRC-32 that skips its own field, 256-byte section
//! alignment, slicing a section out of the file and decoding little-endian words. The
//! checks that report errors stay with each format (their messages name that format's
//! sections).

/// Every section starts at a multiple of this many bytes.
pub(crate) const SECTION_ALIGN: u64 = 256;

/// One entry of a section table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Section {
    pub(crate) offset: u64,
    pub(crate) length: u64,
}

/// A panic-free little-endian field reader over a fixed-size header (reads past the end
/// give 0).
pub(crate) struct Fields<'a>(pub(crate) &'a [u8]);

impl Fields<'_> {
    pub(crate) fn u32(&mut self) -> u32 {
        match self.0.split_first_chunk::<4>() {
            Some((head, rest)) => {
                self.0 = rest;
                u32::from_le_bytes(*head)
            }
            None => 0,
        }
    }

    pub(crate) fn u64(&mut self) -> u64 {
        match self.0.split_first_chunk::<8>() {
            Some((head, rest)) => {
                self.0 = rest;
                u64::from_le_bytes(*head)
            }
            None => 0,
        }
    }
}

/// CRC-32 (IEEE, `crc32fast`) of every byte of `bytes` except the 4-byte checksum field
/// at `checksum_offset`.
pub(crate) fn checksum(bytes: &[u8], checksum_offset: usize) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(bytes.get(..checksum_offset).unwrap_or(bytes));
    hasher.update(bytes.get(checksum_offset + 4..).unwrap_or_default());
    hasher.finalize()
}

/// `value` rounded up to [`SECTION_ALIGN`], or `None` on overflow.
pub(crate) fn align_up(value: u64) -> Option<u64> {
    value.checked_add(SECTION_ALIGN - 1).map(|v| v / SECTION_ALIGN * SECTION_ALIGN)
}

/// The bytes of `section` (empty when it lies outside `bytes`; callers check first).
pub(crate) fn section_bytes(bytes: &[u8], section: Section) -> &[u8] {
    let start = usize::try_from(section.offset).unwrap_or(usize::MAX);
    let end = usize::try_from(section.offset.saturating_add(section.length)).unwrap_or(usize::MAX);
    bytes.get(start..end).unwrap_or_default()
}

/// Splits `bytes` into groups of `N` little-endian `u32` words (a partial group at the
/// end is ignored; callers pass whole sections).
pub(crate) fn le_words<const N: usize>(bytes: &[u8]) -> Vec<[u32; N]> {
    bytes
        .chunks_exact(4 * N)
        .map(|chunk| {
            let mut words = [0u32; N];
            for (word, le) in words.iter_mut().zip(chunk.chunks_exact(4)) {
                *word = u32::from_le_bytes(le.first_chunk::<4>().copied().unwrap_or_default());
            }
            words
        })
        .collect()
}
