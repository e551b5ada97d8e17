//! `PointCloud`: positions with optional normals.

use crate::error::{Error, Result};
use crate::math::{Point3, Vector3};

/// A set of points, optionally with one normal per point.
///
/// ```
/// use subdyn::mesh::PointCloud;
/// use subdyn::math::Point3;
/// let cloud = PointCloud::new(vec![Point3::origin(), Point3::new(1.0, 2.0, 3.0)], None).unwrap();
/// assert_eq!(cloud.len(), 2);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointCloud {
    /// Point positions.
    pub positions: Vec<Point3>,
    /// Normals, one per point, when the source had them.
    pub normals: Option<Vec<Vector3>>,
}

impl PointCloud {
    /// Builds a cloud, checking finite coordinates and that normals (if any)
    /// match the points one to one.
    pub fn new(positions: Vec<Point3>, normals: Option<Vec<Vector3>>) -> Result<Self> {
        super::poly_mesh::check_finite(&positions)?;
        if let Some(n) = &normals
            && n.len() != positions.len()
        {
            return Err(Error::size_mismatch(format!(
                "{} normals for {} points",
                n.len(),
                positions.len()
            )));
        }
        Ok(PointCloud { positions, normals })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True when the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
}
