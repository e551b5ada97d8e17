//! Untangling: where the limit surface crosses itself, the control points
//! of the faces there are smoothed (Taubin 1995, λ|μ steps), during a level
//! with a refit and stiffer fairness ([`untangled`]) and after the last one
//! without a refit ([`untangle_after_fit`]).

use crate::error::Result;
use crate::limit::QuadtreeCache;
use crate::math::{Point3, Real};
use crate::mesh::PolyMesh;
use crate::subdivision::Refiner;

use super::Untangling;
use super::crease_options;
use super::creases::Crease;
use super::init::voxel_surface::taubin_smoothed_where;
use super::quality::{CHECK_RATE, SelfIntersections};

/// Taubin steps on the control points of the faces an untangling round
/// marks (`FitParams::untangle_rounds`).
const UNTANGLE_SMOOTHING_STEPS: usize = 3;

/// Samples per side of every tessellation tile untangling checks: the
/// pleats it finds are larger than a tile, and a check at this rate costs
/// about a third of one at [`super::quality::CHECK_RATE`] (Spot, level 1:
/// 0.35 s against 0.85 s); the report still counts at that rate.
pub(super) const UNTANGLE_CHECK_RATE: usize = 2;

/// The untangling after the last level tries another round only after one
/// that removed at least this fraction of the crossing pairs, as each round
/// costs a tessellation of the surface. Pleats go in a round or a few, parts
/// grown into each other lose a few percent a round. Chosen on the choose
/// rows of the corpus: plate-n1 goes 362, 149, 86, 70, 0 (a round of 19 %
/// before the last), spot-out 1,710, 1,706 (0.2 %); checked on the others:
/// dragon-n1 stops after one round (10 %), chair-n1 after three (475, 394,
/// 379), cow-out after one.
const FINAL_UNTANGLE_GAIN: Real = 0.15;

/// One untangling round (`FitParams::untangle_rounds`): the control points
/// `p` of the `crossing` faces of `mesh` (those with a tessellation triangle
/// that crosses another) get [`UNTANGLE_SMOOTHING_STEPS`] Taubin steps, and
/// the umbrella weights of those points and of their `ring` neighbours are
/// multiplied by `stiffening`. Returns the smoothed points.
pub(super) fn untangled(
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
pub(super) fn untangle_after_fit(
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
