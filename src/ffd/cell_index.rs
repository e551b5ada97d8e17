//! `CellIndex`: a uniform grid over the bounding boxes of a refined lattice's
//! cells, so that finding the cell that holds a point looks at a few
//! candidates instead of scanning every cell.

use crate::lattice::TypeNCells;
use crate::math::{Point3, Real};

/// A uniform bucket grid of cell indices.
#[derive(Clone, Debug)]
pub struct CellIndex {
    lo: Point3,
    size: Real,
    dims: [usize; 3],
    offsets: Vec<u32>,
    cells: Vec<u32>,
    boxes: Vec<(Point3, Point3)>,
}

impl CellIndex {
    /// Indexes every cell by its bounding box grown by `margin` (absolute).
    /// The bucket size is the mean cell box extent, with at most about
    /// `4 · cells` buckets.
    pub fn new(cells: &TypeNCells, x: &[Point3], margin: Real) -> CellIndex {
        let boxes: Vec<(Point3, Point3)> = (0..cells.len())
            .map(|c| {
                let mut lo = x[cells.apex[c] as usize];
                let mut hi = lo;
                let centre = std::iter::once(&cells.centre[c]);
                for &v in cells.ring.row(c).iter().chain(centre) {
                    let q = x[v as usize];
                    for k in 0..3 {
                        lo[k] = lo[k].min(q[k] - margin);
                        hi[k] = hi[k].max(q[k] + margin);
                    }
                }
                (lo, hi)
            })
            .collect();
        let mut lo = Point3::new(Real::MAX, Real::MAX, Real::MAX);
        let mut hi = Point3::new(Real::MIN, Real::MIN, Real::MIN);
        let mut extent = 0.0;
        for (a, b) in &boxes {
            for k in 0..3 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
            extent += (b - a).max();
        }
        let n = boxes.len().max(1) as Real;
        let span = (hi - lo).max().max(Real::MIN_POSITIVE);
        let mut size = (extent / n).max(span * 1e-6);
        // Keep the bucket count near the cell count.
        let count = |s: Real| {
            (0..3)
                .map(|k| ((hi[k] - lo[k]) / s).ceil().max(1.0))
                .product::<Real>()
        };
        while count(size) > 4.0 * n + 64.0 {
            size *= 1.25;
        }
        let dims = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / size).ceil() as usize).max(1));
        let bucket = |q: &Point3, k: usize| (((q[k] - lo[k]) / size) as usize).min(dims[k] - 1);
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (c, (a, b)) in boxes.iter().enumerate() {
            let (i0, j0, k0) = (bucket(a, 0), bucket(a, 1), bucket(a, 2));
            let (i1, j1, k1) = (bucket(b, 0), bucket(b, 1), bucket(b, 2));
            for k in k0..=k1 {
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        pairs.push(((i + dims[0] * (j + dims[1] * k)) as u32, c as u32));
                    }
                }
            }
        }
        let nb = dims[0] * dims[1] * dims[2];
        let csr = crate::lattice::Csr::from_pairs(nb, pairs.iter().copied());
        CellIndex {
            lo,
            size,
            dims,
            offsets: csr.offsets,
            cells: csr.items,
            boxes,
        }
    }

    /// Cells whose (grown) box may contain `p`; empty outside the grid.
    pub fn candidates(&self, p: &Point3) -> &[u32] {
        let mut idx = [0usize; 3];
        for k in 0..3 {
            let t = (p[k] - self.lo[k]) / self.size;
            if !(t >= 0.0 && t < self.dims[k] as Real + 1e-9) {
                return &[];
            }
            idx[k] = (t as usize).min(self.dims[k] - 1);
        }
        let b = idx[0] + self.dims[0] * (idx[1] + self.dims[1] * idx[2]);
        &self.cells[self.offsets[b] as usize..self.offsets[b + 1] as usize]
    }

    /// True when `p` lies in the (grown) bounding box of cell `c`: a cheap
    /// test before solving for local coordinates.
    pub fn box_contains(&self, c: u32, p: &Point3) -> bool {
        let (lo, hi) = &self.boxes[c as usize];
        (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k])
    }

    /// Bytes held by the index.
    pub fn bytes(&self) -> usize {
        4 * (self.offsets.len() + self.cells.len()) + 48 * self.boxes.len()
    }
}
