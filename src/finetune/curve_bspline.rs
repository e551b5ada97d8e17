//! `BSplineCurve`: an ordinary (non-periodic) B-spline curve with an explicit
//! knot vector, evaluated by de Boor's algorithm. Fine-tuned curves are
//! returned in this form; a closed curve repeats its first `degree − m + 1`…
//! wrapped control points at the end so that the same evaluator traces it.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

/// A B-spline curve of degree `D` with control points `c_0 … c_{N−1}` and
/// knots `u_0 ≤ … ≤ u_{N+D}`; it is defined on `[u_D, u_N]`.
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineCurve {
    /// Degree `D`.
    pub degree: usize,
    /// `N + D + 1` non-decreasing knots.
    pub knots: Vec<Real>,
    /// `N` control points.
    pub control_points: Vec<Point3>,
}

impl BSplineCurve {
    /// Checks the sizes, that the knots are finite and non-decreasing and
    /// that no interior knot has multiplicity above `D`.
    pub fn new(degree: usize, knots: Vec<Real>, control_points: Vec<Point3>) -> Result<Self> {
        let n = control_points.len();
        if n < degree + 1 || knots.len() != n + degree + 1 {
            return Err(Error::input(format!(
                "a degree-{degree} B-spline with {n} control points needs {} knots, got {}",
                n + degree + 1,
                knots.len()
            )));
        }
        if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return Err(Error::input("knots must be finite and non-decreasing"));
        }
        if (1..n).any(|i| knots[i + degree] <= knots[i]) {
            return Err(Error::input(format!(
                "an interior knot has multiplicity above the degree {degree}"
            )));
        }
        Ok(BSplineCurve {
            degree,
            knots,
            control_points,
        })
    }

    /// The parameter domain `[u_D, u_N]`.
    pub fn domain(&self) -> (Real, Real) {
        (
            self.knots[self.degree],
            self.knots[self.control_points.len()],
        )
    }

    /// Index `l` of the knot span `[u_l, u_{l+1})` holding `t` (clamped to the domain).
    fn span_of(&self, t: Real) -> usize {
        let (d, n) = (self.degree, self.control_points.len());
        let mut l = d;
        while l + 1 < n && self.knots[l + 1] <= t {
            l += 1;
        }
        l
    }

    /// The point at `t` (de Boor's algorithm); `t` is clamped to the domain.
    pub fn point(&self, t: Real) -> Point3 {
        let (lo, hi) = self.domain();
        let t = t.clamp(lo, hi);
        let d = self.degree;
        let l = self.span_of(t);
        let mut c: Vec<Vector3> = (0..=d)
            .map(|j| self.control_points[l - d + j].coords)
            .collect();
        for r in 1..=d {
            for j in (r..=d).rev() {
                let i = l - d + j;
                let (a, b) = (self.knots[i], self.knots[i + d + 1 - r]);
                let w = if b > a { (t - a) / (b - a) } else { 0.0 };
                c[j] = (1.0 - w) * c[j - 1] + w * c[j];
            }
        }
        Point3::from(c[d])
    }

    /// The derivative curve (degree `D − 1`, control points
    /// `D (c_{i+1} − c_i) / (u_{i+D+1} − u_{i+1})`, knots without the ends).
    pub fn derivative_curve(&self) -> Result<BSplineCurve> {
        let d = self.degree;
        if d == 0 {
            return Err(Error::input("a degree-0 curve has no derivative curve"));
        }
        let points = self
            .control_points
            .windows(2)
            .enumerate()
            .map(|(i, w)| {
                let h = self.knots[i + d + 1] - self.knots[i + 1];
                Point3::from((d as Real / h) * (w[1] - w[0]))
            })
            .collect();
        BSplineCurve::new(d - 1, self.knots[1..self.knots.len() - 1].to_vec(), points)
    }

    /// The first derivative at `t`.
    pub fn tangent(&self, t: Real) -> Result<Vector3> {
        Ok(self.derivative_curve()?.point(t).coords)
    }

    /// `count + 1` points at equally spaced parameters over the domain.
    pub fn samples(&self, count: usize) -> Vec<Point3> {
        let (lo, hi) = self.domain();
        let count = count.max(1);
        (0..=count)
            .map(|i| self.point(lo + (hi - lo) * i as Real / count as Real))
            .collect()
    }
}
