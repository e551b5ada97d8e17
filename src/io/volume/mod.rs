//! Reading volumes (MRI, CT, slice stacks) into [`Volume`](crate::volume::Volume):
//! NIfTI-1 (`.nii`, `.nii.gz`), directories of PNG / TIFF / EXR slices,
//! multi-page TIFF, single EXR images and raw samples with a JSON header.
//! See [`read_volume`] for the conventions and the precedence of the
//! voxel-to-world sources.

mod decoded;
mod detect;
mod exr;
mod nifti;
mod nifti_header;
mod raw;
mod read;
mod samples;
mod sidecar;
mod slices;
mod tiff;

pub use detect::VolumeFormat;
pub use read::{VolumeFile, VolumeReadOptions, read_volume};
