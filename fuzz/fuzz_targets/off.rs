//! The OFF reader, as a mesh and as a point cloud, from bytes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use subdyn::io::{MeshFormat, read_mesh_from_bytes, read_points_from_bytes};

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::init();
    let name = Path::new("fuzz.off");
    let _ = read_mesh_from_bytes(data, MeshFormat::Off, name);
    let _ = read_points_from_bytes(data, MeshFormat::Off, name);
});
