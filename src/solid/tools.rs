//! Sculpting tools (McDonnell & Qin, §5.4): the rope tool, fixing and
//! freeing control points, run-time stiffness and damping, make plastic.
//! Extrusion and trimming live in [`edit`](super::edit).
//!
//! What each tool rebuilds: ropes nothing; fix / free the partition
//! (`A₁`, `A₁ᵀ`, factor of `A₁ᵀ M A₁`) and drop the implicit preconditioner;
//! stiffness and damping only drop the preconditioner; make plastic only
//! resets rest lengths.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use super::model::Solid;
use super::params::check_value;
use super::springs::Stiffness;

/// A rope: a spring from mass point `point` to a moving target that pulls
/// only when longer than its rest length (the paper's "non-compressible rope
/// tool"): force `k (l − L) u` towards the target for `l > L`, energy
/// `½ k (l − L)²`.
#[derive(Clone, Debug, PartialEq)]
pub struct Rope {
    /// The mass point it pulls.
    pub point: usize,
    /// Where its other end is.
    pub target: Point3,
    /// Stiffness `k` (force per length).
    pub stiffness: Real,
    /// Rest length `L` (0: the point is dragged onto the target).
    pub rest_length: Real,
}

impl Rope {
    /// Force on the mass point and the rope's energy, at mass points `d`.
    pub fn force_energy(&self, d: &[Point3]) -> (Vector3, Real) {
        let to = self.target - d[self.point];
        let l = to.norm();
        if l <= self.rest_length || l == 0.0 {
            return (Vector3::zeros(), 0.0);
        }
        let s = l - self.rest_length;
        (to * (self.stiffness * s / l), 0.5 * self.stiffness * s * s)
    }

    /// `H w` with the rope's Hessian at `d` (zero when slack; transverse term clamped).
    pub fn hessian_times(&self, d: &[Point3], w: Vector3) -> Vector3 {
        let to = self.target - d[self.point];
        let l = to.norm();
        if l <= self.rest_length || l == 0.0 {
            return Vector3::zeros();
        }
        let u = to / l;
        let along = u * u.dot(&w);
        (along + (w - along) * (1.0 - self.rest_length / l)) * self.stiffness
    }
}

impl Solid {
    /// The mass point closest to `q` (the paper's linear search).
    pub fn nearest_mass_point(&self, q: &Point3) -> usize {
        let mut best = (Real::INFINITY, 0);
        for (i, d) in self.d.iter().enumerate() {
            let s = (d - q).norm_squared();
            if s < best.0 {
                best = (s, i);
            }
        }
        best.1
    }

    /// Attaches a rope to mass point `point`; returns its index.
    pub fn add_rope(
        &mut self,
        point: usize,
        target: Point3,
        stiffness: Real,
        rest_length: Real,
    ) -> Result<usize> {
        if point >= self.d.len() {
            return Err(Error::out_of_range(format!(
                "rope: mass point {point} does not exist ({} mass points)",
                self.d.len()
            )));
        }
        check_target(&target)?;
        check_value("rope stiffness", stiffness, true)?;
        check_value("rope rest length", rest_length, false)?;
        self.ropes.push(Rope {
            point,
            target,
            stiffness,
            rest_length,
        });
        Ok(self.ropes.len() - 1)
    }

    /// Moves the far end of rope `rope`.
    pub fn set_rope_target(&mut self, rope: usize, target: Point3) -> Result<()> {
        check_target(&target)?;
        let n = self.ropes.len();
        let r = self.ropes.get_mut(rope).ok_or_else(|| {
            Error::out_of_range(format!("rope {rope} does not exist ({n} ropes)"))
        })?;
        r.target = target;
        Ok(())
    }

    /// The ropes attached.
    pub fn ropes(&self) -> &[Rope] {
        &self.ropes
    }

    /// Removes every rope.
    pub fn release_ropes(&mut self) {
        self.ropes.clear();
    }

    /// Fixes (`fixed = true`) or frees control points; rebuilds the partition
    /// (on error the fixed set is left unchanged). Fixed points stop.
    pub fn set_fixed(&mut self, points: &[usize], fixed: bool) -> Result<()> {
        if let Some(&i) = points.iter().find(|&&i| i >= self.p.len()) {
            return Err(Error::out_of_range(format!(
                "control point {i} does not exist ({} control points)",
                self.p.len()
            )));
        }
        let before = self.fixed.clone();
        for &i in points {
            self.fixed[i] = fixed;
        }
        let result = self.rebuild_partition();
        if result.is_err() {
            self.fixed = before;
        }
        result
    }

    /// Changes the spring stiffnesses (per unit rest length).
    pub fn set_stiffness(&mut self, stiffness: Stiffness) -> Result<()> {
        check_value("normal spring stiffness", stiffness.edge, false)?;
        check_value("virtual spring stiffness", stiffness.virtual_, false)?;
        self.params.stiffness = stiffness;
        self.precond = None;
        Ok(())
    }

    /// Changes the damping `γ` per unit mass.
    pub fn set_damping(&mut self, damping: Real) -> Result<()> {
        check_value("damping", damping, false)?;
        self.params.damping = damping;
        self.precond = None;
        Ok(())
    }

    /// Make plastic: every spring's rest length, virtual springs included,
    /// becomes its current length, so the current shape is the new rest
    /// shape (McDonnell & Qin, §5.4). Velocities are kept; see [`halt`](Self::halt).
    pub fn make_plastic(&mut self) -> Result<()> {
        self.springs.set_rest(&self.d)?;
        self.p_rest = self.p.clone();
        Ok(())
    }

    /// Sets control-point positions and velocities (a pose or a kick); the
    /// rest shape is unchanged and fixed points keep zero velocity.
    pub fn set_state(&mut self, p: &[Point3], v: &[Vector3]) -> Result<()> {
        if p.len() != self.p.len() || v.len() != self.p.len() {
            return Err(Error::size_mismatch(format!(
                "state of {} positions and {} velocities for {} control points",
                p.len(),
                v.len(),
                self.p.len()
            )));
        }
        if p.iter().any(|x| !x.coords.iter().all(|c| c.is_finite()))
            || v.iter().any(|x| !x.iter().all(|c| c.is_finite()))
        {
            return Err(Error::non_finite("state: a coordinate is not finite"));
        }
        self.p = p.to_vec();
        self.v = v
            .iter()
            .zip(&self.fixed)
            .map(|(v, &f)| if f { Vector3::zeros() } else { *v })
            .collect();
        self.refresh();
        Ok(())
    }

    /// Stops every motion (all velocities zero).
    pub fn halt(&mut self) {
        self.v.iter_mut().for_each(|v| *v = Vector3::zeros());
        self.refresh();
    }
}

fn check_target(t: &Point3) -> Result<()> {
    if t.coords.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::non_finite(format!(
            "rope target {:?} is not finite",
            t.coords.as_slice()
        )))
    }
}
