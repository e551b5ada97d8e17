//! Optimal leg vectors of the edge loops (fine-tuning paper, §4.4: "by using
//! the assigned control values of the edges we can determine optimal lengths
//! and optimal angles of the edge joints in the loop").
//!
//! **Derivation (Doo-Sabin).** Along a loop the converted mesh is the cubic
//! (double-knot) form of a quadratic B-spline curve `P(t)` with legs
//! `Δᵢ = Pᵢ₊₁ − Pᵢ`. `P'` is the linear B-spline whose value at the knot of
//! edge `i` is `Δᵢ`; a linear scalar function `α` with control value `aᵢ` on
//! edge `i` gives `Q' = α P'`, quadratic on the segment around `Pᵢ` with
//! Bernstein coefficients `aᵢ₋₁Δᵢ₋₁, (aᵢ₋₁Δᵢ + aᵢΔᵢ₋₁)/2, aᵢΔᵢ`.
//! Integrating to a cubic Bézier and reading off the double-knot B-spline
//! polygon: the F-leg (interval 0) of edge `i` is `(2/3) aᵢ Δᵢ` and the
//! V-leg (interval 1) at `Pᵢ` is `(aᵢ₋₁Δᵢ + aᵢΔᵢ₋₁)/6`. With `α ≡ 1` these are
//! the converted legs `(2/3)Δᵢ` and `(Δᵢ + Δᵢ₋₁)/6`, so in terms of the
//! current converted legs `Fᵢ`, `V`:
//! target F-leg `aᵢ Fᵢ`, target V-leg `V + ((aᵢ₋₁ − 1) Fᵢ + (aᵢ − 1) Fᵢ₋₁)/4`
//! (exact on regular meshes; on others it keeps `α ≡ 1` an identity).
//!
//! **Catmull-Clark input** (no conversion): every leg is scaled by its
//! edge's value, `aₑ Lₑ` (an approximation: the exact product of a linear
//! `α` and a cubic derivative is quartic and has no Catmull-Clark polygon).

use crate::math::{Point3, Real, Vector3};

use super::EdgeLoop;

/// The role of a leg in the target construction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegKind {
    /// Scaled by its own value: F-legs, and every leg of a Catmull-Clark mesh.
    Scaled,
    /// A V-leg of a converted Doo-Sabin mesh: bent by its neighbours' values.
    Joint,
}

/// Target leg vectors of one loop, in loop order (`legs[k]` from
/// `vertices[k]` to `vertices[k + 1]`). `value[e]` is the control value of
/// edge `e`, `kind[e]` its role.
pub fn loop_targets(lp: &EdgeLoop, x: &[Point3], value: &[Real], kind: &[LegKind]) -> Vec<Vector3> {
    let m = lp.edges.len();
    let nv = lp.vertices.len();
    let leg = |k: usize| x[lp.vertices[(k + 1) % nv] as usize] - x[lp.vertices[k] as usize];
    let neighbour = |k: usize, forward: bool| -> Option<usize> {
        if forward {
            if k + 1 < m {
                Some(k + 1)
            } else if lp.closed {
                Some(0)
            } else {
                None
            }
        } else if k > 0 {
            Some(k - 1)
        } else if lp.closed {
            Some(m - 1)
        } else {
            None
        }
    };
    (0..m)
        .map(|k| {
            let e = lp.edges[k] as usize;
            match kind[e] {
                LegKind::Scaled => leg(k) * value[e],
                LegKind::Joint => {
                    let mut t = leg(k);
                    for fwd in [true, false] {
                        // The next F-leg is weighted by the previous F-leg's value and vice versa.
                        let (Some(near), Some(far)) = (neighbour(k, fwd), neighbour(k, !fwd))
                        else {
                            continue;
                        };
                        if kind[lp.edges[near] as usize] != LegKind::Scaled
                            || kind[lp.edges[far] as usize] != LegKind::Scaled
                        {
                            continue;
                        }
                        let a_far = value[lp.edges[far] as usize];
                        t += leg(near) * ((a_far - 1.0) / 4.0);
                    }
                    t
                }
            }
        })
        .collect()
}
