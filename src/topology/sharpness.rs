//! Crease sharpness of edges and vertices, and the vertex rule it implies.
//!
//! Conventions follow DeRose, Kass and Truong 1998 ("Subdivision surfaces in
//! character animation", §3) as implemented by OpenSubdiv's `Sdc` with the
//! uniform crease method: a sharpness `s ≥ 10` is infinite; otherwise each
//! level decrements it by one (`max(0, s − 1)`). Boundary edges are infinitely
//! sharp.

use crate::error::{Error, Result};
use crate::math::Real;

use super::Level;

/// Sharpness at or above which a crease never smooths out.
pub const SHARPNESS_INFINITE: Real = 10.0;

/// Per-edge and per-vertex sharpness of one level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sharpness {
    /// One value per edge (0 = smooth).
    pub edge: Vec<Real>,
    /// One value per vertex (0 = smooth; infinite = corner).
    pub vertex: Vec<Real>,
}

/// The rule a vertex is refined with, from its number of sharp incident edges
/// and its own sharpness (DeRose et al. 1998, §3.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum VertexRule {
    /// No sharp edges: the Catmull-Clark vertex rule.
    Smooth,
    /// One sharp edge: refined with the smooth rule.
    Dart,
    /// Two sharp edges: the cubic B-spline curve rule `(a + 6v + b) / 8`.
    Crease,
    /// Three or more sharp edges, or a sharp vertex: the vertex stays put.
    Corner,
}

/// Sharpness after one level of uniform decrement.
pub fn decrement(s: Real) -> Real {
    if s >= SHARPNESS_INFINITE {
        s
    } else {
        (s - 1.0).max(0.0)
    }
}

impl VertexRule {
    /// The rule for a vertex with the given sharpness and incident edge sharpnesses.
    pub fn from_sharpness(vertex: Real, edges: impl Iterator<Item = Real>) -> VertexRule {
        if vertex > 0.0 {
            return VertexRule::Corner;
        }
        match edges.filter(|&s| s > 0.0).count() {
            0 => VertexRule::Smooth,
            1 => VertexRule::Dart,
            2 => VertexRule::Crease,
            _ => VertexRule::Corner,
        }
    }
}

impl Sharpness {
    /// Level-0 sharpness: user creases `(i, j, s)` (vertex pairs, 0-based),
    /// boundary edges infinite, and — for the edge-and-corner boundary rule —
    /// boundary vertices with a single face infinitely sharp (corners).
    pub fn initial(
        level: &Level,
        creases: &[(u32, u32, Real)],
        corners: bool,
    ) -> Result<Sharpness> {
        let mut edge = vec![0.0; level.num_edges()];
        for (k, &(i, j, s)) in creases.iter().enumerate() {
            if s.is_nan() || s < 0.0 {
                return Err(Error::Input(format!(
                    "crease {k} ({i}, {j}) has sharpness {s}; sharpness must be ≥ 0"
                )));
            }
            let e = find_edge(level, i, j).ok_or_else(|| {
                Error::Input(format!(
                    "crease {k}: vertices {i} and {j} are not joined by an edge of the mesh"
                ))
            })?;
            // Stored at single precision, as OpenSubdiv does, so that results
            // agree with it bit for bit (2.3 is 2.2999999523…).
            edge[e] = (s as f32 as Real).min(SHARPNESS_INFINITE);
        }
        for (e, s) in edge.iter_mut().enumerate() {
            if level.is_boundary_edge(e) {
                *s = SHARPNESS_INFINITE;
            }
        }
        let vertex = (0..level.num_vertices)
            .map(|v| {
                if corners && level.vertex_faces(v).len() == 1 {
                    SHARPNESS_INFINITE
                } else {
                    0.0
                }
            })
            .collect();
        Ok(Sharpness { edge, vertex })
    }

    /// The rule of vertex `v` at this level.
    pub fn rule(&self, level: &Level, v: usize) -> VertexRule {
        VertexRule::from_sharpness(
            self.vertex[v],
            level.vertex_edges(v).iter().map(|&e| self.edge[e as usize]),
        )
    }

    /// The rule vertex `v` will have after one more level (sharpness decremented).
    pub fn child_rule(&self, level: &Level, v: usize) -> VertexRule {
        VertexRule::from_sharpness(
            decrement(self.vertex[v]),
            level
                .vertex_edges(v)
                .iter()
                .map(|&e| decrement(self.edge[e as usize])),
        )
    }

    /// True when any edge or vertex has a finite, non-zero sharpness.
    pub fn has_semi_sharp(&self) -> bool {
        self.edge
            .iter()
            .chain(&self.vertex)
            .any(|&s| s > 0.0 && s < SHARPNESS_INFINITE)
    }

    /// Largest finite sharpness (0 when there is none).
    pub fn max_finite(&self) -> Real {
        self.edge
            .iter()
            .chain(&self.vertex)
            .copied()
            .filter(|&s| s < SHARPNESS_INFINITE)
            .fold(0.0, Real::max)
    }
}

/// The edge joining vertices `i` and `j`, if any.
pub fn find_edge(level: &Level, i: u32, j: u32) -> Option<usize> {
    if i as usize >= level.num_vertices || j as usize >= level.num_vertices {
        return None;
    }
    level
        .vertex_edges(i as usize)
        .iter()
        .map(|&e| e as usize)
        .find(|&e| level.other_vertex(e, i) == j && i != j)
}
