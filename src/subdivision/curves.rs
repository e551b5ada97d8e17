//! Uniform B-spline subdivision curves: quadratic (Chaikin, the curve case of
//! Doo-Sabin) and cubic (the curve case of Catmull-Clark), open and closed.
//! Every refinement step is a [`StencilTable`] `P_{k+1} = S P_k`; limit points
//! and derivatives are rows of the uniform B-spline basis.
//!
//! **Parameterisation.** A curve of degree `d` over control points
//! `P_0 … P_{n-1}` has integer knots; span `i` covers `t ∈ [i, i+1]` and uses
//! `P_i … P_{i+d}` (indices mod `n` when closed). A closed curve has `n`
//! spans, `t ∈ [0, n)`; an open one is the *unclamped* uniform B-spline on its
//! `n − d` interior spans, `t ∈ [0, n − d]` (it starts near, not at, `P_0`).
//! The basis function of `P_j` is supported on `[j − d, j + 1]`; its Greville
//! abscissa (centre) is `j − (d − 1)/2`.
//!
//! **Refinement.** With this convention one step maps `t ↦ 2t`:
//! - quadratic (Chaikin): `Q_{2i} = ¾P_i + ¼P_{i+1}`, `Q_{2i+1} = ¼P_i + ¾P_{i+1}`;
//! - cubic: `Q_{2i} = ½(P_i + P_{i+1})`, `Q_{2i+1} = ⅛(P_i + 6P_{i+1} + P_{i+2})`.
//!
//! An open curve keeps only the rows whose stencils exist (`2n − 2` points for
//! quadratic, `2n − 3` for cubic), which is again the same unclamped B-spline.

use crate::error::{Error, Result};
use crate::math::Real;
use crate::stencil::StencilTable;

/// The two uniform B-spline curve schemes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveScheme {
    /// Degree 2 (Chaikin corner cutting; the curve case of Doo-Sabin).
    Quadratic,
    /// Degree 3 (the curve case of Catmull-Clark).
    Cubic,
}

impl CurveScheme {
    /// Polynomial degree `d` of the limit curve (2 or 3).
    pub fn degree(self) -> usize {
        match self {
            CurveScheme::Quadratic => 2,
            CurveScheme::Cubic => 3,
        }
    }
}

/// The connectivity of a subdivision curve (no positions): scheme, number of
/// control points and whether the polygon is closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CurveTopology {
    /// The subdivision scheme.
    pub scheme: CurveScheme,
    /// Number of control points `n`.
    pub num_points: usize,
    /// Closed (periodic) polygon.
    pub closed: bool,
}

/// Largest number of control points accepted (indices are `u32`).
const MAX_POINTS: usize = 1 << 28;

impl CurveTopology {
    /// Checks the counts: an open curve needs at least `d + 1` points, a
    /// closed one at least 3.
    pub fn new(scheme: CurveScheme, num_points: usize, closed: bool) -> Result<Self> {
        let need = if closed { 3 } else { scheme.degree() + 1 };
        if num_points < need || num_points > MAX_POINTS {
            return Err(Error::input(format!(
                "{} {} curve needs {need} to {MAX_POINTS} control points, got {num_points}",
                if closed { "a closed" } else { "an open" },
                format!("{scheme:?}").to_lowercase()
            )));
        }
        Ok(CurveTopology {
            scheme,
            num_points,
            closed,
        })
    }

    /// Degree `d` of the limit curve.
    pub fn degree(&self) -> usize {
        self.scheme.degree()
    }

    /// Number of polynomial spans: `n` when closed, `n − d` when open.
    pub fn num_spans(&self) -> usize {
        if self.closed {
            self.num_points
        } else {
            self.num_points - self.degree()
        }
    }

    /// Number of legs (edges) of the control polygon: `n` closed, `n − 1` open.
    pub fn num_legs(&self) -> usize {
        if self.closed {
            self.num_points
        } else {
            self.num_points - 1
        }
    }

    /// Control point `i + k` of span `i` (wrapped when closed).
    pub fn span_point(&self, span: usize, k: usize) -> usize {
        (span + k) % self.num_points
    }

    /// The topology after one refinement step.
    pub fn refined(&self) -> Result<CurveTopology> {
        let n = self.num_points;
        let m = match (self.closed, self.scheme) {
            (true, _) => 2 * n,
            (false, CurveScheme::Quadratic) => 2 * n - 2,
            (false, CurveScheme::Cubic) => 2 * n - 3,
        };
        CurveTopology::new(self.scheme, m, self.closed)
    }

    /// The refinement stencil `S` (`refined().num_points × n`), `P_{k+1} = S P_k`.
    pub fn refine_stencil(&self) -> Result<StencilTable> {
        let child = self.refined()?;
        let n = self.num_points;
        let mut table = StencilTable::with_capacity(n, child.num_points, 3 * child.num_points);
        let at = |i: usize| (i % n) as u32;
        for r in 0..child.num_points {
            let i = r / 2;
            match (self.scheme, r % 2) {
                (CurveScheme::Quadratic, 0) => table.push_row([(at(i), 0.75), (at(i + 1), 0.25)]),
                (CurveScheme::Quadratic, _) => table.push_row([(at(i), 0.25), (at(i + 1), 0.75)]),
                (CurveScheme::Cubic, 0) => table.push_row([(at(i), 0.5), (at(i + 1), 0.5)]),
                (CurveScheme::Cubic, _) => {
                    table.push_row([(at(i), 0.125), (at(i + 1), 0.75), (at(i + 2), 0.125)])
                }
            }
        }
        Ok(table)
    }

    /// The composed stencil of `levels` refinement steps and the topology it yields.
    pub fn refine_levels(&self, levels: usize) -> Result<(CurveTopology, StencilTable)> {
        let mut topo = *self;
        let mut s = StencilTable::identity(self.num_points);
        for _ in 0..levels {
            s = topo.refine_stencil()?.compose(&s)?;
            topo = topo.refined()?;
        }
        Ok((topo, s))
    }

    /// Span index and local parameter `u ∈ [0, 1]` of `t`. Closed curves wrap
    /// `t` into `[0, n)`; open curves reject `t` outside `[0, n − d]`.
    pub fn locate(&self, t: Real) -> Result<(usize, Real)> {
        let spans = self.num_spans() as Real;
        if !t.is_finite() || (!self.closed && !(0.0..=spans).contains(&t)) {
            return Err(Error::input(format!(
                "curve parameter {t} is outside [0, {spans}]"
            )));
        }
        let t = if self.closed { t.rem_euclid(spans) } else { t };
        let span = (t.floor() as usize).min(self.num_spans() - 1);
        Ok((span, t - span as Real))
    }

    /// Limit stencil: one row per parameter `t`, giving the curve point
    /// (`derivative = 0`) or its `derivative`-th derivative with respect to `t`
    /// as a combination of control points (exact uniform B-spline evaluation).
    pub fn limit_stencil(&self, params: &[Real], derivative: usize) -> Result<StencilTable> {
        let d = self.degree();
        let mut table =
            StencilTable::with_capacity(self.num_points, params.len(), (d + 1) * params.len());
        for &t in params {
            let (span, u) = self.locate(t)?;
            let w = span_basis(d, u, derivative);
            table.push_row((0..=d).map(|k| (self.span_point(span, k) as u32, w[k])));
        }
        Ok(table)
    }
}

/// The uniform B-spline → Bézier matrix of one span, `M[l][j]`: Bézier point
/// `b_l = Σ_j M[l][j] P_{i+j}` for degrees 0 to 3 (from the blossom
/// `b_l = P[i, …, i (d−l times), i+1, … (l times)]`).
pub fn bspline_to_bezier(degree: usize) -> &'static [[Real; 4]] {
    const D0: [[Real; 4]; 1] = [[1.0, 0.0, 0.0, 0.0]];
    const D1: [[Real; 4]; 2] = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]];
    const D2: [[Real; 4]; 3] = [
        [0.5, 0.5, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.5, 0.5, 0.0],
    ];
    const D3: [[Real; 4]; 4] = [
        [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
        [0.0, 2.0 / 3.0, 1.0 / 3.0, 0.0],
        [0.0, 1.0 / 3.0, 2.0 / 3.0, 0.0],
        [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
    ];
    match degree {
        0 => &D0,
        1 => &D1,
        2 => &D2,
        _ => &D3,
    }
}

/// Bernstein polynomials `B_l^degree(u)`, `l = 0..=degree`.
pub fn bernstein(degree: usize, u: Real) -> Vec<Real> {
    let mut b = vec![0.0; degree + 1];
    b[0] = 1.0;
    for r in 1..=degree {
        for l in (0..=r).rev() {
            let left = if l > 0 { b[l - 1] } else { 0.0 };
            b[l] = (1.0 - u) * b[l] + u * left;
        }
    }
    b
}

/// Weights of the `d + 1` control points of a span at local `u` for the
/// `derivative`-th derivative (0 = position) of the uniform B-spline.
pub fn span_basis(d: usize, u: Real, derivative: usize) -> Vec<Real> {
    if derivative > d {
        return vec![0.0; d + 1];
    }
    let m = bspline_to_bezier(d);
    // Bézier coefficient weights of the derivative: differences of rows, scaled.
    let mut rows: Vec<[Real; 4]> = m.to_vec();
    let mut scale = 1.0;
    for r in 0..derivative {
        let deg = d - r;
        scale *= deg as Real;
        rows = (0..deg)
            .map(|l| std::array::from_fn(|j| rows[l + 1][j] - rows[l][j]))
            .collect();
    }
    let b = bernstein(d - derivative, u);
    (0..=d)
        .map(|j| {
            scale
                * rows
                    .iter()
                    .zip(&b)
                    .map(|(row, bl)| row[j] * bl)
                    .sum::<Real>()
        })
        .collect()
}
