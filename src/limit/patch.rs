//! A face's neighbourhood cut out of a level ([`Ring`]) and subdivided
//! locally ([`LocalPatch`]), every local vertex kept as a row of weights
//! over the base control points: what exact evaluation
//! ([`super::local_eval`]) and the patch table's quadtrees subdivide.

use crate::math::{Real, Vector3};
use crate::stencil::RowBuilder;
use crate::subdivision::{refine_stencil, refine_topology};
use crate::topology::{Level, NONE, SHARPNESS_INFINITE, Sharpness, find_edge};

use super::local_eval::patch_grid;
use super::vertex_masks::{CornerKind, corner_kind};

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
    pub(crate) sharp: Sharpness,
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

    pub(crate) fn ncols(&self) -> usize {
        self.cols.len()
    }

    /// Subdivides once and keeps the 1-ring of the child of the current face
    /// at corner `k`.
    pub(crate) fn descend(&mut self, k: usize) {
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
    pub(crate) fn accumulate(&self, b: &RowBuilder, scale: Real, out: &mut [Real]) {
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
