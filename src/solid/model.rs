//! `Solid`: a dynamic Catmull-Clark subdivision solid (McDonnell & Qin,
//! §4.1–4.2, §5.2): control points `p` of a volume lattice, mass points
//! `d = A p` on its level-`L` refinement (eq. 2, `A` the composed
//! MacCracken–Joy stencil `S_L`), a spring network on that lattice, lumped
//! masses and mass-proportional damping, and the partition
//! `d = A₁ p₁ + A₂ p₂` into free and fixed control points (fig. 6).
//!
//! Control-point dynamics (eq. 5–6 with the spring forces in place of `K d`):
//! `A₁ᵀ M A₁ p̈₁ = A₁ᵀ (f_d − D ḋ + f_springs)`, `f_springs = −∂E/∂d`.
//! `A₁ᵀ M A₁` is constant for a topology and a fixed set: it is assembled
//! and Cholesky-factored once (dense; the control lattice is small).
//!
//! What is rebuilt when (see also [`tools`](super::tools)): a topology change
//! (extrude, trim) rebuilds everything below the control lattice — hierarchy,
//! `A`, springs, masses, partition; fixing or freeing control points rebuilds
//! only the partition (`A₁`, `A₁ᵀ`, the factor of `A₁ᵀ M A₁`); stiffness and
//! damping changes only drop the implicit integrator's preconditioner; make
//! plastic only resets rest lengths.

use nalgebra::{Cholesky, Dyn};

use crate::error::{Error, Result};
use crate::lattice::{Lattice, LatticeHierarchy, LatticeTopology, cell_volume};
use crate::math::{Point3, Real, Vector3};
use crate::stencil::StencilTable;

use super::params::SolidParams;
use super::products::cholesky;
use super::springs::SpringNetwork;
use super::tools::Rope;

/// Most refinement levels a solid accepts (level 4 of a 27-point cube has 35,937 mass points).
pub const MAX_SOLID_LEVEL: usize = 4;

/// The free/fixed partition of the control points and its matrices.
#[derive(Clone, Debug)]
pub(crate) struct Partition {
    /// Indices of the free control points (the unknowns `p₁`).
    pub free: Vec<usize>,
    /// `A₁`: the columns of `A` of the free control points.
    pub a1: StencilTable,
    /// `A₁ᵀ`.
    pub a1t: StencilTable,
    /// Cholesky factor of `A₁ᵀ M A₁` (`None` when every point is fixed).
    pub mass_factor: Option<Cholesky<Real, Dyn>>,
}

/// Cached preconditioner of the implicit step for one time step and material.
#[derive(Clone, Debug)]
pub(crate) struct Preconditioner {
    /// The time step it was built for.
    pub h: Real,
    /// Its factor.
    pub factor: PrecondFactor,
    /// CG iterations beyond the first, summed over the steps since it was built.
    pub excess: usize,
    /// Rebuild it at the next step (the lagged Hessian has drifted).
    pub stale: bool,
}

/// The factored preconditioner matrix.
#[derive(Clone, Debug)]
pub(crate) enum PrecondFactor {
    /// `(1 + hγ) A₁ᵀ M A₁ + h² A₁ᵀ L A₁` (`n × n`, applied per coordinate).
    Laplacian(Cholesky<Real, Dyn>),
    /// `A₁ᵀ ((1 + hγ) M + h² K) A₁` at a past step (`3n × 3n`).
    Hessian(Cholesky<Real, Dyn>),
}

/// A dynamic subdivision solid and its sculpting state.
#[derive(Clone, Debug)]
pub struct Solid {
    /// Material and solver parameters (change them through the tools).
    pub(crate) params: SolidParams,
    /// The control lattice (its positions are those of the last rebuild; see [`Solid::control_points`]).
    pub(crate) control: Lattice,
    pub(crate) p: Vec<Point3>,
    pub(crate) v: Vec<Vector3>,
    pub(crate) p_rest: Vec<Point3>,
    pub(crate) fixed: Vec<bool>,
    pub(crate) fine: LatticeTopology,
    pub(crate) a: StencilTable,
    pub(crate) part: Partition,
    pub(crate) mass: Vec<Real>,
    pub(crate) springs: SpringNetwork,
    pub(crate) ropes: Vec<Rope>,
    pub(crate) d: Vec<Point3>,
    pub(crate) dd: Vec<Vector3>,
    pub(crate) precond: Option<Preconditioner>,
    /// The implicit step's last `Δṗ₁` (its CG's next initial guess).
    pub(crate) last_dv: Vec<Vector3>,
    /// Buffers of the implicit step's spring Hessians.
    pub(crate) hess: super::springs::SpringHessians,
    /// Block pattern of the spring Hessian (built when first needed).
    pub(crate) pattern: Option<super::reduced::BlockPattern>,
    pub(crate) time: Real,
}

/// Lumped masses: every cell's mass `ρ · volume` (at the rest positions)
/// shared equally among its vertices.
pub fn lumped_masses(topo: &LatticeTopology, rest: &[Point3], density: Real) -> Result<Vec<Real>> {
    let mut m = vec![0.0; topo.num_vertices];
    for c in 0..topo.num_cells() {
        let vol = cell_volume(rest, topo, c)?;
        let vs = topo.cell_vertices.row(c);
        for &v in vs {
            m[v as usize] += density * vol / vs.len() as Real;
        }
    }
    if let Some(i) = m.iter().position(|&x| !(x > 0.0 && x.is_finite())) {
        return Err(Error::input(format!("mass point {i} has mass {}", m[i])));
    }
    Ok(m)
}

impl Solid {
    /// A solid at rest in the lattice's shape (the lattice's positions are the
    /// control points and the rest shape), with no fixed point and no rope.
    pub fn new(lattice: &Lattice, params: SolidParams) -> Result<Solid> {
        params.check()?;
        let n = lattice.num_vertices();
        let mut solid = Solid {
            params,
            control: lattice.clone(),
            p: lattice.positions.clone(),
            v: vec![Vector3::zeros(); n],
            p_rest: lattice.positions.clone(),
            fixed: vec![false; n],
            fine: LatticeTopology::default(),
            a: StencilTable::default(),
            part: Partition {
                free: Vec::new(),
                a1: StencilTable::default(),
                a1t: StencilTable::default(),
                mass_factor: None,
            },
            mass: Vec::new(),
            springs: SpringNetwork::default(),
            ropes: Vec::new(),
            d: Vec::new(),
            dd: Vec::new(),
            precond: None,
            last_dv: Vec::new(),
            hess: Default::default(),
            pattern: None,
            time: 0.0,
        };
        solid.rebuild_all()?;
        Ok(solid)
    }

    /// Rebuilds everything below the control lattice: hierarchy to level `L`,
    /// `A`, springs (rest lengths from `A p_rest`), masses, partition.
    pub(crate) fn rebuild_all(&mut self) -> Result<()> {
        let level = self.params.level;
        let h = LatticeHierarchy::from_topology(&self.control.topology, &self.control.tags, level)?;
        self.a = h.stencil_to_level(level)?;
        let mut levels = h.levels;
        self.fine = levels
            .pop()
            .map(|l| l.topology)
            .ok_or_else(|| Error::input("empty lattice hierarchy"))?;
        let rest = self.a.apply(&self.p_rest)?;
        self.springs = SpringNetwork::new(&self.fine, &rest)?;
        self.mass = lumped_masses(&self.fine, &rest, self.params.density)?;
        self.pattern = None;
        self.rebuild_partition()
    }

    /// Rebuilds `A₁`, `A₁ᵀ` and the factor of `A₁ᵀ M A₁` for the current fixed set.
    pub(crate) fn rebuild_partition(&mut self) -> Result<()> {
        let free: Vec<usize> = (0..self.p.len()).filter(|&i| !self.fixed[i]).collect();
        let a1t = self.a.transpose().select_rows(&free);
        let a1 = a1t.transpose();
        let mass_factor = if free.is_empty() {
            None
        } else {
            let m_hat = a1t.compose(&a1.scale_rows(&self.mass)?)?;
            Some(cholesky(&m_hat, "control-point mass matrix A₁ᵀMA₁")?)
        };
        for (i, v) in self.v.iter_mut().enumerate() {
            if self.fixed[i] {
                *v = Vector3::zeros();
            }
        }
        self.part = Partition {
            free,
            a1,
            a1t,
            mass_factor,
        };
        self.precond = None;
        self.last_dv.clear();
        self.refresh();
        Ok(())
    }

    /// `d = A p`, `ḋ = A ṗ` (fixed points have zero velocity, so this is `A₁ ṗ₁`).
    pub(crate) fn refresh(&mut self) {
        self.d.resize(self.a.num_rows(), Point3::origin());
        self.dd.resize(self.a.num_rows(), Vector3::zeros());
        self.a.apply_into(&self.p, &mut self.d);
        self.a.apply_into(&self.v, &mut self.dd);
    }

    /// Control-point positions `p`.
    pub fn control_points(&self) -> &[Point3] {
        &self.p
    }

    /// Control-point velocities `ṗ`.
    pub fn control_velocities(&self) -> &[Vector3] {
        &self.v
    }

    /// Rest positions of the control points (the shape the springs rest in).
    pub fn rest_control_points(&self) -> &[Point3] {
        &self.p_rest
    }

    /// The control lattice in its current shape.
    pub fn control_lattice(&self) -> Lattice {
        Lattice {
            positions: self.p.clone(),
            topology: self.control.topology.clone(),
            tags: self.control.tags.clone(),
        }
    }

    /// Which control points are fixed.
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }

    /// Mass points `d = A p`.
    pub fn mass_points(&self) -> &[Point3] {
        &self.d
    }

    /// Mass-point velocities `ḋ = A ṗ`.
    pub fn mass_velocities(&self) -> &[Vector3] {
        &self.dd
    }

    /// Lumped mass of every mass point.
    pub fn masses(&self) -> &[Real] {
        &self.mass
    }

    /// The level-`L` lattice topology the springs live on.
    pub fn fine_topology(&self) -> &LatticeTopology {
        &self.fine
    }

    /// `A` (mass points × control points).
    pub fn subdivision_matrix(&self) -> &StencilTable {
        &self.a
    }

    /// The spring network.
    pub fn springs(&self) -> &SpringNetwork {
        &self.springs
    }

    /// The parameters in force.
    pub fn params(&self) -> &SolidParams {
        &self.params
    }

    /// Simulated time.
    pub fn time(&self) -> Real {
        self.time
    }

    /// Kinetic energy `½ Σ m_i |ḋ_i|² = ½ ṗᵀ AᵀMA ṗ`.
    pub fn kinetic_energy(&self) -> Real {
        0.5 * self
            .mass
            .iter()
            .zip(&self.dd)
            .map(|(m, v)| m * v.norm_squared())
            .sum::<Real>()
    }

    /// Energy stored in the normal and virtual springs.
    pub fn spring_energy(&self) -> Real {
        self.springs.energy(&self.d, self.params.stiffness)
    }

    /// Energy stored in the rope springs.
    pub fn rope_energy(&self) -> Real {
        self.ropes
            .iter()
            .fold(0.0, |s, r| s + r.force_energy(&self.d).1)
    }

    /// Kinetic plus spring energy (ropes excluded: they are external).
    pub fn energy(&self) -> Real {
        self.kinetic_energy() + self.spring_energy()
    }

    /// Linear momentum `Σ m_i ḋ_i`.
    pub fn momentum(&self) -> Vector3 {
        self.mass
            .iter()
            .zip(&self.dd)
            .fold(Vector3::zeros(), |s, (m, v)| s + *m * v)
    }

    /// The boundary surface of the level-`L` lattice: its boundary faces over
    /// the mass points they use (renumbered).
    pub fn boundary_mesh(&self) -> Result<crate::mesh::PolyMesh> {
        let t = &self.fine;
        let mut map = vec![u32::MAX; self.d.len()];
        let mut positions = Vec::new();
        let mut faces = Vec::new();
        for f in t.boundary_faces() {
            let loop_: Vec<u32> = t
                .faces
                .row(f as usize)
                .iter()
                .map(|&v| {
                    if map[v as usize] == u32::MAX {
                        map[v as usize] = positions.len() as u32;
                        positions.push(self.d[v as usize]);
                    }
                    map[v as usize]
                })
                .collect();
            faces.push(loop_);
        }
        crate::mesh::PolyMesh::from_faces(positions, &faces)
    }

    /// The damping forces `−γ m_i ḋ_i` on the mass points.
    pub(crate) fn damping_forces(&self) -> Vec<Vector3> {
        self.mass
            .iter()
            .zip(&self.dd)
            .map(|(m, v)| -self.params.damping * m * v)
            .collect()
    }

    /// Total forces on the mass points: springs, ropes and damping `−γ m_i ḋ_i`;
    /// returns them with the spring energy.
    pub(crate) fn mass_point_forces(&self) -> (Vec<Vector3>, Real) {
        let mut f = self.damping_forces();
        let e = self
            .springs
            .add_forces(&self.d, self.params.stiffness, &mut f);
        for r in &self.ropes {
            f[r.point] += r.force_energy(&self.d).0;
        }
        (f, e)
    }
}
