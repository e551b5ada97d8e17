//! The OpenEXR volume reader.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::{VolumeReadOptions, read_volume};

fuzz_target!(|data: &[u8]| {
    let dir = subdyn_fuzz::scratch(&["fuzz.exr"]);
    let _ = read_volume(
        subdyn_fuzz::file(&dir, "fuzz.exr", data),
        &VolumeReadOptions::default(),
    );
});
