//! The OBJ reader, as a mesh and as a point cloud, from bytes, and its
//! OpenSubdiv tags from a file.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use subdyn::io::{MeshFormat, read_mesh_from_bytes, read_points_from_bytes};

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::init();
    let name = Path::new("fuzz.obj");
    let _ = read_mesh_from_bytes(data, MeshFormat::Obj, name);
    let _ = read_points_from_bytes(data, MeshFormat::Obj, name);
    // OpenSubdiv's `t` tag lines, read from the file.
    let dir = subdyn_fuzz::scratch(&["fuzz.obj"]);
    let _ = subdyn::io::read_obj_tags(subdyn_fuzz::file(&dir, "fuzz.obj", data));
});
