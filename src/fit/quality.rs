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
//!
//! Each finding larger than its threshold becomes a one-line warning naming
//! the size and where (the bounding box of the largest connected far
//! region, or of the points), printed by `subdyn fit` and kept in the report.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::limit::tessellate;
use crate::math::{Point3, Real, bounding_box};
use crate::mesh::PolyMesh;
use crate::subdivision::{RefineOptions, Refiner};
use crate::topology::UnionFind;

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
    /// One line per finding above its threshold.
    pub warnings: Vec<String>,
}

/// Assesses the limit surface of `control` against the screened `data`
/// points (`data_tree` over them), whose distances to the surface are
/// `distance`; `diameter` is the data's bounding-box diagonal.
pub fn assess(
    control: &PolyMesh,
    data: &[Point3],
    data_tree: &ImmutableKdTree<Real, 3>,
    distance: &[Real],
    diameter: Real,
) -> Result<FitQuality> {
    let far = FAR_PCT / 100.0 * diameter;
    let refiner = Refiner::new(control, &RefineOptions::default())?;
    let (mesh, normals) = tessellate(&refiner, &control.positions, 4)?;
    let tris: Vec<[u32; 3]> = (0..mesh.num_faces())
        .flat_map(|f| {
            let v = mesh.face(f);
            (1..v.len() - 1).map(move |i| [v[0], v[i], v[i + 1]])
        })
        .collect();
    let p = &mesh.positions;
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
        largest_region(&tris, p, &facts.iter().map(|f| f.1).collect::<Vec<_>>());
    let far_points: Vec<Point3> = data
        .iter()
        .zip(distance)
        .filter(|(_, d)| **d > far)
        .map(|(q, _)| *q)
        .collect();
    let far_point_fraction = far_points.len() as Real / data.len().max(1) as Real;
    let folded_triangles = facts.iter().filter(|f| f.2).count();
    let mut q = FitQuality {
        far_surface_fraction,
        far_surface_region,
        far_point_fraction,
        far_point_region: Region::of(&far_points),
        folded_triangles,
        triangles: tris.len(),
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
    Ok(q)
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
