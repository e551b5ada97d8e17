//! The exact fine-tuned curve `Q(t) = P(t_0) + ∫_{t_0}^t α(s) P'(s) ds`
//! (fine-tuning paper, idea of §2 / §4.2: `Q'(t) = α(t) P'(t)`; the excerpt
//! lacks the curve sections, so the construction is derived here).
//!
//! **Derivation.** Let `P` be a uniform B-spline of degree `d` and `α` one of
//! degree `k` on the same integer knots. On each span `[i, i+1]` (local
//! `u = t − i`):
//! 1. `P` in Bézier form `b_0 … b_d` ([`bspline_to_bezier`]); then
//!    `P'(u) = Σ_l d (b_{l+1} − b_l) B_l^{d−1}(u)`.
//! 2. `α(u) = Σ_i α_i B_i^k(u)` likewise.
//! 3. Product of Bernstein forms: `α P' = Σ_l c_l B_l^{k+d−1}` with
//!    `c_l = Σ_{i+j=l} C(k,i) C(d−1,j) / C(k+d−1,l) · α_i p_j`.
//! 4. Integration raises the degree to `D = k + d`: `q_0 = Q(i)`,
//!    `q_{l+1} = q_l + c_l / D` (span length 1). Spans are chained, so `Q`
//!    is continuous; `Q(t_0) = P(t_0)` at the start of the first span.
//!
//! `α` is `C^{k−1}` and `P'` is `C^{d−2}` at the knots, so `Q` is `C^c` with
//! `c = min(k, d − 1)`. It is therefore a B-spline of degree `D` on the same
//! integer knots, each of multiplicity `m = D − c` (the degree elevation and
//! knot insertion the paper mentions). Its control points are blossoms: with
//! knots `t_j = ⌊j/m⌋`, control point `j` is `Q[t_{j+1}, …, t_{j+D}]`, computed
//! from the Bézier form of any span the window covers (de Casteljau with a
//! different parameter on each level). For `d = 2, k = 1` this gives `D = 3`,
//! `m = 2`: knot intervals alternating 1 and 0, the paper's non-uniform
//! Catmull-Clark setting of §4.3.
//!
//! For a closed curve the integral over one period, the *gap*
//! `G = ∫_0^n α P'`, is in general not zero, so `Q` does not close; the
//! unclosed `Q` is quasi-periodic (`Q(t + n) = Q(t) + G`), and its control
//! points satisfy `C_{j+N} = C_j + G` with `N = n m`. The legs
//! `C_{j+1} − C_j` are thus periodic: they are the optimal legs of energy (13).

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::subdivision::{CurveTopology, bspline_to_bezier};

use super::curve_alpha::ScalarFunction;
use super::curve_bspline::BSplineCurve;

/// The exact fine-tuned curve in Bézier and B-spline form.
#[derive(Clone, Debug)]
pub struct ExactFinetune {
    /// Degree `D = k + d`.
    pub degree: usize,
    /// Multiplicity `m = D − min(k, d − 1)` of every integer knot.
    pub multiplicity: usize,
    /// Bézier control points of each span (`D + 1` each).
    pub spans: Vec<Vec<Point3>>,
    /// `Q` as a B-spline over all spans (for a closed input: the unclosed curve over `[0, n]`).
    pub curve: BSplineCurve,
    /// `Q(end) − Q(start)` for a closed input (zero vector for an open one).
    pub gap: Vector3,
    /// Closed input: the `N = n m` control points `C_0 … C_{N−1}` of the
    /// quasi-periodic `Q` (empty for an open input).
    pub periodic_points: Vec<Point3>,
}

/// Binomial coefficient `C(n, k)` as a real.
fn binomial(n: usize, k: usize) -> Real {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as Real / (i + 1) as Real)
}

/// Bézier points of `Q` on each span (steps 1–4 of the module docs).
pub fn finetuned_spans(
    topo: &CurveTopology,
    points: &[Point3],
    alpha: &ScalarFunction,
) -> Result<Vec<Vec<Point3>>> {
    if points.len() != topo.num_points || alpha.closed != topo.closed {
        return Err(Error::size_mismatch(format!(
            "{} control points and a {} α for a {} curve of {} points",
            points.len(),
            if alpha.closed { "closed" } else { "open" },
            if topo.closed { "closed" } else { "open" },
            topo.num_points
        )));
    }
    let (d, k) = (topo.degree(), alpha.degree);
    let big = k + d;
    let m = bspline_to_bezier(d);
    let mut spans = Vec::with_capacity(topo.num_spans());
    let mut start: Option<Point3> = None;
    for i in 0..topo.num_spans() {
        let b: Vec<Vector3> = (0..=d)
            .map(|l| {
                (0..=d)
                    .map(|j| m[l][j] * points[topo.span_point(i, j)].coords)
                    .sum()
            })
            .collect();
        let q0 = *start.get_or_insert(Point3::from(b[0]));
        let dp: Vec<Vector3> = (0..d).map(|l| d as Real * (b[l + 1] - b[l])).collect();
        let a = alpha.span_bernstein(i);
        let mut q = Vec::with_capacity(big + 1);
        q.push(q0);
        for l in 0..big {
            let mut c = Vector3::zeros();
            for (ii, ai) in a.iter().enumerate() {
                if l >= ii && l - ii < d {
                    let j = l - ii;
                    c += (binomial(k, ii) * binomial(d - 1, j) / binomial(big - 1, l)) * ai * dp[j];
                }
            }
            let next = q[l] + c / big as Real;
            q.push(next);
        }
        start = q.last().copied();
        spans.push(q);
    }
    Ok(spans)
}

/// Blossom `Q[u_1, …, u_D]` of one Bézier span (local parameters).
fn blossom(bezier: &[Point3], args: &[Real]) -> Point3 {
    let mut c: Vec<Vector3> = bezier.iter().map(|p| p.coords).collect();
    for (r, &u) in args.iter().enumerate() {
        for l in 0..c.len() - 1 - r {
            c[l] = (1.0 - u) * c[l] + u * c[l + 1];
        }
    }
    Point3::from(c[0])
}

/// Control point `j` (knots `t_j = ⌊j/m⌋`) of the spline whose spans are `spans`.
fn control_point(spans: &[Vec<Point3>], degree: usize, m: usize, j: isize) -> Point3 {
    let knot = |x: isize| x.div_euclid(m as isize);
    let last = spans.len() as isize - 1;
    let i = ((j + degree as isize + 1).div_euclid(m as isize) - 1).clamp(0, last);
    let args: Vec<Real> = (1..=degree as isize)
        .map(|r| (knot(j + r) - i) as Real)
        .collect();
    blossom(&spans[i as usize], &args)
}

/// The B-spline of degree `D`, knot multiplicity `m`, over `spans`, with
/// control points `j = m − 1 − D … S m − 1` (`S` spans) and knots `⌊j/m⌋`.
pub fn spline_from_spans(spans: &[Vec<Point3>], m: usize) -> Result<BSplineCurve> {
    let degree = spans.first().map_or(0, |s| s.len().saturating_sub(1));
    let j0 = m as isize - 1 - degree as isize;
    let j1 = (spans.len() * m) as isize - 1;
    let points: Vec<Point3> = (j0..=j1)
        .map(|j| control_point(spans, degree, m, j))
        .collect();
    let knots = (0..points.len() + degree + 1)
        .map(|i| (i as isize + j0).div_euclid(m as isize) as Real)
        .collect();
    BSplineCurve::new(degree, knots, points)
}

/// A closed B-spline (as an ordinary one with wrapped control points) from
/// the `N = n m` periodic control points `C_0 … C_{N−1}`.
pub fn closed_spline(periodic: &[Point3], degree: usize, m: usize) -> Result<BSplineCurve> {
    let n_total = periodic.len() as isize;
    if n_total == 0 || !periodic.len().is_multiple_of(m) {
        return Err(Error::input(format!(
            "{} periodic control points are not a multiple of the knot multiplicity {m}",
            periodic.len()
        )));
    }
    let j0 = m as isize - 1 - degree as isize;
    let points: Vec<Point3> = (j0..n_total)
        .map(|j| periodic[j.rem_euclid(n_total) as usize])
        .collect();
    let knots = (0..points.len() + degree + 1)
        .map(|i| (i as isize + j0).div_euclid(m as isize) as Real)
        .collect();
    BSplineCurve::new(degree, knots, points)
}

/// Computes the exact fine-tuned curve `Q` of `P` (`points` over `topo`) by `α`.
pub fn exact_finetune(
    topo: &CurveTopology,
    points: &[Point3],
    alpha: &ScalarFunction,
) -> Result<ExactFinetune> {
    let spans = finetuned_spans(topo, points, alpha)?;
    let (d, k) = (topo.degree(), alpha.degree);
    let degree = k + d;
    let multiplicity = degree - k.min(d - 1);
    let curve = spline_from_spans(&spans, multiplicity)?;
    let (gap, periodic_points) = if topo.closed {
        let first = spans[0][0];
        let last = spans[spans.len() - 1][degree];
        let n_total = (spans.len() * multiplicity) as isize;
        let periodic = (0..n_total)
            .map(|j| control_point(&spans, degree, multiplicity, j))
            .collect();
        (last - first, periodic)
    } else {
        (Vector3::zeros(), Vec::new())
    };
    Ok(ExactFinetune {
        degree,
        multiplicity,
        spans,
        curve,
        gap,
        periodic_points,
    })
}
