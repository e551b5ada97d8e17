//! `simplified`: fewer vertices for a closed surface by edge collapses
//! ordered by the quadric error metric (Garland and Heckbert, "Surface
//! simplification using quadric error metrics", SIGGRAPH 1997), keeping its
//! topology: thin parts and narrow gaps survive where a coarser voxel grid
//! would lose or close them.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

use super::{PolyMesh, split_quads};

/// A symmetric 4×4 quadric `Q` (upper triangle, row-major: `q00 q01 q02 q03
/// q11 q12 q13 q22 q23 q33`); the error of a point `x` is `[x 1] Q [x 1]ᵀ`.
type Quadric = [Real; 10];

/// The quadric of the plane `n·x + d = 0` (unit `n`) weighted by `w`: the
/// squared distance to the plane, Garland and Heckbert eq. (2), `K_p = p pᵀ`.
fn plane_quadric(n: Vector3, d: Real, w: Real) -> Quadric {
    let p = [n.x, n.y, n.z, d];
    let mut q = [0.0; 10];
    let mut k = 0;
    for i in 0..4 {
        for j in i..4 {
            q[k] = w * p[i] * p[j];
            k += 1;
        }
    }
    q
}

fn add(a: &Quadric, b: &Quadric) -> Quadric {
    std::array::from_fn(|k| a[k] + b[k])
}

/// `[x 1] Q [x 1]ᵀ`.
fn error(q: &Quadric, x: &Point3) -> Real {
    let (a, b, c) = (x.x, x.y, x.z);
    q[0] * a * a
        + 2.0 * q[1] * a * b
        + 2.0 * q[2] * a * c
        + 2.0 * q[3] * a
        + q[4] * b * b
        + 2.0 * q[5] * b * c
        + 2.0 * q[6] * b
        + q[7] * c * c
        + 2.0 * q[8] * c
        + q[9]
}

/// The point minimising `q` (Garland and Heckbert §4: the 3×3 system of
/// `∂error/∂x = 0`) when it is well conditioned and within an edge length of
/// the edge's midpoint, else the best of the two ends and the midpoint.
fn best_point(q: &Quadric, a: Point3, b: Point3) -> (Point3, Real) {
    let m = nalgebra::Matrix3::new(q[0], q[1], q[2], q[1], q[4], q[5], q[2], q[5], q[7]);
    let mid = nalgebra::center(&a, &b);
    let reach = (b - a).norm();
    if let Some(inv) = m.try_inverse()
        && m.determinant().abs() > 1e-12 * m.norm().powi(3)
    {
        let x = Point3::from(-(inv * Vector3::new(q[3], q[6], q[8])));
        if (x - mid).norm() <= reach {
            return (x, error(q, &x).max(0.0));
        }
    }
    [a, b, mid]
        .into_iter()
        .map(|x| (x, error(q, &x).max(0.0)))
        .fold(
            (mid, Real::INFINITY),
            |best, c| if c.1 < best.1 { c } else { best },
        )
}

/// The closed, edge-manifold, consistently oriented surface `mesh` (any
/// polygons; quads are split by [`split_quads`], larger faces fanned) with
/// edges collapsed, cheapest quadric error first, until at most
/// `target_vertices` remain or no collapse is allowed. A collapse is
/// allowed when it makes no edge longer than `max_edge` (which keeps the
/// triangles of flat parts from growing into slivers), keeps the surface a manifold of the same topology (the
/// link condition: the ends share exactly the two vertices opposite the
/// edge, and these are not joined by an edge of both ends' fans) and turns
/// no triangle by more than 60° or to zero area. The result is triangles,
/// oriented as the input; the same input gives the same output.
pub fn simplified(mesh: &PolyMesh, target_vertices: usize, max_edge: Real) -> Result<PolyMesh> {
    let tri = split_quads(mesh);
    let mut pos = tri.positions.clone();
    let mut tris: Vec<[u32; 3]> = tri.faces().map(|f| [f[0], f[1], f[2]]).collect();
    let nv = pos.len();
    let mut alive_tri = vec![true; tris.len()];
    let mut fans: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (t, f) in tris.iter().enumerate() {
        for &v in f {
            fans[v as usize].push(t as u32);
        }
    }
    check_closed(&tris)?;
    let mut quadric = vec![[0.0; 10]; nv];
    for f in &tris {
        let [a, b, c] = f.map(|v| pos[v as usize]);
        let cross = (b - a).cross(&(c - a));
        let area2 = cross.norm();
        if area2 > 0.0 {
            let n = cross / area2;
            let q = plane_quadric(n, -n.dot(&a.coords), 0.5 * area2);
            for &v in f {
                quadric[v as usize] = add(&quadric[v as usize], &q);
            }
        }
    }
    let mut version = vec![0u32; nv];
    let mut alive = vec![true; nv];
    let mut heap = BinaryHeap::new();
    let push = |heap: &mut BinaryHeap<_>,
                pos: &[Point3],
                quadric: &[Quadric],
                version: &[u32],
                a: u32,
                b: u32| {
        let (a, b) = (a.min(b), a.max(b));
        let q = add(&quadric[a as usize], &quadric[b as usize]);
        let (_, cost) = best_point(&q, pos[a as usize], pos[b as usize]);
        heap.push(Reverse((
            cost.to_bits(),
            a,
            b,
            version[a as usize],
            version[b as usize],
        )));
    };
    for f in &tris {
        for i in 0..3 {
            let (a, b) = (f[i], f[(i + 1) % 3]);
            if a < b {
                push(&mut heap, &pos, &quadric, &version, a, b);
            }
        }
    }
    let mut remaining = nv;
    while remaining > target_vertices.max(4) {
        let Some(Reverse((_, a, b, va, vb))) = heap.pop() else {
            break;
        };
        let (ai, bi) = (a as usize, b as usize);
        if !alive[ai] || !alive[bi] || version[ai] != va || version[bi] != vb {
            continue;
        }
        let q = add(&quadric[ai], &quadric[bi]);
        let (x, _) = best_point(&q, pos[ai], pos[bi]);
        if !collapse_allowed(&tris, &fans, &pos, a, b, x, max_edge) {
            continue;
        }
        // b goes into a at x: triangles with both die, the others take a.
        for &t in &fans[bi].clone() {
            let f = &mut tris[t as usize];
            if f.contains(&a) {
                alive_tri[t as usize] = false;
                for &v in f.iter() {
                    fans[v as usize].retain(|&s| s != t);
                }
            } else {
                for v in f.iter_mut() {
                    if *v == b {
                        *v = a;
                    }
                }
                fans[ai].push(t);
            }
        }
        fans[bi].clear();
        alive[bi] = false;
        remaining -= 1;
        pos[ai] = x;
        quadric[ai] = q;
        version[ai] += 1;
        let mut ring: Vec<u32> = fans[ai]
            .iter()
            .flat_map(|&t| tris[t as usize])
            .filter(|&v| v != a)
            .collect();
        ring.sort_unstable();
        ring.dedup();
        for v in ring {
            push(&mut heap, &pos, &quadric, &version, a, v);
        }
    }
    let mut index = vec![u32::MAX; nv];
    let mut positions = Vec::with_capacity(remaining);
    for v in 0..nv {
        if alive[v] {
            index[v] = positions.len() as u32;
            positions.push(pos[v]);
        }
    }
    let faces: Vec<Vec<u32>> = tris
        .iter()
        .zip(&alive_tri)
        .filter(|(_, a)| **a)
        .map(|(f, _)| f.iter().map(|&v| index[v as usize]).collect())
        .collect();
    PolyMesh::from_faces(positions, &faces)
}

/// Errors unless every edge of `tris` has exactly two triangles, once in
/// each direction (closed, edge-manifold, oriented).
fn check_closed(tris: &[[u32; 3]]) -> Result<()> {
    let mut directed: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|f| (0..3).map(move |i| (f[i], f[(i + 1) % 3])))
        .collect();
    directed.sort_unstable();
    let twice = directed.windows(2).any(|w| w[0] == w[1]);
    let unpaired = directed
        .iter()
        .any(|&(a, b)| directed.binary_search(&(b, a)).is_err());
    if twice || unpaired {
        return Err(Error::Topology(
            "simplification needs a closed, consistently oriented manifold surface".into(),
        ));
    }
    Ok(())
}

/// Whether collapsing `b` into `a` at `x` keeps the surface a manifold of
/// the same topology without turning a triangle over (see [`simplified`]).
fn collapse_allowed(
    tris: &[[u32; 3]],
    fans: &[Vec<u32>],
    pos: &[Point3],
    a: u32,
    b: u32,
    x: Point3,
    max_edge: Real,
) -> bool {
    let ring = |v: u32| -> Vec<u32> {
        let mut r: Vec<u32> = fans[v as usize]
            .iter()
            .flat_map(|&t| tris[t as usize])
            .filter(|&w| w != v)
            .collect();
        r.sort_unstable();
        r.dedup();
        r
    };
    let (ra, rb) = (ring(a), ring(b));
    let common: Vec<u32> = ra
        .iter()
        .filter(|v| rb.binary_search(v).is_ok())
        .cloned()
        .collect();
    if common.len() != 2 || ra.len() <= 3 || rb.len() <= 3 {
        return false;
    }
    if ra
        .iter()
        .chain(&rb)
        .any(|&v| v != a && v != b && (pos[v as usize] - x).norm() > max_edge)
    {
        return false;
    }
    let has = |v: u32, t: [u32; 3]| {
        fans[v as usize].iter().any(|&s| {
            let f = tris[s as usize];
            t.iter().all(|w| f.contains(w))
        })
    };
    let (c, d) = (common[0], common[1]);
    if has(a, [a, c, d]) || has(b, [b, c, d]) {
        return false;
    }
    const MIN_COS: Real = 0.5;
    for (v, fan) in [(a, &fans[a as usize]), (b, &fans[b as usize])] {
        for &t in fan {
            let f = tris[t as usize];
            if f.contains(&a) && f.contains(&b) {
                continue;
            }
            let p = f.map(|w| pos[w as usize]);
            let q = f.map(|w| if w == v { x } else { pos[w as usize] });
            let before = (p[1] - p[0]).cross(&(p[2] - p[0]));
            let after = (q[1] - q[0]).cross(&(q[2] - q[0]));
            let (nb, na) = (before.norm(), after.norm());
            if na <= 1e-12 * nb.max(Real::MIN_POSITIVE) || before.dot(&after) < MIN_COS * nb * na {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::init::surface_topology;

    /// The quad torus with `n × m` faces, radii 1 and `r`.
    fn torus(n: usize, m: usize, r: Real) -> PolyMesh {
        let mut p = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (
                    std::f64::consts::TAU * i as Real / n as Real,
                    std::f64::consts::TAU * j as Real / m as Real,
                );
                let rr = 1.0 + r * v.cos();
                p.push(Point3::new(rr * u.cos(), rr * u.sin(), r * v.sin()));
            }
        }
        let id = |i: usize, j: usize| ((i % n) * m + j % m) as u32;
        let faces: Vec<Vec<u32>> = (0..n)
            .flat_map(|i| {
                (0..m).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
            })
            .collect();
        PolyMesh::from_faces(p, &faces).unwrap()
    }

    #[test]
    fn a_thin_torus_keeps_its_hole_and_stays_near_its_surface() {
        // A torus whose tube (radius 0.05) is 40 times thinner than the ring.
        let mesh = torus(96, 12, 0.05);
        let out = simplified(&mesh, 120, Real::INFINITY).unwrap();
        assert!(out.num_vertices() <= 120, "{}", out.num_vertices());
        let topo = surface_topology(&out).unwrap();
        assert_eq!(
            (topo.genus, topo.components, topo.boundary_loops),
            (1, 1, 0)
        );
        // Every vertex stays on the tube (its distance to the ring circle).
        let worst = out
            .positions
            .iter()
            .map(|p| ((p.x.hypot(p.y) - 1.0).hypot(p.z) - 0.05).abs())
            .fold(0.0, Real::max);
        assert!(worst < 0.02, "{worst}");
        assert_eq!(simplified(&mesh, 120, Real::INFINITY).unwrap(), out);
    }

    #[test]
    fn an_open_surface_is_refused() {
        let quad = PolyMesh::from_faces(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            &[vec![0, 1, 2, 3]],
        )
        .unwrap();
        assert!(simplified(&quad, 3, 1.0).is_err());
    }
}
