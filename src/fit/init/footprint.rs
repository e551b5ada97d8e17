//! The footprint of an open scan on a 2-D grid: which cells of the grid over
//! the principal plane become quads of the open cage.
//!
//! Steps: cells with at least `min_points` points; one-cell holes (an empty
//! cell whose four edge neighbours are kept) are filled; the largest
//! 4-connected component is kept; then every grid vertex where two kept cells
//! touch only at a corner (the 2×2 pattern `■□ / □■`, a bow-tie, the only
//! non-manifold configuration a set of grid quads can have) is repaired by
//! adding one of the two empty cells — the one with more kept edge
//! neighbours. Adding a cell never disconnects the set, and the loop ends
//! because every pass adds a cell to a finite grid (at worst all of it, which
//! has no bow-tie).

use std::collections::VecDeque;

/// A boolean mask over `nu × nv` cells, cell `(i, j)` at `i + nu j`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CellMask {
    /// Cells along the first axis.
    pub nu: usize,
    /// Cells along the second axis.
    pub nv: usize,
    /// True for kept cells.
    pub kept: Vec<bool>,
}

impl CellMask {
    /// True when `(i, j)` is inside the grid and kept.
    pub fn get(&self, i: isize, j: isize) -> bool {
        i >= 0
            && j >= 0
            && (i as usize) < self.nu
            && (j as usize) < self.nv
            && self.kept[i as usize + self.nu * j as usize]
    }

    fn set(&mut self, i: isize, j: isize, value: bool) {
        self.kept[i as usize + self.nu * j as usize] = value;
    }

    fn kept_neighbours(&self, i: isize, j: isize) -> usize {
        [(1, 0), (-1, 0), (0, 1), (0, -1)]
            .iter()
            .filter(|(di, dj)| self.get(i + di, j + dj))
            .count()
    }

    /// Number of kept cells.
    pub fn count(&self) -> usize {
        self.kept.iter().filter(|&&k| k).count()
    }
}

/// How many cells each step of [`footprint`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FootprintStats {
    /// Cells with enough points.
    pub occupied: usize,
    /// One-cell holes filled.
    pub holes_filled: usize,
    /// Cells dropped because they were not in the largest component.
    pub dropped: usize,
    /// Cells added to remove corner-only contacts.
    pub added: usize,
}

/// The manifold footprint from per-cell point counts (see the module docs).
pub fn footprint(
    nu: usize,
    nv: usize,
    counts: &[usize],
    min_points: usize,
) -> (CellMask, FootprintStats) {
    let mut mask = CellMask {
        nu,
        nv,
        kept: counts.iter().map(|&c| c >= min_points).collect(),
    };
    let mut stats = FootprintStats {
        occupied: mask.count(),
        ..Default::default()
    };
    let cells = || (0..nv as isize).flat_map(move |j| (0..nu as isize).map(move |i| (i, j)));
    let holes: Vec<(isize, isize)> = cells()
        .filter(|&(i, j)| !mask.get(i, j) && mask.kept_neighbours(i, j) == 4)
        .collect();
    for &(i, j) in &holes {
        mask.set(i, j, true);
    }
    stats.holes_filled = holes.len();
    let before = mask.count();
    mask = largest_component(&mask);
    stats.dropped = before - mask.count();
    loop {
        let mut changed = false;
        for j in 1..nv as isize {
            for i in 1..nu as isize {
                let (a, b, c, d) = (
                    mask.get(i - 1, j - 1),
                    mask.get(i, j - 1),
                    mask.get(i - 1, j),
                    mask.get(i, j),
                );
                if a == d && b == c && a != b {
                    let (e0, e1) = if a {
                        ((i, j - 1), (i - 1, j))
                    } else {
                        ((i - 1, j - 1), (i, j))
                    };
                    let pick =
                        if mask.kept_neighbours(e1.0, e1.1) > mask.kept_neighbours(e0.0, e0.1) {
                            e1
                        } else {
                            e0
                        };
                    mask.set(pick.0, pick.1, true);
                    stats.added += 1;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    (mask, stats)
}

/// The largest 4-connected component of `mask` (the first found on ties).
pub fn largest_component(mask: &CellMask) -> CellMask {
    let (nu, nv) = (mask.nu, mask.nv);
    let mut label = vec![usize::MAX; nu * nv];
    let mut best = (0usize, usize::MAX);
    let mut queue = VecDeque::new();
    for start in 0..nu * nv {
        if !mask.kept[start] || label[start] != usize::MAX {
            continue;
        }
        label[start] = start;
        queue.push_back(start);
        let mut size = 0;
        while let Some(c) = queue.pop_front() {
            size += 1;
            let (i, j) = ((c % nu) as isize, (c / nu) as isize);
            for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                let (x, y) = (i + di, j + dj);
                if mask.get(x, y) {
                    let n = x as usize + nu * y as usize;
                    if label[n] == usize::MAX {
                        label[n] = start;
                        queue.push_back(n);
                    }
                }
            }
        }
        if size > best.0 {
            best = (size, start);
        }
    }
    CellMask {
        nu,
        nv,
        kept: label.iter().map(|&l| l == best.1).collect(),
    }
}
