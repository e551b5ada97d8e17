//! How far a finished fit can be trusted, measured on the result itself: the
//! defects an automatic fit can end with and that the per-level error
//! statistics hide (issue 24, "honest failure").
//!
//! - **Surface far from the data** (webs across gaps, flaps past a scan's
//!   border, parts bridged wrongly): the limit surface is tessellated
//!   ([`crate::limit::tessellate`], 4 × 4 samples per face) and each
//!   triangle's centroid is looked up among the data points; triangles more
//!   than [`FAR_PCT`] % of the diagonal from every point are *far*. On a
//!   scan with unseen regions (between legs, under a base) the surface
//!   there is an interpolation, far from every point too: the report cannot
//!   tell a web from a gap in the coverage, it says where.
//! - **Points far from the surface** (a part the model missed: a leg, an
//!   ear): the fraction of the screened points whose distance to the limit
//!   surface exceeds [`FAR_PCT`] % of the diagonal.
//! - **Folds** (pinches, the surface turned over): triangles whose
//!   geometric normal points against the limit normals at all three of its
//!   corners; a fold of the limit surface is where `Sᵤ × Sᵥ` turns over, and
//!   the tessellation's triangles flip there.
//! - **Self-intersections** ([`SelfIntersections`]): pairs of tessellation
//!   triangles that share no vertex and intersect, the test of Open3D's
//!   `is_self_intersecting()`: pleats and pinches where the surface passes
//!   through itself without turning over at any one triangle. The fit
//!   stiffens and refits the faces they come from
//!   ([`FitParams::untangle_rounds`](super::FitParams::untangle_rounds)),
//!   smooths them once more after the last level
//!   ([`FitParams::final_untangle_rounds`](super::FitParams::final_untangle_rounds));
//!   what is left is reported.
//!
//! - **Tangled control faces**: faces of the control mesh that fold over in
//!   their own plane ([`polygon_folds`]): the cage is tangled there, and
//!   triangle-mesh readers that ear-clip polygons (Open3D) refuse the file.
//!
//! Each finding larger than its threshold becomes a one-line warning naming
//! the size and where (the bounding box of the largest connected far
//! region, or of the points), printed by `subdyn fit` and kept in the report.

use std::sync::{Arc, Mutex, PoisonError};

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::limit::{PatchTable, QuadtreeCache, Tessellation};
use crate::math::{Point3, Real, Vector3, bounding_box, polygon_folds};
use crate::mesh::PolyMesh;
use crate::metrics::self_intersecting_pairs;
use crate::subdivision::Refiner;
use crate::topology::{UnionFind, face_of_corner};

/// Samples per side of every tessellation tile [`assess`] checks (the
/// default rate of `subdyn fit --limit-out`).
pub const CHECK_RATE: usize = 4;

/// "Far": more than this percentage of the bounding-box diagonal (the
/// Hausdorff goal of a fit).
pub const FAR_PCT: Real = 1.0;

/// A far surface is reported above this fraction of the surface area.
pub const FAR_AREA_FRACTION: Real = 0.002;

/// Far points are reported above this fraction of the screened points.
pub const FAR_POINT_FRACTION: Real = 0.001;

/// An axis-aligned box (where a finding is).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Region {
    /// Lower corner.
    pub min: [Real; 3],
    /// Upper corner.
    pub max: [Real; 3],
}

impl Region {
    fn of(points: &[Point3]) -> Option<Region> {
        bounding_box(points).map(|(lo, hi)| Region {
            min: [lo.x, lo.y, lo.z],
            max: [hi.x, hi.y, hi.z],
        })
    }

    fn describe(&self) -> String {
        let f = |v: [Real; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
        format!("{} to {}", f(self.min), f(self.max))
    }
}

/// The findings of [`assess`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FitQuality {
    /// Fraction of the limit surface's area farther than [`FAR_PCT`] % of
    /// the diagonal from every data point.
    pub far_surface_fraction: Real,
    /// The largest connected far part of the surface.
    pub far_surface_region: Option<Region>,
    /// Fraction of the screened points farther than [`FAR_PCT`] % of the
    /// diagonal from the surface.
    pub far_point_fraction: Real,
    /// Where those points are.
    pub far_point_region: Option<Region>,
    /// Triangles of the 4 × 4 tessellation turned over against the limit
    /// normals (folds).
    pub folded_triangles: usize,
    /// Triangles of that tessellation.
    pub triangles: usize,
    /// Pairs of those triangles that share no vertex and intersect.
    pub self_intersecting_pairs: usize,
    /// Where they are.
    pub self_intersection_region: Option<Region>,
    /// Control faces that fold over in their plane ([`polygon_folds`]).
    pub tangled_faces: usize,
    /// Where they are.
    pub tangled_face_region: Option<Region>,
    /// One line per finding above its threshold.
    pub warnings: Vec<String>,
}

/// Assesses the limit surface of `control`, whose tessellation at
/// [`CHECK_RATE`] and self-intersections are `sx`, against the screened
/// `data` points (`data_tree` over them), whose distances to the surface
/// are `distance`; `diameter` is the data's bounding-box diagonal.
pub fn assess(
    control: &PolyMesh,
    sx: SelfIntersections,
    data: &[Point3],
    data_tree: &ImmutableKdTree<Real, 3>,
    distance: &[Real],
    diameter: Real,
) -> Result<FitQuality> {
    let far = FAR_PCT / 100.0 * diameter;
    let (tris, p, normals) = (sx.triangles(), &sx.positions, &sx.normals);
    // Per triangle: area, far from the data, folded.
    let facts: Vec<(Real, bool, bool)> = tris
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            let n = (b - a).cross(&(c - a));
            let centre = Point3::from((a.coords + b.coords + c.coords) / 3.0);
            let nn = data_tree.nearest_one::<SquaredEuclidean>(&[centre.x, centre.y, centre.z]);
            let folded = t.iter().all(|&i| normals[i as usize].dot(&n) < 0.0);
            (0.5 * n.norm(), nn.distance.sqrt() > far, folded)
        })
        .collect();
    let area: Real = facts.iter().map(|f| f.0).sum();
    let far_area: Real = facts.iter().filter(|f| f.1).map(|f| f.0).sum();
    let far_surface_fraction = if area > 0.0 { far_area / area } else { 0.0 };
    let far_surface_region =
        largest_region(tris, p, &facts.iter().map(|f| f.1).collect::<Vec<_>>());
    let far_points: Vec<Point3> = data
        .iter()
        .zip(distance)
        .filter(|(_, d)| **d > far)
        .map(|(q, _)| *q)
        .collect();
    let far_point_fraction = far_points.len() as Real / data.len().max(1) as Real;
    let folded_triangles = facts.iter().filter(|f| f.2).count();
    let tangled: Vec<&[u32]> = control
        .faces()
        .filter(|f| polygon_folds(&control.positions, f))
        .collect();
    let mut q = FitQuality {
        far_surface_fraction,
        far_surface_region,
        far_point_fraction,
        far_point_region: Region::of(&far_points),
        folded_triangles,
        triangles: tris.len(),
        self_intersecting_pairs: sx.pairs.len(),
        self_intersection_region: Region::of(
            &sx.pairs
                .iter()
                .flatten()
                .flat_map(|&t| tris[t as usize].map(|v| p[v as usize]))
                .collect::<Vec<_>>(),
        ),
        tangled_faces: tangled.len(),
        tangled_face_region: Region::of(
            &tangled
                .iter()
                .flat_map(|f| f.iter().map(|&v| control.positions[v as usize]))
                .collect::<Vec<_>>(),
        ),
        warnings: Vec::new(),
    };
    if q.far_surface_fraction > FAR_AREA_FRACTION {
        q.warnings.push(format!(
            "{:.1} % of the surface is more than {FAR_PCT} % of the diagonal from every point \
             (a web, a flap, or a region the scan did not see); the largest such part spans {}",
            100.0 * q.far_surface_fraction,
            q.far_surface_region.map_or(String::new(), |r| r.describe())
        ));
    }
    if q.far_point_fraction > FAR_POINT_FRACTION {
        q.warnings.push(format!(
            "{:.2} % of the points are more than {FAR_PCT} % of the diagonal from the surface \
             (a part the model missed?), within {}",
            100.0 * q.far_point_fraction,
            q.far_point_region.map_or(String::new(), |r| r.describe())
        ));
    }
    if q.folded_triangles > 0 {
        q.warnings.push(format!(
            "the limit surface folds over: {} of {} tessellation triangles face against its normals",
            q.folded_triangles, q.triangles
        ));
    }
    if q.tangled_faces > 0 {
        q.warnings.push(format!(
            "{} of the {} control faces fold over in their plane (a tangled cage; Open3D refuses \
             such a control mesh as PLY or OFF), within {}",
            q.tangled_faces,
            control.num_faces(),
            q.tangled_face_region
                .map_or(String::new(), |r| r.describe())
        ));
    }
    if q.self_intersecting_pairs > 0 {
        q.warnings.push(format!(
            "the limit surface intersects itself: {} pairs of its {} tessellation triangles cross, within {}",
            q.self_intersecting_pairs,
            q.triangles,
            q.self_intersection_region
                .map_or(String::new(), |r| r.describe())
        ));
    }
    Ok(q)
}

/// The limit surface tessellated `rate × rate` per tile ([`tessellate`]),
/// fan-triangulated, and its self-intersecting triangle pairs
/// ([`self_intersecting_pairs`]).
pub struct SelfIntersections {
    /// Tessellation vertices.
    pub positions: Vec<Point3>,
    /// Limit normals at them.
    pub normals: Vec<Vector3>,
    /// The control face each triangle lies on.
    pub face: Vec<u32>,
    /// Intersecting pairs (indices into [`triangles`](Self::triangles)).
    pub pairs: Vec<[u32; 2]>,
    /// The control points checked.
    control: Vec<Point3>,
    /// What [`moved`](Self::moved) reuses of the first check
    /// ([`of`](Self::of)).
    first: Arc<FirstCheck>,
}

/// What [`SelfIntersections::moved`] reuses of the first check: the
/// tessellation, its triangles and the patch table.
struct FirstCheck {
    triangles: Vec<[u32; 3]>,
    plan: Tessellation,
    table: Mutex<PatchTable>,
}

impl SelfIntersections {
    /// The tessellation of the limit surface of `refiner`'s mesh with
    /// control points `positions`, and its self-intersections.
    pub fn of(refiner: &Refiner, positions: &[Point3], rate: usize) -> Result<Self> {
        Self::with_quadtrees(refiner, positions, rate, QuadtreeCache::default())
    }

    /// [`of`](Self::of) with the quadtrees of irregular patches looked up
    /// in and added to `quadtrees` (a fit's checks share the fit's cache:
    /// most local structures recur from check to check and level to level).
    pub fn with_quadtrees(
        refiner: &Refiner,
        positions: &[Point3],
        rate: usize,
        quadtrees: QuadtreeCache,
    ) -> Result<Self> {
        let plan = Tessellation::new(refiner, rate)?;
        let table = PatchTable::with_quadtrees(refiner, positions, 1, quadtrees)?;
        let (points, normals) = plan.evaluate(&table, None)?;
        let mesh = plan.mesh(points)?;
        let level = &refiner.level;
        // `tessellate` gives every face one tile when all are quads, else
        // one per corner, each rate² quads in tile order.
        let quads = (0..level.num_faces()).all(|f| level.face_vertices(f).len() == 4);
        let corner_face = face_of_corner(&level.face_offsets);
        let per_tile = rate * rate;
        let mut triangles = Vec::with_capacity(2 * mesh.num_faces());
        let mut face = Vec::with_capacity(2 * mesh.num_faces());
        for q in 0..mesh.num_faces() {
            let v = mesh.face(q);
            let tile = q / per_tile;
            let f = if quads {
                tile as u32
            } else {
                corner_face[tile]
            };
            for i in 1..v.len() - 1 {
                triangles.push([v[0], v[i], v[i + 1]]);
                face.push(f);
            }
        }
        let pairs = self_intersecting_pairs(&mesh.positions, &triangles)?;
        Ok(SelfIntersections {
            positions: mesh.positions,
            normals,
            face,
            pairs,
            control: positions.to_vec(),
            first: Arc::new(FirstCheck {
                triangles,
                plan,
                table: Mutex::new(table),
            }),
        })
    }

    /// The same check after the control points moved to `positions`: the
    /// pairs [`of`](Self::of) would give. Only the faces whose limit surface
    /// moved (those with a vertex sharing a face with a moved control point)
    /// are evaluated again.
    pub fn moved(&self, refiner: &Refiner, positions: &[Point3]) -> Result<Self> {
        let level = &refiner.level;
        let moved: Vec<bool> = self
            .control
            .iter()
            .zip(positions)
            .map(|(a, b)| a != b)
            .collect();
        let mut near = vec![false; level.num_vertices];
        for f in 0..level.num_faces() {
            let fv = level.face_vertices(f);
            if fv.iter().any(|&v| moved[v as usize]) {
                for &v in fv {
                    near[v as usize] = true;
                }
            }
        }
        let faces: Vec<bool> = (0..level.num_faces())
            .map(|f| level.face_vertices(f).iter().any(|&v| near[v as usize]))
            .collect();
        let first = &*self.first;
        // A poisoned lock still holds a whole table: `set_positions` below
        // overwrites every position it uses.
        let mut table = first.table.lock().unwrap_or_else(PoisonError::into_inner);
        table.set_positions(positions)?;
        let (points, normals) = first
            .plan
            .evaluate(&table, Some((&faces, &self.positions, &self.normals)))?;
        Ok(SelfIntersections {
            pairs: self_intersecting_pairs(&points, &first.triangles)?,
            positions: points,
            normals,
            face: self.face.clone(),
            control: positions.to_vec(),
            first: self.first.clone(),
        })
    }

    /// Tessellation triangles (indices into `positions`).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.first.triangles
    }

    /// Per control face of the mesh (`num_faces` of them): whether a
    /// triangle on it takes part in a self-intersection.
    pub fn faces(&self, num_faces: usize) -> Vec<bool> {
        let mut out = vec![false; num_faces];
        for &t in self.pairs.iter().flatten() {
            out[self.face[t as usize] as usize] = true;
        }
        out
    }
}

/// The bounding box of the largest (by triangle count) connected set of
/// `marked` triangles, triangles connected through shared vertices.
fn largest_region(tris: &[[u32; 3]], p: &[Point3], marked: &[bool]) -> Option<Region> {
    let mut sets = UnionFind::new(p.len());
    let far = || tris.iter().zip(marked).filter(|(_, m)| **m).map(|(t, _)| t);
    for t in far() {
        sets.union(t[0] as usize, t[1] as usize);
        sets.union(t[0] as usize, t[2] as usize);
    }
    let mut count = std::collections::BTreeMap::<usize, usize>::new();
    for t in far() {
        *count.entry(sets.find(t[0] as usize)).or_default() += 1;
    }
    let (&best, _) = count
        .iter()
        .max_by_key(|(r, c)| (**c, std::cmp::Reverse(**r)))?;
    let vertices: Vec<Point3> = far()
        .filter(|t| sets.find(t[0] as usize) == best)
        .flat_map(|t| t.map(|i| p[i as usize]))
        .collect();
    Region::of(&vertices)
}
