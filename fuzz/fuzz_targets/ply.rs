//! The PLY reader, as a mesh and as a point cloud, from bytes; gzip
//! streams also from a `.ply.gz` file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::MeshFormat;

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::read_mesh_and_points(data, MeshFormat::Ply);
    // A gzip stream goes through the file reader's capped inflation.
    if data.starts_with(&[0x1f, 0x8b]) {
        let dir = subdyn_fuzz::scratch(&["fuzz.ply.gz"]);
        let _ = subdyn::io::read_mesh(subdyn_fuzz::file(&dir, "fuzz.ply.gz", data));
    }
});
