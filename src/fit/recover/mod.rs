//! Recovering shapes from volumes (MRI, CT, slice stacks): the dynamic
//! surface pulled by image forces, multilevel as for scans (Qin, Mandal,
//! Vemuri 1998, §4.2 and §6).

mod driver;
mod init;
mod pad;
mod params;
mod part_cage;
mod prepare;
mod quality;
mod report;
mod start;
mod two_sided;
mod voxel_components;

pub use driver::{RecoverResult, recover_shape};
pub use init::{ComponentCage, component_cage, seed_cage};
pub use pad::{opened_at_box, padded_at_level};
pub use params::{BONE_HU, RecoverParams, SKIN_HU};
pub use prepare::{PreparedVolume, prepare_volume, prepare_volume_owned};
pub use quality::poor_result;
pub use report::{RecoverLevel, RecoverReport};
pub use start::{CAGE_SIGMA_VOXELS, InitialModel, RecoverStart, initial_model};
