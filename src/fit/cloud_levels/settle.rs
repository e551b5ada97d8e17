//! One level of the point-cloud fit set up and settled: the closest-point
//! engine and the level's system, the implicit steps with the data springs
//! and the surface-to-data springs until the energy or the trimmed error
//! settles, the untangling rounds, and the error over every point.

use std::time::Instant;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::dynamics::{MaterialParams, PcgParams, parameter_area};
use crate::error::Result;
use crate::forces::{RowSprings, robust_weights};
use crate::limit::{ClosestPointEngine, ClosestPointParams};
use crate::math::{Point3, Real};
use crate::mesh::PolyMesh;
use crate::subdivision::Refiner;
use crate::topology::face_of_corner;

use super::super::fairness::{umbrella_matrix, vertex_rings};
use super::super::quality::SelfIntersections;
use super::super::sampling::{surface_samples, trimmed_rms};
use super::super::system::LevelSystem;
use super::super::untangle::{UNTANGLE_CHECK_RATE, untangled};
use super::super::{ErrorStats, LevelReport};
use super::{Carried, CloudFit, Residuals};

/// A settled level: its report, its engine (at the fitted positions) and
/// what its refinement ranks faces by.
pub(super) struct Settled {
    pub report: LevelReport,
    pub engine: ClosestPointEngine,
    pub residuals: Residuals,
}

impl CloudFit<'_> {
    /// Sets up `level` of `mesh` (refined by `refiner`) and settles it;
    /// `mesh` ends with the fitted positions.
    pub(super) fn settle(
        &mut self,
        level: usize,
        refiner: &Refiner,
        mesh: &mut PolyMesh,
    ) -> Result<Settled> {
        let level_start = Instant::now();
        let (diameter, start) = (self.diameter, self.start);
        let n_all = self.points.len() as Real;
        let CloudFit {
            params,
            points,
            ref data,
            ref data_tree,
            ref shuffled,
            ref order,
            ref quadtrees,
            ref mut progress,
            ref mut carried_hints,
            ref mut refinement,
            ..
        } = *self;
        let mut engine = ClosestPointEngine::with_quadtrees(
            refiner,
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
        let ring = vertex_rings(mesh);
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
                refiner,
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
                mesh,
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
        let kept: Vec<Real> = self.data_index.iter().map(|&i| dist[i]).collect();
        let kept_error = ErrorStats::new(&kept, diameter);
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
            kept_error,
            points_used: used.len(),
            rejected: w.iter().filter(|&&w| w == 0.0).count() as Real / n_all,
            refinement: std::mem::take(refinement),
        };
        Ok(Settled {
            report,
            engine,
            residuals: Residuals {
                w,
                dist,
                face,
                surface_dist,
                face_of_patch,
                last_hints,
            },
        })
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
