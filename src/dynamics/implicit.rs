//! The implicit step of a dynamic surface (Qin, Mandal, Vemuri 1998,
//! eq. 16 and §III-C), assembled in one place for every caller: the
//! interactive [`SurfaceDynamics`](super::SurfaceDynamics) and the levels
//! of the point-cloud fit and of the volume recovery.
//!
//! With `p̈ ≈ (p⁺ − 2p + p⁻)/Δt²` and `ṗ ≈ (p⁺ − p)/Δt`, the paper's
//! `M p̈ + D ṗ + K p = f_p` becomes one linear system per step,
//!
//! `(M/Δt² + D/Δt + K + S) p⁺ = M/Δt² (2p − p⁻) + D/Δt p + f`,
//!
//! `S` the stiffness of the implicit springs (`Σ k JᵀJ`) and `f` every
//! other term of the right-hand side (the springs' `Σ k Jᵀ d`, explicit
//! loads such as inflation). Without a mass it is the first-order (massless)
//! step of `D ṗ + K p = f_p`. The time step is folded into the matrices an
//! [`ImplicitSystem`] holds (`M/Δt²`, `D/Δt`); how the system is solved is
//! the caller's choice (conjugate gradients warm-started from `p`, or a
//! reused Cholesky factor).

use crate::error::Result;
use crate::math::Point3;
use crate::stencil::StencilTable;

/// The matrices of the implicit step with the time step folded in.
#[derive(Clone, Debug)]
pub struct ImplicitSystem {
    /// `M/Δt² + D/Δt + K`: the step's matrix without the springs.
    pub base: StencilTable,
    /// `D/Δt`.
    pub damping: StencilTable,
    /// `M/Δt²` (`None`: the first-order step).
    pub mass: Option<StencilTable>,
}

impl ImplicitSystem {
    /// The step's matrix `base + S` and right-hand side
    /// `D/Δt p + Σ terms + M/Δt² (2p − p⁻)` at positions `p` (`p_before`
    /// one step before) for springs of stiffness `springs` and the
    /// right-hand-side `terms` (one vector per control point each). A
    /// spring matrix in `base`'s pattern (as a
    /// [`PatchAssembly`](crate::forces::PatchAssembly) makes both) is added
    /// entry by entry in its own storage; another pattern is merged.
    pub fn system(
        &self,
        springs: Option<StencilTable>,
        terms: &[&[Point3]],
        p: &[Point3],
        p_before: &[Point3],
    ) -> Result<(StencilTable, Vec<Point3>)> {
        let base = &self.base;
        let a = match springs {
            Some(mut s)
                if s.num_cols == base.num_cols
                    && s.offsets == base.offsets
                    && s.indices == base.indices =>
            {
                for (x, y) in s.weights.iter_mut().zip(&base.weights) {
                    *x += y;
                }
                s
            }
            Some(s) => base.linear_combination(1.0, &s, 1.0)?,
            None => base.clone(),
        };
        let mut rhs = self.damping.apply(p)?;
        for term in terms {
            for (r, f) in rhs.iter_mut().zip(*term) {
                r.coords += f.coords;
            }
        }
        if let Some(m) = &self.mass {
            let inertia: Vec<Point3> = p
                .iter()
                .zip(p_before)
                .map(|(a, b)| Point3::from(2.0 * a.coords - b.coords))
                .collect();
            for (r, x) in rhs.iter_mut().zip(m.apply(&inertia)?) {
                r.coords += x.coords;
            }
        }
        Ok((a, rhs))
    }
}
