//! Fresh buffers that a document's bulk is written into once, backed by transparent huge
//! pages where the kernel offers them.
//!
//! A fresh buffer is mapped page by page as it is first written. On this kind of machine
//! (a VM, Linux with transparent huge pages in `madvise` mode, the default of Debian and
//! Ubuntu) a 4 KiB fault costs more than writing its page, so writing a fresh colour buffer
//! of hundreds of MB spends more time in faults than in the writes (`perf` of `bench pack`:
//! `clear_page_erms`, `exc_page_fault`). Asking for huge pages (`madvise(MADV_HUGEPAGE)`)
//! before the first write maps 2 MiB per fault instead. It is advice: contents, length and
//! capacity are those of `vec!`, and where the kernel has no huge pages (or this is not
//! Linux) nothing changes.
//!
//! Used where a document's bulk is written once, start to end: the store's slab chunks when
//! a document opens, the packer's outputs (open, export, leaving paint mode after a
//! resolution change) and the paint layout's colour bytes (entering paint mode). Not for
//! the copy a dab makes of a shared store chunk: there it was measured and did not help
//! (`bench paint`'s `session_first_dab` at 2.3M triangles: slower in both of two runs,
//! about twice as slow in one; the current figure is in docs/BENCHMARKS.md, "Other rows"),
//! and a huge-page fault may wait for the kernel to compact memory, which in the middle of a
//! stroke is a stall the artist sees.

use bytemuck::Zeroable;

/// The size of a transparent huge page on x86-64 and aarch64 (4 KiB base pages).
pub const HUGE_PAGE: usize = 2 << 20;

/// `len` zeroed values. The memory is fresh (mapped on first write, zeroed by the kernel), so
/// nothing is written here; huge pages are advised before any page is touched.
pub fn zeroed<T: Zeroable>(len: usize) -> Vec<T> {
    let buffer = bytemuck::zeroed_vec::<T>(len);
    advise_huge_pages(&buffer);
    buffer
}

/// `len` copies of `value`, written after huge pages are advised.
pub fn filled<T: Clone>(len: usize, value: T) -> Vec<T> {
    let mut buffer = with_capacity(len);
    buffer.resize(len, value);
    buffer
}

/// An empty buffer with room for `capacity` values, huge pages advised for that room.
fn with_capacity<T>(capacity: usize) -> Vec<T> {
    let buffer = Vec::with_capacity(capacity);
    advise_huge_pages(&buffer);
    buffer
}

/// Advises huge pages for the whole 2 MiB-aligned pages inside `buffer`'s allocation
/// (its capacity). No effect on smaller buffers.
fn advise_huge_pages<T>(buffer: &Vec<T>) {
    advise_huge_pages_bytes(buffer.as_ptr() as usize, buffer.capacity().saturating_mul(std::mem::size_of::<T>()));
}

#[cfg(target_os = "linux")]
fn advise_huge_pages_bytes(address: usize, bytes: usize) {
    let Some(end) = address.checked_add(bytes) else { return };
    let Some(first) = address.checked_next_multiple_of(HUGE_PAGE) else { return };
    let last = end - end % HUGE_PAGE;
    if last > first {
        // SAFETY: `first..last` lies inside one live allocation (the caller's buffer) and is
        // page-aligned. MADV_HUGEPAGE changes only how the kernel backs those pages, never
        // their contents or the mapping's protection; an error (e.g. EINVAL where the kernel
        // has no transparent huge pages) leaves the memory as it was, so it is ignored.
        unsafe {
            libc::madvise(first as *mut libc::c_void, last - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages_bytes(_address: usize, _bytes: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contents_are_those_of_vec() {
        for len in [0, 1, 7, HUGE_PAGE / 16 + 3, 3 * HUGE_PAGE / 16] {
            assert_eq!(zeroed::<[f32; 4]>(len), vec![[0.0f32; 4]; len]);
            assert_eq!(zeroed::<u8>(len), vec![0u8; len]);
            assert_eq!(filled(len, [0.25f32, -1.0, f32::MAX, 1.0]), vec![[0.25f32, -1.0, f32::MAX, 1.0]; len]);
        }
    }

    /// The advice reaches the kernel: the mapping holding a big buffer carries the `hg` flag
    /// (`MADV_HUGEPAGE`) in `/proc/self/smaps`. Skipped where the kernel has no transparent
    /// huge pages.
    #[cfg(target_os = "linux")]
    #[test]
    fn big_buffers_are_advised_huge_pages() {
        if !std::path::Path::new("/sys/kernel/mm/transparent_hugepage/enabled").exists() {
            eprintln!("skipped: this kernel has no transparent huge pages");
            return;
        }
        let buffer = filled(8 * HUGE_PAGE, 7u8);
        let probe = (buffer.as_ptr() as usize).next_multiple_of(HUGE_PAGE) + HUGE_PAGE;
        let smaps = std::fs::read_to_string("/proc/self/smaps").expect("smaps");
        let mut flags = None;
        let mut inside = false;
        for line in smaps.lines() {
            if let Some((range, _)) = line.split_once(' ')
                && let Some((start, end)) = range.split_once('-')
                && let (Ok(start), Ok(end)) = (usize::from_str_radix(start, 16), usize::from_str_radix(end, 16))
            {
                inside = (start..end).contains(&probe);
            } else if inside && let Some(rest) = line.strip_prefix("VmFlags:") {
                flags = Some(rest.split_whitespace().map(str::to_owned).collect::<Vec<_>>());
            }
        }
        let flags = flags.expect("the buffer's mapping is listed");
        assert!(flags.iter().any(|f| f == "hg"), "no MADV_HUGEPAGE on the buffer's mapping: {flags:?}");
        assert!(buffer.iter().all(|&b| b == 7));
    }
}
