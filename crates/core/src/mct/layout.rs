//! Where every face's texel block lies in the Mesh Color Texture atlas.
//!
//! Faces are grouped by their *block resolution* `R_b = max(R_f, R_e of its three edges)`
//! (the talk's "two resolutions per face": content at `R_f`, block at `R_b`, so the finer
//! side of a mixed edge keeps all its samples), and paired with a neighbour of the same
//! `R_b` across a manifold edge `p → q` (greedy, in face order). A pair is laid out
//!
//! - at **level 0** as a *tent*: both faces are right triangles whose right angle is `p`,
//!   sharing the leg `p → q` (one column of texels: the edge's colours stored once). Each
//!   face's hypotenuse is followed by a *ring* of interpolated texels
//!   `c₃ = c₁ + c₂ − c₀`, which makes hardware bilinear filtering across the hypotenuse
//!   cells equal mesh colors' linear filter along that edge. Tents alternate up and down
//!   so their rings interlock: a row of height `R_b + 1` holds two pairs every
//!   `2R_b + 6` texels, 1 texel per face unused. The atlas wraps around in x (the sampler
//!   repeats horizontally; only tents cross the right edge), so a row of tents has no ragged
//!   ends: the last down tent interlocks with the first up tent across the edge;
//! - at **levels ≥ 1** as a *square* of side `r + 1` texels, `r = R_b >> level`, the two
//!   faces sharing its diagonal `p → q` (no ring: the diagonal is read from the same
//!   texels by both faces, so it is continuous, but it is the bilinear patch of the
//!   square's cells there rather than the linear interpolation of the edge; measured).
//!   Squares follow each other in *strips* ([`super::strips`]): consecutive squares of a
//!   strip share a side, the mesh edge between them, so a strip of `L` squares takes
//!   `L·r + 1` columns rather than `L·(r + 1)`. A group's strips are cut into strip rows of
//!   `S` pairs (the same rows at every level), several strip rows side by side per atlas row.
//!
//! A face without a partner takes a tent or square alone, with its ring. Every group and
//! level is a full-width band of block rows in one atlas: level-0 bands first, then the
//! bands of levels 1, 2, ... A face record (`u32`), the band table ([`MctBands`]) and one
//! word per strip row (which pairs start a new piece of strip) are all a shader needs to
//! place a face's corners at any level.

use crate::colors::layout::MAX_LOG2_RESOLUTION;
use crate::mct::MctError;
use crate::mct::ring::right_angle_at_q;
use crate::mct::strips::{EdgeFaces, Oriented, ROW_SIZES, StripRows, strip_rows};
use crate::packing::linear::PackedMesh;
use rayon::prelude::*;

/// Number of block-resolution groups (`log2 R_b` = 0..=12) and of levels per group.
pub const GROUPS: usize = MAX_LOG2_RESOLUTION as usize + 1;

/// Largest pair index a face record holds (22 bits).
pub const MAX_PAIRS_PER_GROUP: u32 = 1 << 22;

/// One face's placement in a `u32` (keep in sync with `mct_record_*` in
/// crates/render/shaders/mct.wgsl):
///
/// | bits | field |
/// |---|---|
/// | 0–1 | corner of `p` (0, 1, 2) |
/// | 2 | `q` is the corner after `p` (1) or before it (0) |
/// | 3 | side: 0 = first face of its pair, 1 = second |
/// | 4–7 | `log2 R_b` |
/// | 8 | the square (levels ≥ 1) is mirrored vertically |
/// | 9 | swap: the square has `p` where this record's `q` is and `q` where its `p` is (the tent's right angle was moved to the other end of the shared edge, [`super::ring`]) |
/// | 10–31 | pair index within the group |
#[repr(transparent)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MctFaceRecord(pub u32);

const _: () = assert!(std::mem::size_of::<MctFaceRecord>() == 4);

impl MctFaceRecord {
    /// Packs the fields; `pair < MAX_PAIRS_PER_GROUP`, `corner_p < 3`, `log2_block <= 12`.
    pub fn new(corner_p: u32, q_next: bool, second: bool, log2_block: u32, pair: u32, [flip, swap]: [bool; 2]) -> Self {
        MctFaceRecord(
            (corner_p & 3)
                | (u32::from(q_next) << 2)
                | (u32::from(second) << 3)
                | ((log2_block & 15) << 4)
                | (u32::from(flip) << 8)
                | (u32::from(swap) << 9)
                | (pair << 10),
        )
    }
    /// Whether the square of levels ≥ 1 exchanges `p` and `q`.
    pub fn swap(self) -> bool {
        self.0 & 512 != 0
    }
    /// Whether the square of levels ≥ 1 is mirrored vertically.
    pub fn flip(self) -> bool {
        self.0 & 256 != 0
    }
    /// The corner of the shared edge's start `p`.
    pub fn corner_p(self) -> usize {
        (self.0 & 3) as usize
    }
    /// The corner of the shared edge's end `q`.
    pub fn corner_q(self) -> usize {
        (self.corner_p() + if self.0 & 4 != 0 { 1 } else { 2 }) % 3
    }
    /// The corner opposite the shared edge.
    pub fn corner_third(self) -> usize {
        3 - self.corner_p() - self.corner_q()
    }
    /// Whether the face is the second of its pair.
    pub fn second(self) -> bool {
        self.0 & 8 != 0
    }
    /// `log2 R_b`.
    pub fn log2_block(self) -> u32 {
        (self.0 >> 4) & 15
    }
    /// The pair's index within its group.
    pub fn pair(self) -> u32 {
        self.0 >> 10
    }
}

/// Where the band of group `g` (`log2 R_b`) at `level` starts and how many blocks a row
/// holds: `[y, per_row, skip, ·]` at index `g · GROUPS + level` (level 0: tent *periods*
/// per row, two pairs each; levels ≥ 1: strip rows per atlas row). A band may start in the
/// free end of the previous band's last row: its first `skip` slots (periods or strip rows)
/// are left empty, so slot `i + skip` of the band is its `i`-th, at row `(i + skip) / per_row`.
/// The group's level-0 entry holds its strip rows in word 3: `log2 S | pieces << 3 |
/// first mask << 9` (pairs per strip row, most pieces in one, index of its first strip-row
/// mask in [`MctLayout::masks`]); the other entries' word 3 is 0. The renderer uploads it repacked for
/// crates/render/shaders/mct.wgsl (`gpu_bands` in crates/render/src/mct.rs: per entry the
/// band of this level and of the next, each `y | per_row << 16`, and the group's strip rows).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MctBands {
    /// `[y, per_row, 0, 0]` per group and level.
    pub bands: [[u32; 4]; GROUPS * GROUPS],
}

const _: () = assert!(std::mem::size_of::<MctBands>() == 2704);

impl Default for MctBands {
    fn default() -> Self {
        MctBands { bands: [[0; 4]; GROUPS * GROUPS] }
    }
}

impl MctBands {
    /// `(y, per_row)` of group `log2_block` at `level`.
    pub fn band(&self, log2_block: u32, level: u32) -> (u32, u32) {
        let b = self.bands[log2_block as usize * GROUPS + level as usize];
        (b[0], b[1])
    }
    /// Empty slots before the band's first block.
    pub fn skip(&self, log2_block: u32, level: u32) -> u32 {
        self.bands[log2_block as usize * GROUPS + level as usize][2]
    }
    /// Group `log2_block`'s strip rows: (index of its first mask, `log2 S`, most pieces per row).
    pub fn strip_rows(&self, log2_block: u32) -> (u32, u32, u32) {
        let b = self.bands[log2_block as usize * GROUPS][3];
        (b >> 9, b & 7, (b >> 3) & 63)
    }
}

/// A texel block's frame: the texel of the face's right-angle corner and the texel steps
/// of its two legs. Lattice point `(α, β)` (`α + β <= r`) is texel `origin + α·ex + β·ey`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockFrame {
    /// Texel of the right-angle corner.
    pub origin: [i64; 2],
    /// Texel step along the `α` leg.
    pub ex: [i64; 2],
    /// Texel step along the `β` leg.
    pub ey: [i64; 2],
    /// Face corners at the right angle, at the end of the `α` leg and of the `β` leg.
    pub corners: [usize; 3],
    /// Resolution of the block at this level.
    pub r: u32,
}

impl BlockFrame {
    /// The texel-space point (texel centres at integers) of barycentric `w` (face corner order).
    pub fn point(&self, w: [f32; 3]) -> [f32; 2] {
        let r = self.r as f32;
        let (a, b) = (r * w[self.corners[1]], r * w[self.corners[2]]);
        std::array::from_fn(|c| self.origin[c] as f32 + a * self.ex[c] as f32 + b * self.ey[c] as f32)
    }
    /// The texel of lattice point `(α, β)`.
    pub fn texel(&self, alpha: u32, beta: u32) -> [i64; 2] {
        std::array::from_fn(|c| self.origin[c] + i64::from(alpha) * self.ex[c] + i64::from(beta) * self.ey[c])
    }
}

/// The atlas layout of a mesh: one record per face, the band table and the atlas size.
#[derive(Debug, Clone, PartialEq)]
pub struct MctLayout {
    /// One record per face.
    pub records: Vec<MctFaceRecord>,
    /// Band of every group and level.
    pub bands: MctBands,
    /// Atlas width in texels.
    pub width: u32,
    /// Atlas height in texels.
    pub height: u32,
    /// Faces of each pair (`[first, second]`, `second == u32::MAX` for a lone face), per group.
    pub pairs: Vec<Vec<[u32; 2]>>,
    /// MIP levels of every face: the packed mesh's vertex levels (`1 + log2 max R`), so a
    /// coarse face keeps following its vertices' chains as far as its finer neighbours
    /// (blocks of resolution 1 past `log2 R_b`).
    pub levels: u32,
    /// One word per strip row, groups one after the other (band table word 2): bit `j ≥ 1`
    /// set when pair `j` of the row starts a new piece of strip.
    pub masks: Vec<u32>,
}

/// What the band placement needs of one group.
#[derive(Debug, Clone, Copy, Default)]
struct GroupRows {
    /// Pairs.
    count: u64,
    /// Most pieces in a strip row, per `log2 S`.
    pieces: [u32; ROW_SIZES],
}

impl GroupRows {
    /// Columns of a strip row of `1 << log2_row` blocks of resolution `r`.
    fn row_width(&self, log2_row: usize, r: u64) -> u64 {
        (r << log2_row) + u64::from(self.pieces[log2_row])
    }
}

/// Width in texels a level-0 row of `periods` tent periods of resolution `r` needs: the
/// atlas wraps around horizontally (the sampler repeats in x), so the last period's down
/// tent continues past the right edge at the left edge, where it interlocks with the first.
fn tent_row_width(r: u64, periods: u64) -> u64 {
    periods * (2 * r + 6)
}

impl MctLayout {
    /// Lays out `packed`'s faces in an atlas at most `max_dimension` texels wide and high.
    ///
    /// Fails before allocating anything atlas-sized when a face record is unreadable, a
    /// group has more than [`MAX_PAIRS_PER_GROUP`] pairs, or the atlas would not fit.
    pub fn new(packed: &PackedMesh, max_dimension: u32) -> Result<MctLayout, MctError> {
        let log2_blocks = block_resolutions(packed)?;
        let (matched, edges) = pair_faces(packed, &log2_blocks);
        for (g, list) in matched.iter().enumerate() {
            if list.len() as u64 >= u64::from(MAX_PAIRS_PER_GROUP) {
                return Err(MctError::TooManyFaces { resolution: 1 << g, pairs: list.len() as u64 });
            }
        }
        let levels = packed.vertex_levels.clamp(1, GROUPS as u32);
        let mut pair_of = vec![u32::MAX; packed.indices.len()];
        for list in &matched {
            for (index, pair) in list.iter().enumerate() {
                for &face in pair.iter().filter(|&&f| f != u32::MAX) {
                    pair_of[face as usize] = index as u32;
                }
            }
        }
        let rows: Vec<StripRows> = (0..GROUPS)
            .into_par_iter()
            .map(|g| strip_rows(packed, &edges, &matched[g], &pair_of, &log2_blocks, g as u32, levels))
            .collect();
        let groups: [GroupRows; GROUPS] =
            std::array::from_fn(|g| GroupRows { count: rows[g].pairs.len() as u64, pieces: rows[g].pieces });
        let width = choose_width(&groups, levels, max_dimension)?;
        let (bands, y) = place_bands(&groups, levels, width);
        check_height(y, max_dimension, width)?;
        let mut masks = Vec::new();
        for (g, group) in rows.iter().enumerate() {
            masks.extend(group.masks(bands.strip_rows(g as u32).1));
        }
        if masks.len() as u64 >= u64::from(MAX_PAIRS_PER_GROUP) {
            // The band table holds a group's first mask in 23 bits.
            return Err(MctError::TooManyFaces { resolution: 1, pairs: masks.len() as u64 });
        }
        let mut records = vec![MctFaceRecord::default(); packed.indices.len()];
        for (g, group) in rows.iter().enumerate() {
            let swaps: Vec<bool> = group
                .pairs
                .par_iter()
                .map(|pair| right_angle_at_q(packed, pair.faces, pair.p, pair.q, 1 << g))
                .collect();
            for (index, (pair, swap)) in group.pairs.iter().zip(swaps).enumerate() {
                assign_records(packed, &mut records, g as u32, index as u32, pair, swap);
            }
        }
        let pairs = rows.into_iter().map(|group| group.pairs.into_iter().map(|p| p.faces).collect()).collect();
        Ok(MctLayout { records, bands, width, height: y.max(1) as u32, pairs, levels, masks })
    }

    /// The frame of `face`'s block at `level` (clamped to the last level
    /// `levels − 1`), or `None` for a face that does not exist.
    pub fn frame(&self, face: u32, level: u32) -> Option<BlockFrame> {
        let record = *self.records.get(face as usize)?;
        Some(frame_of(record, &self.bands, &self.masks, level.min(self.levels - 1)))
    }

    /// Texels in the atlas.
    pub fn texel_count(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Bytes of the face records and the strip-row masks (one `u32` each).
    pub fn record_bytes(&self) -> u64 {
        4 * (self.records.len() + self.masks.len()) as u64
    }

    /// Entries of the band table the GPU needs: `levels` per group up to the finest
    /// (crates/render/src/mct.rs `gpu_bands`, 16 bytes each).
    pub fn gpu_band_entries(&self) -> u64 {
        let groups = self.pairs.iter().rposition(|list| !list.is_empty()).map_or(1, |g| g + 1);
        groups as u64 * u64::from(self.levels)
    }
}

/// [`MctLayout::frame`] from a record, the band table and the strip-row masks (the shader's
/// arithmetic); `level` must be below the layout's `levels`. Past `log2 R_b` the block has
/// resolution 1. A mask missing from `masks` reads as 0.
pub fn frame_of(record: MctFaceRecord, bands: &MctBands, masks: &[u32], level: u32) -> BlockFrame {
    let g = record.log2_block();
    let level = level.min(GROUPS as u32 - 1);
    let pair = u64::from(record.pair());
    let (band_y, per_row) = bands.band(g, level);
    let (band_y, per_row) = (i64::from(band_y), u64::from(per_row.max(1)));
    let skip = u64::from(bands.skip(g, level));
    let (p, q, t) = (record.corner_p(), record.corner_q(), record.corner_third());
    let r = 1i64 << g.saturating_sub(level);
    if level == 0 {
        // Tent: right angle at p, α leg towards the third corner (±x), β leg towards q (±y).
        let period = pair / 2 + skip;
        let (row, col) = ((period / per_row) as i64, (period % per_row) as i64);
        let base_x = col * (2 * r + 6);
        let top = band_y + row * (r + 1);
        let up = pair % 2 == 0;
        let (xc, yb, dy) = if up { (base_x + r + 1, top, 1) } else { (base_x + 2 * r + 4, top + r, -1) };
        let dx = if record.second() { -1 } else { 1 };
        BlockFrame { origin: [xc, yb], ex: [dx, 0], ey: [0, dy], corners: [p, t, q], r: r as u32 }
    } else {
        // Square in a strip row: the first face's right angle (its third corner) at the
        // square's origin, p at (r, 0), q at (0, r); the second face's at (r, r); mirrored
        // vertically when the record says so.
        let (mask_base, log2_row, pieces) = bands.strip_rows(g);
        let (p, q) = if record.swap() { (q, p) } else { (p, q) };
        let log2_row = log2_row.min(31);
        let (strip_row, j) = (pair >> log2_row, pair & ((1 << log2_row) - 1));
        let mask = masks.get((u64::from(mask_base) + strip_row) as usize).copied().unwrap_or(0);
        let before = (u64::from(mask) & ((2u64 << j) - 2)).count_ones();
        let width = (r << log2_row) + i64::from(pieces);
        let slot = strip_row + skip;
        let (row, col) = ((slot / per_row) as i64, (slot % per_row) as i64);
        let (x0, y0) = (col * width + j as i64 * r + i64::from(before), band_y + row * (r + 1));
        let r32 = r as u32;
        match (record.second(), record.flip()) {
            (false, false) => BlockFrame { origin: [x0, y0], ex: [1, 0], ey: [0, 1], corners: [t, p, q], r: r32 },
            (false, true) => BlockFrame { origin: [x0, y0 + r], ex: [1, 0], ey: [0, -1], corners: [t, p, q], r: r32 },
            (true, false) => {
                BlockFrame { origin: [x0 + r, y0 + r], ex: [0, -1], ey: [-1, 0], corners: [t, p, q], r: r32 }
            }
            (true, true) => BlockFrame { origin: [x0 + r, y0], ex: [0, 1], ey: [-1, 0], corners: [t, p, q], r: r32 },
        }
    }
}

fn check_height(height: u64, max_dimension: u32, width: u32) -> Result<(), MctError> {
    if height > u64::from(max_dimension) {
        return Err(MctError::AtlasTooLarge { width, height, max_dimension });
    }
    Ok(())
}

/// `log2 R_b` of every face.
pub(crate) fn block_resolutions(packed: &PackedMesh) -> Result<Vec<u8>, MctError> {
    packed
        .face_records
        .par_iter()
        .enumerate()
        .map(|(face, record)| {
            let mut log2 = record.resolution().ok_or(MctError::BadRecord { face: face as u32 })?.log2();
            for k in 0..3 {
                log2 = log2.max(record.edge(k).ok_or(MctError::BadRecord { face: face as u32 })?.1.log2());
            }
            Ok(log2 as u8)
        })
        .collect()
}

/// Pairs every face with an unpaired neighbour of the same `R_b` across a manifold edge
/// (a near-maximum matching); lists per group, and the faces of every edge.
pub(crate) fn pair_faces(packed: &PackedMesh, log2_blocks: &[u8]) -> (Vec<Vec<[u32; 2]>>, EdgeFaces) {
    // Half-edges (lo, hi, face) sorted, so the faces of an edge are adjacent.
    let mut half: Vec<(u64, u32)> = packed
        .indices
        .par_iter()
        .enumerate()
        .flat_map_iter(|(face, c)| {
            (0..3).filter_map(move |k| {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                (a != b).then(|| ((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), face as u32))
            })
        })
        .collect();
    half.par_sort_unstable();
    // Neighbour across each manifold edge, per face (up to 3).
    let mut neighbours = vec![[u32::MAX; 3]; packed.indices.len()];
    let mut start = 0;
    while start < half.len() {
        let mut end = start + 1;
        while end < half.len() && half[end].0 == half[start].0 {
            end += 1;
        }
        if end - start == 2 {
            let (f, g) = (half[start].1, half[start + 1].1);
            if f != g {
                push_neighbour(&mut neighbours[f as usize], g);
                push_neighbour(&mut neighbours[g as usize], f);
            }
        }
        start = end;
    }
    // Only neighbours of the same block resolution can share a block.
    for (face, slots) in neighbours.iter_mut().enumerate() {
        for slot in slots.iter_mut() {
            if *slot != u32::MAX && log2_blocks[*slot as usize] != log2_blocks[face] {
                *slot = u32::MAX;
            }
        }
    }
    let mate = maximal_matching(&neighbours);
    let mut pairs = vec![Vec::new(); GROUPS];
    for (face, &m) in mate.iter().enumerate() {
        if m == u32::MAX || (face as u32) < m {
            pairs[usize::from(log2_blocks[face])].push([face as u32, m]);
        }
    }
    (pairs, EdgeFaces::new(half))
}

/// A near-maximum matching of the faces' dual graph (degree ≤ 3): greedy by fewest
/// unmatched neighbours first (a face with one candidate left takes it before a neighbour
/// with more choices steals it), then augmenting paths of any length ([`augment`]), each of
/// which turns two unmatched faces into one more pair. Returns each face's mate or `u32::MAX`.
fn maximal_matching(neighbours: &[[u32; 3]]) -> Vec<u32> {
    let n = neighbours.len();
    let mut mate = vec![u32::MAX; n];
    let free = |mate: &[u32], f: u32| f != u32::MAX && mate[f as usize] == u32::MAX;
    let degree = |mate: &[u32], f: usize| neighbours[f].iter().filter(|&&g| free(mate, g)).count();
    let mut buckets: [Vec<u32>; 4] = Default::default();
    for f in 0..n {
        buckets[degree(&mate, f)].push(f as u32);
    }
    loop {
        // The unmatched face of smallest positive degree (stale entries skipped).
        let mut picked = None;
        for d in 1..4 {
            while let Some(f) = buckets[d].pop() {
                if mate[f as usize] != u32::MAX {
                    continue;
                }
                let now = degree(&mate, f as usize);
                if now == d {
                    picked = Some(f);
                    break;
                }
                if now > 0 {
                    buckets[now].push(f);
                }
            }
            if picked.is_some() {
                break;
            }
        }
        let Some(f) = picked else { break };
        let partner = neighbours[f as usize]
            .iter()
            .copied()
            .filter(|&g| g != f && free(&mate, g))
            .min_by_key(|&g| degree(&mate, g as usize));
        let Some(g) = partner else { continue };
        mate[f as usize] = g;
        mate[g as usize] = f;
        for h in neighbours[f as usize].into_iter().chain(neighbours[g as usize]) {
            if free(&mate, h) {
                let d = degree(&mate, h as usize);
                buckets[d].push(h);
            }
        }
    }
    augment(neighbours, &mut mate);
    mate
}

/// Augmenting paths: from each unmatched face a breadth-first search of alternating paths
/// (unmatched edge, matched edge, ...) to another unmatched face, then the path flipped.
fn augment(neighbours: &[[u32; 3]], mate: &mut [u32]) {
    // Without blossom shrinking it may miss a path through an odd cycle; each search visits
    // at most `AUGMENT_LIMIT` faces, so meshes with many lone faces stay linear.
    const AUGMENT_LIMIT: usize = 4096;
    let n = neighbours.len();
    let mut parent = vec![u32::MAX; n];
    let mut seen = vec![u32::MAX; n];
    for u in 0..n as u32 {
        if mate[u as usize] != u32::MAX {
            continue;
        }
        seen[u as usize] = u;
        let mut queue = std::collections::VecDeque::from([u]);
        let mut found = None;
        let mut visited = 0;
        'search: while let Some(x) = queue.pop_front() {
            for y in neighbours[x as usize] {
                if y == u32::MAX || seen[y as usize] == u {
                    continue;
                }
                if mate[y as usize] == u32::MAX {
                    parent[y as usize] = x;
                    found = Some(y);
                    break 'search;
                }
                let w = mate[y as usize];
                if seen[w as usize] == u {
                    continue;
                }
                seen[y as usize] = u;
                seen[w as usize] = u;
                parent[y as usize] = x;
                queue.push_back(w);
                visited += 2;
            }
            if visited > AUGMENT_LIMIT {
                break;
            }
        }
        // Flip: y – x = mate(x)... back to u.
        let Some(mut y) = found else { continue };
        loop {
            let x = parent[y as usize];
            let next = mate[x as usize];
            mate[y as usize] = x;
            mate[x as usize] = y;
            if x == u {
                break;
            }
            y = next;
        }
    }
}

fn push_neighbour(slots: &mut [u32; 3], face: u32) {
    if let Some(slot) = slots.iter_mut().find(|s| **s == u32::MAX) {
        *slot = face;
    }
}

/// Writes the records of pair `index` of group `g`; `swap`: the tents' right angle at the
/// square's `q` (the record's `p` is then the square's `q`).
fn assign_records(packed: &PackedMesh, records: &mut [MctFaceRecord], g: u32, index: u32, pair: &Oriented, swap: bool) {
    let (p, q) = if swap { (pair.q, pair.p) } else { (pair.p, pair.q) };
    for (side, &face) in pair.faces.iter().enumerate() {
        let Some(corners) = packed.indices.get(face as usize) else { continue };
        let find = |v: u32| corners.iter().position(|&c| c == v).unwrap_or(0);
        let (cp, cq) = (find(p), find(q));
        records[face as usize] =
            MctFaceRecord::new(cp as u32, cq == (cp + 1) % 3, side == 1, g, index, [pair.flip, swap]);
    }
}

/// The last row of the band placed last: where it ends and how much of it is used.
#[derive(Debug, Clone, Copy, Default)]
struct LastRow {
    /// Row below it.
    end: u64,
    /// Its height.
    height: u64,
    /// Columns used from the left.
    used: u64,
}

/// Places a band of `count` slots `slot_width` columns wide (`reach` more for its last slot)
/// and `height` rows high, `per_row` per atlas row, after `last`: in the free end of `last`'s
/// row when it is at least as high, a slot fits there and the band's rows do not wrap around
/// the atlas (`fits`: a tent row that does would reach into `last`). Returns `[y, skip]` and
/// its last row.
fn place_band(
    last: LastRow,
    count: u64,
    [per_row, slot_width, reach, height]: [u64; 4],
    fits: bool,
) -> ([u64; 2], LastRow) {
    let skip = last.used.div_ceil(slot_width);
    let (y, skip) = if fits && last.height >= height && skip < per_row && last.used > 0 {
        (last.end - height, skip)
    } else {
        (last.end, 0)
    };
    let slots = count + skip;
    let rows = slots.div_ceil(per_row).max(1);
    let in_last = slots - (rows - 1) * per_row;
    let end = y + rows * height;
    let used = if in_last >= per_row { u64::MAX / 2 } else { in_last * slot_width + reach };
    ([y, skip], LastRow { end, height, used })
}

/// The band of every group and level at atlas width `width` (which must hold the widest
/// group's tent row and its narrowest strip row), each group's strip rows of the size that
/// takes the fewest atlas rows, and the atlas height.
fn place_bands(groups: &[GroupRows; GROUPS], levels: u32, width: u32) -> (MctBands, u64) {
    let mut bands = MctBands::default();
    let width = u64::from(width);
    let mut last = LastRow::default();
    // Each group's strip-row size: the one of least height (ties: the larger, fewer masks).
    let mut mask_base = 0u64;
    for (g, &group) in groups.iter().enumerate() {
        if group.count == 0 {
            continue;
        }
        let heights = |log2_row: usize| -> Option<u64> {
            (1..levels as usize).try_fold(0u64, |sum, level| {
                let r = 1u64 << g.saturating_sub(level);
                let per_row = width / group.row_width(log2_row, r);
                (per_row > 0).then(|| sum + group.count.div_ceil(1 << log2_row).div_ceil(per_row) * (r + 1))
            })
        };
        let log2_row = (0..ROW_SIZES).rev().filter(|&s| heights(s).is_some()).min_by_key(|&s| heights(s)).unwrap_or(0);
        bands.bands[g * GROUPS][3] =
            log2_row as u32 | (group.pieces[log2_row].min(63) << 3) | ((mask_base as u32) << 9);
        mask_base += group.count.div_ceil(1 << log2_row);
    }
    // Level 0: tents, groups from the finest down.
    for g in (0..GROUPS).rev() {
        let group = groups[g];
        if group.count == 0 {
            continue;
        }
        let r = 1u64 << g;
        let periods = (width / (2 * r + 6)).max(1);
        let fits = periods * (2 * r + 6) + r <= width;
        let ([y, skip], row) = place_band(last, group.count.div_ceil(2), [periods, 2 * r + 6, r, r + 1], fits);
        bands.bands[g * GROUPS][..3].copy_from_slice(&[y as u32, periods as u32, skip as u32]);
        last = row;
    }
    // Levels ≥ 1: strip rows of squares, down to the last vertex level for every group.
    for level in 1..levels as usize {
        for g in (0..GROUPS).rev() {
            let group = groups[g];
            if group.count == 0 {
                continue;
            }
            let log2_row = (bands.bands[g * GROUPS][3] & 7) as usize;
            let r = 1u64 << g.saturating_sub(level);
            let row_width = group.row_width(log2_row, r);
            let per_row = (width / row_width).max(1);
            let strip_rows = group.count.div_ceil(1 << log2_row);
            let ([y, skip], row) = place_band(last, strip_rows, [per_row, row_width, 0, r + 1], true);
            bands.bands[g * GROUPS + level][..3].copy_from_slice(&[y as u32, per_row as u32, skip as u32]);
            last = row;
        }
    }
    (bands, last.end)
}

/// The atlas width of least area (ties: the squarer) among the widths that hold the widest
/// group's tent row and strip row and keep both sides within `max_dimension`.
fn choose_width(groups: &[GroupRows; GROUPS], levels: u32, max_dimension: u32) -> Result<u32, MctError> {
    let widest = (0..GROUPS)
        .filter(|&g| groups[g].count > 0)
        .map(|g| {
            let strip = if levels > 1 { groups[g].row_width(0, 1 << g.saturating_sub(1)) } else { 0 };
            tent_row_width(1 << g, 1).max(strip)
        })
        .max()
        .unwrap_or(1);
    if widest > u64::from(max_dimension) {
        return Err(MctError::AtlasTooLarge { width: widest as u32, height: 0, max_dimension });
    }
    let mut best: Option<(u64, u64, u32)> = None;
    let mut width = widest;
    while width <= u64::from(max_dimension) {
        let (_, height) = place_bands(groups, levels, width as u32);
        if height <= u64::from(max_dimension) {
            let key = (width * height.max(1), width.abs_diff(height));
            if best.is_none_or(|(area, skew, _)| key < (area, skew)) {
                best = Some((key.0, key.1, width as u32));
            }
        }
        if height < width / 2 {
            break;
        }
        width += 1;
    }
    match best {
        Some((_, _, width)) => Ok(width),
        None => {
            let (_, height) = place_bands(groups, levels, max_dimension);
            Err(MctError::AtlasTooLarge { width: max_dimension, height, max_dimension })
        }
    }
}
