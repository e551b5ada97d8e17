//! Local coordinates of a point in a refined lattice cell, as weights over
//! the cell's vertices (MacCracken & Joy 1996, §4 and §6): trilinear
//! coordinates found by Newton's method in hexahedral (type-3) cells, and
//! barycentric coordinates in the partition of a type-n cell into `4n`
//! tetrahedra about its cell point.

use nalgebra::Matrix3;

use crate::lattice::TypeNCells;
use crate::math::{Point3, Real, Vector3};

/// Where a point lies in a cell: weights over lattice vertices and how far
/// outside the cell it is (0 inside; otherwise the largest violation of a
/// coordinate bound, in parameter units).
#[derive(Clone, Debug, Default)]
pub struct CellCoords {
    /// `(vertex, weight)` pairs; the weights sum to one.
    pub weights: Vec<(u32, Real)>,
    /// 0 inside the cell; the largest parameter-bound violation otherwise.
    pub outside_by: Real,
    /// Newton iterations used (0 for a tetrahedral partition).
    pub iterations: usize,
    /// The cell face (four vertices) across which the point lies outside
    /// the most; `None` inside.
    pub exit_face: Option<[u32; 4]>,
}

/// Corners (in [`TypeNCells::hexahedron`] order) of the faces `u = 0`,
/// `u = 1`, `v = 0`, `v = 1`, `w = 0`, `w = 1`.
const HEX_PARAM_FACES: [[usize; 4]; 6] = [
    [0, 2, 6, 4],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 3, 7, 6],
    [0, 1, 3, 2],
    [4, 5, 7, 6],
];

/// The trilinear basis at `(u, v, w)` in the order of [`TypeNCells::hexahedron`].
fn trilinear_basis(u: Real, v: Real, w: Real) -> [Real; 8] {
    let (a, b, c) = (1.0 - u, 1.0 - v, 1.0 - w);
    [
        a * b * c,
        u * b * c,
        a * v * c,
        u * v * c,
        a * b * w,
        u * b * w,
        a * v * w,
        u * v * w,
    ]
}

/// Trilinear coordinates of `p` in the hexahedron with corners `x` (order
/// `000, 100, 010, 110, 001, 101, 011, 111`) by Newton's method from the
/// centre, with the exact trilinear Jacobian (MacCracken & Joy, §6, use an
/// interpolated approximate Jacobian; the exact one converges quadratically).
/// Returns `(u, v, w)` and the iterations, or `None` when the Jacobian is
/// singular or Newton does not converge in 30 steps.
pub fn trilinear_coords(x: &[Point3; 8], p: &Point3) -> Option<([Real; 3], usize)> {
    let scale = (x[7] - x[0]).norm().max((x[6] - x[1]).norm());
    let mut t = [0.5; 3];
    let mut last = Real::INFINITY;
    for it in 1..=30 {
        let [u, v, w] = t;
        let n = trilinear_basis(u, v, w);
        let mut q = Vector3::zeros();
        for i in 0..8 {
            q += n[i] * x[i].coords;
        }
        let r = p.coords - q;
        // ∂x/∂u etc. from differences of opposite corners.
        let (a, b, c) = (1.0 - u, 1.0 - v, 1.0 - w);
        let du = (x[1] - x[0]) * b * c
            + (x[3] - x[2]) * v * c
            + (x[5] - x[4]) * b * w
            + (x[7] - x[6]) * v * w;
        let dv = (x[2] - x[0]) * a * c
            + (x[3] - x[1]) * u * c
            + (x[6] - x[4]) * a * w
            + (x[7] - x[5]) * u * w;
        let dw = (x[4] - x[0]) * a * b
            + (x[5] - x[1]) * u * b
            + (x[6] - x[2]) * a * v
            + (x[7] - x[3]) * u * v;
        let j = Matrix3::from_columns(&[du, dv, dw]);
        let d = j.try_inverse()? * r;
        for k in 0..3 {
            t[k] += d[k];
        }
        if !t.iter().all(|x| x.is_finite()) || t.iter().any(|x| x.abs() > 1e3) {
            return None;
        }
        // Converged when the step or the residual is at round-off level
        // (relative to the coordinates' magnitude, not just the cell size).
        let roundoff = 8.0 * Real::EPSILON * (p.coords.norm() + scale);
        if d.norm() < 1e-12 || r.norm() <= roundoff {
            return Some((t, it));
        }
        last = d.norm();
    }
    (last < 1e-9).then_some((t, 30))
}

/// Local coordinates of `p` in cell `c` of a refined level with positions `x`.
pub fn cell_coords(cells: &TypeNCells, c: usize, x: &[Point3], p: &Point3) -> Option<CellCoords> {
    if let Some(h) = cells.hexahedron(c) {
        let corners = h.map(|v| x[v as usize]);
        let (t, iterations) = trilinear_coords(&corners, p)?;
        let mut outside_by: Real = 0.0;
        let mut exit_face = None;
        for (k, &s) in t.iter().enumerate() {
            for (side, viol) in [(0, -s), (1, s - 1.0)] {
                if viol > outside_by {
                    outside_by = viol;
                    exit_face = Some(HEX_PARAM_FACES[2 * k + side].map(|i| h[i]));
                }
            }
        }
        let n = trilinear_basis(t[0], t[1], t[2]);
        return Some(CellCoords {
            weights: h.iter().zip(n).map(|(&v, w)| (v, w)).collect(),
            outside_by,
            iterations,
            exit_face,
        });
    }
    tetrahedral_coords(cells, c, x, p)
}

/// The triangles of the `2n` quad faces of type-n cell `c`, each quad split
/// along the diagonal through its smallest vertex index, so that two cells
/// sharing a face split it the same way.
pub fn cell_triangles(cells: &TypeNCells, c: usize) -> Vec<([u32; 3], [u32; 4])> {
    let r = cells.ring.row(c);
    let m = r.len();
    let mut tris = Vec::with_capacity(2 * m);
    for i in 0..m / 2 {
        let (e, f, e1) = (r[2 * i], r[2 * i + 1], r[(2 * i + 2) % m]);
        let f0 = r[(2 * i + m - 1) % m];
        for q in [[cells.apex[c], e, f, e1], [cells.centre[c], f0, e, f]] {
            let k = (0..4).min_by_key(|&k| q[k]).unwrap_or(0);
            let (a, b, cc, d) = (q[k], q[(k + 1) % 4], q[(k + 2) % 4], q[(k + 3) % 4]);
            tris.push(([a, b, cc], q));
            tris.push(([a, cc, d], q));
        }
    }
    tris
}

/// Barycentric coordinates in the `4n` tetrahedra about the cell point
/// (the average of the cell's `2n + 2` vertices; MacCracken & Joy, §5–6):
/// `P = P₀ + u (P₁ − P₀) + v (P₂ − P₀) + w (P₃ − P₀)` solved directly.
/// The cell point's weight is spread evenly over the cell's vertices. The
/// tetrahedron with the smallest violation is chosen.
fn tetrahedral_coords(
    cells: &TypeNCells,
    c: usize,
    x: &[Point3],
    p: &Point3,
) -> Option<CellCoords> {
    let mut verts: Vec<u32> = vec![cells.apex[c], cells.centre[c]];
    verts.extend_from_slice(cells.ring.row(c));
    let k = verts.len() as Real;
    let centre = verts
        .iter()
        .fold(Vector3::zeros(), |s, &v| s + x[v as usize].coords)
        / k;
    // (violation, triangle, barycentric coordinates, quad of the triangle)
    type Tet = (Real, [u32; 3], [Real; 4], [u32; 4]);
    let mut best: Option<Tet> = None;
    for (t, quad) in cell_triangles(cells, c) {
        let [a, b, d] = t.map(|v| x[v as usize].coords - centre);
        let Some(inv) = Matrix3::from_columns(&[a, b, d]).try_inverse() else {
            continue;
        };
        let l = inv * (p.coords - centre);
        let bary = [1.0 - l.sum(), l[0], l[1], l[2]];
        let viol = bary.iter().map(|&s| -s).fold(0.0, Real::max);
        if best.as_ref().is_none_or(|b| viol < b.0) {
            best = Some((viol, t, bary, quad));
        }
    }
    let (outside_by, t, bary, quad) = best?;
    let mut weights: Vec<(u32, Real)> = verts.iter().map(|&v| (v, bary[0] / k)).collect();
    for (i, &v) in t.iter().enumerate() {
        if let Some(w) = weights.iter_mut().find(|w| w.0 == v) {
            w.1 += bary[i + 1];
        }
    }
    Some(CellCoords {
        weights,
        outside_by,
        iterations: 0,
        exit_face: (outside_by > 0.0).then_some(quad),
    })
}
