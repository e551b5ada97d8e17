//! The 2×2 parameter maps of patches and their children: which child
//! holds a point, the child's own parameters, and the chain rule that
//! carries derivatives from a child's parameters to its parent's.

use std::ops::{Add, Mul};

use crate::math::Real;

/// Parameter position of corner `k` of a quad.
pub(crate) const CORNERS: [[Real; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

pub(crate) const IDENTITY: [[Real; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];

/// The quadrant of `(s, t)`: the child at corner 0, 1, 2 or 3. Ties go to
/// the upper half, as in OpenSubdiv's `Bfr`.
pub(crate) fn quadrant(st: [Real; 2]) -> usize {
    match (st[0] >= 0.5, st[1] >= 0.5) {
        (false, false) => 0,
        (true, false) => 1,
        (true, true) => 2,
        (false, true) => 3,
    }
}

/// Child `k` of a quad has its corner 0 at the parent's corner `k`, `s`
/// towards corner `k + 1` and `t` towards corner `k − 1` (the refiner's child
/// order). Returns the child's `(s, t)` for the parent's `st` and the matrix
/// `M` with `child = M (st − corner_k)`.
pub(crate) fn child_frame(k: usize, st: [Real; 2]) -> ([Real; 2], [[Real; 2]; 2]) {
    let o = CORNERS[k];
    let a = sub(CORNERS[(k + 1) % 4], o);
    let b = sub(CORNERS[(k + 3) % 4], o);
    let m = [[2.0 * a[0], 2.0 * a[1]], [2.0 * b[0], 2.0 * b[1]]];
    let d = sub(st, o);
    let c = mat_vec(m, d);
    ([c[0].clamp(0.0, 1.0), c[1].clamp(0.0, 1.0)], m)
}

/// Sub-face of an `n`-gon holding `(u, v)` and the sub-face's own `(s, t)`:
/// sub-face `i` covers `[tu, tu + ½] × [tv, tv + ½]`, `(tu, tv) = (i mod d,
/// i div d)`, `d = ⌈√n⌉`; values past three quarters of a tile count for
/// the next tile, as in `Bfr`.
pub(crate) fn subface(n: usize, u: Real, v: Real) -> (usize, [Real; 2]) {
    let d = (n as Real).sqrt().ceil() as usize;
    let rows = n.div_ceil(d);
    let tu = ((u + 0.25).floor().max(0.0) as usize).min(d - 1);
    let tv = ((v + 0.25).floor().max(0.0) as usize).min(rows - 1);
    let i = (tv * d + tu).min(n - 1);
    let (tu, tv) = ((i % d) as Real, (i / d) as Real);
    (
        i,
        [
            (2.0 * (u - tu)).clamp(0.0, 1.0),
            (2.0 * (v - tv)).clamp(0.0, 1.0),
        ],
    )
}

/// `a · b` for 2×2 matrices.
pub(crate) fn mat_mul(a: [[Real; 2]; 2], b: [[Real; 2]; 2]) -> [[Real; 2]; 2] {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// `a · x` for a 2×2 matrix.
pub(crate) fn mat_vec(a: [[Real; 2]; 2], x: [Real; 2]) -> [Real; 2] {
    [
        a[0][0] * x[0] + a[0][1] * x[1],
        a[1][0] * x[0] + a[1][1] * x[1],
    ]
}

pub(crate) fn sub(a: [Real; 2], b: [Real; 2]) -> [Real; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// Chain rule for `(s', t') = J (s, t) + c`: maps `[Ps', Pt', Ps's', Ps't', Pt't']`
/// to `[Ps, Pt, Pss, Pst, Ptt]`.
pub(crate) fn chain<T>(d: [T; 5], j: [[Real; 2]; 2]) -> [T; 5]
where
    T: Copy + Mul<Real, Output = T> + Add<Output = T>,
{
    let (su, sv, tu, tv) = (j[0][0], j[0][1], j[1][0], j[1][1]);
    [
        d[0] * su + d[1] * tu,
        d[0] * sv + d[1] * tv,
        d[2] * (su * su) + d[3] * (2.0 * su * tu) + d[4] * (tu * tu),
        d[2] * (su * sv) + d[3] * (su * tv + sv * tu) + d[4] * (tu * tv),
        d[2] * (sv * sv) + d[3] * (2.0 * sv * tv) + d[4] * (tv * tv),
    ]
}
