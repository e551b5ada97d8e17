//! The point-cloud fit as a force source of the shared multilevel loop
//! ([`super::levels::run_levels`]; Qin, Mandal, Vemuri 1998, §6): at each
//! level the data springs and the surface-to-data springs pull the limit
//! surface, the untangling rounds smooth and stiffen where it crosses
//! itself, the error over every point is measured, level 0 is fitted again
//! with the sharp creases found in the data, and an adaptive level that
//! fitted worse than its parent is replaced by the parent refined uniformly.
//! The faces to split are those whose residual is above the noise
//! ([`super::refine_marks`]) and the webs (surface samples off the data).

use std::time::Instant;

use kiddo::ImmutableKdTree;

use crate::error::{Error, Result};
use crate::limit::QuadtreeCache;
use crate::math::{Point3, Real, bbox_diagonal};
use crate::mesh::{PointCloud, PolyMesh};
use crate::subdivision::{CornerImage, Refiner};
use crate::topology::SHARPNESS_INFINITE;

use super::crease_options;
use super::creases::{Crease, CreaseData, detect_creases, refined_creases};
use super::init::outliers::{Screening, screen};
use super::levels::{Level, LevelFit, Next, Refine, Refined, Verdict, fitted_worse};
use super::refine_marks::{face_residuals, faces_above_noise, faces_off_data};
use super::sampling::shuffled_order;
use super::{FitParams, LevelReport, Refinement, ToleranceStat};

mod settle;
use settle::Settled;

/// A previous level's closest point carried to the next level.
enum Carried {
    /// At `(s, t)` of this base face of the new control mesh (located on
    /// its patches once they are built).
    Face(u32, [Real; 2]),
    /// At `(s, t)` of this patch of the new control mesh (the same surface
    /// piece, or where its face gained corners a nearby one: a start only).
    Patch(u32, [Real; 2]),
}

/// Level 0 as fitted without creases, while it is fitted again with them.
struct WithoutCreases {
    mesh: PolyMesh,
    dist: Vec<Real>,
    report: LevelReport,
}

/// What the refinement of the last fitted level ranks its faces by.
struct Residuals {
    /// Every point's robust weight, distance and control face.
    w: Vec<Real>,
    dist: Vec<Real>,
    face: Vec<u32>,
    /// The surface samples' distances to the data, when those springs act.
    surface_dist: Option<Vec<Real>>,
    /// The control face of each level-1 patch.
    face_of_patch: Vec<u32>,
    /// The used points' closest-point answers.
    last_hints: Vec<(u32, [Real; 2])>,
}

/// The fit of one point cloud, level after level ([`LevelFit`]).
pub(super) struct CloudFit<'a> {
    params: &'a FitParams,
    points: &'a [Point3],
    /// The screening: the points kept for the springs, and the noise.
    keep: Vec<bool>,
    pub data_noise: Real,
    /// The kept points, their indices in `points`, and their tree.
    pub data: Vec<Point3>,
    pub data_index: Vec<usize>,
    pub data_tree: ImmutableKdTree<Real, 3>,
    /// Each level uses a prefix of a fixed even shuffle of the kept points
    /// (`order`: their indices in `points`).
    order: Vec<usize>,
    shuffled: Vec<Point3>,
    pub diameter: Real,
    /// Most local structures at extraordinary vertices recur from level
    /// to level: their quadtrees are built once.
    pub quadtrees: QuadtreeCache,
    start: Instant,
    progress: &'a mut dyn FnMut(usize, usize, Real),
    /// The levels kept.
    pub levels: Vec<LevelReport>,
    /// The distances of the last level kept, to assess the result with, and
    /// its closest-point answers (of the points it used).
    pub final_dist: Vec<Real>,
    final_hints: Vec<(u32, [Real; 2])>,
    /// The previous level's closest points in this level's terms (see
    /// `Carried`).
    carried_hints: Option<Vec<Carried>>,
    /// How the level being fitted was made, for its report.
    refinement: String,
    /// The parent of an adaptive level, kept to refine it uniformly instead
    /// should the adaptive level fit worse.
    adaptive_parent: Option<(PolyMesh, Vec<Crease>)>,
    /// Level 0 as fitted without creases while it is fitted with them
    /// (the creases of the control mesh, `super::creases`, are found after
    /// level 0 and carried through the refinements).
    crease_pass: Option<WithoutCreases>,
    residuals: Option<Residuals>,
    /// Faces marked for their surface samples off the data (the report).
    webs: usize,
}

impl<'a> CloudFit<'a> {
    /// The fit of `cloud` with `params`, its outlier screening given or
    /// done here; `progress(level, step, energy)` after every step.
    pub fn new(
        cloud: &'a PointCloud,
        screening: Option<&Screening>,
        params: &'a FitParams,
        progress: &'a mut dyn FnMut(usize, usize, Real),
    ) -> Result<CloudFit<'a>> {
        params.check()?;
        let points = &cloud.positions;
        if points.len() < 4 {
            return Err(Error::input(format!(
                "the point cloud has {} points; fitting needs at least 4",
                points.len()
            )));
        }
        let diameter = bbox_diagonal(points);
        if !(diameter > 0.0 && diameter.is_finite()) {
            return Err(Error::input("all points coincide: the cloud has no extent"));
        }
        let start = Instant::now();
        // The springs' data: the points without the outliers.
        let (mut keep, data_noise) = match screening {
            Some(s) if s.keep.len() != points.len() => {
                return Err(Error::size_mismatch(format!(
                    "an outlier screening of {} points for a cloud of {}",
                    s.keep.len(),
                    points.len()
                )));
            }
            Some(s) => (s.keep.clone(), s.noise),
            None => {
                let s = screen(points);
                (s.keep, s.noise)
            }
        };
        if !params.drop_outliers {
            keep.fill(true);
        }
        let mut data_index: Vec<usize> = (0..points.len()).filter(|&i| keep[i]).collect();
        if data_index.len() < 4 {
            data_index = (0..points.len()).collect();
        }
        let data: Vec<Point3> = data_index.iter().map(|&i| points[i]).collect();
        let data_tree: ImmutableKdTree<Real, 3> = ImmutableKdTree::new_from_slice(
            &data.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
        );
        let order: Vec<usize> = shuffled_order(data.len())
            .into_iter()
            .map(|j| data_index[j])
            .collect();
        let shuffled: Vec<Point3> = order.iter().map(|&i| points[i]).collect();
        Ok(CloudFit {
            params,
            points,
            keep,
            data_noise,
            data,
            data_index,
            data_tree,
            order,
            shuffled,
            diameter,
            quadtrees: QuadtreeCache::default(),
            start,
            progress,
            levels: Vec::new(),
            final_dist: Vec::new(),
            final_hints: Vec::new(),
            carried_hints: None,
            refinement: String::from("initial"),
            adaptive_parent: None,
            crease_pass: None,
            residuals: None,
            webs: 0,
        })
    }

    /// The points left out of the springs.
    pub fn outliers(&self) -> usize {
        self.points.len() - self.data.len()
    }

    /// When the fit began.
    pub fn started(&self) -> Instant {
        self.start
    }
}

impl LevelFit for CloudFit<'_> {
    fn fit_level(&mut self, at: Level) -> Result<Verdict> {
        let Level {
            number: level,
            refiner,
            mesh,
            creases,
        } = at;
        let Settled {
            report,
            engine,
            residuals,
        } = self.settle(level, refiner, mesh)?;
        let (data_noise, diameter) = (self.data_noise, self.diameter);
        let CloudFit {
            params,
            points,
            ref data,
            ref data_index,
            ref data_tree,
            ref mut levels,
            ref mut final_dist,
            ref mut final_hints,
            ref mut carried_hints,
            ref mut refinement,
            ref mut adaptive_parent,
            ref mut crease_pass,
            ..
        } = *self;
        let n_all = self.points.len() as Real;
        let Residuals {
            ref dist,
            ref last_hints,
            ..
        } = residuals;
        if let (Some((parent, parent_creases)), Some(before)) =
            (adaptive_parent.take(), levels.last())
            && fitted_worse(
                (report.kept_error.rms, report.kept_error.p95),
                (before.kept_error.rms, before.kept_error.p95),
            )
        {
            // Transitions on a coarse mesh can bend the surface more than the
            // split faces gain; refine the parent uniformly instead.
            *refinement = format!(
                "uniform, after an adaptive level ({} control points) that fitted worse than its parent (95th percentile {:.3} % against {:.3} %)",
                report.control_points, report.kept_error.p95_pct, before.kept_error.p95_pct
            );
            *carried_hints = None;
            let h = Refiner::new(&parent, &crease_options(&parent_creases))?.refine_uniform(1)?;
            if h.level(1).num_vertices as Real > params.max_control_fraction * n_all {
                *mesh = parent;
                *creases = parent_creases;
                return Ok(Verdict::Stop(
                    false,
                    format!(
                        "level {level} fitted worse than its parent and a uniform one would have more than {} × the {} data points",
                        params.max_control_fraction,
                        points.len()
                    ),
                ));
            }
            let p1 = h.stencil(0).apply(&parent.positions)?;
            *mesh = h.mesh(1, p1);
            *creases = refined_creases(&h, mesh, None, &parent_creases);
            return Ok(Verdict::Again);
        }
        levels.push(report);
        final_dist.clone_from(dist);
        if let Some(without) = crease_pass.take() {
            // The level fitted again with creases: keep the better fit, as
            // one level, counting both fits' work.
            let with = levels.pop().expect("the level just pushed");
            let smooth = without.report;
            let dropped = fitted_worse(
                (with.kept_error.rms, with.kept_error.p95),
                (smooth.kept_error.rms, smooth.kept_error.p95),
            );
            let refinement = format!(
                "{}; {} crease edges {} (95th percentile {:.3} % with, {:.3} % without)",
                smooth.refinement,
                creases.len(),
                if dropped {
                    "tried and dropped"
                } else {
                    "tagged"
                },
                with.kept_error.p95_pct,
                smooth.kept_error.p95_pct
            );
            let work = (
                with.steps + smooth.steps,
                with.cg_iterations + smooth.cg_iterations,
                with.seconds + smooth.seconds,
                with.setup_seconds + smooth.setup_seconds,
                with.error_seconds + smooth.error_seconds,
            );
            // Dropped, the refinement below still ranks the faces by the
            // creased fit's residuals (the same mesh, fitted as closely).
            let kept = if dropped {
                creases.clear();
                *mesh = without.mesh;
                *final_dist = without.dist;
                smooth
            } else {
                final_hints.clone_from(last_hints);
                with
            };
            levels.push(LevelReport {
                refinement,
                steps: work.0,
                cg_iterations: work.1,
                seconds: work.2,
                setup_seconds: work.3,
                error_seconds: work.4,
                ..kept
            });
        } else {
            final_hints.clone_from(last_hints);
            if level == 0 && params.crease_angle > 0.0 {
                let miss: Vec<Real> = data_index.iter().map(|&i| final_dist[i]).collect();
                let found = detect_creases(
                    refiner,
                    &engine,
                    &mesh.positions,
                    &CreaseData {
                        points: data,
                        miss: &miss,
                        tree: data_tree,
                        noise: data_noise,
                    },
                    params.crease_angle,
                )?;
                if !found.is_empty() {
                    *crease_pass = Some(WithoutCreases {
                        mesh: mesh.clone(),
                        dist: final_dist.clone(),
                        report: levels.pop().expect("the level just pushed"),
                    });
                    *creases = found
                        .into_iter()
                        .map(|(a, b)| (a, b, SHARPNESS_INFINITE))
                        .collect();
                    *carried_hints = Some(
                        final_hints
                            .iter()
                            .map(|&(p, st)| Carried::Patch(p, st))
                            .collect(),
                    );
                    return Ok(Verdict::Again);
                }
            }
        }
        // The kept fit's error (the level without creases, should they
        // have been dropped).
        let error = levels[levels.len() - 1].kept_error;
        let stat = params.tolerance_stat;
        let noise_pct = 100.0 * data_noise / diameter;
        let met = if error.pct(stat) <= params.tolerance_pct {
            Some(format!("tolerance met at level {level}"))
        } else if stat == ToleranceStat::P95
            && noise_pct > 0.0
            && error.p95_pct <= params.noise_tolerance * noise_pct
        {
            Some(format!(
                "the 95th percentile ({:.3} %) is within {} × the estimated noise σ ({:.3} %) at level {level}: a finer level would fit the noise",
                error.p95_pct, params.noise_tolerance, noise_pct
            ))
        } else {
            None
        };
        // The gain is judged on the tolerance's statistic (the 95th
        // percentile by default), which outliers do not dominate as they do
        // the RMS.
        let gain = match levels.as_slice() {
            [.., before, last] => Some((last.kept_error.pct(stat), before.kept_error.pct(stat))),
            _ => None,
        };
        self.residuals = Some(residuals);
        Ok(Verdict::Judge {
            met,
            gain,
            measure: format!("{stat:?} error"),
        })
    }

    fn refinement(&mut self, level: usize, mesh: &PolyMesh) -> Result<Refine> {
        let params = self.params;
        if params.refinement == Refinement::Uniform {
            return Ok(Refine::Uniform);
        }
        let (keep, data_noise) = (&self.keep, self.data_noise);
        let Residuals {
            w,
            dist,
            face,
            surface_dist,
            face_of_patch,
            ..
        } = self.residuals.as_ref().expect("a level was fitted");
        // The points left out of the springs do not count either.
        let counted: Vec<Real> = w
            .iter()
            .zip(keep)
            .map(|(&w, &k)| if k { w } else { 0.0 })
            .collect();
        let (mut marks, _) = faces_above_noise(
            mesh.num_faces(),
            face,
            dist,
            &counted,
            data_noise,
            params.refine_significance,
        );
        // Webs across gaps in the data: surface samples far off it.
        let per_patch = params.surface_samples * params.surface_samples;
        let sample_face: Vec<u32> = (0..surface_dist.as_ref().map_or(0, Vec::len))
            .map(|i| face_of_patch[i / per_patch])
            .collect();
        let off_data = faces_off_data(
            mesh.num_faces(),
            &sample_face,
            surface_dist.as_deref().unwrap_or_default(),
            params.refine_off_data,
        );
        let mut webs = 0;
        for (m, &off) in marks.iter_mut().zip(&off_data) {
            if off && !*m {
                *m = true;
                webs += 1;
            }
        }
        if !marks.contains(&true) {
            return Ok(Refine::Stop(
                false,
                format!(
                    "no face of level {level} is off the data by more than the noise: finer levels would fit the noise"
                ),
            ));
        }
        // The worst first: webs, then by mean squared residual.
        let residual = face_residuals(mesh.num_faces(), face, dist, &counted);
        let mut rank: Vec<usize> = (0..marks.len()).filter(|&f| marks[f]).collect();
        rank.sort_by(|&a, &b| {
            off_data[b]
                .cmp(&off_data[a])
                .then(residual[b].1.total_cmp(&residual[a].1))
                .then(a.cmp(&b))
        });
        self.webs = webs;
        Ok(Refine::Adaptive {
            rank,
            cap: params.max_control_fraction * self.points.len() as Real,
        })
    }

    fn refined(&mut self, next: Next) -> Result<Option<(bool, String)>> {
        let Next {
            level,
            parent: mesh,
            creases,
            how,
            mesh: next,
        } = next;
        let next_vertices = next.num_vertices();
        let last_hints = &self
            .residuals
            .as_ref()
            .expect("a level was fitted")
            .last_hints;
        match how {
            Refined::Uniform => {
                self.refinement = "uniform".into();
                // Patch `f` is the refined mesh's base face `f` (one uniform
                // refinement apart), with the same corner frame.
                self.carried_hints = Some(
                    last_hints
                        .iter()
                        .map(|&(f, st)| Carried::Face(f, st))
                        .collect(),
                );
            }
            Refined::Adaptive(split) => {
                let webs = self.webs;
                let left = split.left;
                self.refinement = format!(
                    "adaptive: {} of {} faces split{}{}",
                    split.marks.iter().filter(|&&m| m).count(),
                    split.marks.len(),
                    if webs > 0 {
                        format!(" ({webs} with surface samples off the data)")
                    } else {
                        String::new()
                    },
                    if left > 0 {
                        format!("; {left} more above the noise left for the control-point budget")
                    } else {
                        String::new()
                    }
                );
                self.adaptive_parent = Some((mesh.clone(), creases.to_vec()));
                let local = &split.local;
                self.carried_hints = Some(
                    last_hints
                        .iter()
                        .map(|&(p, st)| match local.corner_image[p as usize] {
                            CornerImage::Face(g) => Carried::Face(g, st),
                            CornerImage::Corner(g, i) | CornerImage::Changed(g, i) => {
                                Carried::Patch(next.face_offsets[g as usize] + i, st)
                            }
                        })
                        .collect(),
                );
            }
        }
        let params = self.params;
        Ok((next_vertices as Real > params.max_control_fraction * self.points.len() as Real)
            .then(|| {
                (
                    false,
                    format!(
                        "level {} would have {} control points, more than {} × the {} data points",
                        level + 1,
                        next_vertices,
                        params.max_control_fraction,
                        self.points.len()
                    ),
                )
            }))
    }
}
