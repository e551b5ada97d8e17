//! Parameters of point-cloud fitting, with their defaults.

use crate::error::{Error, Result};
use crate::forces::RobustKernel;
use crate::math::Real;

/// Which error statistic the tolerance applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToleranceStat {
    /// The largest data-to-surface distance (the paper's error; any outlier
    /// keeps it high).
    Max,
    /// The 95th percentile of the distances (default: robust to outliers).
    P95,
    /// The root mean square distance.
    Rms,
    /// The mean distance.
    Mean,
}

/// How a level that settled above the tolerance is refined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refinement {
    /// Every face is split (uniform Catmull-Clark, the paper's scheme): the
    /// new control points describe the same surface.
    Uniform,
    /// Only the faces whose data residual is above the noise are split
    /// ([`faces_above_noise`](super::refine_marks::faces_above_noise),
    /// [`refine_marked`](crate::subdivision::refine_marked)). The default:
    /// on the benchmark scans it reaches the same or better accuracy with
    /// 30–78 % fewer control points, in up to 1.6 × the time. Its
    /// transitions (T-vertices, n-gons) fit less well than regular faces, so
    /// a level can end worse than its parent (a sphere with a narrow bump
    /// from a coarse cage, the torus scan); such a level is replaced by a
    /// uniform one (see the driver).
    Adaptive,
}

/// Options of [`fit_point_cloud`](super::fit_point_cloud). Distances are in %
/// of the data's bounding-box diagonal (the object's diameter).
#[derive(Clone, Debug, PartialEq)]
pub struct FitParams {
    /// Stop when this statistic of the data-to-surface distances is at or
    /// below `tolerance_pct` % of the diameter (default 0.1 %). The
    /// distances are those of the points kept in the springs
    /// ([`LevelReport::kept_error`](super::LevelReport)): with 5 % outliers
    /// left out, the 95th percentile of all points is an outlier's distance,
    /// and the fit refined to the last level for them (spot, 5 % outliers:
    /// three levels, 3,445 control points, 1,872 crossing triangle pairs,
    /// against one level, 2,679, none).
    pub tolerance_pct: Real,
    /// The statistic `tolerance_pct` applies to (default [`ToleranceStat::P95`]).
    pub tolerance_stat: ToleranceStat,
    /// Subdivision levels allowed above the initial control mesh (default 3).
    pub max_level: usize,
    /// Implicit steps per level at most (default 20).
    pub max_steps: usize,
    /// A level has settled when the energy changes by less than this fraction
    /// between steps (default 1e-3) …
    pub energy_tolerance: Real,
    /// … or when a step lowers the RMS of the nearest 95 % of the
    /// data-to-surface distances (robust to up to 5 % outliers) by less than
    /// this fraction (default 0.01; 0 turns this test off).
    pub error_tolerance: Real,
    /// Closest points are found by Newton descent from the previous step's
    /// answers; every `reseed_every` steps (default 4) also from the nearest
    /// seed sample, which catches a point whose closest surface part has
    /// changed but needs the seeds' k-d tree rebuilt.
    pub reseed_every: usize,
    /// Uniform or adaptive refinement between levels (default
    /// [`Refinement::Adaptive`]).
    pub refinement: Refinement,
    /// Adaptive refinement splits a face when its mean squared data distance
    /// exceeds the noise variance by this many standard errors (default 3).
    pub refine_significance: Real,
    /// Adaptive refinement also splits a face when one of its surface samples
    /// is farther from its nearest data point than this many times the
    /// median of those distances over the surface (default 4; 0 turns it
    /// off): a web across a gap in the data, which no data point is closest
    /// to, so the residual test never splits it.
    pub refine_off_data: Real,
    /// Stop subdividing when a level lowers the `tolerance_stat` error by
    /// less than this fraction (default 0.1): a finer level would gain little.
    pub min_level_gain: Real,
    /// With the 95th-percentile statistic, the tolerance is also met when
    /// that percentile is at most this multiple of the estimated noise `σ̃`
    /// ([`crate::fit::init::outliers::Screening::noise`]; default 2.05, 0
    /// turns it off). For Gaussian noise along the normal a perfect fit
    /// leaves a 95th percentile of 1.96 σ; a finer level would fit the
    /// noise. Chosen on the choose half of the corpus (spot, sphere, torus,
    /// fandisk, plate at 0.1 % and 0.3 % noise; `benches/compare`): 2.2
    /// stopped the torus at 0.1 % noise and spot at 0.3 % a level early
    /// (Chamfer 0.033 % and 0.076 % against Poisson's 0.025 % and 0.075 %),
    /// 2.05 and 1.98 take the same levels on every choose shape; checked on
    /// the other half (anvil, bracket, bulb, chair, cow, dragon, genus 2,
    /// rocker arm), where it helps the anvil (0.041 % → 0.025 %) and makes
    /// no Chamfer distance worse by more than 2 % (the Hausdorff distance
    /// of genus 2 at 0.3 % noise grows from 0.60 % to 0.90 %).
    pub noise_tolerance: Real,
    /// Do not subdivide when the next level would have more control points
    /// than this fraction of the data points (default 0.5).
    pub max_control_fraction: Real,
    /// Tension weight `λ_t`: `α11 = α22 = λ_t / A` with `A` the parameter
    /// area (the number of faces; default 1e-5). Tension shrinks the surface,
    /// so keep it small.
    pub tension: Real,
    /// Bending weight `λ_b`: `β11 = β22 = λ_b / A`, `β12 = 2 λ_b / A`
    /// (default 1e-4).
    pub bending: Real,
    /// Damping over the time step, `γ / Δt`, relative to the total data
    /// weight (default 0.05): the proximal term of the implicit step.
    pub damping: Real,
    /// Mass over the time step squared, `μ / Δt²`, relative to the total
    /// data weight like `damping` (default 0: the first-order, massless
    /// dynamics; above 0 the paper's second-order dynamics, see the driver).
    pub mass: Real,
    /// Weight of the surface-to-data springs (each surface sample pulled to
    /// its nearest data point) relative to the data-to-surface springs
    /// (default 0.5; 0 turns them off).
    pub surface_weight: Real,
    /// Robust kernel of the surface-to-data springs (default none: every
    /// sample pulls in proportion to its distance). A surface sample far
    /// from the data sits on a web the coarse cage spans across a gap the
    /// scan did not see into (the top of the slot between Spot's hind legs);
    /// its two halves are pulled towards the two walls, which folds the web
    /// into the slot only if the pull grows with the distance. With Huber
    /// weights (1.345 σ̂, the default before) the thin plate held such webs:
    /// Hausdorff 1.04–2.37 % on five of eight noise draws of the Spot scan,
    /// against 0.61–0.90 % on all eight without a kernel (together with
    /// `refine_off_data`). Outliers are out of the data before these springs
    /// are made (`drop_outliers`).
    pub surface_robust: RobustKernel,
    /// Leave the points that [`crate::fit::init::outliers::screen`]
    /// flags (far off the plane of their neighbours, or isolated) out of
    /// both kinds of springs (default true). The robust weights alone let a
    /// lone outlier near the surface pull a spike: it is admitted while the
    /// coarse levels' residuals are large and stays admitted once the
    /// surface has reached it. The error figures still cover every point.
    pub drop_outliers: bool,
    /// A level's springs use at most this many data points per control
    /// point (default 20), an even subsample of the cloud: coarse levels
    /// cannot resolve more, and the cost of a step follows the points used.
    /// The error of every level is still measured on all points.
    pub points_per_control_point: usize,
    /// The same for level 0 alone (default 10): its fit only starts the
    /// next level's, which refits every point it uses, so it needs fewer
    /// (on the Spot scan: the same final accuracy, 0.25 s less).
    pub first_level_points_per_control_point: usize,
    /// Relative residual at which the conjugate-gradient solve of each
    /// implicit step stops (default 1e-5): the step is re-linearised at once,
    /// so solving it further buys nothing.
    pub cg_tolerance: Real,
    /// Surface samples per side of every closest-point patch for the
    /// surface-to-data springs (default 2: 2 × 2 cell centres per patch).
    pub surface_samples: usize,
    /// Robust kernel of the data springs (default Huber, 1.345 σ̂). With
    /// `drop_outliers` the gross outliers are gone before the fit, and a
    /// monotone kernel bounds the pull of the points the surface has not
    /// reached yet without ignoring them, as Tukey's redescending biweight
    /// (4.685 σ̂) does: on the Spot scan Tukey left the slit under the tail
    /// bridged (Hausdorff 1.30 % against 1.06 % with Huber, Chamfer 0.0333 %
    /// against 0.0303 %). Without `drop_outliers`, Tukey's kernel is the one
    /// that keeps outliers from pulling.
    pub robust: RobustKernel,
    /// Uniform level of the closest-point patches, which also carry the
    /// thin plate and the surface samples (default 1).
    pub patch_level: usize,
    /// Gauss-Legendre points per side of every polynomial piece (default 4).
    pub quadrature_order: usize,
    /// Weight `λ_u` of the control net's umbrella energy
    /// ([`crate::fit::fairness`]), `λ_u / n` per control point of a level
    /// with `n` (default 0.1, 0 turns it off): it keeps the springs from
    /// pulling control points out into spikes, which pleat the limit
    /// surface through itself. Chosen on the corpus's choose shapes (Spot,
    /// fandisk, sphere, torus, plate; 0, 0.03, 0.1, 0.3 and 1 tried): 0.1
    /// cut the self-intersections 10–30 fold and lowered the Chamfer
    /// distance on all of them but the torus at 0.1 % noise; 1 rounds
    /// thin parts off.
    pub fairness: Real,
    /// Untangling rounds per level (default 2; 0 turns it off). After a
    /// level's steps its limit surface is tessellated and checked for
    /// triangles that cross ([`crate::fit::quality::SelfIntersections`]);
    /// the control points of the faces they lie on get a few Taubin
    /// smoothing steps, their umbrella weights and their neighbours' are
    /// multiplied by `untangle_stiffening`, and the level is refitted from
    /// there. The next level starts from `fairness` again.
    pub untangle_rounds: usize,
    /// The factor by which each untangling round raises the umbrella
    /// weights it marks (default 10; more than 1).
    pub untangle_stiffening: Real,
    /// Untangling rounds after the last level (default 4; 0 turns them
    /// off): the limit surface is checked at the rate of `--limit-out`
    /// ([`crate::fit::quality::CHECK_RATE`]) and the control points of the
    /// faces it crosses itself on get the same Taubin steps, without a
    /// refit, which would pull the pleat back towards the points that made
    /// it; rounds go on while the crossing pairs get fewer, and the best
    /// positions are kept. Chosen on the corpus's choose shapes (Spot,
    /// fandisk, plate, sphere, torus; pairs in the corpus benchmark's
    /// count): 13 → 0 (spot-n1), 39 → 0, 98 → 2, 29 → 0 (fandisk n3, out,
    /// points), 351 → 0, 285 → 0 (plate n1, out), no Chamfer distance
    /// changed by more than 0.0001 % of the diagonal; checked on the rest:
    /// 71 → 0, 72 → 0 (cow n1, n3), 9 → 0 twice (rocker arm), 53 → 0 (chair
    /// n3), Chamfer within 0.0002 %. Crossings between parts grown into each
    /// other (webs: dragon, bracket, chair at 0.1 %, the outlier scans) fall
    /// by 0–67 % only (the single view bun045: 3 % fewer by the fit's own
    /// count, 2 % more by the benchmark's).
    pub final_untangle_rounds: usize,
    /// Sharp creases (`super::creases`): after level 0, control edges along
    /// which the data's two sides are flat planes meeting at this angle or
    /// more (degrees) and the smooth surface misses the points between them
    /// are tagged infinitely sharp, level 0 is fitted again, and the tags
    /// are kept (and carried through the refinements) if that fit is not
    /// worse (default 50; 0 turns creases off). The result's
    /// [`FitResult::creases`](super::FitResult::creases) lists them. Chosen
    /// on the corpus's choose rows: 30, 40, 50 and 60 tag the same edges on
    /// plate and within 10 % on fandisk (n1, n3, points), while Spot's leg
    /// and ear junctions (smooth, but sharp at level 0's scale) take 17,
    /// 22, 14, 14 edges at 0.3 % noise; checked on the others: genus 2 at
    /// 0.1 % noise 6 → 0 edges from 30 to 50, dragon 16 → 10.
    pub crease_angle: Real,
}

impl Default for FitParams {
    fn default() -> Self {
        FitParams {
            tolerance_pct: 0.1,
            tolerance_stat: ToleranceStat::P95,
            max_level: 3,
            max_steps: 20,
            energy_tolerance: 1e-3,
            error_tolerance: 0.01,
            reseed_every: 4,
            refinement: Refinement::Adaptive,
            refine_significance: 3.0,
            refine_off_data: 4.0,
            min_level_gain: 0.1,
            noise_tolerance: 2.05,
            max_control_fraction: 0.5,
            tension: 1e-5,
            bending: 1e-4,
            damping: 0.05,
            mass: 0.0,
            surface_weight: 0.5,
            surface_robust: RobustKernel::None,
            drop_outliers: true,
            cg_tolerance: 1e-5,
            points_per_control_point: 20,
            first_level_points_per_control_point: 10,
            surface_samples: 2,
            robust: RobustKernel::Huber(1.345),
            patch_level: 1,
            quadrature_order: 4,
            fairness: 0.1,
            untangle_rounds: 2,
            untangle_stiffening: 10.0,
            final_untangle_rounds: 4,
            crease_angle: 50.0,
        }
    }
}

impl FitParams {
    /// Checks every value; the error names the parameter.
    pub fn check(&self) -> Result<()> {
        let bad = |name: &str, v: Real, what: &str| {
            Err(Error::input(format!("fit parameter {name} = {v}: {what}")))
        };
        if !(self.tolerance_pct.is_finite()
            && self.tolerance_pct > 0.0
            && self.tolerance_pct < 100.0)
        {
            return bad(
                "tolerance_pct",
                self.tolerance_pct,
                "expected 0 < tol < 100 (%)",
            );
        }
        if self.max_level > 5 {
            return bad(
                "max_level",
                self.max_level as Real,
                "at most 5 levels (each multiplies the faces by 4)",
            );
        }
        if self.max_steps == 0 || self.max_steps > 10_000 {
            return bad("max_steps", self.max_steps as Real, "expected 1 to 10000");
        }
        for (name, v) in [
            ("energy_tolerance", self.energy_tolerance),
            ("error_tolerance", self.error_tolerance),
            ("min_level_gain", self.min_level_gain),
            ("noise_tolerance", self.noise_tolerance),
            ("max_control_fraction", self.max_control_fraction),
            ("tension", self.tension),
            ("bending", self.bending),
            ("damping", self.damping),
            ("mass", self.mass),
            ("surface_weight", self.surface_weight),
            ("refine_significance", self.refine_significance),
            ("refine_off_data", self.refine_off_data),
            ("fairness", self.fairness),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "must be finite and ≥ 0");
            }
        }
        if !(self.crease_angle.is_finite() && (0.0..180.0).contains(&self.crease_angle)) {
            return bad(
                "crease_angle",
                self.crease_angle,
                "expected 0 (off) to below 180 degrees",
            );
        }
        if !(self.untangle_stiffening.is_finite() && self.untangle_stiffening > 1.0) {
            return bad(
                "untangle_stiffening",
                self.untangle_stiffening,
                "expected a finite factor above 1",
            );
        }
        for (name, rounds) in [
            ("untangle_rounds", self.untangle_rounds),
            ("final_untangle_rounds", self.final_untangle_rounds),
        ] {
            if rounds > 10 {
                return bad(name, rounds as Real, "expected 0 to 10");
            }
        }
        if self.points_per_control_point == 0 {
            return bad("points_per_control_point", 0.0, "expected at least 1");
        }
        if self.first_level_points_per_control_point == 0 {
            return bad(
                "first_level_points_per_control_point",
                0.0,
                "expected at least 1",
            );
        }
        if !(self.cg_tolerance > 0.0 && self.cg_tolerance < 1.0) {
            return bad(
                "cg_tolerance",
                self.cg_tolerance,
                "expected 0 < tolerance < 1",
            );
        }
        if !(1..=8).contains(&self.surface_samples) {
            return bad(
                "surface_samples",
                self.surface_samples as Real,
                "expected 1 to 8",
            );
        }
        if self.reseed_every == 0 {
            return bad("reseed_every", 0.0, "expected at least 1");
        }
        if !(1..=4).contains(&self.patch_level) {
            return bad("patch_level", self.patch_level as Real, "expected 1 to 4");
        }
        if self.refinement == Refinement::Adaptive && self.patch_level != 1 {
            return bad(
                "patch_level",
                self.patch_level as Real,
                "adaptive refinement needs patch_level 1",
            );
        }
        if !(2..=8).contains(&self.quadrature_order) {
            return bad(
                "quadrature_order",
                self.quadrature_order as Real,
                "expected 2 to 8",
            );
        }
        Ok(())
    }
}
