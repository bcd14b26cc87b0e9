//! The blur's lattice stencils, one per face resolution: for every point of a face lattice
//! of resolution `R` (in [`grid_index`] order), where its neighbours sit in the face's
//! gathered grid, and for the boundary points which element holds them. They depend on `R`
//! alone, so a dab builds each once (cached across dabs in the brush's scratch) and every
//! face of that resolution reads its neighbours from a table, with no lattice arithmetic,
//! bounds test or element look-up per point.

use crate::colors::layout::Resolution;

/// Faces up to this resolution use a stencil (at `R = 64` it lists 2,145 points, ~70 KB);
/// finer faces keep the per-row path, which only visits the rows the brush reaches.
pub(super) const MAX_STENCIL_LOG2: u32 = 6;

/// Index of lattice point `(i, j)` in a face grid of resolution `res` (row `i` holds
/// `res + 1 − i` points).
#[inline(always)]
pub(super) fn grid_index(res: u32, i: u32, j: u32) -> usize {
    (i * (res + 1) - i * i.saturating_sub(1) / 2 + j) as usize
}

/// The six lattice neighbours `(di, dj)`, in the order their colours are summed.
pub(super) const NEIGHBOURS: [(i64, i64); 6] = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)];

/// Which element holds a boundary point: corner vertex `0..3`, or face edge `k` (`3 + k`)
/// at `position` counted from the edge's start corner (`1..R`, [`crate::colors::layout`]'s
/// conventions: face edge 0 is `j = 0`, 1 is `i + j = R`, 2 is `i = 0` walked from corner 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Holder {
    pub(super) element: u8,
    pub(super) position: u32,
}

/// A boundary point: its grid index, the grid indices of its neighbours inside the lattice
/// (the first `count`, in [`NEIGHBOURS`]' order) and its holder.
#[derive(Debug, Clone, Copy)]
pub(super) struct BoundaryStencil {
    pub(super) grid: u32,
    pub(super) neighbours: [u32; 6],
    pub(super) count: u32,
    pub(super) holder: Holder,
}

/// The stencil of one resolution.
#[derive(Debug, Clone)]
pub(super) struct Stencil {
    pub(super) res: u32,
    /// Lattice points, `grid_index(res, res, 0) + 1`.
    pub(super) points: usize,
    /// Per interior point, in storage order (thesis eq. 3.2, which is also grid order): its
    /// grid index and its six neighbours' (all inside the lattice), in [`NEIGHBOURS`]' order.
    pub(super) interior: Vec<(u32, [u32; 6])>,
    /// Per boundary point, in grid order.
    pub(super) boundary: Vec<BoundaryStencil>,
}

impl Stencil {
    /// The stencil of resolution `r`.
    pub(super) fn new(r: Resolution) -> Self {
        let res = r.get();
        let (mut interior, mut boundary) = (Vec::new(), Vec::new());
        for i in 0..=res {
            for j in 0..=res - i {
                let grid = grid_index(res, i, j) as u32;
                let (mut neighbours, mut count) = ([0u32; 6], 0u32);
                for (di, dj) in NEIGHBOURS {
                    let (ni, nj) = (i64::from(i) + di, i64::from(j) + dj);
                    if ni < 0 || nj < 0 || ni + nj > i64::from(res) {
                        continue;
                    }
                    neighbours[count as usize] = grid_index(res, ni as u32, nj as u32) as u32;
                    count += 1;
                }
                let holder = match (i, j) {
                    _ if i >= 1 && j >= 1 && i + j < res => None,
                    (0, 0) => Some(Holder { element: 0, position: 0 }),
                    (i, 0) if i == res => Some(Holder { element: 1, position: 0 }),
                    (0, j) if j == res => Some(Holder { element: 2, position: 0 }),
                    (i, 0) => Some(Holder { element: 3, position: i }),
                    (i, j) if i + j == res => Some(Holder { element: 4, position: j }),
                    (_, j) => Some(Holder { element: 5, position: res - j }),
                };
                match holder {
                    None => interior.push((grid, neighbours)),
                    Some(holder) => boundary.push(BoundaryStencil { grid, neighbours, count, holder }),
                }
            }
        }
        Stencil { res, points: grid_index(res, res, 0) + 1, interior, boundary }
    }
}

/// Stencils by `log2 R`, built on first use.
#[derive(Debug, Clone, Default)]
pub(super) struct Stencils(Vec<Option<Stencil>>);

impl Stencils {
    /// Builds the stencils of `resolutions` that have none yet (those up to
    /// [`MAX_STENCIL_LOG2`]).
    pub(super) fn prepare(&mut self, resolutions: impl Iterator<Item = Resolution>) {
        if self.0.is_empty() {
            self.0 = vec![None; MAX_STENCIL_LOG2 as usize + 1];
        }
        for r in resolutions {
            if let Some(slot @ None) = self.0.get_mut(r.log2() as usize) {
                *slot = Some(Stencil::new(r));
            }
        }
    }

    /// The stencil of `r`, when prepared.
    #[inline(always)]
    pub(super) fn get(&self, r: Resolution) -> Option<&Stencil> {
        self.0.get(r.log2() as usize).and_then(Option::as_ref)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point of every stencil, checked against the lattice's definition: the
    /// neighbours are exactly the in-lattice `(i + di, j + dj)`, the interior list is the
    /// storage order of [`crate::colors::layout::interior_offset`], and each boundary point's
    /// holder is what [`crate::colors::layout::classify_sample`] says.
    #[test]
    fn stencils_agree_with_the_lattice_definitions() {
        use crate::colors::layout::{self, SampleLocation};
        for log2 in 0..=MAX_STENCIL_LOG2 {
            let r = Resolution::new(1 << log2).unwrap();
            let res = r.get();
            let stencil = Stencil::new(r);
            let mut coords = Vec::new();
            for i in 0..=res {
                for j in 0..=res - i {
                    coords.push((i, j));
                }
            }
            assert_eq!(coords.len(), stencil.points);
            assert_eq!(stencil.interior.len() as u32, layout::interior_sample_count(r));
            assert_eq!(stencil.interior.len() + stencil.boundary.len(), stencil.points);
            let inside = |i: i64, j: i64| i >= 0 && j >= 0 && i + j <= i64::from(res);
            let expected = |i: u32, j: u32| -> Vec<u32> {
                NEIGHBOURS
                    .iter()
                    .map(|&(di, dj)| (i64::from(i) + di, i64::from(j) + dj))
                    .filter(|&(a, b)| inside(a, b))
                    .map(|(a, b)| coords.iter().position(|&c| c == (a as u32, b as u32)).unwrap() as u32)
                    .collect()
            };
            for (index, &(grid, neighbours)) in stencil.interior.iter().enumerate() {
                let (i, j) = coords[grid as usize];
                assert_eq!(layout::interior_offset(r, i, j), index as u32);
                assert_eq!(neighbours.to_vec(), expected(i, j));
            }
            for point in &stencil.boundary {
                let (i, j) = coords[point.grid as usize];
                assert_eq!(point.neighbours[..point.count as usize].to_vec(), expected(i, j));
                // Walked forwards, an edge sample's storage offset is its position − 1.
                let holder = match layout::classify_sample(r, i, j, [false; 3]).unwrap() {
                    SampleLocation::Vertex { corner } => Holder { element: corner, position: 0 },
                    SampleLocation::Edge { face_edge, offset } => {
                        Holder { element: 3 + face_edge, position: offset + 1 }
                    }
                    SampleLocation::Interior { .. } => panic!("({i}, {j}) at R = {res} is interior"),
                };
                assert_eq!(point.holder, holder, "({i}, {j}) at R = {res}");
            }
        }
    }
}
