//! Exact evaluation of the limit surface at `(face, u, v)` by local
//! subdivision (Stam 1998 evaluates the same surface through an eigenbasis;
//! we subdivide the face's neighbourhood instead, which also covers
//! boundaries and creases with the refiner's own rules).
//!
//! The 1-ring of the face (all faces sharing a vertex with it) is cut out and
//! subdivided locally until the sub-face holding `(u, v)` is a regular
//! bicubic B-spline patch — interior corners of valence 4, or boundary /
//! infinitely sharp corners whose missing points are reflections
//! `2 P_b − P_i` — and the patch is evaluated there. The rows of the local
//! vertices are kept as weights over the base control points, so the result
//! is a limit stencil (a Jacobian row), not just a point. Only the 1-ring is
//! needed: the refined 1-ring of a sub-face depends on the 1-ring of its
//! parent alone (vertex rules read only the corners' rings, which are whole).

use crate::math::Real;
use crate::stencil::RowBuilder;
use crate::topology::{Level, SHARPNESS_INFINITE, Sharpness, VertexRule};

use super::bspline::patch_weights;
use super::param::{CORNERS, IDENTITY, chain, child_frame, mat_mul, quadrant, sub, subface};
use super::patch::{LocalPatch, SampleStencil};
use super::vertex_masks::{
    CornerKind, corner_kind, corner_tangents, limit_position_mask, masks_apply,
};

/// Deepest local subdivision; a point within `2⁻⁴⁰` of an irregular corner
/// is evaluated at the corner.
const MAX_DEPTH: usize = 40;

/// Most levels followed to converge the limit of a dart vertex.
const DART_DEPTH: usize = 80;

/// Depth at which derivatives at an irregular corner are taken (OpenSubdiv
/// `Bfr`'s default smooth approximation level).
const CORNER_DEPTH: usize = 2;

/// Outward direction of quad edge `k` in the 4×4 grid.
const OUT: [[i32; 2]; 4] = [[0, -1], [1, 0], [0, 1], [-1, 0]];

/// Grid position of quad corner `k`.
const GRID: [[i32; 2]; 4] = [[1, 1], [2, 1], [2, 2], [1, 2]];

/// Evaluates the limit surface of `level` (with `sharp`) at `(u, v)` of base
/// face `face`, returning weights over `level`'s vertices. Non-quads use
/// quad sub-faces: sub-face `i` (corner `i`, towards the midpoint of edge
/// `i`, the centroid, the midpoint of edge `i − 1`) occupies
/// `[tu, tu + ½] × [tv, tv + ½]` with tile `(tu, tv) = (i mod d, i div d)`,
/// `d = ⌈√n⌉` (OpenSubdiv `Bfr`'s quad-subface parameterisation).
pub fn evaluate_face(
    level: &Level,
    sharp: &Sharpness,
    face: usize,
    u: Real,
    v: Real,
) -> SampleStencil {
    let mut patch = LocalPatch::around(level, sharp, face);
    let n = level.face_vertices(face).len();
    // (s, t) = jac · (u, v) + offset, tracked for the chain rule.
    let mut st = [u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)];
    let mut jac = [[1.0, 0.0], [0.0, 1.0]];
    let mut depth = 0;
    if n != 4 {
        let (i, sub) = subface(n, u, v);
        st = sub;
        jac = [[2.0, 0.0], [0.0, 2.0]];
        patch.descend(i);
        depth = 1;
    }
    evaluate_local(patch, st, jac, depth)
}

/// [`evaluate_face`] from a quad `patch` already `depth` subdivisions below
/// its base face, at its `(s, t)` = `st`; `jac` maps the caller's
/// parameters to these (the derivatives are returned in the caller's).
/// Weights are over `patch.cols`.
pub(crate) fn evaluate_local(
    mut patch: LocalPatch,
    mut st: [Real; 2],
    mut jac: [[Real; 2]; 2],
    mut depth: usize,
) -> SampleStencil {
    loop {
        let f = patch.face;
        let fv: Vec<u32> = patch.level.face_vertices(f as usize).to_vec();
        let kinds: Vec<CornerKind> = fv
            .iter()
            .map(|&c| corner_kind(&patch.level, &patch.sharp, c as usize, f))
            .collect();
        if kinds.iter().all(|&k| k != CornerKind::Irregular) {
            return regular_patch(&patch, st, jac);
        }
        if depth >= MAX_DEPTH {
            // Within 2⁻⁴⁰ of a corner that is still irregular: evaluate there.
            let near = (0..4)
                .min_by(|&a, &b| {
                    let da = (CORNERS[a][0] - st[0]).abs() + (CORNERS[a][1] - st[1]).abs();
                    let db = (CORNERS[b][0] - st[0]).abs() + (CORNERS[b][1] - st[1]).abs();
                    da.total_cmp(&db)
                })
                .unwrap_or(0);
            st = CORNERS[near];
        }
        if let Some(k) = CORNERS.iter().position(|c| c[0] == st[0] && c[1] == st[1]) {
            let c = fv[k] as usize;
            if kinds[k] == CornerKind::Irregular
                && depth >= CORNER_DEPTH
                && masks_apply(&patch.level, &patch.sharp, c)
            {
                return irregular_corner(&patch, c, k, jac);
            }
        }
        let k = quadrant(st);
        let (child, m) = child_frame(k, st);
        st = child;
        jac = mat_mul(m, jac);
        patch.descend(k);
        depth += 1;
    }
}

/// A cell at an irregular corner followed towards the corner, so that
/// evaluating near a vertex of high valence does not subdivide its whole
/// ring again at every level for every point: link `i` holds, for the cell
/// subdivided `i` times around the corner, the 16 control points of its
/// children on the other three quadrants (regular, hence one bicubic patch
/// each). Evaluation walks the links to the first quadrant off the corner.
/// The result is what [`evaluate_local`] gives, which is still used where
/// the chain stops (a second irregular corner, or [`MAX_DEPTH`]) and
/// exactly at the corner.
pub(crate) struct CornerChain {
    cell: LocalPatch,
    /// Subdivisions of the cell below its base face.
    depth: usize,
    links: Vec<ChainLink>,
    /// The cell subdivided around the corner once per link.
    end: LocalPatch,
}

/// A level of a [`CornerChain`]: the quadrant the chain goes on into and
/// the other quadrants' grid rows ([`LocalPatch::grid_rows`]) where their
/// children are regular.
struct ChainLink {
    corner: usize,
    grids: [Option<Vec<Real>>; 4],
}

impl CornerChain {
    /// The chain of `cell`, `depth` subdivisions below its base face.
    pub(crate) fn new(cell: LocalPatch, depth: usize) -> CornerChain {
        let mut links = Vec::new();
        let mut end = cell.clone();
        for _ in depth..MAX_DEPTH {
            let fv = end.level.face_vertices(end.face as usize);
            let irregular: Vec<usize> = (0..fv.len())
                .filter(|&k| {
                    corner_kind(&end.level, &end.sharp, fv[k] as usize, end.face)
                        == CornerKind::Irregular
                })
                .collect();
            let &[corner] = &irregular[..] else { break };
            let refined = end.refined();
            let grids = std::array::from_fn(|k| {
                let child = refined.child_face(k);
                (k != corner && refined.is_regular(child)).then(|| refined.grid_rows(child))
            });
            end = refined.extract(end.child_face(corner));
            links.push(ChainLink { corner, grids });
        }
        CornerChain {
            cell,
            depth,
            links,
            end,
        }
    }

    /// The weights (over the cell's columns) of the position and
    /// derivatives at the cell's `(s, t)`, as [`evaluate_local`] gives them.
    pub(crate) fn evaluate(&self, at: [Real; 2]) -> SampleStencil {
        let (mut st, mut jac) = (at, IDENTITY);
        for link in &self.links {
            let k = quadrant(st);
            let (child, m) = child_frame(k, st);
            if k != link.corner {
                return match &link.grids[k] {
                    Some(grid) => grid_patch(&self.cell, grid, child, mat_mul(m, jac)),
                    None => evaluate_local(self.cell.clone(), at, IDENTITY, self.depth),
                };
            }
            if st == CORNERS[k] {
                return evaluate_local(self.cell.clone(), at, IDENTITY, self.depth);
            }
            st = child;
            jac = mat_mul(m, jac);
        }
        let depth = self.depth + self.links.len();
        evaluate_local(self.end.clone(), st, jac, depth)
    }
}

/// [`regular_patch`] of a patch given by its 16 grid rows over the columns
/// of `like`.
fn grid_patch(
    like: &LocalPatch,
    grid: &[Real],
    st: [Real; 2],
    jac: [[Real; 2]; 2],
) -> SampleStencil {
    let nc = like.ncols();
    let w = patch_weights(st[0], st[1]);
    let mut local: [Vec<Real>; 6] = std::array::from_fn(|_| vec![0.0; nc]);
    for (i, row) in grid.chunks(nc.max(1)).enumerate() {
        for q in 0..6 {
            if w[q][i] != 0.0 {
                for (o, &x) in local[q].iter_mut().zip(row) {
                    *o += w[q][i] * x;
                }
            }
        }
    }
    chain_rule(like, local, jac)
}

/// The 16 control points `P[a][b]` (index `4a + b`, `a` along the face's
/// `u`) of the bicubic B-spline patch of regular face `f`, as combinations of
/// the level's vertices. Across a boundary or infinitely sharp edge the
/// missing row is the reflection `2 P_edge − P_inner`, which reproduces the
/// boundary and crease rules (the boundary curve is the cubic B-spline of the
/// boundary vertices); a corner patch reflects both ways.
///
/// `f` must be a quad whose corners are all regular ([`corner_kind`]).
pub(crate) fn patch_grid(level: &Level, sharp: &Sharpness, f: usize) -> [RowBuilder; 16] {
    let fv = level.face_vertices(f);
    let fe = level.face_edge_list(f);
    let inf =
        |e: u32| sharp.edge[e as usize] >= SHARPNESS_INFINITE || level.is_boundary_edge(e as usize);
    let mut grid: [Option<RowBuilder>; 16] = std::array::from_fn(|_| None);
    let at = |p: [i32; 2]| (4 * p[0] + p[1]) as usize;
    let single = |v: u32| {
        let mut b = RowBuilder::default();
        b.add(v, 1.0);
        b
    };
    for k in 0..4 {
        grid[at(GRID[k])] = Some(single(fv[k]));
    }
    let add = |g: [i32; 2], o: [i32; 2]| [g[0] + o[0], g[1] + o[1]];
    let reflect = |grid: &[Option<RowBuilder>; 16], p: [i32; 2], inner: [i32; 2]| {
        // 2 P(p) − P(inner)
        let mut b = RowBuilder::default();
        if let (Some(x), Some(y)) = (&grid[at(p)], &grid[at(inner)]) {
            b.add_scaled(x, 2.0);
            b.add_scaled(y, -1.0);
        }
        b
    };
    // Points across each edge.
    for k in 0..4 {
        let (ck, cn) = (GRID[k], GRID[(k + 1) % 4]);
        let o = OUT[k];
        if inf(fe[k]) {
            for g in [ck, cn] {
                let inner = [g[0] - o[0], g[1] - o[1]];
                grid[at(add(g, o))] = Some(reflect(&grid, g, inner));
            }
        } else {
            let [f0, f1] = level.edge_faces[fe[k] as usize];
            let g = if f0 as usize == f { f1 } else { f0 } as usize;
            let gv = level.face_vertices(g);
            // In g the edge runs fv[k+1] -> fv[k]; then x (next to fv[k]), y (next to fv[k+1]).
            let i = gv.iter().position(|&x| x == fv[k]).unwrap_or(0);
            let x = gv[(i + 1) % 4];
            let y = gv[(i + 2) % 4];
            grid[at(add(ck, o))] = Some(single(x));
            grid[at(add(cn, o))] = Some(single(y));
        }
    }
    // Diagonal points at each corner.
    for k in 0..4 {
        let g = GRID[k];
        let (o_lead, o_trail) = (OUT[k], OUT[(k + 3) % 4]);
        let d = add(add(g, o_lead), o_trail);
        let (cut_lead, cut_trail) = (inf(fe[k]), inf(fe[(k + 3) % 4]));
        let b = if cut_lead {
            // reflect across the leading edge: 2 P(g + o_trail) − P(g + o_trail − o_lead)
            let p = add(g, o_trail);
            reflect(&grid, p, [p[0] - o_lead[0], p[1] - o_lead[1]])
        } else if cut_trail {
            let p = add(g, o_lead);
            reflect(&grid, p, [p[0] - o_trail[0], p[1] - o_trail[1]])
        } else {
            // Smooth valence-4 corner: the face opposite in the ring.
            let ring = level.vertex_ring(fv[k] as usize);
            let i = ring
                .faces
                .iter()
                .position(|&x| x as usize == f)
                .unwrap_or(0);
            let opp = ring.faces[(i + 2) % ring.faces.len()] as usize;
            let ov = level.face_vertices(opp);
            let j = ov.iter().position(|&x| x == fv[k]).unwrap_or(0);
            single(ov[(j + 2) % 4])
        };
        grid[at(d)] = Some(b);
    }
    grid.map(|g| g.unwrap_or_default())
}

/// Evaluates a regular patch and maps derivatives from `(s, t)` back to the base `(u, v)`.
fn regular_patch(patch: &LocalPatch, st: [Real; 2], jac: [[Real; 2]; 2]) -> SampleStencil {
    let grid = patch_grid(&patch.level, &patch.sharp, patch.face as usize);
    let w = patch_weights(st[0], st[1]);
    let nc = patch.ncols();
    // Derivatives in (s, t), then chain rule to (u, v).
    let mut local: [Vec<Real>; 6] = std::array::from_fn(|_| vec![0.0; nc]);
    for (i, b) in grid.iter().enumerate() {
        for q in 0..6 {
            if w[q][i] != 0.0 {
                patch.accumulate(b, w[q][i], &mut local[q]);
            }
        }
    }
    chain_rule(patch, local, jac)
}

/// Maps `(P, Ps, Pt, Pss, Pst, Ptt)` to `(P, Pu, Pv, Puu, Puv, Pvv)` with
/// `(s, t) = J (u, v) + c`.
fn chain_rule(patch: &LocalPatch, local: [Vec<Real>; 6], j: [[Real; 2]; 2]) -> SampleStencil {
    let nc = patch.ncols();
    let mut out: [Vec<Real>; 6] = std::array::from_fn(|_| vec![0.0; nc]);
    for i in 0..nc {
        out[0][i] = local[0][i];
        let d = chain([1, 2, 3, 4, 5].map(|q| local[q][i]), j);
        for q in 0..5 {
            out[q + 1][i] = d[q];
        }
    }
    SampleStencil {
        cols: patch.cols.clone(),
        weights: out,
    }
}

/// Limit position of a dart vertex (corner `k` of the current face), as
/// weights over `cols`.
///
/// At a dart (an infinitely sharp crease ending inside the surface) the
/// smooth limit mask is not exact: the crease's midpoint rule changes the
/// local subdivision matrix. The mask applied at level `j` converges to the
/// limit geometrically as `j` grows, so the corner is followed down until
/// successive masks agree to round-off. (OpenSubdiv applies the smooth mask
/// at whatever level it stops; its results differ from the limit by about
/// 1e-3 of the size of the surrounding faces at level 3.)
fn dart_limit(patch: &LocalPatch, k: usize) -> Vec<Real> {
    let mask = |p: &LocalPatch| {
        let c = p.level.face_vertices(p.face as usize)[0] as usize;
        let mut b = RowBuilder::default();
        limit_position_mask(&p.level, &p.sharp, c, 1.0, &mut b);
        let mut out = vec![0.0; p.ncols()];
        p.accumulate(&b, 1.0, &mut out);
        out
    };
    let mut p = patch.refined().extract(patch.child_face(k));
    let mut prev = mask(&p);
    for _ in 0..DART_DEPTH {
        p.descend(0);
        let next = mask(&p);
        let change: Real = next.iter().zip(&prev).map(|(a, b)| (a - b).abs()).sum();
        prev = next;
        if change < 1e-15 {
            break;
        }
    }
    prev
}

/// Position and first derivatives exactly at irregular corner `k` of the
/// current face (second derivatives are reported as zero there: the
/// surface has no bounded curvature parameterisation at such a point).
fn irregular_corner(patch: &LocalPatch, c: usize, k: usize, jac: [[Real; 2]; 2]) -> SampleStencil {
    let nc = patch.ncols();
    let mut local: [Vec<Real>; 6] = std::array::from_fn(|_| vec![0.0; nc]);
    if patch.sharp.rule(&patch.level, c) == VertexRule::Dart {
        local[0] = dart_limit(patch, k);
    } else {
        let mut pos = RowBuilder::default();
        limit_position_mask(&patch.level, &patch.sharp, c, 1.0, &mut pos);
        patch.accumulate(&pos, 1.0, &mut local[0]);
    }
    let (lead, trail) = corner_tangents(&patch.level, &patch.sharp, c, patch.face);
    // Along the leading edge the parameter moves by a = corner(k+1) − corner(k),
    // along the trailing edge by b = corner(k−1) − corner(k); ∇ = 3 (a T_lead + b T_trail).
    let a = sub(CORNERS[(k + 1) % 4], CORNERS[k]);
    let b = sub(CORNERS[(k + 3) % 4], CORNERS[k]);
    for q in 0..2 {
        let (x, y) = (a[q], b[q]);
        if x != 0.0 {
            patch.accumulate(&lead, 3.0 * x, &mut local[1 + q]);
        }
        if y != 0.0 {
            patch.accumulate(&trail, 3.0 * y, &mut local[1 + q]);
        }
    }
    chain_rule(patch, local, jac)
}
