//! Sharp creases found in the data and tagged on the control mesh.
//!
//! Smooth surfaces round a machined edge off, and Poisson reconstruction
//! cannot do otherwise; a Catmull-Clark surface can keep it, with the edges
//! of its control mesh along the crease tagged infinitely sharp (DeRose,
//! Kass and Truong 1998; the idea of fitting piecewise smooth surfaces with
//! tagged creases is Hoppe et al. 1994's). After level 0, every interior
//! control edge is tested against the data around it
//! ([`crease_edges`]): the points near the surface beside the edge are split
//! by the side of the edge they lie on, a plane is fitted to each side, and
//! the edge is a crease when both sides are flat, their planes meet at
//! [`FitParams::crease_angle`](super::FitParams::crease_angle) or more, and
//! the planes' line of intersection runs along the edge and close to it. An
//! edge that does not follow a crease of the data (the crease crosses its
//! faces) is not tagged: the test never guesses where a crease runs between
//! control edges. The driver then fits the level once more with the tags,
//! keeps them only if that fit is not worse ([`super::levels::fitted_worse`]),
//! and carries them through the refinements ([`refined_creases`]).

use std::collections::HashSet;
use std::num::NonZero;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use super::init::outliers::plane;
use crate::error::Result;
use crate::limit::ClosestPointEngine;
use crate::math::{Point3, Real, Vector3, newell_normal};
use crate::mesh::PolyMesh;
use crate::subdivision::{Hierarchy, Refiner};
use crate::topology::{Level, NONE, SHARPNESS_INFINITE, find_edge};

/// A sharp edge `(i, j, s)`: vertices `i < j`, sharpness `s`, as
/// [`RefineOptions::creases`](crate::subdivision::RefineOptions::creases)
/// holds them.
pub type Crease = (u32, u32, Real);

/// Data points looked at around each edge (the nearest ones to the surface
/// point by its midpoint, within [`REACH`] edge lengths).
const NEIGHBOURS: NonZero<usize> = NonZero::new(48).unwrap();

/// How far from the edge's surface point the points of its two sides may
/// be, in edge lengths.
const REACH: Real = 1.5;

/// Points closer to the edge than this many edge lengths (across it) belong
/// to neither side: the crease itself and the rounding a noisy scan gives it.
const BAND: Real = 0.15;

/// Fewest points on each side for a plane to count.
const MIN_SIDE_POINTS: usize = 6;

/// The planes' line of intersection must run within this angle of the edge.
const MAX_LINE_ANGLE_DEG: Real = 35.0;

/// ... and pass within this many edge lengths of the edge's surface point.
const MAX_LINE_OFFSET: Real = 0.5;

/// A side is flat when its points' RMS distance from their plane is at most
/// this many noise σ, or [`FLAT_EDGE_FRACTION`] of the edge length when that
/// is larger (noise-free data).
const FLAT_NOISE_MULTIPLE: Real = 3.0;

/// See [`FLAT_NOISE_MULTIPLE`].
const FLAT_EDGE_FRACTION: Real = 0.05;

/// The smooth surface must miss the points by the edge (within [`BAND`]):
/// their RMS distance to it is above this many noise σ. Where the smooth
/// fit already explains the data to the noise (a fillet, a neck, a bent
/// limb), a crease would only add a kink.
const MISS_NOISE_MULTIPLE: Real = 2.0;

/// The data a crease is judged on.
pub(crate) struct CreaseData<'a> {
    /// The data points.
    pub points: &'a [Point3],
    /// Each point's distance to the (smooth) limit surface.
    pub miss: &'a [Real],
    /// A tree over `points`.
    pub tree: &'a ImmutableKdTree<Real, 3>,
    /// The data's noise σ (0 when unknown).
    pub noise: Real,
}

/// The control edges of `level` (positions `p`) that follow a crease of the
/// `data` at an angle of at least `min_angle_deg` degrees, as vertex pairs
/// `(i, j)` with `i < j`, ordered by edge. `surface[e]` is the limit-surface
/// point closest to edge `e`'s midpoint. The points by the edge must be off
/// the smooth surface by more than the noise and on the two planes
/// ([`MISS_NOISE_MULTIPLE`]). Isolated edges (neither end on another tagged
/// edge) are left out: a crease is a chain.
fn crease_edges(
    level: &Level,
    p: &[Point3],
    surface: &[Point3],
    data: &CreaseData,
    min_angle_deg: Real,
) -> Vec<(u32, u32)> {
    let CreaseData {
        points,
        miss,
        tree,
        noise,
    } = *data;
    let cos_angle = min_angle_deg.to_radians().cos();
    let centroid = |f: u32| -> Vector3 {
        let vs = level.face_vertices(f as usize);
        vs.iter().map(|&v| p[v as usize].coords).sum::<Vector3>() / vs.len() as Real
    };
    let normal =
        |f: u32| -> Vector3 { newell_normal(p, level.face_vertices(f as usize)).normalize() };
    let tagged: Vec<bool> = (0..level.num_edges())
        .into_par_iter()
        .map(|e| {
            let [a, b] = level.edge_verts[e];
            let [fa, fb] = level.edge_faces[e];
            if fb == NONE {
                return false;
            }
            let along = p[b as usize] - p[a as usize];
            let length = along.norm();
            if length <= 0.0 || !length.is_finite() {
                return false;
            }
            let d = along / length;
            let across = centroid(fa) - centroid(fb);
            let across = across - d * d.dot(&across);
            if across.norm() <= 0.0 || !across.norm().is_finite() {
                return false;
            }
            let u = across.normalize();
            let m = surface[e];
            let reach2 = (REACH * length).powi(2);
            let (mut side_a, mut side_b, mut by_edge) = (Vec::new(), Vec::new(), Vec::new());
            for n in tree.nearest_n::<SquaredEuclidean>(&[m.x, m.y, m.z], NEIGHBOURS) {
                if n.distance > reach2 {
                    break;
                }
                let q = points[n.item as usize].coords;
                let s = (q - m.coords).dot(&u);
                if s > BAND * length {
                    side_a.push(q);
                } else if s < -BAND * length {
                    side_b.push(q);
                } else {
                    by_edge.push((q, miss[n.item as usize]));
                }
            }
            let rms = |x: &mut dyn Iterator<Item = Real>| -> Real {
                let (sum, n) = x.fold((0.0, 0usize), |(s, n), d| (s + d * d, n + 1));
                if n == 0 {
                    0.0
                } else {
                    (sum / n as Real).sqrt()
                }
            };
            let missed = rms(&mut by_edge.iter().map(|b| b.1));
            if by_edge.is_empty() || missed <= MISS_NOISE_MULTIPLE * noise {
                return false;
            }
            if side_a.len() < MIN_SIDE_POINTS || side_b.len() < MIN_SIDE_POINTS {
                return false;
            }
            let (Some((ca, na, ra)), Some((cb, nb, rb))) = (plane(&side_a), plane(&side_b)) else {
                return false;
            };
            let flat = (FLAT_NOISE_MULTIPLE * noise).max(FLAT_EDGE_FRACTION * length);
            if ra > flat || rb > flat {
                return false;
            }
            // Normals facing out, as the control faces do.
            let na = if na.dot(&normal(fa)) < 0.0 { -na } else { na };
            let nb = if nb.dot(&normal(fb)) < 0.0 { -nb } else { nb };
            let cos = na.dot(&nb);
            if cos > cos_angle {
                return false;
            }
            let line = na.cross(&nb);
            let sin = line.norm();
            if line.dot(&d).abs() < MAX_LINE_ANGLE_DEG.to_radians().cos() * sin {
                return false;
            }
            // Distance from m to the planes' line: the offset x ⟂ line with
            // na·x = −ha and nb·x = −hb.
            let (ha, hb) = ((m.coords - ca).dot(&na), (m.coords - cb).dot(&nb));
            let offset = (ha * ha + hb * hb - 2.0 * ha * hb * cos).max(0.0).sqrt() / sin;
            // The points by the edge lie on one plane or the other, closer
            // than the smooth surface passes them.
            let on_planes = rms(&mut by_edge
                .iter()
                .map(|(q, _)| ((q - ca).dot(&na).abs()).min((q - cb).dot(&nb).abs())));
            offset <= MAX_LINE_OFFSET * length && on_planes <= flat.min(missed)
        })
        .collect();
    let mut ends = vec![0u32; p.len()];
    for e in (0..tagged.len()).filter(|&e| tagged[e]) {
        for v in level.edge_verts[e] {
            ends[v as usize] += 1;
        }
    }
    (0..tagged.len())
        .filter(|&e| tagged[e])
        .map(|e| level.edge_verts[e])
        .filter(|[a, b]| ends[*a as usize] > 1 || ends[*b as usize] > 1)
        .map(|[a, b]| (a.min(b), a.max(b)))
        .collect()
}

/// The control edges of the control mesh of `refiner` (positions `p`)
/// along creases of the `data` ([`crease_edges`]), with the surface points
/// by their midpoints found by `engine`, the level's closest-point engine
/// at `p`.
pub(crate) fn detect_creases(
    refiner: &Refiner,
    engine: &ClosestPointEngine,
    p: &[Point3],
    data: &CreaseData,
    angle: Real,
) -> Result<Vec<(u32, u32)>> {
    let level = &refiner.level;
    let mids: Vec<Point3> = level
        .edge_verts
        .iter()
        .map(|&[a, b]| Point3::from((p[a as usize].coords + p[b as usize].coords) / 2.0))
        .collect();
    let surface: Vec<Point3> = engine
        .closest_points(&mids)?
        .iter()
        .map(|c| c.point)
        .collect();
    Ok(crease_edges(level, p, &surface, data, angle))
}

/// The infinitely sharp creases of `child`, a refinement of a control mesh
/// whose creases are `parent`: `h` is one uniform refinement of that mesh
/// with its creases, and `uniform_vertex[v]` the vertex of `h`'s level 1
/// that child vertex `v` stands for (`None`: `child` is level 1 itself).
/// A child edge is a crease when it is half of a parent crease (a level-1
/// edge the refinement tagged), or a parent crease left whole (a local
/// refinement keeps the parent's vertices as its first ones).
pub(crate) fn refined_creases(
    h: &Hierarchy,
    child: &PolyMesh,
    uniform_vertex: Option<&[u32]>,
    parent: &[Crease],
) -> Vec<Crease> {
    let (level, sharp) = (&h.levels[1], &h.sharpness[1]);
    // (The refiner marks boundary edges infinitely sharp too: not creases.)
    let is_crease =
        |e: usize| sharp.edge[e] >= SHARPNESS_INFINITE && level.edge_faces[e][1] != NONE;
    let Some(uniform_vertex) = uniform_vertex else {
        return (0..level.num_edges())
            .filter(|&e| is_crease(e))
            .map(|e| {
                let [a, b] = level.edge_verts[e];
                (a.min(b), a.max(b), sharp.edge[e])
            })
            .collect();
    };
    let whole: HashSet<(u32, u32)> = parent
        .iter()
        .filter(|c| c.2 >= SHARPNESS_INFINITE)
        .map(|&(a, b, _)| (a.min(b), a.max(b)))
        .collect();
    let num_parent = h.levels[0].num_vertices as u32;
    let mut out = Vec::new();
    let mut seen = HashSet::new();
    for face in child.faces() {
        for (k, &a) in face.iter().enumerate() {
            let b = face[(k + 1) % face.len()];
            let key = (a.min(b), a.max(b));
            if !seen.insert(key) {
                continue;
            }
            let (ua, ub) = (uniform_vertex[a as usize], uniform_vertex[b as usize]);
            let half = find_edge(level, ua, ub).is_some_and(is_crease);
            let kept = key.1 < num_parent && whole.contains(&key);
            if half || kept {
                out.push((key.0, key.1, SHARPNESS_INFINITE));
            }
        }
    }
    out
}
