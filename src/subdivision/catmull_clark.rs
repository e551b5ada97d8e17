//! Catmull-Clark refinement rules with boundaries and creases, as stencil rows.
//!
//! Catmull and Clark 1978; crease rules of DeRose, Kass and Truong 1998 (§3),
//! with the uniform sharpness decrement and fractional blending used by
//! OpenSubdiv's `Sdc` (the default "uniform" crease method):
//!
//! - face point: the centroid `(1/n) Σ vᵢ`;
//! - edge point: smooth `(v₀ + v₁ + f₀ + f₁) / 4` (`fₖ` the new face points),
//!   sharp `(v₀ + v₁) / 2` while both halves stay sharp at the next level,
//!   else the blend `s · sharp + (1 − s) · smooth` (`0 < s ≤ 1` with the
//!   uniform method; the Chaikin method can decay both halves of an edge
//!   with `s > 1`, and then, as OpenSubdiv's `Sdc::Scheme::
//!   ComputeEdgeVertexMask` given the child's rule, blends with `s` as it is);
//!   with the smooth-triangle rule (OpenSubdiv's `TRI_SUB_SMOOTH`) an edge of
//!   two faces of which one at least is a triangle weights each face point
//!   `(w₀ + w₁) / 2` and each end `(1 − w₀ − w₁) / 2`, `wₖ = 0.47` for a
//!   triangle and `¼` for any other face;
//! - vertex point: smooth/dart `((n − 2) v + (1/n) Σ eᵢ + (1/n) Σ fᵢ) / n`
//!   (`eᵢ` edge neighbours, `fᵢ` face points), crease `(a + 6 v + b) / 8`
//!   along the two sharp edges, corner `v`. When the rule changes between this
//!   level and the next (a semi-sharp feature decays), the masks of the two
//!   rules are blended by the average sharpness of the features that decay,
//!   clamped to 1.

use crate::math::Real;
use crate::stencil::{RowBuilder, StencilTable};
use crate::topology::{Level, NONE, Sharpness, VertexRule, decrement};

/// The face-point weight of a triangle next to an edge under the
/// smooth-triangle rule (OpenSubdiv 3.6, `Sdc::Scheme<SCHEME_CATMARK>::
/// assignSmoothMaskForEdge`).
const SMOOTH_TRIANGLE_WEIGHT: Real = 0.47;

/// The stencil table `S` with `P_child = S P_parent` (rows ordered face
/// points, edge points, vertex points) and the child level's sharpness.
/// `smooth_triangles` selects the smooth-triangle edge rule.
pub fn refine_stencil(
    parent: &Level,
    sharp: &Sharpness,
    child: &Level,
    smooth_triangles: bool,
) -> (StencilTable, Sharpness) {
    let nf = parent.num_faces();
    let ne = parent.num_edges();
    let nv = parent.num_vertices;
    let halves = sharp.child_edges(parent);
    let table = StencilTable::from_row_fn(nf + ne + nv, nv, |r, b| {
        if r < nf {
            face_point(parent, r, 1.0, b);
        } else if r < nf + ne {
            let e = r - nf;
            let stays = halves[2 * e] > 0.0 && halves[2 * e + 1] > 0.0;
            edge_point(parent, sharp, e, stays, smooth_triangles, b);
        } else {
            vertex_point(parent, sharp, r - nf - ne, b);
        }
    });
    let mut edge = vec![0.0; child.num_edges()];
    edge[..halves.len()].copy_from_slice(&halves);
    let mut vertex = vec![0.0; child.num_vertices];
    for (v, &s) in sharp.vertex.iter().enumerate() {
        vertex[nf + ne + v] = decrement(s);
    }
    (
        table,
        Sharpness {
            edge,
            vertex,
            method: sharp.method,
        },
    )
}

/// Adds `scale ×` the centroid of face `f`.
fn face_point(level: &Level, f: usize, scale: Real, b: &mut RowBuilder) {
    let fv = level.face_vertices(f);
    let w = scale / fv.len() as Real;
    for &v in fv {
        b.add(v, w);
    }
}

/// `stays`: both halves of the edge are sharp at the next level.
fn edge_point(
    level: &Level,
    sharp: &Sharpness,
    e: usize,
    stays: bool,
    smooth_triangles: bool,
    b: &mut RowBuilder,
) {
    let [v0, v1] = level.edge_verts[e];
    let s = sharp.edge[e];
    let faces = level.edge_faces[e];
    if stays || s == 1.0 || faces[1] == NONE {
        b.add(v0, 0.5);
        b.add(v1, 0.5);
        return;
    }
    // The smooth mask's face weight (¼, or the smooth-triangle weight).
    let fw = if smooth_triangles {
        let w = |f: u32| {
            if level.face_vertices(f as usize).len() == 3 {
                SMOOTH_TRIANGLE_WEIGHT
            } else {
                0.25
            }
        };
        0.5 * (w(faces[0]) + w(faces[1]))
    } else {
        0.25
    };
    // Smooth mask scaled by (1 − s), crease mask by s.
    let smooth = 1.0 - s;
    let vw = 0.5 * (1.0 - 2.0 * fw);
    b.add(v0, 0.5 * s + vw * smooth);
    b.add(v1, 0.5 * s + vw * smooth);
    for &f in &faces {
        face_point(level, f as usize, fw * smooth, b);
    }
}

fn vertex_point(level: &Level, sharp: &Sharpness, v: usize, b: &mut RowBuilder) {
    let v32 = v as u32;
    if level.vertex_faces(v).is_empty() {
        b.add(v32, 1.0); // isolated vertex: carried along unchanged
        return;
    }
    let rule = sharp.rule(level, v);
    let child_rule = sharp.child_rule(level, v);
    if rule == child_rule || rule <= VertexRule::Dart {
        vertex_mask(level, sharp, v, rule, false, 1.0, b);
        return;
    }
    // Fractional weight: mean parent sharpness of the features that become smooth.
    let mut sum = 0.0;
    let mut count = 0usize;
    let vs = sharp.vertex[v];
    if vs > 0.0 && decrement(vs) <= 0.0 {
        sum += vs;
        count += 1;
    }
    for (&e, child) in level
        .vertex_edges(v)
        .iter()
        .zip(sharp.child_edges_at(level, v))
    {
        let s = sharp.edge[e as usize];
        if s > 0.0 && child <= 0.0 {
            sum += s;
            count += 1;
        }
    }
    let fw = if count == 0 {
        0.0
    } else {
        (sum / count as Real).min(1.0)
    };
    vertex_mask(level, sharp, v, rule, false, fw, b);
    vertex_mask(level, sharp, v, child_rule, true, 1.0 - fw, b);
}

/// Adds `scale ×` the vertex-point mask of `rule` at `v`. For the crease rule
/// the sharp edges are those sharp at this level, or at the next level when
/// `child_sharpness` is set.
fn vertex_mask(
    level: &Level,
    sharp: &Sharpness,
    v: usize,
    rule: VertexRule,
    child_sharpness: bool,
    scale: Real,
    b: &mut RowBuilder,
) {
    if scale == 0.0 {
        return;
    }
    let v32 = v as u32;
    match rule {
        VertexRule::Corner => b.add(v32, scale),
        VertexRule::Crease => {
            b.add(v32, 0.75 * scale);
            for (&e, child) in level
                .vertex_edges(v)
                .iter()
                .zip(sharp.child_edges_at(level, v))
            {
                let s = if child_sharpness {
                    child
                } else {
                    sharp.edge[e as usize]
                };
                if s > 0.0 {
                    b.add(level.other_vertex(e as usize, v32), 0.125 * scale);
                }
            }
        }
        VertexRule::Smooth | VertexRule::Dart => {
            let edges = level.vertex_edges(v);
            let faces = level.vertex_faces(v);
            let n = edges.len() as Real;
            let nf = faces.len();
            debug_assert_eq!(edges.len(), nf, "smooth rule at a boundary vertex");
            b.add(v32, scale * (n - 2.0) / n);
            let w = scale / (n * n);
            for &e in edges {
                b.add(level.other_vertex(e as usize, v32), w);
            }
            for &f in faces {
                face_point(level, f as usize, w, b);
            }
        }
    }
}
