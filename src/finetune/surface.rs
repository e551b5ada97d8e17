//! Surface fine tuning (fine-tuning paper, §4.3–4.4): a Doo-Sabin control
//! mesh is converted to a non-uniform Catmull-Clark mesh, control values on
//! the original edges give optimal leg vectors along the edge loops, and the
//! spring energy (14) is minimised with some vertices fixed, on the mesh
//! pre-scaled to the unit cube, by Levenberg-Marquardt
//! (`surface_gauss_newton`) or, with [`FinetuneMethod::NonlinearCg`], by
//! argmin's nonlinear conjugate gradient (`surface_solve`).

use std::time::Instant;

use crate::error::{Error, Result};
use crate::linalg::{LmTimings, REFINEMENT_ITERATIONS};
use crate::math::{Point3, Real, bounding_box};
use crate::mesh::PolyMesh;
use crate::topology::{Level, find_edge};

use super::method::FinetuneMethod;
use super::surface_energy::{SpringEnergy, joint_angles};
use super::surface_solve::minimise;
use super::surface_targets::{LegKind, loop_targets};
use super::{ConvertedEdge, doo_sabin_to_non_uniform, edge_loops};

/// The scheme of the input control mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SurfaceScheme {
    /// A Doo-Sabin mesh: converted to non-uniform Catmull-Clark first (the paper's method).
    #[default]
    DooSabin,
    /// A Catmull-Clark mesh, fine-tuned directly (legs scaled by their values; an approximation).
    CatmullClark,
}

/// Parameters of [`SurfaceFineTune`].
#[derive(Clone, Debug)]
pub struct SurfaceFineTuneParams {
    /// Spring coefficients `(k_l, k_a, k_b)` of energy (14); default `(1, 1, 1)` (the paper's ratio).
    pub k: [Real; 3],
    /// Knot interval used in place of 0 in the conversion; default 0.05 (the paper's figure 16).
    pub epsilon: Real,
    /// Most iterations; default 2000.
    pub max_iters: u64,
    /// Stop when the gradient norm (in the solver's Jacobi-scaled variables) is below this; default 1e-9.
    pub gradient_tolerance: Real,
    /// Stop when the energy fell by less than this fraction over the last
    /// 10 iterations; default 1e-5 (0 disables the rule).
    pub energy_tolerance: Real,
    /// Pre-scale the mesh to the unit cube (and scale back); default true.
    pub prescale: bool,
    /// The minimiser; default Levenberg-Marquardt (`surface_gauss_newton`),
    /// [`FinetuneMethod::NonlinearCg`] is argmin's nonlinear CG.
    pub method: FinetuneMethod,
    /// Levenberg-Marquardt: conjugate-gradient iterations allowed to solve a
    /// step with the previous factorisation before factoring afresh
    /// (`linalg::refined_step`); default [`REFINEMENT_ITERATIONS`] (15), 0 factors
    /// every step.
    pub refinement_iterations: usize,
}

impl Default for SurfaceFineTuneParams {
    fn default() -> Self {
        SurfaceFineTuneParams {
            k: [1.0; 3],
            epsilon: 0.05,
            max_iters: 2000,
            gradient_tolerance: 1e-9,
            energy_tolerance: 1e-5,
            prescale: true,
            method: FinetuneMethod::default(),
            refinement_iterations: REFINEMENT_ITERATIONS,
        }
    }
}

/// What a fine-tuning run did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SurfaceFineTuneReport {
    /// The minimiser used.
    pub method: FinetuneMethod,
    /// Iterations of the minimiser.
    pub iterations: u64,
    /// Energy before the first iteration and after each one (unit-cube scale).
    pub energies: Vec<Real>,
    /// Gradient norm after each iteration (unit-cube scale).
    pub gradient_norms: Vec<Real>,
    /// Why the solver stopped.
    pub termination: String,
    /// Number of edge loops, edge springs, loop joints, shape joints, free vertices.
    pub counts: [usize; 5],
    /// Largest vertex displacement, in the input's units.
    pub max_displacement: Real,
    /// Seconds for the precompute and the solve.
    pub seconds: [f64; 2],
    /// Where Levenberg-Marquardt spent the solve (zero for nonlinear CG).
    pub solver_timings: LmTimings,
}

/// A precomputed fine-tuning problem; [`solve`](Self::solve) minimises it.
#[derive(Clone, Debug)]
pub struct SurfaceFineTune {
    /// The mesh being deformed (the converted mesh for Doo-Sabin input).
    pub mesh: PolyMesh,
    /// Its connectivity.
    pub level: Level,
    /// Knot interval per edge of `level` (1 everywhere for Catmull-Clark input).
    pub intervals: Vec<Real>,
    /// The spring model, in unit-cube coordinates.
    pub energy: SpringEnergy,
    /// True for each vertex of `mesh` that must not move.
    pub fixed: Vec<bool>,
    center: Point3,
    scale: Real,
    params: SurfaceFineTuneParams,
    counts: [usize; 5],
    seconds: f64,
}

fn check_params(p: &SurfaceFineTuneParams) -> Result<()> {
    if p.k.iter().any(|k| !k.is_finite() || *k < 0.0) || p.k.iter().all(|k| *k == 0.0) {
        return Err(Error::input(format!(
            "spring coefficients must be finite, ≥ 0 and not all 0, got {:?}",
            p.k
        )));
    }
    if !p.gradient_tolerance.is_finite()
        || p.gradient_tolerance < 0.0
        || !p.energy_tolerance.is_finite()
        || p.energy_tolerance < 0.0
        || p.max_iters > 1_000_000
    {
        return Err(Error::input(
            "gradient tolerance must be ≥ 0 and at most 1,000,000 iterations",
        ));
    }
    Ok(())
}

impl SurfaceFineTune {
    /// Precomputes the problem: conversion (Doo-Sabin), edge loops, target
    /// lengths and angles. `values` are `(i, j, a)`: the edge between original
    /// vertices `i` and `j` gets control value `a > 0` (unlisted edges 1);
    /// `fixed` are original vertex indices that stay put.
    pub fn new(
        mesh: &PolyMesh,
        scheme: SurfaceScheme,
        values: &[(u32, u32, Real)],
        fixed: &[u32],
        params: &SurfaceFineTuneParams,
    ) -> Result<SurfaceFineTune> {
        let start = Instant::now();
        check_params(params)?;
        let original = Level::from_mesh(mesh)?;
        let mut orig_value = vec![1.0; original.num_edges()];
        for &(i, j, a) in values {
            let e = find_edge(&original, i, j).ok_or_else(|| {
                Error::input(format!("vertices {i} and {j} are not joined by an edge"))
            })?;
            if !a.is_finite() || a <= 0.0 {
                return Err(Error::input(format!(
                    "edge {i}-{j}: control value {a} must be finite and > 0"
                )));
            }
            orig_value[e] = a;
        }
        if let Some(&v) = fixed.iter().find(|&&v| v as usize >= mesh.num_vertices()) {
            return Err(Error::out_of_range(format!(
                "fixed vertex {v} does not exist (the mesh has {} vertices)",
                mesh.num_vertices()
            )));
        }
        let (work, level, intervals, value, kind, fixed_flags) = match scheme {
            SurfaceScheme::DooSabin => {
                let c = doo_sabin_to_non_uniform(mesh, params.epsilon)?;
                let corner_vertex = &original.face_verts;
                let mut value = vec![1.0; c.level.num_edges()];
                let mut kind = vec![LegKind::Joint; c.level.num_edges()];
                for (e, k) in c.edge_kind.iter().enumerate() {
                    if *k == ConvertedEdge::Face {
                        let [a, b] = c.level.edge_verts[e];
                        let (va, vb) = (corner_vertex[a as usize], corner_vertex[b as usize]);
                        let oe = find_edge(&original, va, vb).ok_or_else(|| {
                            Error::Topology(format!("converted edge {e} has no original edge"))
                        })?;
                        value[e] = orig_value[oe];
                        kind[e] = LegKind::Scaled;
                    }
                }
                let fixed_flags = corner_vertex.iter().map(|v| fixed.contains(v)).collect();
                (c.mesh, c.level, c.intervals, value, kind, fixed_flags)
            }
            SurfaceScheme::CatmullClark => {
                let n = original.num_edges();
                let mut fixed_flags = vec![false; mesh.num_vertices()];
                for &v in fixed {
                    fixed_flags[v as usize] = true;
                }
                (
                    mesh.clone(),
                    original,
                    vec![1.0; n],
                    orig_value,
                    vec![LegKind::Scaled; n],
                    fixed_flags,
                )
            }
        };
        let (center, scale) = match (params.prescale, bounding_box(&work.positions)) {
            (true, Some((lo, hi))) => {
                let extent = (hi - lo).max();
                let s = if extent > 0.0 { 1.0 / extent } else { 1.0 };
                (Point3::from((lo.coords + hi.coords) * 0.5), s)
            }
            _ => (Point3::origin(), 1.0),
        };
        let x: Vec<Point3> = work
            .positions
            .iter()
            .map(|p| Point3::from((p - center) * scale))
            .collect();
        let (energy, loops, loop_joints) = spring_model(&level, &x, &value, &kind, params);
        let counts = [
            loops,
            energy.edges.len(),
            loop_joints,
            energy.joints.len() - loop_joints,
            fixed_flags.iter().filter(|f: &&bool| !**f).count(),
        ];
        Ok(SurfaceFineTune {
            counts,
            mesh: work,
            level,
            intervals,
            energy,
            fixed: fixed_flags,
            center,
            scale,
            params: params.clone(),
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// Minimises the energy; returns the fine-tuned mesh (same connectivity
    /// as [`mesh`](Self::mesh)) and the report.
    pub fn solve(&self) -> Result<(PolyMesh, SurfaceFineTuneReport)> {
        let start = Instant::now();
        let x0: Vec<Point3> = self
            .mesh
            .positions
            .iter()
            .map(|p| Point3::from((p - self.center) * self.scale))
            .collect();
        let run = minimise(&self.energy, &x0, &self.fixed, &self.params)?;
        let mut out = self.mesh.clone();
        out.positions = run
            .positions
            .iter()
            .map(|p| self.center + p.coords / self.scale)
            .collect();
        let max_displacement = out
            .positions
            .iter()
            .zip(&self.mesh.positions)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, Real::max);
        let report = SurfaceFineTuneReport {
            method: self.params.method,
            iterations: run.iterations,
            energies: run.energies,
            gradient_norms: run.gradient_norms,
            termination: run.termination,
            counts: self.counts,
            max_displacement,
            seconds: [self.seconds, start.elapsed().as_secs_f64()],
            solver_timings: run.timings,
        };
        Ok((out, report))
    }
}

/// Edge springs and loop joints from the loop targets, shape joints from the
/// current angles between consecutive edges around every vertex.
fn spring_model(
    level: &Level,
    x: &[Point3],
    value: &[Real],
    kind: &[LegKind],
    params: &SurfaceFineTuneParams,
) -> (SpringEnergy, usize, usize) {
    let [k_l, k_a, k_b] = params.k;
    let mut energy = SpringEnergy {
        edges: level.edge_verts.clone(),
        rest_lengths: vec![0.0; level.num_edges()],
        k_l,
        ..Default::default()
    };
    let loops = edge_loops(level);
    for lp in &loops {
        let t = loop_targets(lp, x, value, kind);
        for (k, &e) in lp.edges.iter().enumerate() {
            energy.rest_lengths[e as usize] = t[k].norm();
        }
        let m = lp.edges.len();
        let nv = lp.vertices.len();
        let joints = if lp.closed { m } else { m.saturating_sub(1) };
        for k in 0..joints {
            let k1 = (k + 1) % m;
            let v = |i: usize| lp.vertices[i % nv];
            energy.joints.push([v(k), v(k + 1), v(k + 1), v(k + 2)]);
            energy.rest_angles.push(t[k].angle(&t[k1]));
            energy.joint_weights.push(k_a);
        }
    }
    let first_shape = energy.joints.len();
    for v in 0..level.num_vertices {
        let ring = level.vertex_ring(v);
        let n = ring.edges.len();
        let pairs = if ring.boundary {
            n.saturating_sub(1)
        } else {
            n
        };
        for k in 0..pairs {
            let (a, b) = (ring.edges[k], ring.edges[(k + 1) % n]);
            let v32 = v as u32;
            energy.joints.push([
                v32,
                level.other_vertex(a as usize, v32),
                v32,
                level.other_vertex(b as usize, v32),
            ]);
            energy.joint_weights.push(k_b);
        }
    }
    let shape = joint_angles(&energy.joints[first_shape..], x);
    energy.rest_angles.extend(shape);
    (energy, loops.len(), first_shape)
}
