//! The OBJ reader, as a mesh and as a point cloud, from bytes, and its
//! OpenSubdiv tags from a file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::MeshFormat;

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::read_mesh_and_points(data, MeshFormat::Obj);
    // OpenSubdiv's `t` tag lines, read from the file.
    let dir = subdyn_fuzz::scratch(&["fuzz.obj"]);
    let _ = subdyn::io::read_obj_tags(subdyn_fuzz::file(&dir, "fuzz.obj", data));
});
