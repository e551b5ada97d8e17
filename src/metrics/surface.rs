//! `Surface`: what [`compare`](super::compare()) measures — a polygon mesh, or
//! the Catmull-Clark limit surface of a control mesh.
//!
//! A surface answers two questions: the closest surface point (with its
//! normal) to each query, and a set of area-weighted sample points on it
//! (with normals).
//!
//! - A **mesh** is fan-triangulated into a [`TriangleBvh`]: exact
//!   point-to-triangle distances, face normals, samples from
//!   [`area_samples`].
//! - A **limit surface** uses *exact projection*: closest points come from
//!   the [`ClosestPointEngine`] (Newton iteration on the limit patches, the
//!   same engine fitting uses), normals are the limit normals. Samples are
//!   drawn area-weighted on a dense limit tessellation (`rate × rate` per
//!   quad, [`tessellate`]) and then projected onto the limit surface by the
//!   engine, so every sample lies on the limit surface itself, not on a
//!   chord. The tessellation's vertices are exact limit points and serve as
//!   the surface's vertices.

use crate::error::Result;
use crate::limit::{ClosestPointEngine, ClosestPointParams, tessellate};
use crate::math::{Point3, Real, Vector3, bbox_diagonal};
use crate::mesh::PolyMesh;
use crate::subdivision::{RefineOptions, Refiner};

use super::batch::distances;
use super::bvh::TriangleBvh;
use super::sampling::area_samples;

/// The closest point of a [`Surface`] to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// The closest surface point.
    pub point: Point3,
    /// Its distance from the query.
    pub distance: Real,
    /// Unit surface normal there (zero where undefined, e.g. a degenerate triangle).
    pub normal: Vector3,
}

/// A surface to measure distances to and to draw samples from.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::metrics::Surface;
/// use subdyn::subdivision::RefineOptions;
/// let cube = subdyn::examples::cube();
/// let mesh = Surface::mesh(&cube)?;
/// let limit = Surface::limit(&cube, &RefineOptions::default(), 4)?;
/// let q = [Point3::new(0.5, 0.5, 2.0)];
/// assert_eq!(mesh.closest_points(&q)?[0].distance, 1.0);
/// // The limit surface of the cube cage lies inside it.
/// assert!(limit.closest_points(&q)?[0].distance > 1.0);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub struct Surface {
    /// The triangles samples are drawn from (the mesh, or the limit tessellation).
    bvh: TriangleBvh,
    /// Exact projection onto the limit surface, for a limit surface.
    engine: Option<ClosestPointEngine>,
    /// Points that lie on the surface: the vertices of the triangles.
    vertices: Vec<Point3>,
}

impl Surface {
    /// The polygon mesh itself (fan-triangulated). Errors on a mesh without faces.
    pub fn mesh(mesh: &PolyMesh) -> Result<Self> {
        Ok(Self::from_bvh(TriangleBvh::from_mesh(mesh)?, None))
    }

    /// The Catmull-Clark limit surface of the control mesh `mesh`, measured
    /// by exact projection; `rate` (1 to 1024) is the tessellation rate used
    /// for sampling (see the module docs).
    pub fn limit(mesh: &PolyMesh, options: &RefineOptions, rate: usize) -> Result<Self> {
        let refiner = Refiner::new(mesh, options)?;
        let (tess, _) = tessellate(&refiner, &mesh.positions, rate)?;
        let engine =
            ClosestPointEngine::new(&refiner, &mesh.positions, &ClosestPointParams::default())?;
        Ok(Self::from_bvh(TriangleBvh::from_mesh(&tess)?, Some(engine)))
    }

    fn from_bvh(bvh: TriangleBvh, engine: Option<ClosestPointEngine>) -> Self {
        let mut used = vec![false; bvh.positions().len()];
        for &v in bvh.triangles().iter().flatten() {
            used[v as usize] = true;
        }
        let vertices = bvh
            .positions()
            .iter()
            .zip(&used)
            .filter_map(|(p, &u)| u.then_some(*p))
            .collect();
        Surface {
            bvh,
            engine,
            vertices,
        }
    }

    /// True for a limit surface.
    pub fn is_limit(&self) -> bool {
        self.engine.is_some()
    }

    /// The triangles: the mesh's, or the limit tessellation's.
    pub fn triangles(&self) -> &TriangleBvh {
        &self.bvh
    }

    /// Points on the surface: the vertices used by the triangles (for a
    /// limit surface, the tessellation's exact limit points).
    pub fn vertices(&self) -> &[Point3] {
        &self.vertices
    }

    /// Length of the bounding-box diagonal of [`vertices`](Self::vertices).
    pub fn diagonal(&self) -> Real {
        bbox_diagonal(&self.vertices)
    }

    /// The closest surface point of every query, in parallel. Errors on a
    /// non-finite query.
    pub fn closest_points(&self, queries: &[Point3]) -> Result<Vec<SurfacePoint>> {
        match &self.engine {
            Some(engine) => Ok(engine
                .closest_points(queries)?
                .into_iter()
                .map(|c| SurfacePoint {
                    point: c.point,
                    distance: c.distance,
                    normal: c.normal,
                })
                .collect()),
            None => Ok(distances(&self.bvh, queries)?
                .into_iter()
                .map(|n| SurfacePoint {
                    point: n.point,
                    distance: n.distance,
                    normal: self.bvh.triangle_normal(n.triangle),
                })
                .collect()),
        }
    }

    /// `n` area-weighted sample points on the surface with their unit
    /// normals, deterministic for `seed` ([`area_samples`]).
    pub fn samples(&self, n: usize, seed: u64) -> Result<Vec<(Point3, Vector3)>> {
        let samples = area_samples(self.bvh.positions(), self.bvh.triangles(), n, seed)?;
        match &self.engine {
            Some(engine) => {
                let points: Vec<Point3> = samples.iter().map(|s| s.0).collect();
                Ok(engine
                    .closest_points(&points)?
                    .into_iter()
                    .map(|c| (c.point, c.normal))
                    .collect())
            }
            None => Ok(samples
                .into_iter()
                .map(|(p, t)| (p, self.bvh.triangle_normal(t)))
                .collect()),
        }
    }
}
