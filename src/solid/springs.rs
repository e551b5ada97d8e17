//! The mass-spring network of a dynamic subdivision solid on its finest
//! lattice (McDonnell & Qin, §5.1, figs. 3–4).
//!
//! - *Normal springs*: one per lattice edge, "connected to their immediate
//!   neighbors" ("normal" means ordinary here, not the surface normal).
//! - *Virtual springs*: for every corner `m` of every face (interior faces
//!   included) a spring from `m` to the massless virtual point
//!   `v = ½ (m_prev + m_next)`, the midpoint of `m`'s two neighbours in that
//!   face (fig. 3: `v₁ = ½ (m₂ + m₄)`). They resist changes of the face's
//!   internal angles. The paper contrasts them with "traditional diagonal
//!   springs" and does not use diagonal springs, so neither does this network.
//!
//! Every spring is a vector `Δ = Σ_i b_i x_i` of mass points with `Σ b_i = 0`
//! (`b = (1, −1)` for an edge, `(1, −½, −½)` for a virtual spring), energy
//! `E = ½ k (|Δ| − L₀)²`, force `−b_i k (|Δ| − L₀) Δ/|Δ|` on point `i`, so the
//! forces of every spring sum to zero (momentum is conserved) and are
//! invariant under rotations. Stiffness `k = κ · ℓ`, `κ` the per-type
//! coefficient and `ℓ` the spring's rest length when the network was built:
//! a lattice of such springs has the same effective modulus at every level.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::lattice::LatticeTopology;
use crate::math::{Point3, Real, Vector3, reduction_parts};

/// Edge and virtual springs of a lattice, with rest lengths and length scales.
#[derive(Clone, Debug, Default)]
pub struct SpringNetwork {
    /// Normal (edge) springs `(i, j)`: `Δ = x_i − x_j`.
    pub edges: Vec<[u32; 2]>,
    /// Virtual springs `(m, a, b)`: `Δ = x_m − ½ (x_a + x_b)`.
    pub virtuals: Vec<[u32; 3]>,
    /// Rest length `L₀` of every edge spring.
    pub edge_rest: Vec<Real>,
    /// Rest length `L₀` of every virtual spring.
    pub virtual_rest: Vec<Real>,
    /// Length scale `ℓ` of every edge spring (its stiffness is `κ_edge · ℓ`).
    pub edge_scale: Vec<Real>,
    /// Length scale `ℓ` of every virtual spring.
    pub virtual_scale: Vec<Real>,
    /// Number of mass points.
    pub num_points: usize,
    /// The virtual springs of face `f` are `face_offsets[f]..face_offsets[f + 1]`
    /// (one per corner, in loop order).
    pub face_offsets: Vec<u32>,
}

/// Stiffness coefficients `κ` of the two spring types (per unit length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stiffness {
    /// `κ` of the normal (edge) springs.
    pub edge: Real,
    /// `κ` of the virtual springs.
    pub virtual_: Real,
}

fn edge_delta(x: &[Point3], s: &[u32; 2]) -> Vector3 {
    x[s[0] as usize] - x[s[1] as usize]
}

fn virtual_delta(x: &[Point3], s: &[u32; 3]) -> Vector3 {
    x[s[0] as usize].coords - 0.5 * (x[s[1] as usize].coords + x[s[2] as usize].coords)
}

/// `k (|Δ| − L₀) Δ/|Δ|` and the energy `½ k (|Δ| − L₀)²` of one spring.
fn tension(d: Vector3, rest: Real, k: Real) -> (Vector3, Real) {
    let l = d.norm();
    if l <= 0.0 {
        return (Vector3::zeros(), 0.5 * k * rest * rest);
    }
    let stretch = l - rest;
    (d * (k * stretch / l), 0.5 * k * stretch * stretch)
}

/// The spring's Hessian `H = k [u uᵀ + t (I − u uᵀ)]`, `t = max(0, 1 − L₀/|Δ|)`
/// (the transverse term clamped at zero so that `H` stays positive
/// semi-definite), stored as `[u_x, u_y, u_z, k, k t]`.
fn hessian(d: Vector3, rest: Real, k: Real) -> [Real; 5] {
    let l = d.norm();
    if l <= 0.0 {
        return [0.0, 0.0, 0.0, k, k];
    }
    let u = d / l;
    [u.x, u.y, u.z, k, k * (1.0 - rest / l).max(0.0)]
}

/// `H δ` for a Hessian stored by [`hessian`].
fn hessian_times(h: &[Real; 5], delta: Vector3) -> Vector3 {
    let u = Vector3::new(h[0], h[1], h[2]);
    delta * h[4] + u * ((h[3] - h[4]) * u.dot(&delta))
}

/// The spring Hessians at one configuration, for repeated products (the
/// implicit integrator's CG iterations).
#[derive(Clone, Debug, Default)]
pub struct SpringHessians {
    edges: Vec<[Real; 5]>,
    virtuals: Vec<[Real; 5]>,
}

/// The `3 × 3` matrix of a Hessian stored by [`hessian`]: `k_t I + (k − k_t) u uᵀ`.
fn hessian_matrix(h: &[Real; 5]) -> nalgebra::Matrix3<Real> {
    let u = Vector3::new(h[0], h[1], h[2]);
    nalgebra::Matrix3::identity() * h[4] + u * u.transpose() * (h[3] - h[4])
}

impl SpringHessians {
    /// The `3 × 3` Hessian of edge spring `s`.
    pub fn edge_matrix(&self, s: usize) -> nalgebra::Matrix3<Real> {
        hessian_matrix(&self.edges[s])
    }

    /// The `3 × 3` Hessian of virtual spring `s`.
    pub fn virtual_matrix(&self, s: usize) -> nalgebra::Matrix3<Real> {
        hessian_matrix(&self.virtuals[s])
    }
}

/// Splits `0..n` into one contiguous range per worker and sums the per-range
/// accumulations of `body` into `out` (conflict-free parallel scatter).
fn scatter_sum(
    n: usize,
    points: usize,
    out: &mut [Vector3],
    body: impl Fn(std::ops::Range<usize>, &mut [Vector3]) -> Real + Sync,
) -> Real {
    let parts = reduction_parts(n, 2048);
    let size = n.div_ceil(parts);
    let results: Vec<(Vec<Vector3>, Real)> = (0..parts)
        .into_par_iter()
        .map(|p| {
            let mut acc = vec![Vector3::zeros(); points];
            let e = body(p * size..((p + 1) * size).min(n), &mut acc);
            (acc, e)
        })
        .collect();
    summed_partials(results, out)
}

/// Adds the per-thread accumulators into `out` and returns their energies' sum.
fn summed_partials(results: Vec<(Vec<Vector3>, Real)>, out: &mut [Vector3]) -> Real {
    let mut energy = 0.0;
    for (acc, e) in results {
        energy += e;
        for (o, a) in out.iter_mut().zip(acc) {
            *o += a;
        }
    }
    energy
}

impl SpringNetwork {
    /// The springs of a lattice topology with rest lengths (and length scales)
    /// from the rest positions `rest`. Errors when a spring has zero rest
    /// length (coincident mass points) or the sizes disagree.
    pub fn new(topo: &LatticeTopology, rest: &[Point3]) -> Result<SpringNetwork> {
        if rest.len() != topo.num_vertices {
            return Err(Error::size_mismatch(format!(
                "spring network: {} rest positions for {} mass points",
                rest.len(),
                topo.num_vertices
            )));
        }
        let edges = topo.edges.clone();
        let mut virtuals = Vec::with_capacity(topo.faces.items.len());
        let face_offsets = topo.faces.offsets.clone();
        for f in 0..topo.num_faces() {
            let l = topo.faces.row(f);
            let k = l.len();
            for i in 0..k {
                virtuals.push([l[i], l[(i + k - 1) % k], l[(i + 1) % k]]);
            }
        }
        let mut net = SpringNetwork {
            edges,
            virtuals,
            num_points: topo.num_vertices,
            face_offsets,
            ..SpringNetwork::default()
        };
        net.set_rest(rest)?;
        net.edge_scale = net.edge_rest.clone();
        net.virtual_scale = net.virtual_rest.clone();
        Ok(net)
    }

    /// Number of springs (edge and virtual).
    pub fn len(&self) -> usize {
        self.edges.len() + self.virtuals.len()
    }

    /// True when there is no spring.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sets every rest length, virtual springs included, to the current
    /// length in `x` ("make plastic", McDonnell & Qin §5.4). The length
    /// scales (stiffnesses) are unchanged. Errors on a zero length.
    pub fn set_rest(&mut self, x: &[Point3]) -> Result<()> {
        if x.len() != self.num_points {
            return Err(Error::size_mismatch(format!(
                "spring network: {} positions for {} mass points",
                x.len(),
                self.num_points
            )));
        }
        let edge_rest: Vec<Real> = self.edges.iter().map(|s| edge_delta(x, s).norm()).collect();
        let virtual_rest: Vec<Real> = self
            .virtuals
            .iter()
            .map(|s| virtual_delta(x, s).norm())
            .collect();
        if let Some(i) = edge_rest.iter().position(|&l| !(l > 0.0 && l.is_finite())) {
            let [a, b] = self.edges[i];
            return Err(Error::input(format!(
                "spring between mass points {a} and {b} has length {} (coincident points)",
                edge_rest[i]
            )));
        }
        if let Some(i) = virtual_rest
            .iter()
            .position(|&l| !(l > 0.0 && l.is_finite()))
        {
            let [m, a, b] = self.virtuals[i];
            return Err(Error::input(format!(
                "virtual spring of mass point {m} (neighbours {a}, {b}) has length {} (a flat face corner)",
                virtual_rest[i]
            )));
        }
        self.edge_rest = edge_rest;
        self.virtual_rest = virtual_rest;
        Ok(())
    }

    /// Adds the spring forces `−∂E/∂x` at positions `x` into `out` and
    /// returns the spring energy `E = Σ ½ k (|Δ| − L₀)²`.
    pub fn add_forces(&self, x: &[Point3], k: Stiffness, out: &mut [Vector3]) -> Real {
        let ne = self.edges.len();
        scatter_sum(self.len(), self.num_points, out, |range, acc| {
            let mut energy = 0.0;
            for s in range {
                if s < ne {
                    let e = &self.edges[s];
                    let (t, en) = tension(
                        edge_delta(x, e),
                        self.edge_rest[s],
                        k.edge * self.edge_scale[s],
                    );
                    acc[e[0] as usize] -= t;
                    acc[e[1] as usize] += t;
                    energy += en;
                } else {
                    let v = s - ne;
                    let e = &self.virtuals[v];
                    let (t, en) = tension(
                        virtual_delta(x, e),
                        self.virtual_rest[v],
                        k.virtual_ * self.virtual_scale[v],
                    );
                    acc[e[0] as usize] -= t;
                    acc[e[1] as usize] += 0.5 * t;
                    acc[e[2] as usize] += 0.5 * t;
                    energy += en;
                }
            }
            energy
        })
    }

    /// The spring energy `E` at positions `x`.
    pub fn energy(&self, x: &[Point3], k: Stiffness) -> Real {
        let e: Real = self
            .edges
            .par_iter()
            .zip(&self.edge_rest)
            .zip(&self.edge_scale)
            .map(|((s, &r), &l)| tension(edge_delta(x, s), r, k.edge * l).1)
            .sum();
        let v: Real = self
            .virtuals
            .par_iter()
            .zip(&self.virtual_rest)
            .zip(&self.virtual_scale)
            .map(|((s, &r), &l)| tension(virtual_delta(x, s), r, k.virtual_ * l).1)
            .sum();
        e + v
    }

    /// The springs' Hessians `∂²E/∂Δ²` at `x` (transverse terms clamped to
    /// keep them positive semi-definite), written into `h` (its buffers are
    /// reused): the stiffness `K` of the implicit integrator, linearised once
    /// per step.
    pub fn hessians_into(&self, x: &[Point3], k: Stiffness, h: &mut SpringHessians) {
        h.edges.resize(self.edges.len(), [0.0; 5]);
        h.virtuals.resize(self.virtuals.len(), [0.0; 5]);
        h.edges
            .par_iter_mut()
            .with_min_len(4096)
            .zip(&self.edges)
            .zip(&self.edge_rest)
            .zip(&self.edge_scale)
            .for_each(|(((o, s), &r), &l)| *o = hessian(edge_delta(x, s), r, k.edge * l));
        h.virtuals
            .par_iter_mut()
            .with_min_len(4096)
            .zip(&self.virtuals)
            .zip(&self.virtual_rest)
            .zip(&self.virtual_scale)
            .for_each(|(((o, s), &r), &l)| *o = hessian(virtual_delta(x, s), r, k.virtual_ * l));
    }

    /// One pass for the implicit step's right-hand side: writes the
    /// Hessians at `x` into `h` (as [`hessians_into`](Self::hessians_into)),
    /// adds the forces `−∂E/∂x` minus `c K v` into `out` (as
    /// [`add_forces`](Self::add_forces) followed by
    /// [`add_hessian_product`](Self::add_hessian_product) of `−c v`) and
    /// returns the spring energy. Each worker takes a contiguous share of the
    /// edge and of the virtual springs.
    pub fn add_forces_minus_hessian_product(
        &self,
        x: &[Point3],
        v: &[Vector3],
        k: Stiffness,
        c: Real,
        out: &mut [Vector3],
        h: &mut SpringHessians,
    ) -> Real {
        let (ne, nv) = (self.edges.len(), self.virtuals.len());
        h.edges.resize(ne, [0.0; 5]);
        h.virtuals.resize(nv, [0.0; 5]);
        let parts = reduction_parts(ne + nv, 2048);
        let (ce, cv) = (ne.div_ceil(parts), nv.div_ceil(parts));
        let mut shares = Vec::with_capacity(parts);
        let (mut he, mut hv) = (&mut h.edges[..], &mut h.virtuals[..]);
        for p in 0..parts {
            let (a, rest_e) = std::mem::take(&mut he).split_at_mut(ce.min(ne - (p * ce).min(ne)));
            let (b, rest_v) = std::mem::take(&mut hv).split_at_mut(cv.min(nv - (p * cv).min(nv)));
            shares.push((p, a, b));
            he = rest_e;
            hv = rest_v;
        }
        let results: Vec<(Vec<Vector3>, Real)> = shares
            .into_par_iter()
            .map(|(p, he, hv)| {
                let mut acc = vec![Vector3::zeros(); self.num_points];
                let mut energy = 0.0;
                for (i, o) in he.iter_mut().enumerate() {
                    let s = p * ce + i;
                    let e = &self.edges[s];
                    let d = edge_delta(x, e);
                    let kk = k.edge * self.edge_scale[s];
                    let (t, en) = tension(d, self.edge_rest[s], kk);
                    *o = hessian(d, self.edge_rest[s], kk);
                    let y = t + hessian_times(o, v[e[0] as usize] - v[e[1] as usize]) * c;
                    acc[e[0] as usize] -= y;
                    acc[e[1] as usize] += y;
                    energy += en;
                }
                for (i, o) in hv.iter_mut().enumerate() {
                    let s = p * cv + i;
                    let e = &self.virtuals[s];
                    let d = virtual_delta(x, e);
                    let kk = k.virtual_ * self.virtual_scale[s];
                    let (t, en) = tension(d, self.virtual_rest[s], kk);
                    *o = hessian(d, self.virtual_rest[s], kk);
                    let dv = v[e[0] as usize] - 0.5 * (v[e[1] as usize] + v[e[2] as usize]);
                    let y = t + hessian_times(o, dv) * c;
                    acc[e[0] as usize] -= y;
                    acc[e[1] as usize] += 0.5 * y;
                    acc[e[2] as usize] += 0.5 * y;
                    energy += en;
                }
                (acc, energy)
            })
            .collect();
        summed_partials(results, out)
    }

    /// Adds `K w` into `out` with the Hessians of [`hessians_into`](Self::hessians_into).
    /// Virtual springs are processed face by face: a face's corners are read
    /// and written once for all its springs.
    pub fn add_hessian_product(&self, h: &SpringHessians, w: &[Vector3], out: &mut [Vector3]) {
        let ne = self.edges.len();
        let nf = self.face_offsets.len().saturating_sub(1);
        scatter_sum(ne + nf, self.num_points, out, |range, acc| {
            for item in range {
                if item < ne {
                    let e = &self.edges[item];
                    let dw = w[e[0] as usize] - w[e[1] as usize];
                    let y = hessian_times(&h.edges[item], dw);
                    acc[e[0] as usize] += y;
                    acc[e[1] as usize] -= y;
                    continue;
                }
                let f = item - ne;
                let (a, b) = (
                    self.face_offsets[f] as usize,
                    self.face_offsets[f + 1] as usize,
                );
                let k = b - a;
                if k == 4 {
                    // Quads (every face of a refined hexahedral lattice): fixed neighbours.
                    let c = [0, 1, 2, 3].map(|i| self.virtuals[a + i][0] as usize);
                    let wl = c.map(|i| w[i]);
                    let mut yl = [Vector3::zeros(); 4];
                    for (i, (p, n)) in [(3, 1), (0, 2), (1, 3), (2, 0)].into_iter().enumerate() {
                        let y = hessian_times(&h.virtuals[a + i], wl[i] - 0.5 * (wl[p] + wl[n]));
                        yl[i] += y;
                        yl[p] -= 0.5 * y;
                        yl[n] -= 0.5 * y;
                    }
                    for i in 0..4 {
                        acc[c[i]] += yl[i];
                    }
                } else if k <= 8 {
                    // Corner i of the face is spring a + i, its neighbours i − 1 and i + 1.
                    let mut wl = [Vector3::zeros(); 8];
                    let mut yl = [Vector3::zeros(); 8];
                    for i in 0..k {
                        wl[i] = w[self.virtuals[a + i][0] as usize];
                    }
                    for i in 0..k {
                        let (p, n) = ((i + k - 1) % k, (i + 1) % k);
                        let y = hessian_times(&h.virtuals[a + i], wl[i] - 0.5 * (wl[p] + wl[n]));
                        yl[i] += y;
                        yl[p] -= 0.5 * y;
                        yl[n] -= 0.5 * y;
                    }
                    for i in 0..k {
                        acc[self.virtuals[a + i][0] as usize] += yl[i];
                    }
                } else {
                    for v in a..b {
                        let e = &self.virtuals[v];
                        let dw = w[e[0] as usize] - 0.5 * (w[e[1] as usize] + w[e[2] as usize]);
                        let y = hessian_times(&h.virtuals[v], dw);
                        acc[e[0] as usize] += y;
                        acc[e[1] as usize] -= 0.5 * y;
                        acc[e[2] as usize] -= 0.5 * y;
                    }
                }
            }
            0.0
        });
    }

    /// The isotropic graph Laplacian `L = Σ_s k_s b_s b_sᵀ` (one scalar per
    /// pair of mass points), as `(row, column, value)` triplets: an upper
    /// bound of the spring Hessian's every `3 × 3`-block pattern, used to
    /// precondition the implicit solve.
    pub fn laplacian_rows(&self, k: Stiffness) -> Vec<Vec<(u32, Real)>> {
        let mut rows: Vec<Vec<(u32, Real)>> = vec![Vec::new(); self.num_points];
        for (s, e) in self.edges.iter().enumerate() {
            let ks = k.edge * self.edge_scale[s];
            let b = [(e[0], 1.0), (e[1], -1.0)];
            for &(i, wi) in &b {
                for &(j, wj) in &b {
                    rows[i as usize].push((j, ks * wi * wj));
                }
            }
        }
        for (s, e) in self.virtuals.iter().enumerate() {
            let ks = k.virtual_ * self.virtual_scale[s];
            let b = [(e[0], 1.0), (e[1], -0.5), (e[2], -0.5)];
            for &(i, wi) in &b {
                for &(j, wj) in &b {
                    rows[i as usize].push((j, ks * wi * wj));
                }
            }
        }
        rows
    }
}
