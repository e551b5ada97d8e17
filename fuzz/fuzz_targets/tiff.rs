//! The multi-page TIFF volume reader.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::{VolumeReadOptions, read_volume};

fuzz_target!(|data: &[u8]| {
    let dir = subdyn_fuzz::scratch(&["fuzz.tif"]);
    let _ = read_volume(
        subdyn_fuzz::file(&dir, "fuzz.tif", data),
        &VolumeReadOptions::default(),
    );
});
