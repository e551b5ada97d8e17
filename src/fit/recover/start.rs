//! [`initial_model`]: where `subdyn recover` starts (a seed sphere, the
//! cage of a connected component, or a given mesh), shared by the CLI and
//! the Python package.

use serde_json::{Value, json};

use super::init::{component_cage, seed_cage};
use super::prepare::PreparedVolume;
use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::mesh::PolyMesh;
use crate::volume::gaussian_smoothed;

/// The least smoothing, in voxels, of the volume the automatic cage and its
/// component are taken from (the iso-surface's default σ before the image
/// forces got less): less joins and splits components on real images (the
/// MNI ventricle's dark component at ¼ voxel holds eight times the control
/// points).
pub const CAGE_SIGMA_VOXELS: Real = 0.5;

/// Where a recovery starts.
#[derive(Clone, Debug)]
pub enum RecoverStart {
    /// A small sphere ([`seed_cage`]) of `radius_voxels` voxels around
    /// `point`, which must lie inside the object (genus 0 only).
    Seed {
        /// World point inside the object.
        point: Point3,
        /// Radius in voxels.
        radius_voxels: Real,
    },
    /// The cage of the object above the inside level ([`component_cage`]):
    /// the connected component holding `seed`, else every part (the
    /// largest component and those of at least 1 % of its voxels); any
    /// genus.
    Auto {
        /// World point selecting the component.
        seed: Option<Point3>,
        /// Cage cells along the object's longest side (2 to 128).
        resolution: usize,
    },
    /// A given closed control mesh in world coordinates.
    Mesh(PolyMesh),
}

/// What a recovery starts from ([`initial_model`]).
#[derive(Clone, Debug)]
pub struct InitialModel {
    /// The initial control mesh.
    pub mesh: PolyMesh,
    /// The object's iso-surface points for the two-sided forces
    /// ([`ComponentCage::boundary`](super::ComponentCage::boundary)) when
    /// the object is known (an automatic cage); empty otherwise.
    pub boundary: Vec<Point3>,
    /// The `init` object of `subdyn recover --report` (`method`: `seed`,
    /// `auto` or `mesh`, with the counts).
    pub report: Value,
}

/// The initial model for `start` in `prepared`. `bright_inside` is false
/// for dark objects.
pub fn initial_model(
    prepared: &PreparedVolume,
    start: &RecoverStart,
    bright_inside: bool,
) -> Result<InitialModel> {
    let volume = &prepared.smoothed;
    match start {
        RecoverStart::Seed {
            point: p,
            radius_voxels,
        } => {
            if !volume.contains(p) {
                let (lo, hi) = volume.world_bounds();
                return Err(Error::input(format!(
                    "seed ({}, {}, {}) lies outside the volume, which spans ({:.2}, {:.2}, {:.2}) to ({:.2}, {:.2}, {:.2})",
                    p.x, p.y, p.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
                )));
            }
            let v = volume.sample(p);
            let inside = if bright_inside {
                v > prepared.inside_level
            } else {
                v < prepared.inside_level
            };
            if !inside {
                return Err(Error::input(format!(
                    "seed ({}, {}, {}) is not inside the object: the smoothed intensity there is {v:.4}, {} the inside level {:.4}",
                    p.x,
                    p.y,
                    p.z,
                    if bright_inside {
                        "not above"
                    } else {
                        "not below"
                    },
                    prepared.inside_level
                )));
            }
            if !(radius_voxels.is_finite() && *radius_voxels > 0.0) {
                return Err(Error::input(format!(
                    "seed radius {radius_voxels} must be positive"
                )));
            }
            let mesh = seed_cage(*p, radius_voxels * volume.voxel_size())?;
            let value = json!({"method": "seed", "seed": [p.x, p.y, p.z],
                "radius_voxels": radius_voxels,
                "vertices": mesh.num_vertices(), "faces": mesh.num_faces()});
            Ok(InitialModel {
                mesh,
                boundary: Vec::new(),
                report: value,
            })
        }
        RecoverStart::Mesh(mesh) => {
            let value = json!({"method": "mesh",
                "vertices": mesh.num_vertices(), "faces": mesh.num_faces()});
            Ok(InitialModel {
                mesh: mesh.clone(),
                boundary: Vec::new(),
                report: value,
            })
        }
        RecoverStart::Auto { seed, resolution } => {
            if !(2..=128).contains(resolution) {
                return Err(Error::out_of_range(format!(
                    "resolution {resolution} is out of range: expected 2 to 128"
                )));
            }
            // The object and its cage are taken at no less than
            // [`CAGE_SIGMA_VOXELS`] of smoothing: Gaussians compose, so a
            // volume smoothed less is smoothed by the difference.
            let cage_sigma = CAGE_SIGMA_VOXELS * volume.voxel_size();
            let smoother = (prepared.sigma < cage_sigma)
                .then(|| {
                    gaussian_smoothed(volume, (cage_sigma.powi(2) - prepared.sigma.powi(2)).sqrt())
                })
                .transpose()?;
            let cage = component_cage(
                smoother.as_ref().unwrap_or(volume),
                volume,
                prepared.inside_level,
                bright_inside,
                *seed,
                *resolution,
            )?;
            let value = json!({"method": "auto", "component_voxels": cage.voxels,
                "components": cage.components, "parts": cage.parts, "block_voxels": cage.block,
                "lost_voxels": cage.lost_voxels, "simplified_from_block": cage.simplified_from,
                "genus": cage.genus, "boundary_points": cage.boundary.len(),
                "vertices": cage.mesh.num_vertices(), "faces": cage.mesh.num_faces()});
            Ok(InitialModel {
                mesh: cage.mesh,
                boundary: cage.boundary,
                report: value,
            })
        }
    }
}
