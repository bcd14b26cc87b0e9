//! The content checks shared by the reader and the writer: limits, positions, indices, face
//! records, the band table, the pairs the records describe, and every block inside the atlas
//! (module docs of [`super`]).

use super::error::MctFileError;
use super::{MAX_ATLAS_SIDE, MAX_LEVELS};
use crate::mct::layout::{GROUPS, MctBands, MctFaceRecord, frame_of};

/// The atlas size and level count limits.
pub(super) fn check_limits(width: u32, height: u32, levels: u32) -> Result<(), MctFileError> {
    if !(1..=MAX_ATLAS_SIDE).contains(&width) || !(1..=MAX_ATLAS_SIDE).contains(&height) {
        return Err(MctFileError::AtlasSize { width, height });
    }
    if !(1..=MAX_LEVELS).contains(&levels) {
        return Err(MctFileError::Levels(levels));
    }
    Ok(())
}

/// What [`check_content`] reads: the mesh and the layout without its pair lists.
pub(super) struct Content<'a> {
    pub(super) positions: &'a [[f32; 3]],
    pub(super) density: &'a [f32],
    pub(super) indices: &'a [[u32; 3]],
    pub(super) records: &'a [MctFaceRecord],
    pub(super) masks: &'a [u32],
    pub(super) bands: &'a MctBands,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) levels: u32,
}

/// Checks the content of a file whose sections have consistent sizes (see the module
/// docs) and returns the pair lists the records describe.
pub(super) fn check_content(content: &Content<'_>) -> Result<Vec<Vec<[u32; 2]>>, MctFileError> {
    let Content { positions, density, indices, records, masks, bands, width, height, levels } = *content;
    check_limits(width, height, levels)?;
    for (vertex, position) in (0u64..).zip(positions) {
        if !position.iter().all(|c| c.is_finite()) {
            return Err(MctFileError::NonFinitePosition { vertex, position: *position });
        }
    }
    for (vertex, &value) in (0u64..).zip(density) {
        if !(value.is_finite() && value >= 0.0) {
            return Err(MctFileError::BadDensity { vertex, density: value });
        }
    }
    let vertex_count = positions.len() as u64;
    for (triangle, corners) in (0u64..).zip(indices) {
        for (corner, &index) in corners.iter().enumerate() {
            if u64::from(index) >= vertex_count {
                return Err(MctFileError::IndexOutOfRange { triangle, corner, index, vertex_count });
            }
        }
    }
    let faces_per_group = check_records(records, levels)?;
    check_bands(bands, &faces_per_group, levels)?;
    let pairs = rebuild_pairs(records, &faces_per_group)?;
    check_strip_rows(bands, masks, &pairs)?;
    check_pair_edges(indices, records, &pairs)?;
    check_blocks_inside(records, bands, masks, width, height, levels)?;
    Ok(pairs)
}

/// Checks every record's fields; returns the number of faces of each block resolution.
fn check_records(records: &[MctFaceRecord], levels: u32) -> Result<[u64; GROUPS], MctFileError> {
    let mut faces_per_group = [0u64; GROUPS];
    for (face, &record) in (0u64..).zip(records) {
        let corner = record.0 & 3;
        if corner >= 3 {
            return Err(MctFileError::RecordCorner { face, record: record.0, corner });
        }
        let log2 = record.log2_block();
        if log2 >= GROUPS as u32 {
            return Err(MctFileError::RecordResolution { face, record: record.0, log2 });
        }
        if log2 >= levels {
            return Err(MctFileError::RecordLevels { face, resolution: 1 << log2, needed: log2 + 1, levels });
        }
        faces_per_group[log2 as usize] += 1;
    }
    for (face, &record) in (0u64..).zip(records) {
        let g = record.log2_block();
        let faces = faces_per_group[g as usize];
        if u64::from(record.pair()) >= faces {
            return Err(MctFileError::PairIndex { face, pair: record.pair(), resolution: 1 << g, faces });
        }
    }
    Ok(faces_per_group)
}

/// Reserved words zero (word 3 of a group's level-0 entry holds its strip rows when it has
/// faces); a row width wherever a face reads the band, and fewer empty leading slots than a
/// row holds.
fn check_bands(bands: &MctBands, faces_per_group: &[u64; GROUPS], levels: u32) -> Result<(), MctFileError> {
    for (index, entry) in bands.bands.iter().enumerate() {
        let (resolution, level) = (1u32 << (index / GROUPS), (index % GROUPS) as u32);
        let used = faces_per_group[index / GROUPS] > 0 && level < levels;
        for (word, &value) in entry.iter().enumerate().skip(2) {
            let allowed = used && (word == 2 || level == 0);
            if value != 0 && !allowed {
                return Err(MctFileError::BandReserved { resolution, level, word, value });
            }
        }
        if used && entry[2] >= entry[1].max(1) {
            return Err(MctFileError::BandReserved { resolution, level, word: 2, value: entry[2] });
        }
    }
    for (g, &faces) in faces_per_group.iter().enumerate() {
        if faces == 0 {
            continue;
        }
        for level in 0..levels {
            if bands.band(g as u32, level).1 == 0 {
                return Err(MctFileError::EmptyBand { resolution: 1 << g, level, faces });
            }
        }
    }
    Ok(())
}

/// Each group's strip rows: at most 32 pairs, 1..=S+1 pieces, its masks right after the
/// previous group's, each with bit 0 and the bits past the row clear and at most `pieces − 1`
/// piece starts; no mask left over.
fn check_strip_rows(bands: &MctBands, masks: &[u32], pairs: &[Vec<[u32; 2]>]) -> Result<(), MctFileError> {
    let mut next = 0u64;
    for (g, list) in pairs.iter().enumerate().filter(|(_, list)| !list.is_empty()) {
        let resolution = 1u32 << g;
        let (mask_base, log2_row, pieces) = bands.strip_rows(g as u32);
        let per_row = 1u64.checked_shl(log2_row).unwrap_or(u64::MAX);
        let rows = (list.len() as u64).div_ceil(per_row.max(1));
        if log2_row > 5 || pieces == 0 || u64::from(pieces) > per_row + 1 || u64::from(mask_base) != next {
            return Err(MctFileError::StripRows { resolution, log2_row, pieces, mask_base, masks: masks.len() as u64 });
        }
        for index in next..next + rows {
            let Some(&mask) = masks.get(index as usize) else {
                return Err(MctFileError::MaskCount { stored: masks.len() as u64, expected: next + rows });
            };
            let allowed = if per_row >= 32 { u32::MAX - 1 } else { ((1u32 << per_row) - 1) & !1 };
            if mask & !allowed != 0 || mask.count_ones() + 1 > pieces {
                return Err(MctFileError::StripMask { index, mask, resolution, per_row: per_row as u32, pieces });
            }
        }
        next += rows;
    }
    if next != masks.len() as u64 {
        return Err(MctFileError::MaskCount { stored: masks.len() as u64, expected: next });
    }
    Ok(())
}

/// The pair lists the records describe (`[first, second or u32::MAX]` per pair, per group),
/// refusing a slot claimed twice and a pair without a first face.
fn rebuild_pairs(
    records: &[MctFaceRecord],
    faces_per_group: &[u64; GROUPS],
) -> Result<Vec<Vec<[u32; 2]>>, MctFileError> {
    // Every pair index is below its group's face count (check_records): at most one entry
    // per face is allocated.
    let mut pairs: Vec<Vec<[u32; 2]>> =
        faces_per_group.iter().map(|&faces| vec![[u32::MAX; 2]; usize::try_from(faces).unwrap_or(0)]).collect();
    let mut used = [0usize; GROUPS];
    for (face, &record) in (0u32..).zip(records) {
        let g = record.log2_block() as usize;
        let side = u32::from(record.second());
        let pair = record.pair();
        let Some(slot) = pairs.get_mut(g).and_then(|list| list.get_mut(pair as usize)) else {
            continue; // unreachable after check_records
        };
        let entry = &mut slot[side as usize];
        if *entry != u32::MAX {
            return Err(MctFileError::DuplicateSlot {
                face: u64::from(face),
                other: u64::from(*entry),
                resolution: 1 << g,
                pair,
                side,
            });
        }
        *entry = face;
        used[g] = used[g].max(pair as usize + 1);
    }
    for (g, list) in pairs.iter_mut().enumerate() {
        list.truncate(used[g]);
        if let Some(pair) = list.iter().position(|entry| entry[0] == u32::MAX) {
            return Err(MctFileError::MissingFirst { resolution: 1 << g, pair: pair as u64 });
        }
    }
    Ok(pairs)
}

/// Both faces of a pair name the same vertices as `p` and `q`.
fn check_pair_edges(
    indices: &[[u32; 3]],
    records: &[MctFaceRecord],
    pairs: &[Vec<[u32; 2]>],
) -> Result<(), MctFileError> {
    let edge = |face: u32| -> [u32; 2] {
        let (corners, record) = (indices.get(face as usize), records.get(face as usize));
        match (corners, record) {
            (Some(c), Some(r)) => [c[r.corner_p()], c[r.corner_q()]],
            _ => [u32::MAX; 2],
        }
    };
    for (g, list) in pairs.iter().enumerate() {
        for (pair, &[first, second]) in (0u64..).zip(list) {
            if second == u32::MAX {
                continue;
            }
            let (first_edge, second_edge) = (edge(first), edge(second));
            if first_edge != second_edge {
                return Err(MctFileError::PairEdge {
                    first: u64::from(first),
                    second: u64::from(second),
                    resolution: 1 << g,
                    pair,
                    first_edge,
                    second_edge,
                });
            }
        }
    }
    Ok(())
}

/// Every texel a face's block can make the GPU read, at every level, lies in the atlas.
///
/// A block of resolution `r` has texels at lattice points `α + β ≤ r` and ring texels at
/// `α + β = r + 1` with `α, β ≥ 1` (bilinear filtering of a point `α + β ≤ r` reads only
/// these with a non-zero weight). Their convex hull has the corners `(0, 0)`, `(r, 0)`,
/// `(0, r)`, `(r, 1)`, `(1, r)`; the frame maps lattice points to texels affinely and the
/// atlas is a rectangle, so those five suffice. The atlas wraps around in x (tents cross the
/// right edge), so `x` may reach up to twice the width; `y` must lie in the atlas. `(r + 1, 0)` and `(0, r + 1)` are not the
/// block's (they belong to the neighbouring block or lie past the atlas edge).
fn check_blocks_inside(
    records: &[MctFaceRecord],
    bands: &MctBands,
    masks: &[u32],
    width: u32,
    height: u32,
    levels: u32,
) -> Result<(), MctFileError> {
    let (w, h) = (i64::from(width), i64::from(height));
    for (face, &record) in (0u64..).zip(records) {
        for level in 0..levels {
            let frame = frame_of(record, bands, masks, level);
            let r = frame.r;
            for (alpha, beta) in [(0, 0), (r, 0), (0, r), (r, 1), (1, r)] {
                let texel = frame.texel(alpha, beta);
                if !(0..2 * w).contains(&texel[0]) || !(0..h).contains(&texel[1]) {
                    return Err(MctFileError::OutsideAtlas { face, level, texel, width, height });
                }
            }
        }
    }
    Ok(())
}
