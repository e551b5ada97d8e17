//! Limit masks at a vertex: the exact limit position, and the corner
//! tangents used where the parametric derivative is singular.
//!
//! Limit positions (Halstead, Kass, DeRose 1993, eq. 4 and §A; crease and
//! corner rules as in DeRose, Kass, Truong 1998):
//! - smooth or dart vertex of valence `n`: `(n² V + 4 Σ Eⱼ + Σ Fⱼ) / (n (n + 5))`
//!   (`Eⱼ` edge neighbours, `Fⱼ` diagonal vertices of the quads);
//! - crease vertex: `(Eₐ + 4 V + E_b) / 6` along the two sharp edges;
//! - corner: `V`.
//!
//! At an extraordinary vertex the derivative with respect to the face
//! parameters is zero or unbounded, so a sample exactly there reports the
//! derivative of the cubic corner approximation used by OpenSubdiv's
//! `Bfr` (Loop, Schaefer, Ni, Castaño 2009, "Approximating subdivision
//! surfaces with Gregory patches", §3): `D = 3 (E − P)` per unit of the
//! sub-patch parameter, with edge points `E = P + T`. For an interior
//! vertex of valence `n` (θ = 2π/n), along edge `k`:
//! `T_k = e(n) / (2 (n + 5)) Σⱼ [4 (1 + cos θ) cos((j − k)θ) Eⱼ + (cos((j − k)θ) + cos((j + 1 − k)θ)) Fⱼ]`
//! with `e(n) = 16 / (n (cos θ + 5 + √((cos θ + 9)(cos θ + 1))))`; for a
//! boundary or crease sector of `k` faces (θ = π/k) along its edge `m`:
//! `T_m = sin(mθ) T_int + cos(mθ) T_bnd`, `T_bnd = (E₀ − E_k)/6` and
//! `T_int = ⅓ [γ V + α (E₀ + E_k) + Σᵢ 4 sin(iθ)/(3k + cos θ) Eᵢ + Σᵢ (sin iθ + sin (i+1)θ)/(3k + cos θ) Fᵢ]`,
//! `γ = −4 sin θ / (3k + cos θ)`, `α = −(1 + 2 cos θ) √(1 + cos θ) / ((3k + cos θ) √(1 − cos θ))`.
//! These weights reproduce OpenSubdiv 3.6's `Bfr` samples at extraordinary
//! vertices to round-off (see `tests/limit.rs`).

use std::f64::consts::PI;

use crate::math::Real;
use crate::stencil::RowBuilder;
use crate::topology::{Level, SHARPNESS_INFINITE, Sharpness, VertexRing};

/// How a face corner behaves for bicubic patch evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CornerKind {
    /// Interior, valence 4, no sharp edges: a regular B-spline corner.
    Smooth,
    /// On a boundary or infinitely sharp crease with two faces on this
    /// face's side: a regular boundary corner (phantom points by reflection).
    Crease,
    /// A corner (sharp vertex or three or more sharp edges) with this face
    /// alone in its sector: a regular corner patch.
    Corner,
    /// Anything else: needs more subdivision.
    Irregular,
}

fn is_inf(level: &Level, sharp: &Sharpness, e: usize) -> bool {
    sharp.edge[e] >= SHARPNESS_INFINITE || level.is_boundary_edge(e)
}

/// True when no semi-sharp feature touches `v` and every face at `v` is a quad:
/// the limit masks below apply.
pub fn masks_apply(level: &Level, sharp: &Sharpness, v: usize) -> bool {
    let semi = |s: Real| s > 0.0 && s < SHARPNESS_INFINITE;
    !semi(sharp.vertex[v])
        && level
            .vertex_edges(v)
            .iter()
            .all(|&e| !semi(sharp.edge[e as usize]))
        && level
            .vertex_faces(v)
            .iter()
            .all(|&f| level.face_vertices(f as usize).len() == 4)
}

/// Number of faces in the sector of `ring` that holds `ring.faces[i]`,
/// bounded by infinitely sharp edges, and the index of that sector's first edge.
fn sector(level: &Level, sharp: &Sharpness, ring: &VertexRing, i: usize) -> (usize, usize) {
    let n = ring.faces.len();
    let sharp_edge = |k: usize| is_inf(level, sharp, ring.edges[k % ring.edges.len()] as usize);
    // walk backwards to the sector's leading sharp edge
    let mut start = i;
    let mut steps = 0;
    while !sharp_edge(start) && steps < n {
        start = (start + n - 1) % n;
        steps += 1;
    }
    if steps == n {
        return (n, 0); // no sharp edge at all
    }
    let mut count = 1;
    let mut k = start + 1;
    while !sharp_edge(k) && count < n {
        count += 1;
        k += 1;
    }
    (count, start)
}

/// Classifies corner `v` of face `f` (see [`CornerKind`]).
pub fn corner_kind(level: &Level, sharp: &Sharpness, v: usize, f: u32) -> CornerKind {
    if !masks_apply(level, sharp, v) {
        return CornerKind::Irregular;
    }
    let ring = level.vertex_ring(v);
    let Some(i) = ring.faces.iter().position(|&g| g == f) else {
        return CornerKind::Irregular;
    };
    let n_inf = level
        .vertex_edges(v)
        .iter()
        .filter(|&&e| is_inf(level, sharp, e as usize))
        .count();
    let corner = sharp.vertex[v] >= SHARPNESS_INFINITE || n_inf >= 3;
    if corner {
        return if n_inf >= 2 && sector(level, sharp, &ring, i).0 == 1 {
            CornerKind::Corner
        } else {
            CornerKind::Irregular
        };
    }
    match n_inf {
        0 if ring.faces.len() == 4 && !ring.boundary => CornerKind::Smooth,
        2 if sector(level, sharp, &ring, i).0 == 2 => CornerKind::Crease,
        _ => CornerKind::Irregular,
    }
}

/// Far end of ring edge `k` and the vertex of ring face `k` opposite `v` (quads).
fn ring_points(level: &Level, ring: &VertexRing, v: u32) -> (Vec<u32>, Vec<u32>) {
    let e: Vec<u32> = ring
        .edges
        .iter()
        .map(|&e| level.other_vertex(e as usize, v))
        .collect();
    let f: Vec<u32> = ring
        .faces
        .iter()
        .map(|&g| {
            let fv = level.face_vertices(g as usize);
            let i = fv.iter().position(|&x| x == v).unwrap_or(0);
            fv[(i + 2) % fv.len()]
        })
        .collect();
    (e, f)
}

/// Adds `scale ×` the exact limit-position mask of `v`. Requires
/// [`masks_apply`]; isolated vertices map to themselves.
pub fn limit_position_mask(
    level: &Level,
    sharp: &Sharpness,
    v: usize,
    scale: Real,
    b: &mut RowBuilder,
) {
    let v32 = v as u32;
    if level.vertex_faces(v).is_empty() {
        b.add(v32, scale);
        return;
    }
    match sharp.rule(level, v) {
        crate::topology::VertexRule::Corner => b.add(v32, scale),
        crate::topology::VertexRule::Crease => {
            b.add(v32, scale * 2.0 / 3.0);
            for &e in level.vertex_edges(v) {
                if is_inf(level, sharp, e as usize) {
                    b.add(level.other_vertex(e as usize, v32), scale / 6.0);
                }
            }
        }
        _ => {
            let ring = level.vertex_ring(v);
            let (e, f) = ring_points(level, &ring, v32);
            let n = ring.faces.len() as Real;
            let d = n * (n + 5.0);
            b.add(v32, scale * n * n / d);
            for &x in &e[..ring.faces.len()] {
                b.add(x, scale * 4.0 / d);
            }
            for &x in &f {
                b.add(x, scale / d);
            }
        }
    }
}

/// Corner tangents `(T_lead, T_trail)` of face `f` at its irregular corner
/// `v`, along the face's leading edge at `v` (towards the next corner) and its
/// trailing edge (towards the previous corner); the parametric derivative
/// along each edge is `3 T` per unit of the sub-patch parameter (module docs).
/// Requires [`masks_apply`].
pub fn corner_tangents(
    level: &Level,
    sharp: &Sharpness,
    v: usize,
    f: u32,
) -> (RowBuilder, RowBuilder) {
    let v32 = v as u32;
    let ring = level.vertex_ring(v);
    let (e, fp) = ring_points(level, &ring, v32);
    let i = ring.faces.iter().position(|&g| g == f).unwrap_or(0);
    let n_inf = level
        .vertex_edges(v)
        .iter()
        .filter(|&&x| is_inf(level, sharp, x as usize))
        .count();
    let mut lead = RowBuilder::default();
    let mut trail = RowBuilder::default();
    if sharp.vertex[v] >= SHARPNESS_INFINITE || n_inf >= 3 {
        // Sharp corner: the cubic edge points are ⅔ V + ⅓ E, so T = (E − V)/3.
        let nxt = e[i % e.len()];
        let prv = e[(i + 1) % e.len()];
        for (t, x) in [(&mut lead, nxt), (&mut trail, prv)] {
            t.add(x, 1.0 / 3.0);
            t.add(v32, -1.0 / 3.0);
        }
        return (lead, trail);
    }
    if n_inf <= 1 && !ring.boundary {
        // Smooth or dart: the interior formula (a dart is refined smoothly).
        let n = ring.faces.len();
        let nr = n as Real;
        let theta = 2.0 * PI / nr;
        let c = theta.cos();
        let ef = 16.0 / (nr * ((c + 5.0) + ((c + 9.0) * (c + 1.0)).sqrt()));
        let scale = ef / (2.0 * (nr + 5.0));
        for (t, k) in [(&mut lead, i), (&mut trail, (i + 1) % n)] {
            for j in 0..n {
                let d = (j + n - k) as Real * theta;
                t.add(e[j], scale * 4.0 * (1.0 + c) * d.cos());
                t.add(fp[j], scale * (d.cos() + (d + theta).cos()));
            }
        }
        return (lead, trail);
    }
    // Boundary or crease sector: rotate so the sector starts at its sharp edge.
    let (k, start) = sector(level, sharp, &ring, i);
    let ne = ring.edges.len();
    let ee: Vec<u32> = (0..=k).map(|j| e[(start + j) % ne]).collect();
    let ff: Vec<u32> = (0..k).map(|j| fp[(start + j) % ring.faces.len()]).collect();
    let kr = k as Real;
    let theta = PI / kr;
    let (c, s) = (theta.cos(), theta.sin());
    let den = 3.0 * kr + c;
    let mut t_int = RowBuilder::default();
    let mut t_bnd = RowBuilder::default();
    t_bnd.add(ee[0], 1.0 / 6.0);
    t_bnd.add(ee[k], -1.0 / 6.0);
    let alpha = if k == 1 {
        0.0
    } else {
        -(1.0 + 2.0 * c) * (1.0 + c).sqrt() / (den * (1.0 - c).sqrt())
    };
    t_int.add(v32, -4.0 * s / den / 3.0);
    t_int.add(ee[0], alpha / 3.0);
    t_int.add(ee[k], alpha / 3.0);
    for (j, &x) in ee.iter().enumerate().take(k).skip(1) {
        t_int.add(x, 4.0 * (j as Real * theta).sin() / den / 3.0);
    }
    for (j, &x) in ff.iter().enumerate() {
        let w = ((j as Real * theta).sin() + ((j + 1) as Real * theta).sin()) / den / 3.0;
        t_int.add(x, w);
    }
    let m_lead = (i + ring.faces.len() - start) % ring.faces.len();
    for (t, m) in [(&mut lead, m_lead), (&mut trail, m_lead + 1)] {
        let a = m as Real * theta;
        t.add_scaled(&t_int, a.sin());
        t.add_scaled(&t_bnd, a.cos());
    }
    (lead, trail)
}
