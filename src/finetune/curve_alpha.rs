//! The scalar function `α(t)` of curve fine tuning and how control values on
//! the edges or vertices of the control polygon become its B-spline
//! coefficients (fine-tuning paper, §4.3 and footnote 4, curve case).
//!
//! `α` is a uniform B-spline of degree `k ∈ {1, 2, 3}` on the **same integer
//! knots** as the curve (the paper's requirement that the segmentation of `α`
//! equals the curve's). With the span convention of
//! [`CurveTopology`](crate::subdivision::CurveTopology) span `i` of `α` uses
//! coefficients `a_i … a_{i+k}`, whose Greville abscissae are `j − (k − 1)/2`.
//! A curve of degree `d` has vertex `P_v` at `v − (d − 1)/2` and the midpoint
//! of edge `P_e P_{e+1}` at `e − d/2 + 1`. Each coefficient takes the control
//! value of the polygon element sitting at the same abscissa:
//!
//! | curve `d` | `α` degree `k` | values on | coefficient `a_j` |
//! |---|---|---|---|
//! | 2 (quadratic) | 1 | edges    | edge `j` |
//! | 2 | 2 | vertices | vertex `j` |
//! | 2 | 3 | edges    | edge `j − 1` |
//! | 3 (cubic) | 1 | vertices | vertex `j + 1` |
//! | 3 | 2 | edges    | edge `j` |
//! | 3 | 3 | vertices | vertex `j` |
//!
//! (For the quadratic curve this is the paper's footnote 4: linear and cubic
//! `α` on edges, quadratic on vertices.) Closed curves wrap the indices.
//! An open curve has `n − d` spans and needs `n − d + k` coefficients; element
//! indices beyond the polygon's ends take the nearest end value (only the
//! case `d = 2, k = 3`), and elements no coefficient refers to are ignored
//! (only the end vertices when `d = 3, k = 1`). A constant value list gives a
//! constant `α` in every case.

use crate::error::{Error, Result};
use crate::math::Real;
use crate::subdivision::{CurveTopology, bspline_to_bezier, span_basis};

/// Where the control values of `α` live on the control polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValuesOn {
    /// One value per leg `P_e P_{e+1}`.
    Edges,
    /// One value per control point.
    Vertices,
}

/// `α` as a uniform B-spline: degree `k` and coefficients `a_j` (span `i`
/// uses `a_i … a_{i+k}`; closed curves wrap).
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarFunction {
    /// Degree `k` (1, 2 or 3).
    pub degree: usize,
    /// B-spline coefficients: `n` when closed, `n − d + k` when open.
    pub coefficients: Vec<Real>,
    /// Closed (periodic) like its curve.
    pub closed: bool,
}

/// Largest accepted magnitude of a control value.
const MAX_VALUE: Real = 1e6;

/// Where control values go for a curve of degree `curve_degree` and `α` of
/// degree `alpha_degree`, and the offset `s` in `a_j = value[j + s]`.
pub fn values_on(curve_degree: usize, alpha_degree: usize) -> (ValuesOn, isize) {
    let diff = curve_degree as isize - alpha_degree as isize;
    if diff.rem_euclid(2) == 0 {
        (ValuesOn::Vertices, diff / 2)
    } else {
        (ValuesOn::Edges, (diff - 1).div_euclid(2))
    }
}

/// Builds `α` of degree `alpha_degree` from one control value per edge or
/// vertex (see the module table for which and how). Values must be finite,
/// positive and at most `1e6`.
pub fn alpha_from_values(
    topo: &CurveTopology,
    alpha_degree: usize,
    values: &[Real],
) -> Result<ScalarFunction> {
    if !(1..=3).contains(&alpha_degree) {
        return Err(Error::input(format!(
            "the degree of α must be 1, 2 or 3, got {alpha_degree}"
        )));
    }
    let (on, offset) = values_on(topo.degree(), alpha_degree);
    let count = match on {
        ValuesOn::Edges => topo.num_legs(),
        ValuesOn::Vertices => topo.num_points,
    };
    if values.len() != count {
        return Err(Error::input(format!(
            "α of degree {alpha_degree} on a degree-{} curve takes one value per {}: expected {count}, got {}",
            topo.degree(),
            if on == ValuesOn::Edges {
                "edge"
            } else {
                "vertex"
            },
            values.len()
        )));
    }
    if let Some((i, v)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0 && **v <= MAX_VALUE))
    {
        return Err(Error::input(format!(
            "control value {i} is {v}; values must be positive, finite and at most {MAX_VALUE}"
        )));
    }
    let num = if topo.closed {
        topo.num_points
    } else {
        topo.num_spans() + alpha_degree
    };
    let coefficients = (0..num as isize)
        .map(|j| {
            let e = j + offset;
            let e = if topo.closed {
                e.rem_euclid(count as isize)
            } else {
                e.clamp(0, count as isize - 1)
            };
            values[e as usize]
        })
        .collect();
    Ok(ScalarFunction {
        degree: alpha_degree,
        coefficients,
        closed: topo.closed,
    })
}

impl ScalarFunction {
    /// The constant function `c` of degree `degree` on the curve's knots.
    pub fn constant(topo: &CurveTopology, degree: usize, c: Real) -> Result<ScalarFunction> {
        let (on, _) = values_on(topo.degree(), degree);
        let count = match on {
            ValuesOn::Edges => topo.num_legs(),
            ValuesOn::Vertices => topo.num_points,
        };
        alpha_from_values(topo, degree, &vec![c; count])
    }

    /// Coefficient `a_{span + k}` (wrapped when closed).
    fn coefficient(&self, span: usize, k: usize) -> Real {
        self.coefficients[(span + k) % self.coefficients.len()]
    }

    /// Bernstein coefficients of `α` on span `span` (degree `k`, local `u ∈ [0, 1]`).
    pub fn span_bernstein(&self, span: usize) -> Vec<Real> {
        let m = bspline_to_bezier(self.degree);
        (0..=self.degree)
            .map(|l| {
                (0..=self.degree)
                    .map(|j| m[l][j] * self.coefficient(span, j))
                    .sum()
            })
            .collect()
    }

    /// `α(t)` on `topo`'s parameter domain.
    pub fn value(&self, topo: &CurveTopology, t: Real) -> Result<Real> {
        let (span, u) = topo.locate(t)?;
        let w = span_basis(self.degree, u, 0);
        Ok((0..=self.degree)
            .map(|j| w[j] * self.coefficient(span, j))
            .sum())
    }
}
