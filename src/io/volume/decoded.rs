//! [`Decoded`]: what a format reader returns before the voxel-to-world map is
//! settled (command-line overrides, sidecar, defaults) in `read`.

use nalgebra::Matrix3;

use crate::math::{Point3, Real};

/// Where the file puts the grid in the world.
#[derive(Clone, Debug)]
pub(crate) enum Placement {
    /// The file gives the whole map `world = origin + linear · index` (NIfTI).
    Affine {
        /// Linear part, mm per index step.
        linear: Matrix3<Real>,
        /// World position of voxel (0, 0, 0).
        origin: Point3,
    },
    /// The file may give an axis-aligned spacing (TIFF ImageJ metadata) and
    /// nothing else; the rest comes from the sidecar or the defaults.
    Grid {
        /// Spacing from the file's own metadata, when it has any.
        spacing: Option<[Real; 3]>,
    },
}

/// Samples and geometry as one format reader found them.
#[derive(Clone, Debug)]
pub(crate) struct Decoded {
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Samples, x fastest.
    pub data: Vec<f32>,
    /// The file's own placement.
    pub placement: Placement,
    /// Format description, e.g. `NIfTI-1 .nii.gz, u8, little-endian`.
    pub source: String,
    /// What the reader decided on the way.
    pub notes: Vec<String>,
    /// Whether the samples are already physical (NIfTI applies its own
    /// `scl_slope`), so a sidecar's intensity scale must not be applied again.
    pub physical: bool,
}
