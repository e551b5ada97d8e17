//! The OpenEXR volume reader.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| subdyn_fuzz::read_volume_file("fuzz.exr", data));
