//! Energy (14) of surface fine tuning as a sum of squares over the free
//! vertices' displacements, minimised by `levenberg_marquardt` (the default;
//! `surface_solve` keeps argmin's nonlinear CG).
//!
//! Residuals: `√k_l (l − l_opt)` per edge spring (`∂/∂x_b = √k_l (x_b − x_a)/l`),
//! `√k (θ − θ_opt)` per joint with the gradients of
//! [`angle_and_gradients`], so that `Σ r² = E` of eq. 14; every joint also
//! gets the two zero-valued curvature rows of `angle_curvature` (the loop
//! joints are straight at rest, where Gauss-Newton alone has no stiffness
//! across the loop's plane). Fixed vertices carry no variables.

use crate::math::{Point3, Real, Vector3};

use super::angle_curvature::transverse_rows;
use super::levenberg_marquardt::{LeastSquares, Residuals};
use super::surface_energy::{SpringEnergy, angle_and_gradients};

/// Energy (14) over the displacements `z` of the free vertices (3 per vertex).
pub struct SurfacePointProblem<'a> {
    energy: &'a SpringEnergy,
    start: &'a [Point3],
    /// First variable of each vertex; `None` for a fixed vertex.
    var_of: Vec<Option<usize>>,
    /// Each joint's distinct free vertices.
    joint_layouts: Vec<JointLayout>,
    /// Jacobi scaling `s_v` per free vertex, for the reported gradient norm.
    scale: &'a [Real],
    free: &'a [usize],
}

impl<'a> SurfacePointProblem<'a> {
    /// The problem moving the vertices `free` of `start`; `scale` (one per
    /// free vertex) scales the gradient whose norm is tested.
    pub fn new(
        energy: &'a SpringEnergy,
        start: &'a [Point3],
        free: &'a [usize],
        scale: &'a [Real],
    ) -> Self {
        let mut var_of = vec![None; start.len()];
        for (k, &v) in free.iter().enumerate() {
            var_of[v] = Some(3 * k);
        }
        let joint_layouts = energy
            .joints
            .iter()
            .map(|j| JointLayout::new(j, &var_of))
            .collect();
        SurfacePointProblem {
            energy,
            start,
            var_of,
            joint_layouts,
            scale,
            free,
        }
    }

    /// All vertex positions at displacements `z`.
    pub fn positions(&self, z: &[Real]) -> Vec<Point3> {
        let mut x = self.start.to_vec();
        for (k, &v) in self.free.iter().enumerate() {
            x[v] += Vector3::new(z[3 * k], z[3 * k + 1], z[3 * k + 2]);
        }
        x
    }

    /// Appends residual `r` with vertex gradients `(vertex, ∂r/∂x)`.
    fn push(&self, out: &mut Residuals, r: Real, grads: &[(u32, Vector3)]) {
        for &(v, g) in grads {
            if let Some(base) = self.var_of[v as usize] {
                push_vertex(out, base, &g);
            }
        }
        out.values.push(r);
        out.start.push(out.vars.len());
    }
}

/// Appends the gradient `g` of a vertex whose first variable is `base`.
fn push_vertex(out: &mut Residuals, base: usize, g: &Vector3) {
    out.vars.extend_from_slice(&[base, base + 1, base + 2]);
    out.grads.extend_from_slice(&[g.x, g.y, g.z]);
}

/// A joint `[j₀, j₁, j₂, j₃]` as its distinct free vertices: a joint names
/// its shared vertex twice (`j₁ = j₂` or `j₀ = j₂`), and its rows name each
/// variable once, with that vertex's two gradients summed.
struct JointLayout {
    /// First variable of each distinct free vertex.
    bases: [usize; 4],
    /// How many of `bases` are used.
    count: usize,
    /// Index into `bases` of each `jᵢ`; `None` for a fixed vertex.
    slot: [Option<usize>; 4],
}

impl JointLayout {
    fn new(joint: &[u32; 4], var_of: &[Option<usize>]) -> Self {
        let mut layout = JointLayout {
            bases: [0; 4],
            count: 0,
            slot: [None; 4],
        };
        for (i, &v) in joint.iter().enumerate() {
            let Some(base) = var_of[v as usize] else {
                continue;
            };
            let found = layout.bases[..layout.count].iter().position(|&b| b == base);
            layout.slot[i] = Some(found.unwrap_or_else(|| {
                layout.bases[layout.count] = base;
                layout.count += 1;
                layout.count - 1
            }));
        }
        layout
    }

    /// Appends residual `r` whose gradients with respect to `x[jᵢ]` are `grads[i]`.
    fn push(&self, out: &mut Residuals, r: Real, grads: [Vector3; 4]) {
        let mut summed = [Vector3::zeros(); 4];
        for (slot, g) in self.slot.iter().zip(&grads) {
            if let Some(s) = slot {
                summed[*s] += g;
            }
        }
        for (base, g) in self.bases.iter().zip(&summed).take(self.count) {
            push_vertex(out, *base, g);
        }
        out.values.push(r);
        out.start.push(out.vars.len());
    }
}

impl LeastSquares for SurfacePointProblem<'_> {
    fn num_vars(&self) -> usize {
        3 * self.free.len()
    }

    fn nodes(&self) -> Vec<usize> {
        (0..3 * self.free.len()).map(|i| i / 3).collect()
    }

    fn energy(&self, z: &[Real]) -> Real {
        self.energy.energy(&self.positions(z))
    }

    fn residuals(&self, z: &[Real], out: &mut Residuals) {
        out.clear();
        let x = self.positions(z);
        let e = self.energy;
        let sl = e.k_l.sqrt();
        let zero = Vector3::zeros();
        for (k, &[a, b]) in e.edges.iter().enumerate() {
            let d = x[b as usize] - x[a as usize];
            let l = d.norm();
            let u = if l > 0.0 { d * (sl / l) } else { zero };
            let r = sl * (l - e.rest_lengths[k]);
            self.push(out, r, &[(b, u), (a, -u)]);
        }
        for (k, j) in e.joints.iter().enumerate() {
            let u = x[j[1] as usize] - x[j[0] as usize];
            let w = x[j[3] as usize] - x[j[2] as usize];
            let (theta, gu, gw) = angle_and_gradients(&u, &w);
            let s = e.joint_weights[k].sqrt();
            let rows = |gu: Vector3, gw: Vector3| [-gu * s, gu * s, -gw * s, gw * s];
            let layout = &self.joint_layouts[k];
            layout.push(out, s * (theta - e.rest_angles[k]), rows(gu, gw));
            for (du, dw) in transverse_rows(&u, &w, theta, e.rest_angles[k]) {
                layout.push(out, 0.0, rows(du, dw));
            }
        }
    }

    fn gradient_norm(&self, _z: &[Real], gradient: &[Real]) -> Real {
        gradient
            .iter()
            .enumerate()
            .map(|(i, g)| (g * self.scale[i / 3]).powi(2))
            .sum::<Real>()
            .sqrt()
    }
}
