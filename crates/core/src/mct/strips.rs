//! Strips of squares for levels ≥ 1: the pairs of one block-resolution group ordered so that
//! consecutive squares share a side (a mesh edge whose colours are then stored once), cut into
//! *strip rows* of `S` pairs.
//!
//! A pair is a quad `t₁ → p → t₂ → q` (its faces share the diagonal `p → q`); a strip enters
//! a square through one side and leaves it through the opposite side, into the pair across
//! that edge. Each square is oriented so that the edge it enters by lies on its left column
//! with the vertices where the previous square's right column put them: the face owning that
//! edge is the pair's first face, the edge's diagonal vertex is `q`, and the square is mirrored
//! vertically (`flip`) when the face's third vertex is at the top (layout.rs `frame_of`).
//!
//! A strip row of `S` pairs holds *pieces* (runs of one strip); a piece of `L` squares of side
//! `r` takes `L·r + 1` texel columns, so a row takes `S·r + pieces`. The band table stores
//! the most pieces any row of the group has, and one `u32` per row (`masks`) marks the pairs
//! that start a new piece: a square's column in its row is `j·r + popcount(mask & bits 1..=j)`.

use crate::packing::linear::PackedMesh;

/// Largest strip row (pairs); a row's piece starts fit one `u32`.
pub const MAX_STRIP_ROW: u32 = 32;

/// One pair of a group's sequence, oriented for its square at levels ≥ 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Oriented {
    /// First and second face (`u32::MAX` for a lone face).
    pub faces: [u32; 2],
    /// Vertex ids of the shared edge's `p` and `q` (a lone face: its corners 0 and 1).
    pub p: u32,
    pub q: u32,
    /// Square mirrored vertically.
    pub flip: bool,
}

/// Number of strip-row sizes `S = 1, 2, 4, ..., 32`.
pub const ROW_SIZES: usize = MAX_STRIP_ROW.trailing_zeros() as usize + 1;

/// A group's pairs in strip order, with where each piece of strip starts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct StripRows {
    /// Pairs in order (record pair index = position).
    pub pairs: Vec<Oriented>,
    /// Whether each pair starts a strip.
    pub starts: Vec<bool>,
    /// Most pieces in one strip row, per `log2 S`.
    pub pieces: [u32; ROW_SIZES],
}

impl StripRows {
    /// The strip-row masks in rows of `1 << log2_row` pairs.
    pub fn masks(&self, log2_row: u32) -> Vec<u32> {
        self.starts.chunks(1 << log2_row).map(row_mask).collect()
    }
}

/// Bit `j ≥ 1` set where pair `j` of a strip row starts a piece.
fn row_mask(row: &[bool]) -> u32 {
    row.iter().enumerate().skip(1).filter(|(_, s)| **s).fold(0u32, |m, (j, _)| m | (1 << j))
}

/// Neighbour lookup across manifold edges: `(lo << 32 | hi, face)` sorted.
pub(crate) struct EdgeFaces(Vec<(u64, u32)>);

impl EdgeFaces {
    pub(crate) fn new(half: Vec<(u64, u32)>) -> Self {
        EdgeFaces(half)
    }
    /// The faces of edge `{a, b}` when exactly two faces share it.
    pub(crate) fn faces(&self, a: u32, b: u32) -> Option<[u32; 2]> {
        let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
        let start = self.0.partition_point(|&(k, _)| k < key);
        let end = self.0.partition_point(|&(k, _)| k <= key);
        match self.0.get(start..end) {
            Some([x, y]) => Some([x.1, y.1]),
            _ => None,
        }
    }
}

/// The quad cycle `[t₁, p, t₂, q]` of pair `[f, g]` (`f`'s corners after its third vertex).
fn quad(packed: &PackedMesh, [f, g]: [u32; 2]) -> Option<[u32; 4]> {
    let (a, b) = (packed.indices.get(f as usize)?, packed.indices.get(g as usize)?);
    let k = (0..3).find(|&k| !b.contains(&a[k]))?;
    let t2 = *b.iter().find(|v| !a.contains(v))?;
    Some([a[k], a[(k + 1) % 3], t2, a[(k + 2) % 3]])
}

/// Orders `pairs` (one group's `[first, second]`, lone faces `second == u32::MAX`) into
/// strips, and counts the pieces strip rows of each size would hold. `levels == 1` needs no
/// squares: the pairs keep their order, with no piece starts.
pub(super) fn strip_rows(
    packed: &PackedMesh,
    edges: &EdgeFaces,
    pairs: &[[u32; 2]],
    pair_of: &[u32],
    group_of: &[u8],
    g: u32,
    levels: u32,
) -> StripRows {
    if levels <= 1 {
        let pairs: Vec<Oriented> = pairs.iter().map(|&faces| default_orientation(packed, faces)).collect();
        let starts = vec![false; pairs.len()];
        return StripRows { pairs, starts, pieces: [1; ROW_SIZES] };
    }
    let mut chains = chains(packed, edges, pairs, &|face| {
        (group_of.get(face as usize).copied() == Some(g as u8)).then(|| pair_of.get(face as usize).copied()).flatten()
    });
    // Long and short strips alternate, so that rows hold similar numbers of pieces.
    chains.sort_by_key(|c| std::cmp::Reverse(c.len()));
    let mut order = Vec::with_capacity(chains.len());
    let (mut lo, mut hi) = (0, chains.len());
    while lo < hi {
        order.push(lo);
        lo += 1;
        if lo < hi {
            hi -= 1;
            order.push(hi);
        }
    }
    let mut sequence = Vec::with_capacity(pairs.len());
    let mut starts = Vec::with_capacity(pairs.len());
    for &c in &order {
        for (i, &pair) in chains[c].iter().enumerate() {
            sequence.push(pair);
            starts.push(i == 0);
        }
    }
    let pieces = std::array::from_fn(|log2_row| {
        starts.chunks(1 << log2_row).map(|row| 1 + row_mask(row).count_ones()).max().unwrap_or(1)
    });
    StripRows { pairs: sequence, starts, pieces }
}

fn default_orientation(packed: &PackedMesh, faces: [u32; 2]) -> Oriented {
    let corners = packed.indices.get(faces[0] as usize).copied().unwrap_or_default();
    if faces[1] == u32::MAX {
        return Oriented { faces, p: corners[0], q: corners[1], flip: false };
    }
    match quad(packed, faces) {
        Some([_, p, _, q]) => Oriented { faces, p, q, flip: false },
        None => Oriented { faces, p: corners[0], q: corners[1], flip: false },
    }
}

/// Chains of pairs whose consecutive squares share a side, each oriented; lone faces and
/// pairs without such a neighbour are chains of one.
fn chains(
    packed: &PackedMesh,
    edges: &EdgeFaces,
    pairs: &[[u32; 2]],
    pair_of: &dyn Fn(u32) -> Option<u32>,
) -> Vec<Vec<Oriented>> {
    let quads: Vec<Option<[u32; 4]>> =
        pairs.iter().map(|&p| if p[1] == u32::MAX { None } else { quad(packed, p) }).collect();
    // The pair across side `s` of pair `i` (same group, not lone).
    let across = |i: usize, s: usize| -> Option<(usize, usize)> {
        let c = quads[i]?;
        let (a, b) = (c[s], c[(s + 1) % 4]);
        let [x, y] = edges.faces(a, b)?;
        let other = if pairs[i].contains(&x) { y } else { x };
        let j = pair_of(other)? as usize;
        let cj = quads.get(j).copied().flatten()?;
        let e = (0..4).find(|&e| {
            let (u, v) = (cj[e], cj[(e + 1) % 4]);
            (u == a && v == b) || (u == b && v == a)
        })?;
        (j != i).then_some((j, e))
    };
    let mut used = vec![false; pairs.len()];
    let mut stamp = vec![0u32; pairs.len()];
    let mut order: Vec<usize> = (0..pairs.len()).collect();
    order.sort_by_key(|&i| (0..4).filter(|&s| across(i, s).is_some()).count());
    let mut out = Vec::new();
    let mut current = 0u32;
    for start in order {
        if used[start] {
            continue;
        }
        let mut best: Vec<usize> = vec![start];
        let mut entry_side = 3;
        for axis in 0..2 {
            current += 1;
            stamp[start] = current;
            let walk = |side: usize, stamp: &mut Vec<u32>| {
                let mut list = Vec::new();
                let (mut i, mut s) = (start, side);
                while let Some((j, e)) = across(i, s) {
                    if used[j] || stamp[j] == current {
                        break;
                    }
                    stamp[j] = current;
                    list.push((j, e));
                    (i, s) = (j, (e + 2) % 4);
                }
                list
            };
            let forward = walk(axis, &mut stamp);
            let backward = walk(axis + 2, &mut stamp);
            if forward.len() + backward.len() + 1 > best.len() {
                // The chain runs from the far end of `backward` to the far end of `forward`;
                // its first square is entered through the side opposite its exit.
                best = backward
                    .iter()
                    .rev()
                    .map(|&(j, _)| j)
                    .chain([start])
                    .chain(forward.iter().map(|&(j, _)| j))
                    .collect();
                // The far end of `backward` was entered from its successor in the chain.
                entry_side = match backward.last() {
                    Some(&(_, e)) => (e + 2) % 4,
                    None => (axis + 2) % 4,
                };
            }
        }
        for &i in &best {
            used[i] = true;
        }
        out.push(orient_chain(packed, pairs, &quads, &best, entry_side));
    }
    out
}

/// Orients the squares of `chain`, the first entered through side `entry_side` of its quad.
fn orient_chain(
    packed: &PackedMesh,
    pairs: &[[u32; 2]],
    quads: &[Option<[u32; 4]>],
    chain: &[usize],
    entry_side: usize,
) -> Vec<Oriented> {
    let Some(c) = quads[chain[0]] else {
        return vec![default_orientation(packed, pairs[chain[0]])];
    };
    // Enter with the third vertex at the bottom (unflipped).
    let (a, b) = (c[entry_side], c[(entry_side + 1) % 4]);
    let (mut u, mut v) = if a == c[0] || a == c[2] { (a, b) } else { (b, a) };
    let mut out = Vec::with_capacity(chain.len());
    for &i in chain {
        let Some([t1, p, t2, q]) = quads[i] else {
            out.push(default_orientation(packed, pairs[i]));
            continue;
        };
        let [f, g] = pairs[i];
        let t = if u == t1 || u == t2 { u } else { v };
        let d = if t == u { v } else { u };
        let (first, second, other_third) = if t == t1 { (f, g, t2) } else { (g, f, t1) };
        let p_new = if d == q { p } else { q };
        let flip = u != t;
        out.push(Oriented { faces: [first, second], p: p_new, q: d, flip });
        (u, v) = if flip { (other_third, p_new) } else { (p_new, other_third) };
    }
    out
}
