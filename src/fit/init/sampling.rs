//! Sampling density of a point cloud and snapping a cage onto it.

use super::voxel_surface::taubin_smoothed;
use crate::error::Result;
use crate::math::{Point3, Real, Vector3, newell_normal};
use crate::mesh::PolyMesh;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZero;

/// Neighbours counted by [`sampling_radius`].
const K: usize = 8;

/// Query points used by [`sampling_radius`] at most.
const QUERIES: usize = 2000;

/// A k-d tree over the points (item = point index).
pub fn point_tree(points: &[Point3]) -> ImmutableKdTree<Real, 3> {
    let coords: Vec<[Real; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
    ImmutableKdTree::new_from_slice(&coords)
}

/// Estimated covering radius of the sampling: the median, over up to 2000
/// evenly strided points, of the distance to the 8th nearest other point.
/// For uniform sampling of density `ρ` this is about `√(8 / (π ρ))`, a
/// little above the radius of the typical empty disc between samples, so
/// balls of this radius around the points cover the sampled surface.
pub fn sampling_radius(points: &[Point3], tree: &ImmutableKdTree<Real, 3>) -> Real {
    let k = (K + 1).min(points.len());
    let Some(k) = NonZero::new(k) else {
        return 0.0;
    };
    let stride = points.len().div_ceil(QUERIES).max(1);
    let mut d: Vec<Real> = points
        .iter()
        .step_by(stride)
        .map(|p| {
            tree.nearest_n::<SquaredEuclidean>(&[p.x, p.y, p.z], k)
                .last()
                .map_or(0.0, |nn| nn.distance.sqrt())
        })
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    let mid = d.len() / 2;
    d.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    d[mid]
}

/// Area-weighted vertex normals (sum of the faces' fan cross products), unit
/// length, zero for a vertex whose faces cancel.
pub fn vertex_normals(mesh: &PolyMesh) -> Vec<Vector3> {
    let mut n = vec![Vector3::zeros(); mesh.num_vertices()];
    for f in mesh.faces() {
        let p0 = mesh.positions[f[0] as usize];
        let mut area = Vector3::zeros();
        for w in f.windows(2).skip(1) {
            area +=
                (mesh.positions[w[0] as usize] - p0).cross(&(mesh.positions[w[1] as usize] - p0));
        }
        for &v in f {
            n[v as usize] += area;
        }
    }
    n.iter()
        .map(|v| v.try_normalize(0.0).unwrap_or_else(Vector3::zeros))
        .collect()
}

/// Unit Newell normal of every face (zero for a degenerate face).
pub fn face_normals(mesh: &PolyMesh) -> Vec<Vector3> {
    mesh.faces()
        .map(|f| {
            newell_normal(&mesh.positions, f)
                .try_normalize(0.0)
                .unwrap_or_else(Vector3::zeros)
        })
        .collect()
}

/// Moves the cage's vertices along their normals towards the points,
/// without turning any face over.
///
/// [`SNAP_ROUNDS`] rounds of: offsets `t_i = clamp((q_i − v_i)·n_i, ±max_move)`
/// with `q_i` the point nearest to `v_i` (the move onto `q_i`'s plane normal
/// to the vertex normal `n_i`), `v_i ← v_i + t_i n_i / 2`, then one Taubin
/// λ|μ step to keep the faces even. Then every face that has turned by more
/// than 60° from its orientation before snapping gets its vertices moved
/// halfway back, repeatedly ([`MAX_HALVINGS`] times, then all the way back);
/// a face whose vertices are all back has its old orientation, so the loop
/// ends.
pub fn snapped_to_points(
    mesh: &PolyMesh,
    points: &[Point3],
    tree: &ImmutableKdTree<Real, 3>,
    max_move: Real,
) -> Result<PolyMesh> {
    let mut current = mesh.clone();
    for _ in 0..SNAP_ROUNDS {
        let normals = vertex_normals(&current);
        for (v, n) in current.positions.iter_mut().zip(&normals) {
            let nn = tree.nearest_one::<SquaredEuclidean>(&[v.x, v.y, v.z]);
            let t = (points[nn.item as usize] - *v)
                .dot(n)
                .clamp(-max_move, max_move);
            *v += n * (0.5 * t);
        }
        current = taubin_smoothed(&current, 1);
    }
    let before = face_normals(mesh);
    let mut halvings = vec![0usize; mesh.num_vertices()];
    loop {
        let after = face_normals(&current);
        let mut turned = false;
        for (f, (a, b)) in before.iter().zip(&after).enumerate() {
            if a.dot(b) >= 0.5 {
                continue;
            }
            for &v in mesh.face(f) {
                let v = v as usize;
                let (old, new) = (mesh.positions[v], current.positions[v]);
                if old != new {
                    turned = true;
                    halvings[v] += 1;
                    current.positions[v] = if halvings[v] > MAX_HALVINGS {
                        old
                    } else {
                        old + (new - old) * 0.5
                    };
                }
            }
        }
        if !turned {
            return Ok(current);
        }
    }
}

/// Snap-and-smooth rounds of [`snapped_to_points`].
pub const SNAP_ROUNDS: usize = 6;

/// Halvings of a vertex's move before it is undone.
pub const MAX_HALVINGS: usize = 4;
