//! The multilevel fitting driver (Qin, Mandal, Vemuri 1998, §6).
//!
//! At each level the control points follow the first-order (massless)
//! dynamics `D ṗ + K p = f_p` with implicit Euler steps, the data springs
//! treated implicitly ([`super::system::LevelSystem::step`]),
//! refreshing every spring's closest point before each step. Each step
//! minimises the spring + stiffness energy plus a proximal term, and the
//! closest-point refresh can only lower the spring energy, so the energy
//! `½ Σ k |x − d|² + ½ pᵀ K p` decreases monotonically (with fixed robust
//! weights). When it settles (relative change below the tolerance) the error
//! is measured; above the tolerance the control mesh is subdivided and the
//! fit goes on. Uniform refinement splits every face (the new control points
//! `S p` describe the same surface). Adaptive refinement (the default)
//! splits only the faces whose data residual is above the noise
//! ([`super::refine_marks`], [`crate::subdivision::refine_marked`]) and puts
//! the new control mesh's limit points on the parent's surface by
//! progressive interpolation; should such a level fit worse than its parent
//! (transitions on a very coarse mesh can bend the surface), the parent is
//! refined uniformly instead and the report says so.
//!
//! With a mass (`FitParams::mass` > 0) the steps integrate the paper's
//! second-order dynamics `M p̈ + D ṗ + K p = f_p` (eq. 16) by backward
//! differences, unconditionally stable like the first-order step. The model
//! then carries momentum, so the potential energy may rise for a step while
//! it overshoots; the stop rules ([`super::levels`]) are the same.

use std::time::Instant;

use crate::dynamics::{MaterialParams, PcgParams, parameter_area};
use crate::error::{Error, Result};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::forces::{RowSprings, robust_weights};
use crate::limit::{ClosestPointEngine, ClosestPointParams, QuadtreeCache};
use crate::math::{Point3, Real, bbox_diagonal};
use crate::mesh::{PointCloud, PolyMesh};
use crate::subdivision::{CornerImage, RefineOptions, Refiner};
use crate::topology::{SHARPNESS_INFINITE, face_of_corner};

use super::init::outliers::{Screening, screen};
use super::init::voxel_surface::taubin_smoothed_where;

use super::creases::{Crease, CreaseData, detect_creases, refined_creases};
use super::fairness::{umbrella_matrix, vertex_rings};
use super::levels::{Split, fitted_worse, split_within, stop_after_level};
use super::quality::{CHECK_RATE, SelfIntersections, assess};
use super::refine_marks::{face_residuals, faces_above_noise, faces_off_data};
use super::sampling::{shuffled_order, surface_samples, trimmed_rms};
use super::system::{LevelSystem, check_level_memory};
use super::{ErrorStats, FitParams, FitReport, LevelReport, Refinement, ToleranceStat, Untangling};

/// Taubin steps on the control points of the faces an untangling round
/// marks (`FitParams::untangle_rounds`).
const UNTANGLE_SMOOTHING_STEPS: usize = 3;

/// Samples per side of every tessellation tile untangling checks: the
/// pleats it finds are larger than a tile, and a check at this rate costs
/// about a third of one at [`super::quality::CHECK_RATE`] (Spot, level 1:
/// 0.35 s against 0.85 s); the report still counts at that rate.
const UNTANGLE_CHECK_RATE: usize = 2;

/// The untangling after the last level tries another round only after one
/// that removed at least this fraction of the crossing pairs, as each round
/// costs a tessellation of the surface. Pleats go in a round or a few, parts
/// grown into each other lose a few percent a round. Chosen on the choose
/// rows of the corpus: plate-n1 goes 362, 149, 86, 70, 0 (a round of 19 %
/// before the last), spot-out 1,710, 1,706 (0.2 %); checked on the others:
/// dragon-n1 stops after one round (10 %), chair-n1 after three (475, 394,
/// 379), cow-out after one.
const FINAL_UNTANGLE_GAIN: Real = 0.15;

/// A previous level's closest point carried to the next level.
enum Carried {
    /// At `(s, t)` of this base face of the new control mesh (located on
    /// its patches once they are built).
    Face(u32, [Real; 2]),
    /// At `(s, t)` of this patch of the new control mesh (the same surface
    /// piece, or where its face gained corners a nearby one: a start only).
    Patch(u32, [Real; 2]),
}

/// A fitted model and what it took.
#[derive(Clone, Debug)]
pub struct FitResult {
    /// The control mesh of the finest level reached.
    pub control: PolyMesh,
    /// Its sharp edges `(i, j, s)` (`i < j`, `s` = [`SHARPNESS_INFINITE`]):
    /// the creases found in the data ([`FitParams::crease_angle`]); the
    /// limit surface is `control`'s with these tags
    /// ([`crease_options`]).
    pub creases: Vec<Crease>,
    /// Per-level report.
    pub report: FitReport,
}

/// The refinement options of a fitted control mesh with these `creases`.
pub fn crease_options(creases: &[Crease]) -> RefineOptions {
    RefineOptions {
        creases: creases.to_vec(),
        ..Default::default()
    }
}

/// Level 0 as fitted without creases, while it is fitted again with them.
struct WithoutCreases {
    mesh: PolyMesh,
    dist: Vec<Real>,
    report: LevelReport,
}

/// Fits the limit surface of a control mesh, starting from `init`, to the
/// points of `cloud`. `progress` is called after every implicit step with
/// `(level, step, energy)`.
pub fn fit_point_cloud(
    cloud: &PointCloud,
    init: &PolyMesh,
    params: &FitParams,
    progress: &mut dyn FnMut(usize, usize, Real),
) -> Result<FitResult> {
    fit_screened_cloud(cloud, None, init, params, progress)
}

/// [`fit_point_cloud`] with the cloud's outlier screening already done
/// (`screening`, as [`crate::fit::init::initial_mesh`] reports it; `None`:
/// screened here). Errors when it is not of the cloud's length.
pub fn fit_screened_cloud(
    cloud: &PointCloud,
    screening: Option<&Screening>,
    init: &PolyMesh,
    params: &FitParams,
    progress: &mut dyn FnMut(usize, usize, Real),
) -> Result<FitResult> {
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
    let outliers = points.len() - data.len();
    let data_tree: ImmutableKdTree<Real, 3> =
        ImmutableKdTree::new_from_slice(&data.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>());
    let mut mesh = init.clone();
    let mut levels: Vec<LevelReport> = Vec::new();
    // Each level uses a prefix of a fixed even shuffle of the points
    // (`order`: their indices in `points`).
    let order: Vec<usize> = shuffled_order(data.len())
        .into_iter()
        .map(|j| data_index[j])
        .collect();
    let shuffled: Vec<Point3> = order.iter().map(|&i| points[i]).collect();
    let n_all = points.len() as Real;
    // The previous level's closest points in this level's terms (see
    // `Carried`).
    let mut carried_hints: Option<Vec<Carried>> = None;
    let mut refinement = String::from("initial");
    // The parent of an adaptive level, kept to refine it uniformly instead
    // should the adaptive level fit worse.
    let mut adaptive_parent: Option<(PolyMesh, Vec<Crease>)> = None;
    // Most local structures at extraordinary vertices recur from level to
    // level: their quadtrees are built once.
    let quadtrees = QuadtreeCache::default();
    // The distances of the last level kept, to assess the result with, and
    // its closest-point answers (of the points it used).
    let mut final_dist: Vec<Real> = Vec::new();
    let mut final_hints: Vec<(u32, [Real; 2])> = Vec::new();
    // The sharp creases of the control mesh (`super::creases`): found after
    // level 0, which is then fitted again with them (`crease_pass` holds it
    // as fitted without), and carried through the refinements.
    let mut creases: Vec<Crease> = Vec::new();
    let mut crease_pass: Option<WithoutCreases> = None;
    let (converged, stop_reason) = loop {
        let level = levels.len();
        let level_start = Instant::now();
        check_level_memory(level, mesh.num_faces())?;
        let refiner = Refiner::new(&mesh, &crease_options(&creases))?;
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
            refinement: std::mem::take(&mut refinement),
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
            refinement = format!(
                "uniform, after an adaptive level ({} control points) that fitted worse than its parent (95th percentile {:.3} % against {:.3} %)",
                report.control_points, report.error.p95_pct, before.error.p95_pct
            );
            carried_hints = None;
            let h = Refiner::new(&parent, &crease_options(&parent_creases))?.refine_uniform(1)?;
            if h.level(1).num_vertices as Real > params.max_control_fraction * n_all {
                mesh = parent;
                creases = parent_creases;
                break (
                    false,
                    format!(
                        "level {level} fitted worse than its parent and a uniform one would have more than {} × the {} data points",
                        params.max_control_fraction,
                        points.len()
                    ),
                );
            }
            let p1 = h.stencil(0).apply(&parent.positions)?;
            mesh = h.mesh(1, p1);
            creases = refined_creases(&h, &mesh, None, &parent_creases);
            continue;
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
                mesh = without.mesh;
                final_dist = without.dist;
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
                    crease_pass = Some(WithoutCreases {
                        mesh: mesh.clone(),
                        dist: final_dist.clone(),
                        report: levels.pop().expect("the level just pushed"),
                    });
                    creases = found
                        .into_iter()
                        .map(|(a, b)| (a, b, SHARPNESS_INFINITE))
                        .collect();
                    carried_hints = Some(
                        final_hints
                            .iter()
                            .map(|&(p, st)| Carried::Patch(p, st))
                            .collect(),
                    );
                    continue;
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
        if let Some(stop) = stop_after_level(
            level,
            met,
            params.max_level,
            gain,
            params.min_level_gain,
            &format!("{stat:?} error"),
        ) {
            break stop;
        }
        let h = refiner.refine_uniform(1)?;
        let next_creases;
        let next = match params.refinement {
            Refinement::Uniform => {
                refinement = "uniform".into();
                // Patch `f` is the refined mesh's base face `f` (one uniform
                // refinement apart), with the same corner frame.
                carried_hints = Some(
                    last_hints
                        .iter()
                        .map(|&(f, st)| Carried::Face(f, st))
                        .collect(),
                );
                let p1 = h.stencil(0).apply(&mesh.positions)?;
                let next = h.mesh(1, p1);
                next_creases = refined_creases(&h, &next, None, &creases);
                next
            }
            Refinement::Adaptive => {
                // The points left out of the springs do not count either.
                let counted: Vec<Real> = w
                    .iter()
                    .zip(&keep)
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
                    break (
                        false,
                        format!(
                            "no face of level {level} is off the data by more than the noise: finer levels would fit the noise"
                        ),
                    );
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
                let cap = params.max_control_fraction * n_all;
                let Split {
                    marks,
                    local,
                    creases: local_creases,
                    left,
                } = split_within(&mesh, &h, &creases, &rank, cap)?;
                next_creases = local_creases;
                refinement = format!(
                    "adaptive: {} of {} faces split{}{}",
                    marks.iter().filter(|&&m| m).count(),
                    marks.len(),
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
                adaptive_parent = Some((mesh.clone(), creases.clone()));
                carried_hints = Some(
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
                local.mesh
            }
        };
        if next.num_vertices() as Real > params.max_control_fraction * n_all {
            break (
                false,
                format!(
                    "level {} would have {} control points, more than {} × the {} data points",
                    level + 1,
                    next.num_vertices(),
                    params.max_control_fraction,
                    points.len()
                ),
            );
        }
        mesh = next;
        creases = next_creases;
    };
    let (crossings, final_untangling) = untangle_after_fit(
        &mut mesh,
        &creases,
        params.final_untangle_rounds,
        &quadtrees,
    )?;
    let kept_dist: Vec<Real> = data_index.iter().map(|&i| final_dist[i]).collect();
    let quality = assess(&mesh, crossings, &data, &data_tree, &kept_dist, diameter)?;
    Ok(FitResult {
        control: mesh,
        creases,
        report: FitReport {
            quality,
            noise: data_noise,
            points: points.len(),
            outliers,
            diameter,
            levels,
            converged,
            stop_reason,
            final_untangling,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// One untangling round (`FitParams::untangle_rounds`): the control points
/// `p` of the `crossing` faces of `mesh` (those with a tessellation triangle
/// that crosses another) get [`UNTANGLE_SMOOTHING_STEPS`] Taubin steps, and
/// the umbrella weights of those points and of their `ring` neighbours are
/// multiplied by `stiffening`. Returns the smoothed points.
fn untangled(
    mesh: &PolyMesh,
    ring: &[Vec<u32>],
    p: Vec<Point3>,
    crossing: &[bool],
    umbrella: &mut [Real],
    stiffening: Real,
) -> Vec<Point3> {
    let moving = corners_of(mesh, crossing);
    for (v, r) in ring.iter().enumerate() {
        if moving[v] || r.iter().any(|&u| moving[u as usize]) {
            umbrella[v] *= stiffening;
        }
    }
    let net = PolyMesh {
        positions: p,
        face_offsets: mesh.face_offsets.clone(),
        face_vertices: mesh.face_vertices.clone(),
    };
    taubin_smoothed_where(&net, UNTANGLE_SMOOTHING_STEPS, &moving).positions
}

/// The untangling after the last level ([`FitParams::final_untangle_rounds`]):
/// the control points of the faces whose limit surface crosses itself (at
/// the assessment's rate, [`CHECK_RATE`]) get [`UNTANGLE_SMOOTHING_STEPS`]
/// Taubin steps, without a refit, round after round while each removes at
/// least [`FINAL_UNTANGLE_GAIN`] of the crossing pairs; `mesh` keeps the
/// best positions. Returns their
/// self-intersections (for [`assess`]) and what was done.
fn untangle_after_fit(
    mesh: &mut PolyMesh,
    creases: &[Crease],
    max_rounds: usize,
    quadtrees: &QuadtreeCache,
) -> Result<(SelfIntersections, Untangling)> {
    let refiner = Refiner::new(mesh, &crease_options(creases))?;
    let start = mesh.positions.clone();
    let mut best =
        SelfIntersections::with_quadtrees(&refiner, &start, CHECK_RATE, quadtrees.clone())?;
    let mut done = Untangling {
        pairs_before: best.pairs.len(),
        ..Default::default()
    };
    while !best.pairs.is_empty() && done.rounds < max_rounds {
        let moving = corners_of(mesh, &best.faces(mesh.num_faces()));
        let p = taubin_smoothed_where(mesh, UNTANGLE_SMOOTHING_STEPS, &moving).positions;
        let next = best.moved(&refiner, &p)?;
        done.rounds += 1;
        let (before, after) = (best.pairs.len() as Real, next.pairs.len() as Real);
        if after < before {
            mesh.positions = p;
            best = next;
        }
        if after > (1.0 - FINAL_UNTANGLE_GAIN) * before {
            break;
        }
    }
    for (a, b) in start.iter().zip(&mesh.positions) {
        if a != b {
            done.moved_control_points += 1;
            done.largest_move = done.largest_move.max((a - b).norm());
        }
    }
    Ok((best, done))
}

/// The corners of the faces marked in `faces`, as a mask over the vertices.
fn corners_of(mesh: &PolyMesh, faces: &[bool]) -> Vec<bool> {
    let mut out = vec![false; mesh.num_vertices()];
    for f in (0..mesh.num_faces()).filter(|&f| faces[f]) {
        for &v in mesh.face(f) {
            out[v as usize] = true;
        }
    }
    out
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
