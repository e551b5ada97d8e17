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

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::dynamics::{MaterialParams, PcgParams, parameter_area};
use crate::error::{Error, Result};
use crate::forces::{RowSprings, robust_weights};
use crate::limit::{ClosestPointEngine, ClosestPointParams, QuadtreeCache};
use crate::math::{Point3, Real, bbox_diagonal};
use crate::mesh::{PointCloud, PolyMesh};
use crate::subdivision::{CornerImage, Refiner};
use crate::topology::{SHARPNESS_INFINITE, face_of_corner};

use super::crease_options;
use super::creases::{Crease, CreaseData, detect_creases, refined_creases};
use super::fairness::{umbrella_matrix, vertex_rings};
use super::init::outliers::{Screening, screen};
use super::levels::{LevelFit, Refine, Refined, Verdict, fitted_worse};
use super::quality::SelfIntersections;
use super::refine_marks::{face_residuals, faces_above_noise, faces_off_data};
use super::sampling::{shuffled_order, surface_samples, trimmed_rms};
use super::system::LevelSystem;
use super::untangle::{UNTANGLE_CHECK_RATE, untangled};
use super::{ErrorStats, FitParams, LevelReport, Refinement, ToleranceStat};

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
            return Err(Error::Input(format!(
                "the point cloud has {} points; fitting needs at least 4",
                points.len()
            )));
        }
        let diameter = bbox_diagonal(points);
        if !(diameter > 0.0 && diameter.is_finite()) {
            return Err(Error::Input(
                "all points coincide: the cloud has no extent".into(),
            ));
        }
        let start = Instant::now();
        // The springs' data: the points without the outliers.
        let (mut keep, data_noise) = match screening {
            Some(s) if s.keep.len() != points.len() => {
                return Err(Error::Input(format!(
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
    fn level(&self) -> usize {
        self.levels.len()
    }

    fn fit_level(
        &mut self,
        level: usize,
        refiner: &Refiner,
        mesh: &mut PolyMesh,
        creases: &mut Vec<Crease>,
    ) -> Result<Verdict> {
        let level_start = Instant::now();
        let (data_noise, diameter, start) = (self.data_noise, self.diameter, self.start);
        let n_all = self.points.len() as Real;
        let CloudFit {
            params,
            points,
            ref data,
            ref data_index,
            ref data_tree,
            ref shuffled,
            ref order,
            ref quadtrees,
            ref mut progress,
            ref mut levels,
            ref mut final_dist,
            ref mut final_hints,
            ref mut carried_hints,
            ref mut refinement,
            ref mut adaptive_parent,
            ref mut crease_pass,
            ..
        } = *self;
        let mut engine = ClosestPointEngine::with_quadtrees(
            &refiner,
            &mesh.positions,
            &ClosestPointParams {
                level: params.patch_level,
                // Distances are stationary at the closest point, so 1e-7 in
                // (s, t) still gives them to round-off, in fewer iterations.
                tolerance: 1e-7,
                ..Default::default()
            },
            quadtrees.clone(),
        )?;
        // The thin plate and the damping, patch by patch on the engine's
        // pieces: exact on regular faces (one bicubic each).
        let table = engine.table();
        let area = parameter_area(table);
        let material = MaterialParams::thin_plate(params.tension, params.bending, area);
        let mut system = LevelSystem::new(
            table,
            params.quadrature_order,
            &material,
            params.damping / area,
            (params.mass > 0.0).then(|| params.mass / area),
            0.0,
        )?;
        // The fairness of the control net (`FitParams::fairness`): one
        // umbrella weight per control point, raised where untangling marks.
        let ring = vertex_rings(&mesh);
        let mut umbrella = vec![params.fairness / mesh.num_vertices() as Real; mesh.num_vertices()];
        system.set_fairness(&umbrella_matrix(&ring, &umbrella))?;
        let centres = system
            .assembly
            .rows_at(table, &surface_samples(table, params.surface_samples))?;
        let setup_seconds = level_start.elapsed().as_secs_f64();
        let mut p = mesh.positions.clone();
        // The previous step's positions (at rest when a level starts).
        let mut p_before = p.clone();
        let mut energy: Vec<Real> = Vec::new();
        let (mut step_elapsed, mut step_rms_pct, mut step_p95_pct) =
            (Vec::new(), Vec::new(), Vec::new());
        let mut cg_iterations = 0;
        let mut steps = 0;
        // The previous level's answers, in this level's patches.
        let mut hints: Option<Vec<(u32, [Real; 2])>> = carried_hints.take().map(|h| {
            h.iter()
                .map(|c| match *c {
                    Carried::Face(f, st) => {
                        let (g, st) = engine.table().locate(f as usize, st[0], st[1]);
                        (g as u32, st)
                    }
                    Carried::Patch(g, st) => (g, st),
                })
                .collect()
        });
        let mut trimmed_before: Option<Real> = None;
        // Untangling (`FitParams::untangle_rounds`): the rounds done and
        // the step this round began at.
        let mut untangle_round = 0;
        let mut round_start = 0;
        let per_point = if level == 0 {
            params.first_level_points_per_control_point
        } else {
            params.points_per_control_point
        };
        let used = &shuffled[..shuffled
            .len()
            .min(per_point.saturating_mul(mesh.num_vertices()))
            .max(4)];
        let n = used.len() as Real;
        let (used_dist, last_hints, surface_dist) = loop {
            let fitted = loop {
                // Newton from the previous answers every step; every
                // `reseed_every` steps also from the nearest seed, to catch jumps
                // to another part of the surface.
                let closest = match &hints {
                    Some(h) if steps % params.reseed_every != 0 => {
                        engine.closest_points_local(used, h)?
                    }
                    // A previous level's answers cover a prefix of the points;
                    // the others start from the answer of their nearest point
                    // in that prefix.
                    Some(h) => {
                        let k = h.len().min(used.len());
                        let mut starts = h[..k].to_vec();
                        starts.extend(nearest_answers(&used[..k], &h[..k], &used[k..]));
                        engine.closest_points_near(used, &starts)?
                    }
                    None => engine.closest_points(used)?,
                };
                hints = Some(closest.iter().map(|c| c.patch).collect());
                let dist: Vec<Real> = closest.iter().map(|c| c.distance).collect();
                let w = robust_weights(&dist, params.robust, 1e-6 * diameter);
                let kw: Vec<Real> = w.iter().map(|w| w / n).collect();
                // RMS of the nearest 95 % of the distances: the stall test below
                // must not be dominated by outliers (the full RMS is) nor jump as
                // the robust weights admit or drop points (the inliers' RMS does).
                let trimmed = trimmed_rms(&dist, 0.95);
                // Surface-to-data springs: every surface sample to its nearest
                // data point, so parts of the surface that no data point is
                // closest to (bridges across gaps, flaps) are pulled onto the
                // data too (`FitParams::surface_robust`).
                let surface = if params.surface_weight > 0.0 {
                    let xs = centres.rows().apply(&p)?;
                    let near: Vec<(Point3, Real)> = xs
                        .par_iter()
                        .map(|x| {
                            let nn = data_tree.nearest_one::<SquaredEuclidean>(&[x.x, x.y, x.z]);
                            (data[nn.item as usize], nn.distance.sqrt())
                        })
                        .collect();
                    let dd: Vec<Real> = near.iter().map(|n| n.1).collect();
                    let ws = robust_weights(&dd, params.surface_robust, 1e-6 * diameter);
                    let m = xs.len() as Real;
                    let ks: Vec<Real> = ws.iter().map(|w| params.surface_weight * w / m).collect();
                    let targets: Vec<Point3> = near.iter().map(|n| n.0).collect();
                    Some((xs, targets, ks, dd))
                } else {
                    None
                };
                // The energy first (the springs' ½ k d² and ½ pᵀ K p): the
                // systems are assembled only when another step follows.
                let spring_energy = |d: &[Real], k: &[Real]| -> Real {
                    d.iter().zip(k).map(|(d, k)| 0.5 * k * d * d).sum()
                };
                let e = spring_energy(&dist, &kw)
                    + surface
                        .as_ref()
                        .map_or(0.0, |(_, _, ks, dd)| spring_energy(dd, ks))
                    + system.potential(&p)?;
                progress(level, steps, e);
                let stats = ErrorStats::new(&dist, diameter);
                let settled = steps > round_start
                    && (energy.last().is_some_and(|&prev: &Real| {
                        (prev - e).abs() <= params.energy_tolerance * prev.abs()
                    }) || trimmed_before
                        .is_some_and(|prev: Real| prev - trimmed <= params.error_tolerance * prev));
                trimmed_before = Some(trimmed);
                energy.push(e);
                step_elapsed.push(start.elapsed().as_secs_f64());
                step_rms_pct.push(stats.rms_pct);
                step_p95_pct.push(stats.p95_pct);
                if settled || steps - round_start >= params.max_steps {
                    break (dist, hints.clone(), surface.map(|s| s.3));
                }
                let springs = system.assembly.data_springs(
                    engine.table(),
                    used,
                    &closest,
                    &kw,
                    surface.as_ref().map(|(x, d, k, _)| RowSprings {
                        rows: &centres,
                        x,
                        d,
                        k,
                    }),
                )?;
                let report = system.step(
                    springs,
                    None,
                    &mut p,
                    &mut p_before,
                    &PcgParams {
                        tolerance: params.cg_tolerance,
                        ..Default::default()
                    },
                )?;
                cg_iterations += report.iterations;
                engine.set_positions(&p)?;
                steps += 1;
            };
            if untangle_round >= params.untangle_rounds {
                break fitted;
            }
            let crossing = SelfIntersections::with_quadtrees(
                &refiner,
                &p,
                UNTANGLE_CHECK_RATE,
                quadtrees.clone(),
            )?
            .faces(mesh.num_faces());
            if !crossing.contains(&true) {
                break fitted;
            }
            untangle_round += 1;
            p = untangled(
                &mesh,
                &ring,
                p,
                &crossing,
                &mut umbrella,
                params.untangle_stiffening,
            );
            p_before.clone_from(&p);
            engine.set_positions(&p)?;
            system.set_fairness(&umbrella_matrix(&ring, &umbrella))?;
            round_start = steps;
            trimmed_before = None;
        };
        // The error over every point: the used points' distances are the
        // last step's (descents from the previous answers, at this surface;
        // a descent ends on the surface, so it never understates a
        // distance), the others' from a full search.
        let error_start = Instant::now();
        let mut dist = vec![Real::NAN; points.len()];
        let last_hints = last_hints.unwrap_or_default();
        // The control face holding each point's closest point (a level-1
        // patch is corner `c` of a control face).
        let face_of_patch = face_of_corner(&mesh.face_offsets);
        let mut face = vec![0u32; points.len()];
        for ((&i, &d), h) in order.iter().zip(&used_dist).zip(&last_hints) {
            dist[i] = d;
            face[i] = face_of_patch[h.0 as usize];
        }
        let rest: Vec<usize> = (0..points.len()).filter(|&i| dist[i].is_nan()).collect();
        let rest_points: Vec<Point3> = rest.iter().map(|&i| points[i]).collect();
        for (&i, c) in rest.iter().zip(engine.closest_points(&rest_points)?) {
            dist[i] = c.distance;
            face[i] = face_of_patch[c.patch.0 as usize];
        }
        let w = robust_weights(&dist, params.robust, 1e-6 * diameter);
        let error = ErrorStats::new(&dist, diameter);
        mesh.positions = p;
        let report = LevelReport {
            level,
            control_points: mesh.num_vertices(),
            faces: mesh.num_faces(),
            steps,
            cg_iterations,
            seconds: level_start.elapsed().as_secs_f64(),
            setup_seconds,
            error_seconds: error_start.elapsed().as_secs_f64(),
            elapsed: start.elapsed().as_secs_f64(),
            energy,
            step_elapsed,
            step_rms_pct,
            step_p95_pct,
            error,
            points_used: used.len(),
            rejected: w.iter().filter(|&&w| w == 0.0).count() as Real / n_all,
            refinement: std::mem::take(refinement),
        };
        if let (Some((parent, parent_creases)), Some(before)) =
            (adaptive_parent.take(), levels.last())
            && fitted_worse(
                (report.error.rms, report.error.p95),
                (before.error.rms, before.error.p95),
            )
        {
            // Transitions on a coarse mesh can bend the surface more than the
            // split faces gain; refine the parent uniformly instead.
            *refinement = format!(
                "uniform, after an adaptive level ({} control points) that fitted worse than its parent (95th percentile {:.3} % against {:.3} %)",
                report.control_points, report.error.p95_pct, before.error.p95_pct
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
        final_dist.clone_from(&dist);
        if let Some(without) = crease_pass.take() {
            // The level fitted again with creases: keep the better fit, as
            // one level, counting both fits' work.
            let with = levels.pop().expect("the level just pushed");
            let smooth = without.report;
            let dropped = fitted_worse(
                (with.error.rms, with.error.p95),
                (smooth.error.rms, smooth.error.p95),
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
                with.error.p95_pct,
                smooth.error.p95_pct
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
                final_hints.clone_from(&last_hints);
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
            final_hints.clone_from(&last_hints);
            if level == 0 && params.crease_angle > 0.0 {
                let miss: Vec<Real> = data_index.iter().map(|&i| final_dist[i]).collect();
                let found = detect_creases(
                    &refiner,
                    &engine,
                    &mesh.positions,
                    &CreaseData {
                        points: &data,
                        miss: &miss,
                        tree: &data_tree,
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
        let error = levels[levels.len() - 1].error;
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
            [.., before, last] => Some((last.error.pct(stat), before.error.pct(stat))),
            _ => None,
        };
        self.residuals = Some(Residuals {
            w,
            dist,
            face,
            surface_dist,
            face_of_patch,
            last_hints,
        });
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
            &face,
            &dist,
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
        let residual = face_residuals(mesh.num_faces(), &face, &dist, &counted);
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

    fn refined(
        &mut self,
        level: usize,
        mesh: &PolyMesh,
        creases: &[Crease],
        next: Refined,
        next_vertices: usize,
    ) -> Result<Option<(bool, String)>> {
        let last_hints = &self
            .residuals
            .as_ref()
            .expect("a level was fitted")
            .last_hints;
        match next {
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
                                Carried::Patch(local.mesh.face_offsets[g as usize] + i, st)
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

/// For every query, the closest-point answer (patch and `(s, t)`) of its
/// nearest `known` point: a start for its own search.
fn nearest_answers(
    known: &[Point3],
    answers: &[(u32, [Real; 2])],
    queries: &[Point3],
) -> Vec<(u32, [Real; 2])> {
    if queries.is_empty() || known.is_empty() {
        // No start: out of range, a full search.
        return vec![(u32::MAX, [0.5; 2]); queries.len()];
    }
    let tree = ImmutableKdTree::<Real, 3>::new_from_slice(
        &known.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
    );
    queries
        .par_iter()
        .map(|q| answers[tree.nearest_one::<SquaredEuclidean>(&[q.x, q.y, q.z]).item as usize])
        .collect()
}
