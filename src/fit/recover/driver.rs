//! The multilevel volume-recovery driver (Qin, Mandal, Vemuri 1998, §4.2
//! and §6, the cerebellum and caudate experiments).
//!
//! [`prepare_volume`](super::prepare_volume) smooths the volume (`G_σ * I`),
//! computes the edge potential when edges are wanted, and fixes the
//! intensity that separates inside from outside (the iso-value, or Otsu's
//! threshold). [`recover_shape`] then evolves the control points with the
//! first-order dynamics of the point-cloud fit (the same [`LevelSystem`]
//! and step, and the same multilevel loop, [`crate::fit::levels::run_levels`],
//! of which [`VolumeFit`] is a force source), the spring
//! targets `y = x + t n` being the image boundary found along the normal of
//! every quadrature point (see [`crate::forces::ImageField`]), with stiffness
//! `k` proportional to the point's area. A level ends when the energy
//! settles; if the 95th percentile of `|t|` is above the tolerance the
//! control mesh is subdivided and the evolution goes on.

mod judge;

use std::time::Instant;

use judge::{LOCAL_MISS, local_misses};

use rayon::prelude::*;

use super::two_sided::{Candidates, far_points};
use super::{PreparedVolume, RecoverLevel, RecoverParams, RecoverReport};
use crate::dynamics::{
    MaterialParams, PcgParams, SampleRows, gauss_legendre, patch_sample_rows, square_rule,
};
use crate::error::{Error, Result};
use crate::fit::ErrorStats;
use crate::fit::Refinement;
use crate::fit::levels::{Level, LevelFit, Next, Refine, Refined, Verdict, run_levels};
use crate::fit::system::LevelSystem;
use crate::forces::{
    ImageField, Offset, RowSprings, SpringSystem, inflation_force, spread_point_springs,
};
use crate::limit::{ClosestPointEngine, ClosestPointParams, PatchTable};
use crate::math::{Point3, Real, bbox_diagonal};
use crate::mesh::PolyMesh;
use crate::topology::face_of_corner;

/// A recovered shape and what it took.
#[derive(Clone, Debug)]
pub struct RecoverResult {
    /// The control mesh of the finest level reached.
    pub control: PolyMesh,
    /// The report.
    pub report: RecoverReport,
}

/// The solve step: evolves `init` (a closed, outward-oriented control mesh
/// inside or around the object) to the boundary in `prepared`. `points` are
/// user-placed boundary points (world coordinates; may be empty), each
/// pulling its closest point of the limit surface with a spring, for parts
/// of the boundary the image does not show (Qin et al. 1998, the caudate
/// nucleus). `boundary` are the object's iso-surface points for the
/// two-sided forces (`RecoverParams::two_sided_weight`; may be empty, as
/// when the object is not known). `progress(level, step, energy)` is called
/// after every step.
pub fn recover_shape(
    prepared: &PreparedVolume,
    init: &PolyMesh,
    points: &[Point3],
    boundary: &[Point3],
    params: &RecoverParams,
    progress: &mut dyn FnMut(usize, usize, Real),
) -> Result<RecoverResult> {
    params.check()?;
    crate::mesh::check_finite(&init.positions)?;
    crate::mesh::check_finite(points)?;
    crate::mesh::check_finite(boundary)?;
    let start = Instant::now();
    let mut fit = VolumeFit {
        field: ImageField {
            smoothed: &prepared.smoothed,
            potential: prepared.potential.as_ref(),
            model: params.boundary,
            inside_level: prepared.inside_level,
            bright_inside: params.bright_inside,
            contrast: {
                let (lo, hi) = prepared.smoothed.range();
                (hi - lo) as Real
            },
        },
        voxel: prepared.smoothed.voxel_size(),
        points,
        boundary,
        params,
        progress,
        levels: Vec::new(),
        coarser: None,
        dropped: false,
        off: Vec::new(),
        cap: 0.0,
    };
    let mut mesh = init.clone();
    let (converged, stop_reason) = run_levels(
        &mut fit,
        &mut mesh,
        &mut Vec::new(),
        params.max_level,
        params.min_level_gain,
    )?;
    let returned_level = fit
        .levels
        .len()
        .saturating_sub(1 + usize::from(fit.dropped));
    Ok(RecoverResult {
        control: mesh,
        report: RecoverReport {
            returned_level,
            voxel: fit.voxel,
            sigma: prepared.sigma,
            inside_level: prepared.inside_level,
            smoothing_seconds: prepared.smoothing_seconds,
            potential_seconds: prepared.potential_seconds,
            levels: fit.levels,
            converged,
            stop_reason,
            seconds: start.elapsed().as_secs_f64()
                + prepared.smoothing_seconds
                + prepared.potential_seconds,
        },
    })
}

/// The recovery of one volume, level after level ([`LevelFit`]): image
/// springs along the normals, the two-sided forces and the user's points.
struct VolumeFit<'a> {
    field: ImageField<'a>,
    voxel: Real,
    points: &'a [Point3],
    boundary: &'a [Point3],
    params: &'a RecoverParams,
    progress: &'a mut dyn FnMut(usize, usize, Real),
    levels: Vec<RecoverLevel>,
    /// The previous level's result, returned if the next one is worse.
    coarser: Option<PolyMesh>,
    /// Whether the last level was dropped for it.
    dropped: bool,
    /// How far off the boundary each face of the last level is (counts).
    off: Vec<usize>,
    /// The adaptive refinement's cap on the next level's control points.
    cap: Real,
}

impl VolumeFit<'_> {
    /// The control-point budget of adaptive levels
    /// (`RecoverParams::max_control_share` of the iso-surface points).
    fn budget(&self) -> Real {
        self.params.max_control_share * self.boundary.len() as Real
    }
}

impl LevelFit for VolumeFit<'_> {
    fn fit_level(&mut self, at: Level) -> Result<Verdict> {
        let Level {
            number: level,
            refiner,
            mesh,
            creases: _,
        } = at;
        let level_start = Instant::now();
        let voxel = self.voxel;
        let VolumeFit {
            ref field,
            points,
            boundary,
            params,
            ref mut progress,
            ref mut levels,
            ..
        } = *self;
        if (0..refiner.level.num_edges()).any(|e| refiner.level.is_boundary_edge(e)) {
            return Err(Error::Topology(
                "the initial mesh has a boundary: recovering a volume needs a closed surface"
                    .into(),
            ));
        }
        // Level-1 patches carry everything: the closest points of the user
        // points, the thin plate and damping, and the image springs.
        let mut engine = ClosestPointEngine::new(
            refiner,
            &mesh.positions,
            &ClosestPointParams {
                level: 1,
                ..Default::default()
            },
        )?;
        let table = engine.table();
        // A level-1 patch is corner `c` of a control face.
        let face_of_patch = face_of_corner(&mesh.face_offsets);
        // One set of Gauss points per level-1 patch carries both the image
        // springs and the thin plate: exact on regular patches, and near
        // irregular vertices a fixed number of exact samples instead of
        // `quadrature`'s quadtree leaves, which cost ten times more to
        // assemble for a vanishing share of the area. The tangents give the
        // normals; the positions are rows in the assembly's pattern.
        let SampleRows {
            ju, jv, weights, ..
        } = patch_sample_rows(table, params.quadrature_order)?;
        let at = gauss_points(table, params.quadrature_order);
        let area: Real = weights.iter().sum();
        let material = MaterialParams::thin_plate(params.tension, params.bending, area);
        // Damping on the limit surface is blind to control-point modes that
        // barely move it (a checkerboard over a coarse cage); a small
        // proximal term on the control points themselves, 1 % of D's mean
        // diagonal, keeps the solves from letting them drift.
        let system = LevelSystem::new(
            table,
            params.quadrature_order,
            &material,
            params.damping / area,
            None,
            0.01,
        )?;
        let rows = system.assembly.rows_at(table, &at)?;
        let j = rows.rows();
        let sample_step = 0.25 * voxel;
        let search_of = |p: &[Point3]| {
            params
                .search_voxels
                .unwrap_or((median_edge_length(mesh, p) / voxel / 3.0).clamp(2.0, 12.0))
        };
        let max_steps = if level == 0 {
            4 * params.max_steps
        } else {
            params.max_steps
        };
        let point_k = vec![params.points_weight / points.len().max(1) as Real; points.len()];
        // The two-sided forces' points: every `stride`-th iso-surface point,
        // at most a quarter as many as the samples (their search is most of
        // a step's time; a part the surface misses still holds one point
        // per few voxels of its surface).
        let mut far_from = Candidates::new(if params.two_sided_weight > 0.0 {
            let stride = (4 * boundary.len()).div_ceil(weights.len().max(1)).max(1);
            boundary.iter().step_by(stride).copied().collect()
        } else {
            Vec::new()
        });
        let two_sided_k = params.two_sided_weight / far_from.points.len().max(1) as Real;
        let reach = params.two_sided_voxels * voxel;
        // User points pull a patch as wide as a level-0 control edge at
        // every level (each subdivision halves the edges).
        let point_radius =
            (1u64 << level.min(30)) as Real * median_edge_length(mesh, &mesh.positions);
        let mut p = mesh.positions.clone();
        let mut p_before = p.clone();
        let mut energy: Vec<Real> = Vec::new();
        let (mut steps, mut cg_iterations, mut still) = (0, 0, false);
        let (offsets, unresolved, search, outside_box, unmatched, off, local) = loop {
            let search = search_of(&p);
            let range = search * voxel;
            let xs = j.apply(&p)?;
            let us = ju.apply(&p)?;
            let vs = jv.apply(&p)?;
            let found: Vec<(Point3, Real, Offset)> = (0..xs.len())
                .into_par_iter()
                .map(|i| {
                    let nrm = us[i].coords.cross(&vs[i].coords);
                    let da = nrm.norm();
                    if da.is_nan() || da <= 0.0 {
                        return (xs[i], 0.0, Offset::Boundary(0.0));
                    }
                    let n = nrm / da;
                    let o = field.boundary_offset(&xs[i], &n, range, sample_step);
                    let target = match o {
                        Offset::Boundary(t) => xs[i] + t * n,
                        // Refining a level that has found the boundary:
                        // a sample with none in range is left to the thin
                        // plate, not pushed (pushes at fine levels run away).
                        _ if level > 0 => return (xs[i], 0.0, o),
                        Offset::Inside | Offset::Outside => {
                            xs[i] + range * field.balloon_direction(&xs[i], &n, o == Offset::Inside)
                        }
                    };
                    (target, da * weights[i], o)
                })
                .collect();
            let total: Real = found.iter().map(|f| f.1).sum();
            if total.is_nan() || total <= 0.0 {
                return Err(Error::input(
                    "the model's limit surface has no area; is the initial mesh degenerate?",
                ));
            }
            let beyond: Vec<Real> = xs
                .iter()
                .map(|x| voxels_outside_box(field.smoothed, x))
                .collect();
            let outside = beyond.iter().filter(|&&b| b > 0.0).count();
            if 2 * outside > xs.len() {
                return Err(Error::NotConverged(format!(
                    "the model left the volume at level {level}, step {steps}: start from a finer cage (--resolution) or a seed inside the object"
                )));
            }
            let targets: Vec<Point3> = found.iter().map(|f| f.0).collect();
            let kw: Vec<Real> = found.iter().map(|f| f.1 / total).collect();
            if !points.is_empty() || !far_from.points.is_empty() {
                engine.set_positions(&p)?;
            }
            let (far, far_closest) = far_points(&engine, &xs, &us, &vs, &at, &mut far_from, reach)?;
            let far_k = vec![two_sided_k; far.len()];
            let mut springs = system.assembly.data_springs(
                engine.table(),
                &far,
                &far_closest,
                &far_k,
                Some(RowSprings {
                    rows: &rows,
                    x: &xs,
                    d: &targets,
                    k: &kw,
                }),
            )?;
            if !points.is_empty() {
                let closest = engine.closest_points(points)?;
                let spread =
                    spread_point_springs(j, &xs, points, &closest, &point_k, point_radius)?;
                springs.add(&SpringSystem {
                    matrix: system
                        .assembly
                        .matrix(system.assembly.values_of(&spread.matrix)?),
                    ..spread
                })?;
            }
            let e = springs.energy + system.potential(&p)?;
            progress(level, steps, e);
            let unresolved_area: Real = found
                .iter()
                .filter(|f| !matches!(f.2, Offset::Boundary(_)))
                .map(|f| f.1)
                .sum::<Real>()
                / total;
            // While points still search for the boundary (growing from a
            // seed), the energy stays flat without being settled.
            let settled = (level > 0 || unresolved_area < 0.01)
                && (still
                    || energy.last().is_some_and(|&prev: &Real| {
                        let change = (prev - e).abs();
                        change <= params.energy_tolerance * prev.abs()
                            || change <= 0.5 * (params.settle_voxels * voxel).powi(2)
                    }));
            energy.push(e);
            // A sample farther outside the box than it searches cannot be on
            // its way to a boundary inside it: the level has gone wrong.
            let escaped = beyond.iter().any(|&b| b > search + 1.0);
            if settled || escaped || steps >= max_steps {
                let t: Vec<Real> = found
                    .iter()
                    .filter_map(|f| match f.2 {
                        Offset::Boundary(t) => Some(t.abs() / voxel),
                        _ => None,
                    })
                    .collect();
                let unresolved = 1.0 - t.len() as Real / found.len() as Real;
                let outside_box = beyond.iter().filter(|&&b| b > 1.0).count() as Real
                    / beyond.len().max(1) as Real;
                let unmatched = far.len() as Real / far_from.points.len().max(1) as Real;
                // How far off the boundary each face is, for adaptive
                // refinement: the far iso-surface points whose closest point
                // it holds, and while the offsets' 95th percentile is above
                // the tolerance, its samples farther from the boundary than it
                // (else, with a few local misses, its samples beyond
                // LOCAL_MISS × it).
                let mut off = vec![0usize; mesh.num_faces()];
                let stats = ErrorStats::new(&t, bbox_diagonal(&xs) / voxel);
                let local = local_misses(&t, params.tolerance_voxels);
                let off_limit = if stats.p95 > params.tolerance_voxels {
                    Some(params.tolerance_voxels)
                } else {
                    local.then_some(LOCAL_MISS * params.tolerance_voxels)
                };
                if let Some(limit) = off_limit {
                    for (f, o) in at.iter().zip(&found) {
                        if matches!(o.2, Offset::Boundary(t) if t.abs() > limit * voxel) {
                            off[face_of_patch[f.0] as usize] += 1;
                        }
                    }
                }
                for c in &far_closest {
                    off[face_of_patch[c.patch.0 as usize] as usize] += 1;
                }
                break (
                    stats,
                    unresolved,
                    search,
                    outside_box,
                    unmatched,
                    off,
                    local,
                );
            }
            let load = if params.inflation != 0.0 {
                Some(inflation_force(
                    j,
                    &us,
                    &vs,
                    &weights,
                    params.inflation * voxel / total,
                )?)
            } else {
                None
            };
            let report = system.step(
                springs,
                load.as_deref(),
                &mut p,
                &mut p_before,
                &PcgParams::default(),
            )?;
            cg_iterations += report.iterations;
            steps += 1;
            let moved = p_before
                .iter()
                .zip(&p)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, Real::max);
            still = moved < 0.01 * voxel;
        };
        mesh.positions = p;
        levels.push(RecoverLevel {
            level,
            control_points: mesh.num_vertices(),
            faces: mesh.num_faces(),
            samples: weights.len(),
            steps,
            cg_iterations,
            seconds: level_start.elapsed().as_secs_f64(),
            energy,
            offsets,
            unresolved,
            search_voxels: search,
            outside_box,
            boundary_points: far_from.points.len(),
            unmatched,
        });
        self.judge(mesh, off, local)
    }

    fn refinement(&mut self, level: usize, mesh: &PolyMesh) -> Result<Refine> {
        let (params, voxel, boundary) = (self.params, self.voxel, self.boundary);
        let edge = median_edge_length(mesh, &mesh.positions);
        if 0.5 * edge < params.min_edge_voxels * voxel {
            return Ok(Refine::Stop(
                false,
                format!(
                    "level {} would have control edges of {:.2} voxels, below the {} voxel minimum",
                    level + 1,
                    0.5 * edge / voxel,
                    params.min_edge_voxels
                ),
            ));
        }
        if params.refinement == Refinement::Uniform {
            return Ok(Refine::Uniform);
        }
        // The worst first, within the growth allowed.
        let off = &self.off;
        let mut rank: Vec<usize> = (0..off.len()).filter(|&f| off[f] > 0).collect();
        rank.sort_by(|&a, &b| off[b].cmp(&off[a]).then(a.cmp(&b)));
        if rank.is_empty() {
            return Ok(Refine::Stop(
                false,
                format!(
                    "no face of level {level} is off the boundary: finer levels would not follow it better"
                ),
            ));
        }
        let budget = self.budget();
        let growth = params.max_level_growth * mesh.num_vertices() as Real;
        self.cap = if boundary.is_empty() {
            growth
        } else {
            budget.min(growth)
        };
        Ok(Refine::Adaptive {
            rank,
            cap: self.cap,
        })
    }

    fn refined(&mut self, next: Next) -> Result<Option<(bool, String)>> {
        let Next {
            level,
            parent: mesh,
            creases: _,
            how,
            mesh: next,
        } = next;
        let next_vertices = next.num_vertices();
        if matches!(how, Refined::Adaptive(_)) && next_vertices as Real > self.cap {
            return Ok(Some((
                false,
                format!(
                    "splitting any face of level {level} ({} control points) would pass the budget of {:.0} ({:.0} % of the {} iso-surface points)",
                    mesh.num_vertices(),
                    self.budget(),
                    100.0 * self.params.max_control_share,
                    self.boundary.len()
                ),
            )));
        }
        self.coarser = Some(mesh.clone());
        Ok(None)
    }
}

/// How far `x` lies outside `volume`'s sample box (`0 ≤ index ≤ n − 1`),
/// in index units (voxels along the farthest axis); 0 inside.
fn voxels_outside_box(volume: &crate::volume::Volume, x: &Point3) -> Real {
    let c = volume.continuous_index(x);
    let dims = volume.dims();
    (0..3)
        .map(|a| (-c[a]).max(c[a] - (dims[a] - 1) as Real))
        .fold(0.0, Real::max)
}

/// Median length of the control mesh's edges at positions `p` (each face
/// side counted once per face): a simplified cage's few long edges on flat
/// parts would raise a mean, and with it the search range, far above the
/// thin parts' edges.
fn median_edge_length(mesh: &PolyMesh, p: &[Point3]) -> Real {
    let mut lengths: Vec<Real> = mesh
        .faces()
        .flat_map(|face| (0..face.len()).map(move |i| (face[i], face[(i + 1) % face.len()])))
        .map(|(a, b)| (p[a as usize] - p[b as usize]).norm())
        .collect();
    if lengths.is_empty() {
        return 0.0;
    }
    let mid = lengths.len() / 2;
    *lengths.select_nth_unstable_by(mid, Real::total_cmp).1
}

/// The `order × order` Gauss-Legendre points of every patch of `table`, as
/// [`patch_sample_rows`] takes them (patch after patch, [`square_rule`]'s
/// order within a patch).
fn gauss_points(table: &PatchTable, order: usize) -> Vec<(usize, [Real; 2])> {
    let rule = square_rule(&gauss_legendre(order));
    (0..table.num_patches())
        .flat_map(|f| rule.iter().map(move |&(st, _)| (f, st)))
        .collect()
}
