//! Reading and writing meshes, point clouds and crease lists; reading
//! volumes ([`read_volume`]: NIfTI-1, slice directories, TIFF, EXR, raw + JSON).
//!
//! Formats: OBJ, PLY (ASCII and binary, either byte order), OFF and XYZ, each
//! optionally gzip-compressed (`.ply.gz`, `.obj.gz`, …). The format follows the
//! file extension ([`MeshFormat::from_path`]). Every writer goes through
//! [`atomic_write`], so a failed write never leaves a half-written file.
//!
//! ```no_run
//! use subdyn::io::{read_mesh, write_mesh};
//! let cage = read_mesh("cage.obj")?;
//! write_mesh("cage.ply", &cage, None)?;
//! # Ok::<(), subdyn::Error>(())
//! ```

mod atomic;
mod batch;
mod creases;
mod format;
mod lattice;
mod obj;
mod off;
mod ply;
mod raw;
mod read;
mod source;
mod text;
mod volume;
mod write;
mod xyz;

pub use atomic::{atomic_write, check_writable, remove_temporary_files};
pub use batch::{OutputBatch, check_output_dir_path, create_output_dir};
pub use creases::{ObjTags, SubdivisionTags, read_obj_tags, read_tags, write_tags};
pub use format::MeshFormat;
pub use lattice::{
    LATTICE_FORMAT, is_lattice_file, lattice_from_json, lattice_to_json, read_lattice,
    write_lattice,
};
pub use read::{
    read_mesh, read_mesh_from_bytes, read_obj_from_bytes, read_points, read_points_from_bytes,
};
pub(crate) use source::open_regular;
pub use source::read_input;
pub use volume::{VolumeFile, VolumeFormat, VolumeReadOptions, read_volume};
pub use write::{write_control_mesh, write_mesh, write_mesh_with_creases, write_points};
