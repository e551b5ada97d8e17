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

use crate::math::{Real, Vector3};
use crate::stencil::RowBuilder;
use crate::subdivision::{refine_stencil, refine_topology};
use crate::topology::{Level, NONE, SHARPNESS_INFINITE, Sharpness, VertexRule, find_edge};

use super::bspline::patch_weights;
use super::patch_table::chain;
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

/// A limit sample as weights over control points: value and the
/// derivatives `∂u, ∂v, ∂uu, ∂uv, ∂vv` (one weight array each).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleStencil {
    /// Control points the weights refer to.
    pub cols: Vec<u32>,
    /// `weights[k][i]` is the weight of `cols[i]` in quantity `k`
    /// (0 = position, 1 = ∂u, 2 = ∂v, 3 = ∂uu, 4 = ∂uv, 5 = ∂vv).
    pub weights: [Vec<Real>; 6],
}

/// A neighbourhood of one face, with every local vertex as a dense row of
/// weights over `cols`.
#[derive(Clone)]
pub(crate) struct LocalPatch {
    pub(crate) level: Level,
    sharp: Sharpness,
    pub(crate) cols: Vec<u32>,
    /// `level.num_vertices × cols.len()`, row-major.
    rows: Vec<Real>,
    /// Local index of the face being followed.
    pub(crate) face: u32,
}

impl LocalPatch {
    /// The 1-ring of `face` in `level`, with identity rows over its vertices.
    pub(crate) fn around(level: &Level, sharp: &Sharpness, face: usize) -> LocalPatch {
        Self::of_ring(level, sharp, Ring::of(level, face))
    }

    /// The patch of a gathered [`Ring`] of `level`, with identity rows.
    pub(crate) fn of_ring(level: &Level, sharp: &Sharpness, ring: Ring) -> LocalPatch {
        let ((level, sharp, face), map) = ring.sub_mesh(level, sharp);
        let n = map.len();
        let mut rows = vec![0.0; n * n];
        for i in 0..n {
            rows[i * n + i] = 1.0;
        }
        LocalPatch {
            level,
            sharp,
            cols: map,
            rows,
            face,
        }
    }

    fn ncols(&self) -> usize {
        self.cols.len()
    }

    /// Subdivides once and keeps the 1-ring of the child of the current face
    /// at corner `k`.
    fn descend(&mut self, k: usize) {
        let r = self.refined();
        *self = r.extract(self.child_face(k));
    }

    /// The local child face of the current face at corner `k` (in [`refined`](Self::refined)).
    pub(crate) fn child_face(&self, k: usize) -> u32 {
        self.level.face_offsets[self.face as usize] + k as u32
    }

    /// The whole neighbourhood subdivided once (rows for every child vertex);
    /// its `face` is the child at corner 0.
    pub(crate) fn refined(&self) -> LocalPatch {
        let child = refine_topology(&self.level);
        // The smooth-triangle rule is not carried here (see `TriangleRule`).
        let (s, child_sharp) = refine_stencil(&self.level, &self.sharp, &child, false);
        let nc = self.ncols();
        let mut rows = vec![0.0; child.num_vertices * nc];
        for (cv, out) in rows
            .chunks_mut(nc.max(1))
            .enumerate()
            .take(child.num_vertices)
        {
            let (idx, w) = s.row(cv);
            for (&p, &w) in idx.iter().zip(w) {
                let src = &self.rows[p as usize * nc..(p as usize + 1) * nc];
                for (o, &x) in out.iter_mut().zip(src) {
                    *o += w * x;
                }
            }
        }
        LocalPatch {
            face: self.child_face(0),
            level: child,
            sharp: child_sharp,
            cols: self.cols.clone(),
            rows,
        }
    }

    /// This patch with every local vertex's row applied to the values of
    /// its columns (`value(i)` for column `i`, in order): a patch whose
    /// three columns are x, y and z. Refining it costs O(vertices) instead of O(vertices ×
    /// columns), which is what keeps evaluation near a vertex of high
    /// valence affordable; [`evaluate_local`] then returns coordinates as
    /// its weights.
    pub(crate) fn applied(&self, value: impl Fn(usize) -> Vector3) -> LocalPatch {
        let nc = self.ncols();
        let values: Vec<Vector3> = (0..nc).map(value).collect();
        let mut rows = Vec::with_capacity(3 * self.level.num_vertices);
        for r in self.rows.chunks(nc.max(1)).take(self.level.num_vertices) {
            let p = r
                .iter()
                .zip(&values)
                .fold(Vector3::zeros(), |p, (&w, v)| p + v * w);
            rows.extend_from_slice(&[p.x, p.y, p.z]);
        }
        LocalPatch {
            level: self.level.clone(),
            sharp: self.sharp.clone(),
            cols: vec![0, 1, 2],
            rows,
            face: self.face,
        }
    }

    /// The 1-ring of local face `face`, as a patch of its own.
    pub(crate) fn extract(&self, face: u32) -> LocalPatch {
        let (sub, map) = Ring::of(&self.level, face as usize).sub_mesh(&self.level, &self.sharp);
        let nc = self.ncols();
        let mut rows = Vec::with_capacity(map.len() * nc);
        for &v in &map {
            rows.extend_from_slice(&self.rows[v as usize * nc..(v as usize + 1) * nc]);
        }
        LocalPatch {
            level: sub.0,
            sharp: sub.1,
            cols: self.cols.clone(),
            rows,
            face: sub.2,
        }
    }

    /// True when every corner of local face `f` is regular.
    pub(crate) fn is_regular(&self, f: u32) -> bool {
        self.level
            .face_vertices(f as usize)
            .iter()
            .all(|&c| corner_kind(&self.level, &self.sharp, c as usize, f) != CornerKind::Irregular)
    }

    /// The 16 B-spline control points of regular local face `f`, as dense
    /// rows over `cols`, one after the other (`16 × cols.len()`).
    pub(crate) fn grid_rows(&self, f: u32) -> Vec<Real> {
        let grid = patch_grid(&self.level, &self.sharp, f as usize);
        let nc = self.ncols();
        let mut out = vec![0.0; 16 * nc];
        for (b, row) in grid.iter().zip(out.chunks_mut(nc.max(1))) {
            self.accumulate(b, 1.0, row);
        }
        out
    }

    /// Adds `scale ×` the row of local vertex-combination `b` into `out`.
    fn accumulate(&self, b: &RowBuilder, scale: Real, out: &mut [Real]) {
        let nc = self.ncols();
        for (v, w) in b.entries() {
            let src = &self.rows[v as usize * nc..(v as usize + 1) * nc];
            for (o, &x) in out.iter_mut().zip(src) {
                *o += scale * w * x;
            }
        }
    }
}

/// The faces sharing a vertex with a face of a level (that face first) and
/// their corners in a local numbering: `map[l]` is local vertex `l`'s vertex
/// of the level, face `i` has local corners `verts[offsets[i]..offsets[i + 1]]`.
///
/// The order depends on the topology alone, not on how the level numbers
/// its faces, so that rings of the same structure get the same
/// [`shape_key`](Self::shape_key): the faces around each corner of the face
/// (in its corner order) are taken in rotational order starting from the
/// face, and each face's corners are listed from the corner it was reached
/// through (the face itself from its corner 0). Rotating a neighbour's
/// corner list keeps its orientation, so the sub-mesh is the same surface.
pub(crate) struct Ring {
    faces: Vec<u32>,
    /// Each face's first corner (an index into its corner list).
    firsts: Vec<usize>,
    pub(crate) map: Vec<u32>,
    offsets: Vec<u32>,
    verts: Vec<u32>,
}

impl Ring {
    /// The ring of `face` in `level`.
    pub(crate) fn of(level: &Level, face: usize) -> Ring {
        // Every face around every corner, each with the corner it was
        // reached through; a face met again keeps its first entry. The
        // duplicates are found by sorting, not by searching the list, so a
        // vertex of high valence costs O(n log n), not O(n²).
        let mut met: Vec<(u32, usize)> = vec![(face as u32, 0)];
        for &v in level.face_vertices(face) {
            for g in faces_around(level, face, v) {
                let k = level.face_vertices(g as usize).iter().position(|&w| w == v);
                met.push((g, k.unwrap_or(0)));
            }
        }
        let first = first_occurrences(&met.iter().map(|m| m.0).collect::<Vec<_>>());
        let (faces, firsts): (Vec<u32>, Vec<usize>) = met
            .iter()
            .zip(first)
            .enumerate()
            .filter(|&(i, (_, f))| f as usize == i)
            .map(|(_, (&m, _))| m)
            .unzip();
        let mut offsets = vec![0u32];
        let mut corners = Vec::new();
        for (&g, &first) in faces.iter().zip(&firsts) {
            let fv = level.face_vertices(g as usize);
            corners.extend(fv[first..].iter().chain(&fv[..first]));
            offsets.push(corners.len() as u32);
        }
        // Local vertices numbered in order of first appearance.
        let first = first_occurrences(&corners);
        let mut map: Vec<u32> = Vec::new();
        let mut verts: Vec<u32> = Vec::with_capacity(corners.len());
        for (i, &f) in first.iter().enumerate() {
            let l = if f as usize == i {
                map.push(corners[i]);
                map.len() as u32 - 1
            } else {
                verts[f as usize]
            };
            verts.push(l);
        }
        Ring {
            faces,
            firsts,
            map,
            offsets,
            verts,
        }
    }

    /// Everything the local subdivision of the ring's patch depends on
    /// besides `map`: the local topology, the sharpness of every face's
    /// edges (in face order) and of every local vertex. Rings with equal
    /// keys give equal [`LocalPatch`]es up to `cols`, so they refine to
    /// equal weights. (The rim edges' sharpness is keyed too although the
    /// sub-mesh overrides it: rare extra keys, never a false match.)
    pub(crate) fn shape_key(&self, level: &Level, sharp: &Sharpness) -> Vec<u64> {
        let mut key =
            Vec::with_capacity(1 + self.offsets.len() + 2 * self.verts.len() + self.map.len());
        key.push(self.map.len() as u64);
        key.extend(self.offsets.iter().chain(&self.verts).map(|&x| x as u64));
        for (&g, &first) in self.faces.iter().zip(&self.firsts) {
            let fe = level.face_edge_list(g as usize);
            key.extend(
                fe[first..]
                    .iter()
                    .chain(&fe[..first])
                    .map(|&e| sharp.edge[e as usize].to_bits()),
            );
        }
        key.extend(self.map.iter().map(|&v| sharp.vertex[v as usize].to_bits()));
        key
    }

    /// The ring as a level of its own with its sharpness (rim edges marked
    /// infinitely sharp so rim vertices stay well defined) and the local
    /// index of the face (0), and the map local vertex → vertex of `level`.
    fn sub_mesh(self, level: &Level, sharp: &Sharpness) -> ((Level, Sharpness, u32), Vec<u32>) {
        let map = self.map;
        let sub = Level::from_faces(map.len(), &self.offsets, &self.verts)
            .expect("a sub-mesh of a valid level is valid");
        let edge = sub
            .edge_verts
            .iter()
            .enumerate()
            .map(|(e, &[a, b])| {
                if sub.is_boundary_edge(e) {
                    SHARPNESS_INFINITE
                } else {
                    find_edge(level, map[a as usize], map[b as usize])
                        .map_or(0.0, |g| sharp.edge[g])
                }
            })
            .collect();
        let vertex = map.iter().map(|&v| sharp.vertex[v as usize]).collect();
        (
            (
                sub,
                Sharpness {
                    edge,
                    vertex,
                    method: sharp.method,
                },
                0,
            ),
            map,
        )
    }
}

/// The faces at vertex `v` of face `f` in rotational order from `f`: across
/// the edge into `v`, and on from there; at a boundary also the other way
/// from `f`. Any face at `v` such a walk misses (a non-manifold fan) comes
/// last, in the level's order.
fn faces_around(level: &Level, f: usize, v: u32) -> Vec<u32> {
    let at_v = level.vertex_faces(v as usize);
    let mut out = Vec::with_capacity(at_v.len());
    // `into`: cross the edge ending at `v` (true) or the one starting there.
    for into in [true, false] {
        let mut g = f;
        while out.len() < at_v.len() {
            let fv = level.face_vertices(g);
            let Some(i) = fv.iter().position(|&w| w == v) else {
                break;
            };
            let k = if into {
                (i + fv.len() - 1) % fv.len()
            } else {
                i
            };
            let e = level.face_edge_list(g)[k] as usize;
            let [a, b] = level.edge_faces[e];
            let h = if a as usize == g { b } else { a };
            if h == NONE || h as usize == f || out.contains(&h) {
                break;
            }
            out.push(h);
            g = h as usize;
        }
    }
    for &g in at_v {
        if g as usize != f && !out.contains(&g) {
            out.push(g);
        }
    }
    out
}

/// Parameter position of corner `k` of a quad.
pub(crate) const CORNERS: [[Real; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
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

/// For each item, the index of the first item equal to it, found by sorting
/// (O(n log n)).
fn first_occurrences(items: &[u32]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..items.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (items[i as usize], i));
    let mut first = vec![0; items.len()];
    let mut start = 0;
    for (k, &i) in order.iter().enumerate() {
        if k == 0 || items[order[k - 1] as usize] != items[i as usize] {
            start = i;
        }
        first[i as usize] = start;
    }
    first
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

const IDENTITY: [[Real; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];

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

/// The quadrant of `(s, t)`: the child at corner 0, 1, 2 or 3. Ties go to
/// the upper half, as in OpenSubdiv's `Bfr`.
pub(crate) fn quadrant(st: [Real; 2]) -> usize {
    match (st[0] >= 0.5, st[1] >= 0.5) {
        (false, false) => 0,
        (true, false) => 1,
        (true, true) => 2,
        (false, true) => 3,
    }
}

/// Child `k` of a quad has its corner 0 at the parent's corner `k`, `s`
/// towards corner `k + 1` and `t` towards corner `k − 1` (the refiner's child
/// order). Returns the child's `(s, t)` for the parent's `st` and the matrix
/// `M` with `child = M (st − corner_k)`.
pub(crate) fn child_frame(k: usize, st: [Real; 2]) -> ([Real; 2], [[Real; 2]; 2]) {
    let o = CORNERS[k];
    let a = sub(CORNERS[(k + 1) % 4], o);
    let b = sub(CORNERS[(k + 3) % 4], o);
    let m = [[2.0 * a[0], 2.0 * a[1]], [2.0 * b[0], 2.0 * b[1]]];
    let d = sub(st, o);
    let c = mat_vec(m, d);
    ([c[0].clamp(0.0, 1.0), c[1].clamp(0.0, 1.0)], m)
}

/// Sub-face of an `n`-gon holding `(u, v)` and the sub-face's own `(s, t)`:
/// sub-face `i` covers `[tu, tu + ½] × [tv, tv + ½]`, `(tu, tv) = (i mod d,
/// i div d)`, `d = ⌈√n⌉`; values past three quarters of a tile count for
/// the next tile, as in `Bfr`.
pub(crate) fn subface(n: usize, u: Real, v: Real) -> (usize, [Real; 2]) {
    let d = (n as Real).sqrt().ceil() as usize;
    let rows = n.div_ceil(d);
    let tu = ((u + 0.25).floor().max(0.0) as usize).min(d - 1);
    let tv = ((v + 0.25).floor().max(0.0) as usize).min(rows - 1);
    let i = (tv * d + tu).min(n - 1);
    let (tu, tv) = ((i % d) as Real, (i / d) as Real);
    (
        i,
        [
            (2.0 * (u - tu)).clamp(0.0, 1.0),
            (2.0 * (v - tv)).clamp(0.0, 1.0),
        ],
    )
}

/// `a · b` for 2×2 matrices.
pub(crate) fn mat_mul(a: [[Real; 2]; 2], b: [[Real; 2]; 2]) -> [[Real; 2]; 2] {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// `a · x` for a 2×2 matrix.
pub(crate) fn mat_vec(a: [[Real; 2]; 2], x: [Real; 2]) -> [Real; 2] {
    [
        a[0][0] * x[0] + a[0][1] * x[1],
        a[1][0] * x[0] + a[1][1] * x[1],
    ]
}

fn sub(a: [Real; 2], b: [Real; 2]) -> [Real; 2] {
    [a[0] - b[0], a[1] - b[1]]
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
