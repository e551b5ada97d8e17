//! The multilevel loop that the point-cloud fit and the volume recovery
//! share (Qin, Mandal, Vemuri 1998, §6: the model settles at a level, and
//! is subdivided while its error is above the tolerance), and its rules.
//!
//! [`run_levels`] owns the loop: it checks each level's memory, builds its
//! [`Refiner`], lets the force source ([`LevelFit`]: the fit's data springs,
//! the recovery's image forces) set the level up and settle it, applies the
//! shared stop rules ([`stop_after_level`]) to what the source measured, and
//! refines, uniformly or by splitting the faces the source ranks
//! ([`split_within`]), carrying the creases.

use super::crease_options;
use super::creases::{Crease, refined_creases};
use super::system::check_level_memory;
use crate::error::Result;
use crate::limit::{interpolate_limit_points, limit_stencil};
use crate::math::{Point3, Real};
use crate::mesh::PolyMesh;
use crate::subdivision::{Hierarchy, LocalRefinement, Refiner, close_marks, refine_marked};

/// Iterations of progressive interpolation that put a locally refined
/// level's surface on its parent's.
const LIMIT_ITERATIONS: usize = 60;

/// What a force source says after settling a level ([`LevelFit::fit_level`]).
pub(crate) enum Verdict {
    /// Fit the same level again: the source changed the mesh or its
    /// creases (fitted again with creases found, or refined otherwise).
    Again,
    /// Stop here: converged or not, and why.
    Stop(bool, String),
    /// The level is measured: the shared stop rules decide
    /// ([`stop_after_level`]'s `met`, `gain` and `measure`).
    Judge {
        met: Option<String>,
        gain: Option<(Real, Real)>,
        measure: String,
    },
}

/// How the source wants the level refined ([`LevelFit::refinement`]).
pub(crate) enum Refine {
    /// Every face split.
    Uniform,
    /// The faces of `rank` split, worst first, within `cap` control points
    /// ([`split_within`]).
    Adaptive { rank: Vec<usize>, cap: Real },
    /// No finer level: converged or not, and why.
    Stop(bool, String),
}

/// The next level [`run_levels`] made, shown to the source before it is
/// fitted ([`LevelFit::refined`]).
pub(crate) enum Refined<'a> {
    /// One uniform refinement of the level.
    Uniform,
    /// The split faces (the split's mesh and creases moved to the next
    /// level: [`Next::mesh`]).
    Adaptive(&'a Split),
}

/// The level a source fits ([`LevelFit::fit_level`]): its number, its
/// control mesh and creases (which the source may replace, see
/// [`Verdict::Again`]) and their refiner.
pub(crate) struct Level<'a> {
    pub number: usize,
    pub refiner: &'a Refiner,
    pub mesh: &'a mut PolyMesh,
    pub creases: &'a mut Vec<Crease>,
}

/// The refinement [`run_levels`] made of the level just fitted, shown to
/// the source before it is fitted ([`LevelFit::refined`]).
pub(crate) struct Next<'a> {
    /// The fitted level's number, control mesh and creases.
    pub level: usize,
    pub parent: &'a PolyMesh,
    pub creases: &'a [Crease],
    /// How it was refined, and the refined control mesh.
    pub how: Refined<'a>,
    pub mesh: &'a PolyMesh,
}

/// A force source of the multilevel loop.
pub(crate) trait LevelFit {
    /// Sets up the level, settles it and measures it: its mesh ends with
    /// the fitted positions (or whatever mesh the verdict stands for).
    fn fit_level(&mut self, level: Level) -> Result<Verdict>;

    /// How the level just fitted is refined, once the stop rules go on.
    fn refinement(&mut self, level: usize, mesh: &PolyMesh) -> Result<Refine>;

    /// The next level is made: `Some` stops before fitting it (a budget
    /// passed).
    fn refined(&mut self, next: Next) -> Result<Option<(bool, String)>>;
}

/// Runs the levels of `source` from `mesh` (with its `creases`) until a
/// stop rule or the source ends them: at most `max_level`, and stopping
/// when a level lowers the error measure by less than `min_gain`. `mesh` and
/// `creases` end as the last level's; returns whether the run converged
/// and why it stopped.
pub(crate) fn run_levels(
    source: &mut dyn LevelFit,
    mesh: &mut PolyMesh,
    creases: &mut Vec<Crease>,
    max_level: usize,
    min_gain: Real,
) -> Result<(bool, String)> {
    let mut level = 0;
    loop {
        check_level_memory(level, mesh.num_faces())?;
        let refiner = Refiner::new(mesh, &crease_options(creases))?;
        let fitting = Level {
            number: level,
            refiner: &refiner,
            mesh,
            creases,
        };
        match source.fit_level(fitting)? {
            Verdict::Again => continue,
            Verdict::Stop(converged, reason) => return Ok((converged, reason)),
            Verdict::Judge { met, gain, measure } => {
                if let Some(stop) =
                    stop_after_level(level, met, max_level, gain, min_gain, &measure)
                {
                    return Ok(stop);
                }
            }
        }
        let how = source.refinement(level, mesh)?;
        if let Refine::Stop(converged, reason) = how {
            return Ok((converged, reason));
        }
        let h = refiner.refine_uniform(1)?;
        let (next, next_creases, split) = match how {
            Refine::Adaptive { rank, cap } => {
                let mut split = split_within(mesh, &h, creases, &rank, cap)?;
                let next = std::mem::take(&mut split.local.mesh);
                let next_creases = std::mem::take(&mut split.creases);
                (next, next_creases, Some(split))
            }
            _ => {
                let next = h.mesh(1, h.stencil(0).apply(&mesh.positions)?);
                let next_creases = refined_creases(&h, &next, None, creases);
                (next, next_creases, None)
            }
        };
        let how = split.as_ref().map_or(Refined::Uniform, Refined::Adaptive);
        if let Some(stop) = source.refined(Next {
            level,
            parent: mesh,
            creases,
            how,
            mesh: &next,
        })? {
            return Ok(stop);
        }
        *mesh = next;
        *creases = next_creases;
        level += 1;
    }
}

/// Whether a run stops after `level`, and why: `met` is the reason when
/// the level meets the driver's tolerance (the run has converged); else the
/// run stops at `max_level`, or when `gain` (the level's error measure and
/// its parent's, `None` when the rule does not apply) shows a fall by less
/// than `min_gain` of the parent's — a finer level would gain little.
/// `measure` names the error measure in that reason. `None`: go on.
pub(crate) fn stop_after_level(
    level: usize,
    met: Option<String>,
    max_level: usize,
    gain: Option<(Real, Real)>,
    min_gain: Real,
    measure: &str,
) -> Option<(bool, String)> {
    if let Some(reason) = met {
        return Some((true, reason));
    }
    if level >= max_level {
        return Some((
            false,
            format!("maximum level {level} reached above the tolerance"),
        ));
    }
    match gain {
        Some((last, parent)) if last > (1.0 - min_gain) * parent => Some((
            false,
            format!(
                "level {level} lowered the {measure} by less than {:.0} %: a finer level would gain little",
                100.0 * min_gain
            ),
        )),
        _ => None,
    }
}

/// A level fitted worse than its parent: both its RMS and its 95th
/// percentile are above the parent's. The fit then refines the parent
/// uniformly instead of adaptively; the recovery returns the parent.
pub(crate) fn fitted_worse(last: (Real, Real), parent: (Real, Real)) -> bool {
    last.0 > parent.0 && last.1 > parent.1
}

/// What [`split_within`] made.
pub(crate) struct Split {
    /// The split faces (closed by [`close_marks`]).
    pub marks: Vec<bool>,
    /// The refinement.
    pub local: LocalRefinement,
    /// Its creases ([`refined_creases`]).
    pub creases: Vec<Crease>,
    /// How many ranked faces were left unsplit for the budget.
    pub left: usize,
}

/// [`locally_refined`] with the first faces of `rank` split (closed by
/// [`close_marks`]): all of them when the result has at most `cap` control
/// points, else the longest prefix that keeps within it (found by
/// bisection; the count grows with the prefix), else all of them, for the
/// caller's budget test to stop at. `creases` are `mesh`'s (`h` is refined
/// with them).
pub(crate) fn split_within(
    mesh: &PolyMesh,
    h: &Hierarchy,
    creases: &[Crease],
    rank: &[usize],
    cap: Real,
) -> Result<Split> {
    let split = |k: usize| -> Result<Split> {
        let mut marks = vec![false; mesh.num_faces()];
        for &f in &rank[..k] {
            marks[f] = true;
        }
        let marks = close_marks(h.level(0), &marks);
        let (local, creases) = locally_refined(mesh, h, creases, &marks)?;
        Ok(Split {
            marks,
            local,
            creases,
            left: rank.len() - k,
        })
    };
    let all = split(rank.len())?;
    if all.local.mesh.num_vertices() as Real <= cap {
        return Ok(all);
    }
    // The longest prefix within the budget: `lo` fits (or is 0), `hi` does not.
    let (mut lo, mut hi, mut best) = (0, rank.len(), None);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        let tried = split(mid)?;
        if tried.local.mesh.num_vertices() as Real <= cap {
            lo = mid;
            best = Some(tried);
        } else {
            hi = mid;
        }
    }
    Ok(best.unwrap_or(all))
}

/// `mesh` with its `marked` faces split ([`refine_marked`]; `h` is one
/// uniform refinement of it), the new control points placed so that the
/// limit point of every vertex of a split or changed face lies on `mesh`'s
/// limit surface where the vertex it stands for in uniform refinement has
/// its limit point ([`interpolate_limit_points`]; the other vertices keep
/// their positions, so the surface away from the split faces is unchanged),
/// with its creases (`mesh`'s are `creases`, [`refined_creases`]).
fn locally_refined(
    mesh: &PolyMesh,
    h: &Hierarchy,
    creases: &[Crease],
    marked: &[bool],
) -> Result<(LocalRefinement, Vec<Crease>)> {
    let mut local = refine_marked(mesh, h.level(0), h.stencil(0), marked)?;
    let child_creases = refined_creases(h, &local.mesh, Some(&local.uniform_vertex), creases);
    let parent_limit = limit_stencil(h, 1)?.apply(&mesh.positions)?;
    let targets: Vec<Point3> = local
        .uniform_vertex
        .iter()
        .map(|&u| parent_limit[u as usize])
        .collect();
    let mut movable = vec![false; local.mesh.num_vertices()];
    for (g, &f) in local.parent_face.iter().enumerate() {
        let face = local.mesh.face(g);
        if face != mesh.face(f as usize) {
            for &v in face {
                movable[v as usize] = true;
            }
        }
    }
    (local.mesh.positions, _) = interpolate_limit_points(
        &local.mesh,
        &crease_options(&child_creases),
        &targets,
        &movable,
        LIMIT_ITERATIONS,
    )?;
    Ok((local, child_creases))
}
