//! The lattice JSON reader (topology checks included).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::init();
    let _ = subdyn::io::lattice_from_json(data, Path::new("fuzz.json"));
});
