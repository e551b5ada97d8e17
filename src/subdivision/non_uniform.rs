//! Non-uniform Catmull-Clark subdivision with a knot interval per edge
//! (Sederberg, Zheng, Sewell, Sabin 1998, "Non-uniform recursive subdivision
//! surfaces"), as stencil tables. Each step inserts a knot in the middle of
//! every interval; the child topology is Catmull-Clark's (`refine_topology`).
//!
//! The rules are built from the cubic curve rule for midpoint knot insertion
//! (Sederberg et al. 1998, §2). For a control polygon `… P₀ P₁ …` whose
//! leg `P₀P₁` has interval `d` and neighbouring legs `d₋` (before `P₀`) and
//! `d₊` (after `P₁`):
//!
//! - curve edge point `M = ((d + 2d₊) P₀ + (d + 2d₋) P₁) / (2 (d₋ + d + d₊))`;
//! - curve vertex point at `P` between legs `a` and `b`:
//!   `V = (b E_a + (a + b) P + a E_b) / (2 (a + b))`.
//!
//! The surface rules are the tensor products of these on regular quad
//! regions, generalised as follows (our reconstruction; every rule is affine
//! and reduces to uniform Catmull-Clark when all intervals are equal):
//!
//! - *outer interval* `o(v, e)`: for an interior valence-4 vertex, the interval
//!   of the edge opposite `e` at `v`; at other interior vertices the mean of
//!   the other edges' intervals; at a boundary vertex, for a boundary edge the
//!   other boundary edge's interval, for an interior edge `d(e)` itself;
//! - face point `F = Σᵢ wᵢ Pᵢ / Σᵢ wᵢ`, `wᵢ` the product of `Pᵢ`'s weights in the
//!   curve edge points `M` of its two face edges (exactly the tensor product
//!   on a quad of a regular grid);
//! - edge point `E = (h₁ F₀ + (h₀ + h₁) M + h₀ F₁) / (2 (h₀ + h₁))`, `hₖ` the
//!   mean interval of the two edges of face `k` next to the edge (the curve
//!   vertex rule across the edge); boundary edge: `E = M` along the boundary;
//! - vertex point of valence `n`: `V = β P + Σₑ γₑ Mₑ + Σ_f φ_f F_f` with
//!   `ωₑ = o(v, e) / (2 (d(e) + o(v, e)))`, `γₑ = 8 ωₑ / n²`,
//!   `φ_f = 16 ω ω' / n²` (`ω, ω'` of the face's two edges at `v`) and
//!   `β = 1 − Σγ − Σφ` (the tensor product for `n = 4`; uniform Catmull-Clark
//!   for equal intervals); boundary vertex: the curve vertex rule along the
//!   boundary, or fixed at a valence-2 corner.
//!
//! Denominators that vanish (all intervals zero) fall back to equal weights.
//! Child intervals: each half of a parent edge gets `d / 2`, the edge from
//! face point to edge point gets `h / 2`.

use crate::error::{Error, Result};
use crate::math::Real;
use crate::stencil::{RowBuilder, StencilTable};
use crate::topology::{Level, NONE};

use super::refine_topology;

/// `num / den`, or `fallback` when `den` is zero.
fn ratio(num: Real, den: Real, fallback: Real) -> Real {
    if den > 0.0 { num / den } else { fallback }
}

/// Checks that there is one finite, non-negative interval per edge.
pub fn check_intervals(level: &Level, d: &[Real]) -> Result<()> {
    if d.len() != level.num_edges() {
        return Err(Error::size_mismatch(format!(
            "{} knot intervals given for a mesh with {} edges",
            d.len(),
            level.num_edges()
        )));
    }
    if let Some(e) = d.iter().position(|x| !x.is_finite() || *x < 0.0) {
        return Err(Error::input(format!(
            "knot interval of edge {e} is {}; intervals must be finite and ≥ 0",
            d[e]
        )));
    }
    Ok(())
}

/// Knot-interval geometry of one level.
struct Intervals<'a> {
    level: &'a Level,
    d: &'a [Real],
    corner_face: Vec<u32>,
}

impl Intervals<'_> {
    /// `o(v, e)`: the interval on the far side of `v` along `e`.
    fn outer(&self, v: u32, e: u32) -> Real {
        let l = self.level;
        let edges = l.vertex_edges(v as usize);
        if l.is_boundary_vertex(v as usize) {
            if !l.is_boundary_edge(e as usize) {
                return self.d[e as usize];
            }
            return edges
                .iter()
                .find(|&&x| x != e && l.is_boundary_edge(x as usize))
                .map_or(self.d[e as usize], |&x| self.d[x as usize]);
        }
        if edges.len() == 4 {
            let ring = l.vertex_ring(v as usize);
            if let Some(k) = ring.edges.iter().position(|&x| x == e) {
                return self.d[ring.edges[(k + 2) % 4] as usize];
            }
        }
        let others: Vec<Real> = edges
            .iter()
            .filter(|&&x| x != e)
            .map(|&x| self.d[x as usize])
            .collect();
        if others.is_empty() {
            self.d[e as usize]
        } else {
            others.iter().sum::<Real>() / others.len() as Real
        }
    }

    /// Weights of the curve edge point `M` on edge `e` at its two ends.
    fn edge_weights(&self, e: u32) -> ([u32; 2], [Real; 2]) {
        let [a, b] = self.level.edge_verts[e as usize];
        let d = self.d[e as usize];
        let (oa, ob) = (self.outer(a, e), self.outer(b, e));
        let den = 2.0 * (oa + d + ob);
        let wa = ratio(d + 2.0 * ob, den, 0.5);
        ([a, b], [wa, 1.0 - wa])
    }

    fn add_edge_curve_point(&self, e: u32, s: Real, b: &mut RowBuilder) {
        let (v, w) = self.edge_weights(e);
        b.add(v[0], s * w[0]);
        b.add(v[1], s * w[1]);
    }

    fn add_face_point(&self, f: usize, s: Real, b: &mut RowBuilder) {
        let l = self.level;
        let fv = l.face_vertices(f);
        let fe = l.face_edge_list(f);
        let n = fv.len();
        let weight_at = |e: u32, v: u32| {
            let (ends, w) = self.edge_weights(e);
            if ends[0] == v { w[0] } else { w[1] }
        };
        let w: Vec<Real> = (0..n)
            .map(|i| weight_at(fe[i], fv[i]) * weight_at(fe[(i + n - 1) % n], fv[i]))
            .collect();
        let total: Real = w.iter().sum();
        for (i, &v) in fv.iter().enumerate() {
            b.add(v, s * ratio(w[i], total, 1.0 / n as Real));
        }
    }

    /// Mean interval of the two edges of face `f` next to edge `e`.
    fn cross(&self, f: u32, e: u32) -> Real {
        let fe = self.level.face_edge_list(f as usize);
        let n = fe.len();
        let k = fe.iter().position(|&x| x == e).unwrap_or(0);
        0.5 * (self.d[fe[(k + 1) % n] as usize] + self.d[fe[(k + n - 1) % n] as usize])
    }

    fn add_edge_point(&self, e: u32, b: &mut RowBuilder) {
        let [f0, f1] = self.level.edge_faces[e as usize];
        if f1 == NONE {
            self.add_edge_curve_point(e, 1.0, b);
            return;
        }
        let (h0, h1) = (self.cross(f0, e), self.cross(f1, e));
        let den = 2.0 * (h0 + h1);
        let (w0, w1) = (ratio(h1, den, 0.25), ratio(h0, den, 0.25));
        self.add_face_point(f0 as usize, w0, b);
        self.add_face_point(f1 as usize, w1, b);
        self.add_edge_curve_point(e, 1.0 - w0 - w1, b);
    }

    fn add_vertex_point(&self, v: u32, b: &mut RowBuilder) {
        let l = self.level;
        let vu = v as usize;
        if l.vertex_faces(vu).is_empty() {
            b.add(v, 1.0);
            return;
        }
        if l.is_boundary_vertex(vu) {
            let bnd: Vec<u32> = l
                .vertex_edges(vu)
                .iter()
                .copied()
                .filter(|&e| l.is_boundary_edge(e as usize))
                .collect();
            if l.vertex_faces(vu).len() == 1 || bnd.len() != 2 {
                b.add(v, 1.0); // corner
                return;
            }
            let (ea, eb) = (bnd[0], bnd[1]);
            let (a, bb) = (self.d[ea as usize], self.d[eb as usize]);
            let den = 2.0 * (a + bb);
            let (wa, wb) = (ratio(bb, den, 0.25), ratio(a, den, 0.25));
            self.add_edge_curve_point(ea, wa, b);
            self.add_edge_curve_point(eb, wb, b);
            b.add(v, 1.0 - wa - wb);
            return;
        }
        let ring = l.vertex_ring(vu);
        let n = ring.edges.len() as Real;
        let omega: Vec<Real> = ring
            .edges
            .iter()
            .map(|&e| {
                let (d, o) = (self.d[e as usize], self.outer(v, e));
                ratio(o, 2.0 * (d + o), 0.25)
            })
            .collect();
        let mut rest = 1.0;
        for (k, &e) in ring.edges.iter().enumerate() {
            let g = 8.0 * omega[k] / (n * n);
            self.add_edge_curve_point(e, g, b);
            rest -= g;
        }
        let m = ring.edges.len();
        for (k, &f) in ring.faces.iter().enumerate() {
            let phi = 16.0 * omega[k] * omega[(k + 1) % m] / (n * n);
            self.add_face_point(f as usize, phi, b);
            rest -= phi;
        }
        b.add(v, rest);
    }
}

/// One non-uniform Catmull-Clark step: the stencil (rows: face points, edge
/// points, vertex points, as [`refine_topology`]), the child level and the
/// child intervals. Errors when `d` is not one finite `≥ 0` value per edge.
pub fn non_uniform_step(parent: &Level, d: &[Real]) -> Result<(StencilTable, Level, Vec<Real>)> {
    check_intervals(parent, d)?;
    let mut corner_face = vec![0u32; parent.face_verts.len()];
    for f in 0..parent.num_faces() {
        corner_face[parent.face_offsets[f] as usize..parent.face_offsets[f + 1] as usize]
            .fill(f as u32);
    }
    let iv = Intervals {
        level: parent,
        d,
        corner_face,
    };
    let (nf, ne, nv) = (parent.num_faces(), parent.num_edges(), parent.num_vertices);
    let stencil = StencilTable::from_row_fn(nf + ne + nv, nv, |r, b| {
        if r < nf {
            iv.add_face_point(r, 1.0, b);
        } else if r < nf + ne {
            iv.add_edge_point((r - nf) as u32, b);
        } else {
            iv.add_vertex_point((r - nf - ne) as u32, b);
        }
    });
    let child = refine_topology(parent);
    let mut child_d = vec![0.0; child.num_edges()];
    for e in 0..ne {
        child_d[2 * e] = 0.5 * d[e];
        child_d[2 * e + 1] = 0.5 * d[e];
    }
    for c in 0..parent.face_verts.len() {
        let e = parent.face_edges[c];
        child_d[2 * ne + c] = 0.5 * iv.cross(iv.corner_face[c], e);
    }
    Ok((stencil, child, child_d))
}

/// Levels of a non-uniform Catmull-Clark refinement.
#[derive(Clone, Debug)]
pub struct NonUniformHierarchy {
    /// `levels[k]`: connectivity of level `k`.
    pub levels: Vec<Level>,
    /// `intervals[k]`: one knot interval per edge of level `k`.
    pub intervals: Vec<Vec<Real>>,
    /// `stencils[k]` maps level `k` to level `k + 1`.
    pub stencils: Vec<StencilTable>,
}

impl NonUniformHierarchy {
    /// Refines `level` with intervals `d` (one per edge) `levels` times (≤ 8).
    ///
    /// ```
    /// use subdyn::subdivision::NonUniformHierarchy;
    /// use subdyn::topology::Level;
    /// let cube = subdyn::examples::cube();
    /// let level = Level::from_mesh(&cube).unwrap();
    /// let d = vec![1.0; level.num_edges()];
    /// let h = NonUniformHierarchy::new(level, d, 2).unwrap();
    /// assert_eq!(h.levels[2].num_faces(), 96);
    /// ```
    pub fn new(level: Level, d: Vec<Real>, levels: usize) -> Result<Self> {
        if levels > 8 {
            return Err(Error::input(format!(
                "{levels} non-uniform levels requested; at most 8 are allowed"
            )));
        }
        check_intervals(&level, &d)?;
        let mut h = NonUniformHierarchy {
            levels: vec![level],
            intervals: vec![d],
            stencils: Vec::new(),
        };
        for k in 0..levels {
            let (s, child, cd) = non_uniform_step(&h.levels[k], &h.intervals[k])?;
            h.levels.push(child);
            h.intervals.push(cd);
            h.stencils.push(s);
        }
        Ok(h)
    }

    /// The composed table from level 0 to level `n`.
    pub fn stencil_to_level(&self, n: usize) -> Result<StencilTable> {
        if n >= self.levels.len() {
            return Err(Error::input(format!(
                "level {n} requested but the hierarchy has {} levels",
                self.levels.len() - 1
            )));
        }
        let mut s = StencilTable::identity(self.levels[0].num_vertices);
        for k in 0..n {
            s = self.stencils[k].compose(&s)?;
        }
        Ok(s)
    }
}
