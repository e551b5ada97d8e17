//! The control-point system of one level, shared by the point-cloud fit
//! and the volume recovery: the thin plate `K`, the damping `D` and the
//! mass `M` assembled in the fixed pattern of a [`PatchAssembly`], and the
//! implicit step (Qin, Mandal, Vemuri 1998, eq. 16; assembled by
//! [`ImplicitSystem`]) that both drivers take, with the data springs
//! `Σ k JᵀJ`, `Σ k Jᵀ d` implicit and `f` any explicit load (inflation).
//! The time step is folded into the weights `μ/Δt²` and `γ/Δt` the callers
//! pass.

use crate::dynamics::{
    ImplicitSystem, MaterialParams, PcgParams, PcgReport, patch_damping_matrix, pcg,
    stiffness_and_damping_elements,
};
use crate::error::Result;
use crate::forces::{PatchAssembly, SpringSystem};
use crate::limit::PatchTable;
use crate::math::{Point3, Real};
use crate::memory::{bytes_of, check_memory};
use crate::stencil::StencilTable;

/// About the most bytes one level of the fit or of the recovery holds per
/// control face: its patches, samples, springs, this system, the closest-point
/// engine and the quality tessellations. Peak RSS ÷ the last level's control
/// faces was 73–97 kB on the fit's corpus (spot, sphere, bracket, chair,
/// dragon scans) and on the MNI T1 brain's recovery; rounded up.
pub(crate) const LEVEL_BYTES_PER_FACE: u64 = 100_000;

/// `Ok` when a level of `faces` control faces fits the memory budget
/// ([`crate::memory`]), else the error naming the estimate: checked before a
/// level is built, so a run that would outgrow memory (a huge cloud allowed
/// many control points, a fine uniform level) stops with one line instead.
pub(crate) fn check_level_memory(level: usize, faces: usize) -> Result<()> {
    check_memory(
        &format!("level {level} of {faces} control faces"),
        bytes_of(faces as u64, LEVEL_BYTES_PER_FACE),
    )
}

/// `K`, `D` and `M` of one control mesh in the pattern of its
/// [`PatchAssembly`], and the sums the step needs.
pub(crate) struct LevelSystem {
    /// The pattern the springs are assembled into.
    pub assembly: PatchAssembly,
    /// `K`'s values, without the fairness term.
    k_base: Vec<Real>,
    /// `K + D (+ M)`'s values, without the fairness term.
    kd_base: Vec<Real>,
    /// `K` with the fairness term: the stiffness energy's matrix.
    k: StencilTable,
    /// The step's matrices (`K + D (+ M)` with the fairness term, `D`, `M`).
    implicit: ImplicitSystem,
}

impl LevelSystem {
    /// The system on `table`'s patches: the thin plate of `material` and
    /// damping `gamma` per unit parameter area, both with `order × order`
    /// Gauss points per patch, plus a mass matrix of density `mass` (> 0)
    /// when given, plus `proximal` × the mean diagonal of the damping on
    /// the control points themselves (a term that keeps control-point
    /// modes the limit surface barely shows from drifting; 0 for none).
    pub fn new(
        table: &PatchTable,
        order: usize,
        material: &MaterialParams,
        gamma: Real,
        mass: Option<Real>,
        proximal: Real,
    ) -> Result<LevelSystem> {
        let assembly = PatchAssembly::new(table)?;
        let elements = stiffness_and_damping_elements(table, order, material, gamma)?;
        let [k, mut d] = assembly.values_of_elements(table, |f| elements.get(f))?;
        drop(elements);
        if proximal > 0.0 {
            let n = table.to_level().num_cols;
            let identity = assembly.values_of(&StencilTable::identity(n))?;
            let diagonal: Real = d.iter().zip(&identity).map(|(d, i)| d * i).sum();
            let delta = proximal * diagonal / n.max(1) as Real;
            for (d, i) in d.iter_mut().zip(&identity) {
                *d += delta * i;
            }
        }
        let mut kd_base: Vec<Real> = k.iter().zip(&d).map(|(a, b)| a + b).collect();
        let m = match mass {
            Some(mass) => {
                let m = patch_damping_matrix(table, order, mass)?;
                for (x, y) in kd_base.iter_mut().zip(assembly.values_of(&m)?) {
                    *x += y;
                }
                Some(m)
            }
            None => None,
        };
        Ok(LevelSystem {
            k: assembly.matrix(k.clone()),
            implicit: ImplicitSystem {
                base: assembly.matrix(kd_base.clone()),
                damping: assembly.matrix(d),
                mass: m,
            },
            assembly,
            k_base: k,
            kd_base,
        })
    }

    /// Adds `fairness` (a matrix inside the pattern, such as
    /// [`super::fairness::umbrella_matrix`]) to `K`, replacing the one
    /// added before.
    pub fn set_fairness(&mut self, fairness: &StencilTable) -> Result<()> {
        let u = self.assembly.values_of(fairness)?;
        self.implicit.base = self
            .assembly
            .matrix(self.kd_base.iter().zip(&u).map(|(a, b)| a + b).collect());
        self.k = self
            .assembly
            .matrix(self.k_base.iter().zip(&u).map(|(a, b)| a + b).collect());
        Ok(())
    }

    /// The stiffness energy `½ pᵀ K p`.
    pub fn potential(&self, p: &[Point3]) -> Result<Real> {
        let kp = self.k.apply(p)?;
        Ok(0.5
            * kp.iter()
                .zip(p)
                .map(|(a, b)| a.coords.dot(&b.coords))
                .sum::<Real>())
    }

    /// One implicit step ([`ImplicitSystem`]) from `p` (the previous
    /// step's positions in `p_before`, used by the mass term) with
    /// `springs` (their matrix in the assembly's pattern) and the explicit
    /// `load`: `p` becomes the solution, warm-started from itself,
    /// `p_before` the positions it left.
    pub fn step(
        &self,
        springs: SpringSystem,
        load: Option<&[Point3]>,
        p: &mut [Point3],
        p_before: &mut [Point3],
        cg: &PcgParams,
    ) -> Result<PcgReport> {
        let mut terms = vec![springs.rhs.as_slice()];
        terms.extend(load);
        let (a, rhs) = self
            .implicit
            .system(Some(springs.matrix), &terms, p, p_before)?;
        p_before.copy_from_slice(p);
        pcg(&a, &rhs, p, cg)
    }
}
