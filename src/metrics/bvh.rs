//! `TriangleBvh`: a bounding-volume hierarchy over triangles for exact
//! closest-point (point-to-triangle-mesh distance) and ray-cast queries.
//!
//! Build: binned SAH, collapsed into a 4-wide tree (module `bvh_build`);
//! flat node array in depth-first order with `f32` child boxes rounded
//! outward; triangles copied into leaf order for locality.
//! Queries: closest point in `bvh_closest`, ray cast in `bvh_ray`.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::mesh::PolyMesh;

use super::bvh_build::{Aabb, MAX_DEPTH, build};
use super::bvh_collapse::{Node4, collapse};
use super::self_intersections::pairs_of;
use super::triangle::{PreparedTriangle, check_triangles, triangle_normal};

/// The closest point of a [`TriangleBvh`] to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The closest point on the mesh.
    pub point: Point3,
    /// Its Euclidean distance from the query.
    pub distance: Real,
    /// Index of the triangle it lies on (see [`TriangleBvh::triangles`]).
    pub triangle: usize,
    /// Barycentric coordinates in that triangle (`point = Σ bary[i] · vertex i`).
    pub bary: [Real; 3],
}

/// The first intersection of a ray with a [`TriangleBvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter: the hit is at `origin + t · dir`.
    pub t: Real,
    /// Index of the triangle hit (see [`TriangleBvh::triangles`]).
    pub triangle: usize,
    /// Barycentric coordinates of the hit in that triangle; they sum to 1
    /// and each lies in `[−ε, 1 + ε]`, `ε =` [`RAY_BARY_SLACK`](super::RAY_BARY_SLACK).
    pub bary: [Real; 3],
}

/// Bounding-volume hierarchy over the triangles of a mesh.
///
/// ```
/// use subdyn::math::{Point3, Vector3};
/// use subdyn::metrics::TriangleBvh;
/// let cube = subdyn::examples::cube(); // six quads → twelve triangles
/// let bvh = TriangleBvh::from_mesh(&cube)?;
/// assert_eq!(bvh.triangles().len(), 12);
///
/// let near = bvh.closest_point(Point3::new(0.5, 0.5, 3.0)).unwrap();
/// assert_eq!(near.distance, 2.0);
///
/// let hit = bvh.ray_cast(Point3::new(0.25, 0.5, -1.0), Vector3::z(), f64::INFINITY).unwrap();
/// assert_eq!(hit.t, 1.0);
/// assert_eq!(bvh.face_of(hit.triangle), 4); // the quad on z = 0
/// assert!(bvh.ray_cast(Point3::new(2.0, 0.5, -1.0), Vector3::z(), f64::INFINITY).is_none());
/// # Ok::<(), subdyn::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    positions: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
    faces: Vec<u32>,
    pub(super) nodes: Vec<Node4>,
    /// The centre of the root box; node boxes are relative to it.
    pub(super) origin: [Real; 3],
    /// Largest coordinate of the root box relative to `origin`.
    pub(super) extent: Real,
    /// Triangles in leaf order, prepared for closest-point queries.
    pub(super) leaf_triangles: Vec<PreparedTriangle>,
    /// Triangle corners in leaf order (for ray casts).
    pub(super) leaf_corners: Vec<[Point3; 3]>,
    /// Triangle index of each leaf slot.
    pub(super) leaf_ids: Vec<u32>,
}

impl TriangleBvh {
    /// Builds the hierarchy over `mesh`'s faces, each fan-triangulated from
    /// its first vertex (`(v0, v_i, v_{i+1})`; exact for convex planar
    /// polygons). [`face_of`](Self::face_of) maps triangles back to faces.
    /// Errors on a mesh without faces or an invalid mesh.
    pub fn from_mesh(mesh: &PolyMesh) -> Result<Self> {
        mesh.validate()?;
        if mesh.num_faces() == 0 {
            return Err(Error::input(format!(
                "the mesh has {} vertices but no faces; distances need triangles",
                mesh.num_vertices()
            )));
        }
        let mut triangles = Vec::with_capacity(mesh.face_vertices.len());
        let mut faces = Vec::with_capacity(mesh.face_vertices.len());
        for (f, face) in mesh.faces().enumerate() {
            for i in 1..face.len() - 1 {
                triangles.push([face[0], face[i], face[i + 1]]);
                faces.push(f as u32);
            }
        }
        Self::with_faces(mesh.positions.clone(), triangles, faces)
    }

    /// Builds the hierarchy over explicit triangles (indices into
    /// `positions`). Errors on no triangles, an index out of range or a
    /// non-finite coordinate.
    pub fn new(positions: Vec<Point3>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        let faces = (0..triangles.len() as u32).collect();
        Self::with_faces(positions, triangles, faces)
    }

    fn with_faces(
        positions: Vec<Point3>,
        triangles: Vec<[u32; 3]>,
        faces: Vec<u32>,
    ) -> Result<Self> {
        if triangles.is_empty() {
            return Err(Error::input("no triangles to build a BVH over"));
        }
        check_triangles(&positions, &triangles)?;
        let corners = |tri: &[u32; 3]| tri.map(|v| positions[v as usize]);
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|tri| Aabb::of_triangle(corners(tri)))
            .collect();
        let (binary, leaf_ids) = build(&boxes);
        let root = &binary[0].bounds;
        let origin = [0, 1, 2].map(|k| 0.5 * (root.lo[k] + root.hi[k]));
        let extent = (0..3)
            .map(|k| (root.hi[k] - origin[k]).max(origin[k] - root.lo[k]))
            .fold(0.0, Real::max);
        let nodes = collapse(&binary, &origin);
        let leaf_corners: Vec<[Point3; 3]> = leaf_ids
            .iter()
            .map(|&t| corners(&triangles[t as usize]))
            .collect();
        let leaf_triangles = leaf_corners
            .iter()
            .map(|&[a, b, c]| PreparedTriangle::new(a, b, c))
            .collect();
        Ok(TriangleBvh {
            positions,
            triangles,
            faces,
            nodes,
            origin,
            extent,
            leaf_triangles,
            leaf_corners,
            leaf_ids,
        })
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[Point3] {
        &self.positions
    }

    /// The triangles (vertex indices), in the order [`Nearest::triangle`] and
    /// [`Hit::triangle`] refer to.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The polygon face a triangle came from ([`from_mesh`](Self::from_mesh));
    /// the triangle itself for [`new`](Self::new).
    pub fn face_of(&self, triangle: usize) -> usize {
        self.faces[triangle] as usize
    }

    /// Unit normal of a triangle (right-hand rule; zero when degenerate).
    pub fn triangle_normal(&self, triangle: usize) -> Vector3 {
        let [a, b, c] = self.triangles[triangle].map(|v| self.positions[v as usize]);
        triangle_normal(a, b, c)
    }

    /// Number of (4-wide) nodes of the hierarchy.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// The pairs `[s, t]` (`s < t`, sorted) of the triangles that share no
    /// vertex index and intersect:
    /// [`self_intersecting_pairs`](super::self_intersecting_pairs) of this
    /// hierarchy's triangles (found on a grid, not with the hierarchy).
    pub fn self_intersections(&self) -> Vec<[u32; 2]> {
        pairs_of(&self.positions, &self.triangles)
    }
}

/// Traversal stack size: a visit pops one entry and pushes at most three
/// more than it pops, once per level of the 4-wide tree.
pub(super) const STACK: usize = 3 * (MAX_DEPTH + 2) + 1;

/// The indices 0..4 ordered by increasing `key` (keys are `≥ 0` or `+∞`).
///
/// Branch-free: a non-negative `f32`'s bits order like the number, so each
/// key's two lowest mantissa bits are replaced by its index and the four
/// integers go through a five-comparator sorting network of `min`/`max`
/// (conditional moves, no mispredicted branches). Keys closer than 4 ulp may
/// swap, which changes only the visiting order, never the result.
#[inline]
pub(super) fn ascending(key: &[f32; 4]) -> [usize; 4] {
    let k = [0, 1, 2, 3].map(|i| (key[i].to_bits() & !3) | i as u32);
    let (a, b) = (k[0].min(k[1]), k[0].max(k[1]));
    let (c, d) = (k[2].min(k[3]), k[2].max(k[3]));
    let (a, c) = (a.min(c), a.max(c));
    let (b, d) = (b.min(d), b.max(d));
    let (b, c) = (b.min(c), b.max(c));
    [a, b, c, d].map(|x| (x & 3) as usize)
}
