//! Crease sharpness of edges and vertices, and the vertex rule it implies.
//!
//! Conventions follow DeRose, Kass and Truong 1998 ("Subdivision surfaces in
//! character animation", §3) as implemented by OpenSubdiv's `Sdc` with the
//! uniform crease method: a sharpness `s ≥ 10` is infinite; otherwise each
//! level decrements it by one (`max(0, s − 1)`). Boundary edges are infinitely
//! sharp. The Chaikin method (OpenSubdiv's `CREASE_CHAIKIN`, after Chaikin's
//! curve scheme applied to sharpness values along a crease) decays each half
//! of an edge towards the mean of the other semi-sharp edges at its end.

use crate::error::{Error, Result};
use crate::math::Real;

use super::Level;

/// Sharpness at or above which a crease never smooths out.
pub const SHARPNESS_INFINITE: Real = 10.0;

/// How edge sharpness decays from one level to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CreaseMethod {
    /// Each half of an edge gets `max(0, s − 1)` (DeRose et al. 1998). The default.
    #[default]
    Uniform,
    /// The half of edge `e` at vertex `v` gets `¾ s_e + ¼ mean(others) − 1`
    /// (at least 0), the mean taken over the other semi-sharp edges at `v`;
    /// `s_e − 1` when there are none. Vertex sharpness decays uniformly.
    Chaikin,
}

impl std::str::FromStr for CreaseMethod {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "uniform" => Ok(CreaseMethod::Uniform),
            "chaikin" => Ok(CreaseMethod::Chaikin),
            _ => Err(Error::input(format!(
                "unknown crease method '{s}': expected uniform or chaikin"
            ))),
        }
    }
}

/// Per-edge and per-vertex sharpness of one level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sharpness {
    /// One value per edge (0 = smooth).
    pub edge: Vec<Real>,
    /// One value per vertex (0 = smooth; infinite = corner).
    pub vertex: Vec<Real>,
    /// How the edge values decay.
    pub method: CreaseMethod,
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
    /// user vertex sharpness `(v, s)`, boundary edges infinite, and — for the
    /// edge-and-corner boundary rule (`corners`) — boundary vertices with a
    /// single face infinitely sharp (corners).
    pub fn initial(
        level: &Level,
        creases: &[(u32, u32, Real)],
        vertex_sharpness: &[(u32, Real)],
        corners: bool,
        method: CreaseMethod,
    ) -> Result<Sharpness> {
        let mut edge = vec![0.0; level.num_edges()];
        for (k, &(i, j, s)) in creases.iter().enumerate() {
            if s.is_nan() || s < 0.0 {
                return Err(Error::input(format!(
                    "crease {k} ({i}, {j}) has sharpness {s}; sharpness must be ≥ 0"
                )));
            }
            let e = find_edge(level, i, j).ok_or_else(|| {
                Error::input(format!(
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
        let mut vertex: Vec<Real> = (0..level.num_vertices)
            .map(|v| {
                if corners && level.vertex_faces(v).len() == 1 {
                    SHARPNESS_INFINITE
                } else {
                    0.0
                }
            })
            .collect();
        for (k, &(v, s)) in vertex_sharpness.iter().enumerate() {
            if s.is_nan() || s < 0.0 {
                return Err(Error::input(format!(
                    "vertex sharpness {k} (vertex {v}) is {s}; sharpness must be ≥ 0"
                )));
            }
            let slot = vertex.get_mut(v as usize).ok_or_else(|| {
                Error::out_of_range(format!(
                    "vertex sharpness {k}: vertex {v} is not in the mesh ({} vertices)",
                    level.num_vertices
                ))
            })?;
            *slot = slot.max((s as f32 as Real).min(SHARPNESS_INFINITE));
        }
        Ok(Sharpness {
            edge,
            vertex,
            method,
        })
    }

    /// The sharpness of the two halves of every edge after one level: entry
    /// `2e` is the half at `edge_verts[e][0]`, `2e + 1` the one at
    /// `edge_verts[e][1]` (the order of [`refine_topology`]'s child edges).
    ///
    /// Uniform: `max(0, s − 1)`. Chaikin (OpenSubdiv's `Sdc::Crease::
    /// SubdivideEdgeSharpnessAtVertex`): for a semi-sharp edge `e` at a vertex
    /// `v` with `k ≥ 2` semi-sharp edges (sum `Σ`), `¾ s_e + ¼ (Σ − s_e) /
    /// (k − 1) − 1`, at least 0; `s_e − 1` when `e` is the only one.
    ///
    /// [`refine_topology`]: crate::subdivision::refine_topology
    pub fn child_edges(&self, level: &Level) -> Vec<Real> {
        let mut out = Vec::with_capacity(2 * self.edge.len());
        for e in 0..self.edge.len() {
            for v in level.edge_verts[e] {
                out.push(self.half_at(level, e, v));
            }
        }
        out
    }

    /// The child sharpness of the half of edge `e` at its end `v`.
    fn half_at(&self, level: &Level, e: usize, v: u32) -> Real {
        let s = self.edge[e];
        let semi = |s: Real| s > 0.0 && s < SHARPNESS_INFINITE;
        if self.method == CreaseMethod::Uniform || !semi(s) {
            return decrement(s);
        }
        let (mut sum, mut k) = (0.0, 0usize);
        for &g in level.vertex_edges(v as usize) {
            let t = self.edge[g as usize];
            if semi(t) {
                sum += t;
                k += 1;
            }
        }
        if k < 2 {
            return decrement(s);
        }
        (0.75 * s + 0.25 * (sum - s) / (k - 1) as Real - 1.0).max(0.0)
    }

    /// The child sharpness of the half at `v` of each edge of `v`, in the
    /// order of `level.vertex_edges(v)`.
    pub fn child_edges_at<'a>(
        &'a self,
        level: &'a Level,
        v: usize,
    ) -> impl Iterator<Item = Real> + 'a {
        level
            .vertex_edges(v)
            .iter()
            .map(move |&e| self.half_at(level, e as usize, v as u32))
    }

    /// The rule of vertex `v` at this level.
    pub fn rule(&self, level: &Level, v: usize) -> VertexRule {
        VertexRule::from_sharpness(
            self.vertex[v],
            level.vertex_edges(v).iter().map(|&e| self.edge[e as usize]),
        )
    }

    /// The rule vertex `v` will have after one more level.
    pub fn child_rule(&self, level: &Level, v: usize) -> VertexRule {
        VertexRule::from_sharpness(decrement(self.vertex[v]), self.child_edges_at(level, v))
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
