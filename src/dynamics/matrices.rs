//! Mass, damping and stiffness matrices over the control points.
//!
//! Qin, Mandal, Vemuri 1998, §4 (the finite-element formulation of the
//! dynamic Catmull-Clark surface `x(u, v) = J p`):
//!
//! - mass `M = ∫∫ μ JᵀJ dA` and damping `D = ∫∫ γ JᵀJ dA` (eqs. 10–11);
//! - thin plate under tension
//!   `K = ∫∫ α11 J_uᵀJ_u + α22 J_vᵀJ_v + β11 J_uuᵀJ_uu + β12 J_uvᵀJ_uv + β22 J_vvᵀJ_vv du dv` (eq. 12).
//!
//! `M` and `D` are integrated either over the parameter domain (`dA = du dv`,
//! as in the paper; the integrand is a polynomial and the quadrature exact) or
//! with the surface's area element `dA = |x_u × x_v| du dv` at given positions
//! (physical mass: `Σ M_ij = μ · area`). `K` is always over the base faces'
//! parameter domain, as in the paper. Every matrix is assembled over the
//! level-`L` vertices as a Gram matrix `BᵀB` of square-root-weighted
//! Jacobian rows and carried to the control points through `P_L = S P_0`:
//! `M_0 = Sᵀ M_L S` (the paper's `AᵀMA` when subdividing).

use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;

use super::Quadrature;

/// Physical parameters of the surface (constant over it). Defaults: `μ = 1`,
/// `γ = 1`, `α11 = α22 = 0.01`, `β11 = β22 = 0.001`, `β12 = 0.002`
/// (a thin plate with a little tension, on a model of unit size).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialParams {
    /// Mass density `μ`.
    pub mu: Real,
    /// Damping density `γ`.
    pub gamma: Real,
    /// Tension along `u`, `α11`.
    pub alpha11: Real,
    /// Tension along `v`, `α22`.
    pub alpha22: Real,
    /// Bending `β11` (`x_uu`).
    pub beta11: Real,
    /// Twist `β12` (`x_uv`).
    pub beta12: Real,
    /// Bending `β22` (`x_vv`).
    pub beta22: Real,
}

impl MaterialParams {
    /// The fitting drivers' thin plate under tension, with weights relative
    /// to data terms that sum to 1 over the surface: `α11 = α22 = λ_t / A`,
    /// `β11 = β22 = λ_b / A`, `β12 = 2 λ_b / A` (`A` the parameter area).
    pub fn thin_plate(tension: Real, bending: Real, area: Real) -> MaterialParams {
        MaterialParams {
            alpha11: tension / area,
            alpha22: tension / area,
            beta11: bending / area,
            beta12: 2.0 * bending / area,
            beta22: bending / area,
            ..Default::default()
        }
    }
}

impl Default for MaterialParams {
    fn default() -> Self {
        MaterialParams {
            mu: 1.0,
            gamma: 1.0,
            alpha11: 0.01,
            alpha22: 0.01,
            beta11: 0.001,
            beta12: 0.002,
            beta22: 0.001,
        }
    }
}

impl MaterialParams {
    pub(super) fn check(&self) -> Result<()> {
        let all = [
            ("mu", self.mu),
            ("gamma", self.gamma),
            ("alpha11", self.alpha11),
            ("alpha22", self.alpha22),
            ("beta11", self.beta11),
            ("beta12", self.beta12),
            ("beta22", self.beta22),
        ];
        match all.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            Some((name, v)) => Err(Error::input(format!(
                "material parameter {name} = {v}: must be finite and ≥ 0"
            ))),
            None => Ok(()),
        }
    }
}

/// `M = ∫∫ μ JᵀJ dA` over the control points. With `level_positions` (the
/// level-`L` points `P_L = S P_0`) `dA` is the surface's area element there;
/// without, `dA = du dv`.
pub fn mass_matrix(
    q: &Quadrature,
    s: &StencilTable,
    level_positions: Option<&[Point3]>,
    mu: Real,
) -> Result<StencilTable> {
    MaterialParams {
        mu,
        ..Default::default()
    }
    .check()?;
    area_weighted_gram(q, s, level_positions, mu)
}

/// `D = ∫∫ γ JᵀJ dA` (the mass matrix with density `γ`; `dA` as for
/// [`mass_matrix`]).
pub fn damping_matrix(
    q: &Quadrature,
    s: &StencilTable,
    level_positions: Option<&[Point3]>,
    gamma: Real,
) -> Result<StencilTable> {
    MaterialParams {
        gamma,
        ..Default::default()
    }
    .check()?;
    area_weighted_gram(q, s, level_positions, gamma)
}

/// `K` (thin plate under tension, module docs) over the control points.
pub fn stiffness_matrix(
    q: &Quadrature,
    s: &StencilTable,
    params: &MaterialParams,
) -> Result<StencilTable> {
    params.check()?;
    let r = &q.rows;
    let terms = [
        (&r.du, params.alpha11),
        (&r.dv, params.alpha22),
        (&r.duu, params.beta11),
        (&r.duv, params.beta12),
        (&r.dvv, params.beta22),
    ];
    let mut scaled = Vec::new();
    for (rows, c) in terms {
        if c > 0.0 {
            let w: Vec<Real> = q.weights.iter().map(|w| (c * w).sqrt()).collect();
            scaled.push(rows.scale_rows(&w)?);
        }
    }
    let refs: Vec<&StencilTable> = scaled.iter().collect();
    if refs.is_empty() {
        return Ok(StencilTable::zeros(s.num_cols, s.num_cols));
    }
    let b = StencilTable::stack(&refs)?;
    carried_gram(&b, s)
}

fn area_weighted_gram(
    q: &Quadrature,
    s: &StencilTable,
    level_positions: Option<&[Point3]>,
    density: Real,
) -> Result<StencilTable> {
    let w: Vec<Real> = match level_positions {
        None => q.weights.iter().map(|w| (density * w).sqrt()).collect(),
        Some(x) => {
            if x.len() != s.num_rows() {
                return Err(Error::size_mismatch(format!(
                    "{} level positions for a refinement of {} points",
                    x.len(),
                    s.num_rows()
                )));
            }
            let du = q.rows.du.apply(x)?;
            let dv = q.rows.dv.apply(x)?;
            q.weights
                .iter()
                .zip(du.iter().zip(&dv))
                .map(|(w, (a, b))| (density * w * a.coords.cross(&b.coords).norm()).sqrt())
                .collect()
        }
    };
    carried_gram(&q.rows.p.scale_rows(&w)?, s)
}

/// `(B S)ᵀ (B S) = Sᵀ (BᵀB) S`, formed in that order: the Gram matrix of the
/// sample rows over the level-`L` vertices first (short rows), then carried
/// to the control points — many times cheaper than the Gram matrix of the
/// composed rows, which are two to three times longer.
fn carried_gram(b: &StencilTable, s: &StencilTable) -> Result<StencilTable> {
    b.gram().pulled_back(s)
}
