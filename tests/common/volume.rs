//! Lattice fixtures: the direct tricubic uniform B-spline volume over a
//! regular control grid, used to check Catmull-Clark volume refinement and
//! FFD against the trivariate B-spline case (MacCracken & Joy 1996, §2.1).

use subdyn::lattice::{Lattice, LatticeTopology};
use subdyn::math::Point3;

/// The centred uniform cubic B-spline `N(x)` (support `[-2, 2]`).
pub fn cubic_bspline(x: f64) -> f64 {
    let a = x.abs();
    if a < 1.0 {
        2.0 / 3.0 - a * a + 0.5 * a * a * a
    } else if a < 2.0 {
        (2.0 - a).powi(3) / 6.0
    } else {
        0.0
    }
}

/// `Σ N(t_x − i) N(t_y − j) N(t_z − k) P_ijk` over a grid of `(n+1)³`
/// control points indexed like `subdyn::lattice::box_grid`; `t` in index units.
pub fn tricubic(points: &[Point3], n: [usize; 3], t: [f64; 3]) -> Point3 {
    let mut out = Point3::origin();
    let id = |i: usize, j: usize, k: usize| i + (n[0] + 1) * (j + (n[1] + 1) * k);
    let lo = |x: f64| (x.floor() as i64 - 2).max(0) as usize;
    for k in lo(t[2])..=(t[2].floor() as usize + 2).min(n[2]) {
        for j in lo(t[1])..=(t[1].floor() as usize + 2).min(n[1]) {
            for i in lo(t[0])..=(t[0].floor() as usize + 2).min(n[0]) {
                let w = cubic_bspline(t[0] - i as f64)
                    * cubic_bspline(t[1] - j as f64)
                    * cubic_bspline(t[2] - k as f64);
                out.coords += w * points[id(i, j, k)].coords;
            }
        }
    }
    out
}

/// A square pyramid lattice of one cell: its apex has valence 4 in the cell,
/// so refinement makes type-4 cells there.
pub fn pyramid() -> Lattice {
    let pos = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(0.5, 0.5, 1.0),
    ];
    let cell = vec![
        vec![0, 3, 2, 1],
        vec![0, 1, 4],
        vec![1, 2, 4],
        vec![2, 3, 4],
        vec![3, 0, 4],
    ];
    Lattice::new(pos, LatticeTopology::from_polyhedra(5, &[cell]).unwrap()).unwrap()
}
