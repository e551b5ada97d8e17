//! The self-intersections of a triangle mesh: the pairs of triangles that
//! share no vertex and intersect, the pairs Open3D's
//! `get_self_intersecting_triangles()` reports.
//!
//! Two triangles that are not coplanar intersect exactly when an edge of
//! one crosses the other (Möller, "A fast triangle-triangle intersection
//! test", *JGT* 2(2), 1997, §2: the intersection segment of the two planes
//! is bounded by edge crossings), so each candidate pair is decided by the
//! edge–triangle crossing test [`ray_triangle`] both ways, after Möller's
//! first rejection (one triangle wholly on one side of the other's plane).
//! Coplanar overlaps are not found (the crossing test skips segments
//! parallel to a triangle).
//!
//! The candidates come from a uniform grid (the cell lists of collision
//! detection; Teschner et al., "Optimized spatial hashing for collision
//! detection of deformable objects", VMV 2003, store them hashed, here they
//! are sorted by cell with a radix sort): every triangle's box goes into the
//! cells it overlaps, and the triangles of a cell are paired. A pair whose
//! boxes overlap is tested only in the cell holding the low corner of the
//! overlap, which both boxes occupy: along each axis that is the later of
//! the two boxes' first cells, so each triangle of a cell is marked with
//! the axes its box starts on there, and two are paired only when together
//! they start on all three. Each pair is so met once, with no set of pairs
//! to merge. The cell side is [`CELL_SIDE`] × the median of the triangles'
//! largest box sides (a tessellation's triangles are alike in size),
//! doubled while the entries would pass [`MAX_ENTRIES_PER_TRIANGLE`] per
//! triangle. `O(n)` for triangles of similar size, no tree to build; cells
//! run in parallel and the pairs are sorted, so the result does not depend
//! on the thread count.

use rayon::prelude::*;

use crate::error::Result;
use crate::math::{Point3, Real, Vector3, group_by_key};

use super::bvh_build::Aabb;

use super::triangle::{check_triangles, ray_triangle};

/// Cell entries per triangle, on average, above which the cells are made
/// twice as large (bounds the memory on meshes of very unequal triangles).
const MAX_ENTRIES_PER_TRIANGLE: u64 = 16;

/// The pairs `[s, t]` (`s < t`, sorted) of `triangles` (indices into
/// `positions`) that share no vertex index and intersect (module docs). On
/// a closed tessellated surface, any pair is a place where the surface
/// passes through itself: a fold, a pinch or two parts grown into each
/// other. Errors on an index out of range or a non-finite coordinate.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::metrics::self_intersecting_pairs;
/// let p = |x, y, z| Point3::new(x, y, z);
/// // Two triangles crossing like the arms of an X, and one far away.
/// let positions = [p(0., 0., 0.), p(2., 0., 0.), p(1., 2., 0.),
///                  p(1., 1., -1.), p(1., 1., 1.), p(1., -1., 0.5),
///                  p(9., 9., 9.), p(10., 9., 9.), p(9., 10., 9.)];
/// let pairs = self_intersecting_pairs(&positions, &[[0, 1, 2], [3, 4, 5], [6, 7, 8]])?;
/// assert_eq!(pairs, vec![[0, 1]]);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn self_intersecting_pairs(
    positions: &[Point3],
    triangles: &[[u32; 3]],
) -> Result<Vec<[u32; 2]>> {
    check_triangles(positions, triangles)?;
    Ok(pairs_of(positions, triangles))
}

/// [`self_intersecting_pairs`] of valid input (indices in range, finite
/// positions, at most `u32::MAX` triangles).
pub(crate) fn pairs_of(positions: &[Point3], triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    if triangles.len() < 2 {
        return Vec::new();
    }
    let corners = |t: u32| triangles[t as usize].map(|v| positions[v as usize]);
    let exact: Vec<Aabb> = (0..triangles.len() as u32)
        .into_par_iter()
        .map(|t| Aabb::of_triangle(corners(t)))
        .collect();
    let all = exact.par_iter().copied().reduce(
        || Aabb::EMPTY,
        |mut a, b| {
            a.merge(&b);
            a
        },
    );
    // The boxes are widened by far more than the crossing test's slack
    // (`RAY_BARY_SLACK` of a triangle's size): the candidates are a
    // superset of the pairs whose edges can cross.
    let extent = (0..3)
        .map(|k| 0.5 * (all.hi[k] - all.lo[k]))
        .fold(0.0, Real::max);
    let margin = 1e-9 * extent.max(Real::MIN_POSITIVE);
    let boxes: Vec<Aabb> = exact
        .par_iter()
        .map(|b| Aabb {
            lo: b.lo.map(|x| x - margin),
            hi: b.hi.map(|x| x + margin),
        })
        .collect();
    let grid = Grid::new(&boxes, all.lo.map(|x| x - margin));
    // (cell, triangle) of every cell of every triangle, packed in a `u64`
    // (the cell's key above the triangle), in triangle order, then sorted
    // by cell by stable counting sorts on `DIGIT_BITS` bits at a time (LSD
    // radix sort): each cell's entries in a run, in triangle order.
    let mut entries: Vec<u64> = Vec::with_capacity(grid.entries);
    for (t, b) in boxes.iter().enumerate() {
        grid.push_entries(b, t as u32, &mut entries);
    }
    for shift in (32..32 + grid.key_bits).step_by(DIGIT_BITS as usize) {
        let digit = |e: u64| ((e >> shift) & ((1 << DIGIT_BITS) - 1)) as usize;
        entries = group_by_key(1 << DIGIT_BITS, entries.iter().map(|&e| (digit(e), e))).1;
    }
    let mut runs: Vec<usize> = (0..entries.len())
        .filter(|&i| i == 0 || entries[i] >> 32 != entries[i - 1] >> 32)
        .collect();
    runs.push(entries.len());
    let planes: Vec<Plane> = (0..triangles.len() as u32)
        .into_par_iter()
        .map(|t| Plane::of(corners(t), exact[t as usize].largest_side()))
        .collect();
    let mut pairs: Vec<[u32; 2]> = runs
        .par_windows(2)
        .flat_map_iter(|run| {
            let cell = grid.cell(entries[run[0]] >> 32);
            // Each triangle with the axes its box starts on in this cell.
            let here: Vec<(u32, u8)> = entries[run[0]..run[1]]
                .iter()
                .map(|&e| (e as u32, grid.starts(&boxes[e as u32 as usize], cell)))
                .collect();
            let mut out = Vec::new();
            for (i, &(s, s_starts)) in here.iter().enumerate() {
                let (ts, a) = (&triangles[s as usize], &boxes[s as usize]);
                for &(t, t_starts) in &here[i + 1..] {
                    if s_starts | t_starts != ALL_AXES {
                        continue;
                    }
                    let (tt, b) = (&triangles[t as usize], &boxes[t as usize]);
                    if (0..3).any(|k| a.lo[k] > b.hi[k] || b.lo[k] > a.hi[k])
                        || ts.iter().any(|v| tt.contains(v))
                    {
                        continue;
                    }
                    let (cs, ct) = (corners(s), corners(t));
                    if planes[t as usize].apart(&cs) || planes[s as usize].apart(&ct) {
                        continue;
                    }
                    if crosses(positions, ts, ct) || crosses(positions, tt, cs) {
                        out.push([s, t]);
                    }
                }
            }
            out
        })
        .collect();
    pairs.sort_unstable();
    pairs
}

/// Bits of the cell key sorted per counting-sort pass.
const DIGIT_BITS: u32 = 13;

/// The cell side in medians of the triangles' largest box sides: larger
/// cells hold more triangles to pair, smaller ones more entries to sort
/// (2 was the fastest of 1, 2, 3 and 4 on the tessellations of fits).
const CELL_SIDE: Real = 2.0;

/// [`Grid::starts`] of a box's first cell.
const ALL_AXES: u8 = 0b111;

/// A triangle's plane, for the early rejection of a pair whose one
/// triangle lies wholly on one side of the other's plane (Möller 1997,
/// §2, the first test), which no edge of it can then cross.
struct Plane {
    /// The normal `(b − a) × (c − a)` (not normalised).
    normal: Vector3,
    /// `normal · a`.
    offset: Real,
    /// The largest coordinate extent of the triangle.
    size: Real,
}

/// How far off the plane, relative to the larger triangle's size, all three
/// corners must lie for [`Plane::apart`]: far above the round-off of the
/// crossing test on any triangle that is not a sliver, far below the
/// offsets of a curved surface's neighbouring triangles.
const APART: Real = 1e-6;

impl Plane {
    /// The plane of the triangle with corners `a`, `b`, `c` and largest
    /// box side `size`.
    fn of([a, b, c]: [Point3; 3], size: Real) -> Plane {
        let normal = (b - a).cross(&(c - a));
        Plane {
            normal,
            offset: normal.dot(&a.coords),
            size,
        }
    }

    /// Whether the corners `c` (of a triangle of about `self.size`) all lie
    /// on one side of the plane, each farther than [`APART`] × the larger
    /// size.
    fn apart(&self, c: &[Point3; 3]) -> bool {
        let size = c
            .iter()
            .fold(self.size, |m, p| m.max((p - c[0]).abs().max()));
        let tol = APART * size * self.normal.norm();
        let d = c.map(|p| self.normal.dot(&p.coords) - self.offset);
        tol > 0.0 && (d.iter().all(|&x| x > tol) || d.iter().all(|&x| x < -tol))
    }
}

/// Whether an edge of triangle `s` (each from its lower vertex index, as
/// every triangle sharing it sees it) crosses or touches the triangle with
/// corners `t`.
fn crosses(positions: &[Point3], s: &[u32; 3], [p, q, r]: [Point3; 3]) -> bool {
    (0..3).any(|e| {
        let (a, b) = (s[e].min(s[(e + 1) % 3]), s[e].max(s[(e + 1) % 3]));
        let a = positions[a as usize];
        let dir: Vector3 = positions[b as usize] - a;
        dir != Vector3::zeros() && ray_triangle(a, dir, 1.0, p, q, r).is_some()
    })
}

/// The uniform grid: cells of side `h` from `origin`, `bits[k]` bits of
/// cell index along axis `k` in a cell's key.
struct Grid {
    origin: [Real; 3],
    h: Real,
    bits: [u32; 3],
    /// `bits[0] + bits[1] + bits[2]`.
    key_bits: u32,
    /// The number of entries of all boxes.
    entries: usize,
}

impl Grid {
    /// The grid for `boxes`, from `origin` (module docs), with cell keys of
    /// at most 32 bits.
    fn new(boxes: &[Aabb], origin: [Real; 3]) -> Grid {
        let mut sides: Vec<Real> = boxes.iter().map(Aabb::largest_side).collect();
        let mid = sides.len() / 2;
        let (_, &mut median, _) = sides.select_nth_unstable_by(mid, Real::total_cmp);
        let hi = boxes.iter().fold([Real::NEG_INFINITY; 3], |m, b| {
            [0, 1, 2].map(|k| m[k].max(b.hi[k]))
        });
        let mut grid = Grid {
            origin,
            h: CELL_SIDE * median,
            bits: [0; 3],
            key_bits: 0,
            entries: 0,
        };
        let limit = MAX_ENTRIES_PER_TRIANGLE * boxes.len() as u64;
        loop {
            grid.bits = [0, 1, 2].map(|k| u64::BITS - grid.index(hi[k], k).leading_zeros());
            grid.key_bits = grid.bits.iter().sum();
            // Within 32 bits of key, no box has more than 2³² cells.
            let entries = (grid.key_bits <= 32).then(|| {
                boxes
                    .par_iter()
                    .map(|b| {
                        grid.span(b)
                            .iter()
                            .map(|s| s.end - s.start)
                            .product::<u64>()
                    })
                    .sum::<u64>()
            });
            if let Some(entries) = entries.filter(|&e| e <= limit) {
                grid.entries = entries as usize;
                return grid;
            }
            grid.h *= 2.0;
        }
    }

    /// The cell index of coordinate `x` along `k`.
    fn index(&self, x: Real, k: usize) -> u64 {
        ((x - self.origin[k]) / self.h).floor() as u64
    }

    /// The cell ranges a box overlaps, per axis.
    fn span(&self, b: &Aabb) -> [std::ops::Range<u64>; 3] {
        [0, 1, 2].map(|k| self.index(b.lo[k], k)..self.index(b.hi[k], k) + 1)
    }

    /// Appends the entries of triangle `tri` with box `b` to `out`: the
    /// key of each cell it overlaps above `tri`.
    fn push_entries(&self, b: &Aabb, tri: u32, out: &mut Vec<u64>) {
        let [x, y, z] = self.span(b);
        for i in x {
            for j in y.clone() {
                for k in z.clone() {
                    let key = (((i << self.bits[1]) | j) << self.bits[2]) | k;
                    out.push((key << 32) | u64::from(tri));
                }
            }
        }
    }

    /// The cell of a key.
    fn cell(&self, key: u64) -> [u64; 3] {
        let mask = |bits: u32| (1u64 << bits) - 1;
        [
            key >> (self.bits[1] + self.bits[2]),
            (key >> self.bits[2]) & mask(self.bits[1]),
            key & mask(self.bits[2]),
        ]
    }

    /// Bit `k` set: the box `b`'s first cell along axis `k` is `cell`'s.
    fn starts(&self, b: &Aabb, cell: [u64; 3]) -> u8 {
        (0..3)
            .filter(|&k| self.index(b.lo[k], k) == cell[k])
            .fold(0, |m, k| m | 1 << k)
    }
}
