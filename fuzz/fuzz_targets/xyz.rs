//! The XYZ reader, as a mesh and as a point cloud, from bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::MeshFormat;

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::read_mesh_and_points(data, MeshFormat::Xyz);
});
