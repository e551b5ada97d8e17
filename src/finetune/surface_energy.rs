//! The spring energy (14) of the fine-tuning paper (§4.4):
//!
//! `E = k_l Σᵢ (lᵢᵒᵖᵗ − lᵢ)² + k_a Σᵢ (θᵢᵃ'ᵒᵖᵗ − θᵢᵃ)² + k_b Σᵢ (θᵢᵇ'ᵒᵖᵗ − θᵢᵇ)²`
//!
//! over edge lengths `lᵢ` and joint angles `θᵢ`, with its exact gradient.
//! Every joint is the angle between two vectors `u = x[j₁] − x[j₀]` and
//! `w = x[j₃] − x[j₂]`: for a loop joint `(prev, v, v, next)` (the angle
//! between consecutive legs, 0 when straight), for a shape joint
//! `(v, a, v, b)` (the angle between two edges leaving `v`).
//!
//! `θ = atan2(|u × w|, u · w)`, so with `c = u × w`, `s = |c|`, `d = u · w`:
//! `∂θ/∂u = (d (w × ĉ) − s w) / (s² + d²)` and
//! `∂θ/∂w = (d (ĉ × u) − s u) / (s² + d²)`; at `s = 0` the `ĉ` terms are
//! dropped (a subgradient: the angle is not differentiable at 0 or π).

use rayon::prelude::*;

use crate::math::{Point3, Real, Vector3};

/// Springs and joints with their rest values and weights.
#[derive(Clone, Debug, Default)]
pub struct SpringEnergy {
    /// Edge springs: end vertices.
    pub edges: Vec<[u32; 2]>,
    /// Rest length `lᵒᵖᵗ` of each edge spring.
    pub rest_lengths: Vec<Real>,
    /// Weight of the length term (`k_l`).
    pub k_l: Real,
    /// Joints `[j₀, j₁, j₂, j₃]`: the angle between `x[j₁] − x[j₀]` and `x[j₃] − x[j₂]`.
    pub joints: Vec<[u32; 4]>,
    /// Rest angle `θᵒᵖᵗ` of each joint (radians).
    pub rest_angles: Vec<Real>,
    /// Weight of each joint (`k_a` for loop joints, `k_b` for shape joints).
    pub joint_weights: Vec<Real>,
}

/// The angle between `u` and `w` and its gradients with respect to both.
pub fn angle_and_gradients(u: &Vector3, w: &Vector3) -> (Real, Vector3, Vector3) {
    let c = u.cross(w);
    let s = c.norm();
    let d = u.dot(w);
    let den = s * s + d * d;
    if den == 0.0 {
        return (0.0, Vector3::zeros(), Vector3::zeros());
    }
    let theta = s.atan2(d);
    let (ds_du, ds_dw) = if s > 0.0 {
        let ch = c / s;
        (w.cross(&ch), ch.cross(u))
    } else {
        (Vector3::zeros(), Vector3::zeros())
    };
    let gu = (ds_du * d - w * s) / den;
    let gw = (ds_dw * d - u * s) / den;
    (theta, gu, gw)
}

/// The current angle of every joint.
pub fn joint_angles(joints: &[[u32; 4]], x: &[Point3]) -> Vec<Real> {
    joints
        .iter()
        .map(|j| {
            let u = x[j[1] as usize] - x[j[0] as usize];
            let w = x[j[3] as usize] - x[j[2] as usize];
            angle_and_gradients(&u, &w).0
        })
        .collect()
}

/// Rows per parallel task.
const CHUNK: usize = 2048;

impl SpringEnergy {
    /// The energy at positions `x`.
    pub fn energy(&self, x: &[Point3]) -> Real {
        self.energy_and_gradient(x, false).0
    }

    /// The energy and its gradient (one vector per vertex of `x`); the
    /// gradient is empty when `want_gradient` is false.
    pub fn energy_and_gradient(&self, x: &[Point3], want_gradient: bool) -> (Real, Vec<Vector3>) {
        let n = x.len();
        let mut grad = if want_gradient {
            vec![Vector3::zeros(); n]
        } else {
            Vec::new()
        };
        let mut e = 0.0;
        for (k, &[a, b]) in self.edges.iter().enumerate() {
            let d = x[b as usize] - x[a as usize];
            let l = d.norm();
            let r = l - self.rest_lengths[k];
            e += self.k_l * r * r;
            if want_gradient && l > 0.0 {
                let g = d * (2.0 * self.k_l * r / l);
                grad[b as usize] += g;
                grad[a as usize] -= g;
            }
        }
        // Joints in parallel chunks: (energy, sparse contributions).
        let parts: Vec<(Real, Vec<(u32, Vector3)>)> = self
            .joints
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(ci, chunk)| {
                let mut e = 0.0;
                let mut g = Vec::with_capacity(if want_gradient { 4 * chunk.len() } else { 0 });
                for (i, j) in chunk.iter().enumerate() {
                    let k = ci * CHUNK + i;
                    let u = x[j[1] as usize] - x[j[0] as usize];
                    let w = x[j[3] as usize] - x[j[2] as usize];
                    let (theta, gu, gw) = angle_and_gradients(&u, &w);
                    let r = theta - self.rest_angles[k];
                    let kw = self.joint_weights[k];
                    e += kw * r * r;
                    if want_gradient {
                        let s = 2.0 * kw * r;
                        g.push((j[1], gu * s));
                        g.push((j[0], -gu * s));
                        g.push((j[3], gw * s));
                        g.push((j[2], -gw * s));
                    }
                }
                (e, g)
            })
            .collect();
        for (pe, pg) in parts {
            e += pe;
            for (v, g) in pg {
                grad[v as usize] += g;
            }
        }
        (e, grad)
    }
}
