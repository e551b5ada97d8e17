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

use rayon::prelude::*;

use crate::linalg::{LeastSquares, Residuals};
use crate::math::{Point3, Real, Vector3};

use super::angle_curvature::transverse_rows;
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

    /// Lays out the rows of [`residuals`](LeastSquares::residuals): one per
    /// edge spring, three per joint (angle and two curvature rows), each
    /// naming its free vertices' variables; values and gradients zero.
    fn lay_out(&self, out: &mut Residuals) {
        out.clear();
        let mut row = |bases: &mut dyn Iterator<Item = usize>| {
            for base in bases {
                out.vars.extend_from_slice(&[base, base + 1, base + 2]);
            }
            out.start.push(out.vars.len());
        };
        for &[a, b] in &self.energy.edges {
            row(&mut [b, a].iter().filter_map(|&v| self.var_of[v as usize]));
        }
        for layout in &self.joint_layouts {
            for _ in 0..3 {
                row(&mut layout.bases[..layout.count].iter().copied());
            }
        }
        out.grads.resize(out.vars.len(), 0.0);
        out.values.resize(out.start.len() - 1, 0.0);
    }
}

/// Joints per parallel task of [`SurfacePointProblem::residuals`].
const JOINT_CHUNK: usize = 1024;

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

    /// Writes the gradients `grads[i]` (with respect to `x[jᵢ]`) of one row
    /// into `out` (3 per distinct free vertex, in the order of `bases`).
    fn write(&self, grads: [Vector3; 4], out: &mut [Real]) {
        let mut summed = [Vector3::zeros(); 4];
        for (slot, g) in self.slot.iter().zip(&grads) {
            if let Some(s) = slot {
                summed[*s] += g;
            }
        }
        for (o, g) in out.chunks_exact_mut(3).zip(&summed) {
            o.copy_from_slice(g.as_slice());
        }
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

    /// The rows are laid out once ([`lay_out`](SurfacePointProblem::lay_out));
    /// later calls on the same `out` rewrite values and gradients in place,
    /// the joints in parallel chunks.
    fn residuals(&self, z: &[Real], out: &mut Residuals) {
        let e = self.energy;
        let (ne, nj) = (e.edges.len(), e.joints.len());
        if out.start.len() != ne + 3 * nj + 1 {
            self.lay_out(out);
        }
        let x = self.positions(z);
        let Residuals {
            values,
            start,
            grads,
            ..
        } = out;
        let (edge_values, mut joint_values) = values.split_at_mut(ne);
        let (edge_grads, mut joint_grads) = grads.split_at_mut(start[ne]);
        let sl = e.k_l.sqrt();
        for (k, &[a, b]) in e.edges.iter().enumerate() {
            let d = x[b as usize] - x[a as usize];
            let l = d.norm();
            let u = if l > 0.0 {
                d * (sl / l)
            } else {
                Vector3::zeros()
            };
            edge_values[k] = sl * (l - e.rest_lengths[k]);
            let free = [(b, u), (a, -u)]
                .into_iter()
                .filter(|&(v, _)| self.var_of[v as usize].is_some());
            for (o, (_, g)) in edge_grads[start[k]..start[k + 1]]
                .chunks_exact_mut(3)
                .zip(free)
            {
                o.copy_from_slice(g.as_slice());
            }
        }
        // Joint chunks with their rows' values and gradients.
        let mut chunks = Vec::new();
        for first in (0..nj).step_by(JOINT_CHUNK) {
            let end = (first + JOINT_CHUNK).min(nj);
            let (v, rest) = std::mem::take(&mut joint_values).split_at_mut(3 * (end - first));
            joint_values = rest;
            let len = start[ne + 3 * end] - start[ne + 3 * first];
            let (g, rest) = std::mem::take(&mut joint_grads).split_at_mut(len);
            joint_grads = rest;
            chunks.push((first..end, v, g));
        }
        let fill = |(range, values, grads): (std::ops::Range<usize>, &mut [Real], &mut [Real])| {
            let mut at = 0;
            for (k, value) in range.zip(values.chunks_exact_mut(3)) {
                let j = &e.joints[k];
                let u = x[j[1] as usize] - x[j[0] as usize];
                let w = x[j[3] as usize] - x[j[2] as usize];
                let (theta, gu, gw) = angle_and_gradients(&u, &w);
                let s = e.joint_weights[k].sqrt();
                let rows = |gu: Vector3, gw: Vector3| [-gu * s, gu * s, -gw * s, gw * s];
                let [t1, t2] = transverse_rows(&u, &w, theta, e.rest_angles[k]);
                let layout = &self.joint_layouts[k];
                let width = 3 * layout.count;
                value.copy_from_slice(&[s * (theta - e.rest_angles[k]), 0.0, 0.0]);
                for (du, dw) in [(gu, gw), t1, t2] {
                    layout.write(rows(du, dw), &mut grads[at..at + width]);
                    at += width;
                }
            }
        };
        // One chunk stays on this thread (a hand-over to rayon's pool costs more).
        if chunks.len() > 1 {
            chunks.into_par_iter().for_each(fill);
        } else {
            chunks.into_iter().for_each(fill);
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
